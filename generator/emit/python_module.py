# The part of every emitted Python module (`hamel emit --python`) that is the same for all packages: the region below
# is printed as it stands into <name>.py, after the package's data (name, stamp, sizes, names, default parameters,
# the kernels' output shapes) and before one line per kernel binding it (emit/python_module.cpp writes both). It
# loads lib<name>_python (the kernels and the batch entry points of <name>_python.cpp) with ctypes and needs NumPy,
# nothing else. Everything here is MIT-licensed, as the emitted code it becomes part of.
# hamel emit: python_module begin
import ctypes as _ctypes
import math as _math
import os as _os

import numpy as _np

status_meanings = {
    0: "ok",
    1: "the mass matrix (or an articulated inertia of the recursive solve) is not positive definite",
    2: "a result is not finite",
}


class StatusError(ArithmeticError):
    """A status-returning entry point (rhs_status) met a bad state.

    status: the first bad state's status (1 or 2, see status_meanings); index: its row in a batch (None for
    one state); statuses: every state's status (an int array, 0 where the state was fine); result: the outputs,
    NaN in the rows of bad states."""

    def __init__(self, message, status, index, statuses, result):
        super().__init__(message)
        self.status = status
        self.index = index
        self.statuses = statuses
        self.result = result


def _load():
    here = _os.path.dirname(_os.path.abspath(__file__))
    override = _os.environ.get("HAMEL_" + name.upper() + "_PYTHON_LIBRARY")
    files = ["lib" + name + "_python.so", "lib" + name + "_python.dylib", name + "_python.dll"]
    candidates = [override] if override else [_os.path.join(here, f) for f in files]
    path = next((c for c in candidates if _os.path.isfile(c)), None)
    if path is None:
        raise ImportError(
            name + ": no compiled library " + " or ".join(candidates) + "; build the package with CMake "
            "(cmake -S <package folder> -B <build folder> && cmake --build <build folder>) and import " + name +
            " from the build folder, which holds " + name + ".py and the library")
    lib = _ctypes.CDLL(path)
    for real, numpy_type in (("double", _np.float64), ("float", _np.float32)):
        try:
            stamp_of = getattr(lib, name + "_python_stamp_" + real)
        except AttributeError:
            continue
        stamp_of.restype = _ctypes.c_char_p
        stamp_of.argtypes = []
        built = stamp_of().decode("utf-8", "replace")
        if built != stamp:
            raise ImportError(name + ": " + path + " was built from another emit (" + built + ") than " + __file__ +
                              " (" + stamp + "); rebuild the package")
        return lib, real, _np.dtype(numpy_type)
    raise ImportError(name + ": " + path + " has no " + name + "_python_stamp_double: not the library of " + name +
                      " emitted with --python")


_lib, real_type, dtype = _load()
_SIZE = _ctypes.c_ssize_t
_POINTER = _ctypes.c_void_p


def _real_array(value, what, where):
    if getattr(getattr(value, "dtype", None), "kind", "") == "c":  # NumPy would drop the imaginary part
        raise TypeError(where + ": " + what + " is complex; expected real numbers")
    return _np.asarray(value, dtype=dtype, order="C")


def _rows_of(value, width, what, where):
    # (array, row step, rows): one row shared by every state (step 0, rows None) or one row per state.
    a = _real_array(value, what, where)
    if a.ndim == 1 and a.shape[0] == width:
        return a, 0, None
    if a.ndim == 2 and a.shape[1] == width:
        return a, width, a.shape[0]
    raise ValueError(where + ": " + what + " has shape " + str(_np.shape(value)) + "; expected (" + str(width) +
                     ",) or (N, " + str(width) + ")")


def _scalars_of(value, what, where):
    a = _real_array(value, what, where)
    if a.ndim == 0:
        return a, 0, None
    if a.ndim == 1:
        return a, 1, a.shape[0]
    raise ValueError(where + ": " + what + " has shape " + str(_np.shape(value)) + "; expected a number or (N,)")


def _optional_rows(value, width, default, what, where):
    # Parameters or inputs: None is the default (a null pointer where there are none).
    if value is None:
        if default is None and width > 0:
            raise TypeError(where + ": the model has " + what + " (" + ", ".join(input_names) + "); pass " + what +
                            "= of shape (" + str(width) + ",) or (N, " + str(width) + ")")
        if default is None:
            return None, 0, None
        return default, 0, None
    return _rows_of(value, width, what, where)


def _batch_rows(where, arguments):
    # The number of states: the rows of every argument given per state, which must agree; None for one state.
    rows = None
    for what, (_, _, n) in arguments:
        if n is not None and rows is not None and n != rows:
            raise ValueError(where + ": " + what + " has " + str(n) + " rows, an argument before it " + str(rows))
        if n is not None:
            rows = n
    return rows


def _pointer(a):
    return None if a is None else a.ctypes.data


def _state_arguments(where, t, x, p, inputs, p_width, p_default):
    # (rows, the pointers and steps to pass, the arrays): the caller keeps the arrays until the call has returned.
    arguments = [("t", _scalars_of(t, "t", where)), ("x", _rows_of(x, n_state, "x", where)),
                 ("p", _optional_rows(p, p_width, p_default, "p", where)),
                 ("inputs", _optional_rows(inputs, n_inputs, None, "inputs", where))]
    rows = _batch_rows(where, arguments)
    flat = []
    for _, (a, step, _) in arguments:
        flat += [_pointer(a), step]
    return rows, flat, arguments


def _bind(symbol, arguments, result):
    function = getattr(_lib, name + "_" + symbol + "_batch_" + real_type)
    function.argtypes = arguments
    function.restype = result
    return function


_KERNEL_ARGUMENTS = [_SIZE] + [_POINTER, _SIZE] * 5


def _output(out, rows, shape, where):
    # A new array for the outputs, or the caller's `out` (as (rows,) + shape, a view of the same memory).
    full = (1 if rows is None else rows,) + shape
    if out is None:
        return _np.empty(full, dtype=dtype)
    expected = shape if rows is None else full
    if not (isinstance(out, _np.ndarray) and out.shape == expected and out.dtype == dtype and
            out.flags.c_contiguous and out.flags.writeable):
        raise ValueError(where + ": out must be a writable C-contiguous " + str(dtype) + " array of shape " +
                         str(expected) + "; got " + (str(out.dtype) + " " + str(out.shape) if
                                                     isinstance(out, _np.ndarray) else type(out).__name__))
    return out.reshape(full)


def _kernel(kernel, prepared=False):
    shape, names, summary = kernels[kernel]
    width = _math.prod(shape)
    function = _bind(kernel, _KERNEL_ARGUMENTS, None)
    where = name + "." + kernel

    def call(t, x, p=None, inputs=None, out=None):
        p_default = default_prepared_parameters if prepared else default_parameters
        rows, flat, keep = _state_arguments(where, t, x, p, inputs,
                                            n_prepared_parameters if prepared else n_parameters, p_default)
        result = _output(out, rows, shape, where)
        function(1 if rows is None else rows, *flat, result.ctypes.data, width)
        del keep
        if out is not None:
            return out
        return result[0] if rows is None else result

    call.__name__ = call.__qualname__ = kernel
    call.__doc__ = (summary + ".\n\n" + kernel + "(t, x, p=None, inputs=None): t a number or (N,), x (n_state,) or (N, "
                    "n_state), p (" + ("n_prepared_parameters" if prepared else "n_parameters") + ",) or (N, ...) "
                    "(None: the defaults" + (", prepared" if prepared else "") + "), inputs (n_inputs,) or (N, "
                    "n_inputs). Returns shape " + str(shape) + ", or (N,) + " + str(shape) + " for N states; into "
                    "out when given (a C-contiguous array of that shape and dtype, written in place). "
                    "Outputs: " + ", ".join(names[:12]) + (", ..." if len(names) > 12 else "") + ".")
    return call


def _rhs_status():
    shape = kernels["rhs"][0]
    function = _bind("rhs_status", _KERNEL_ARGUMENTS + [_POINTER], _SIZE)
    where = name + ".rhs_status"

    def rhs_status(t, x, p=None, inputs=None):
        """rhs with a status: returns what rhs returns, or raises StatusError (a subclass of ArithmeticError)
        carrying the status (1: mass matrix not positive definite, 2: a result not finite) when a state is bad."""
        rows, flat, arguments = _state_arguments(where, t, x, p, inputs, n_parameters, default_parameters)
        n = 1 if rows is None else rows
        out = _np.full((n,) + shape, _np.nan, dtype=dtype)
        statuses = _np.zeros(n, dtype=_np.intc)
        bad = function(n, *flat, out.ctypes.data, shape[0], statuses.ctypes.data)
        result = out[0] if rows is None else out
        if bad:
            index = int(_np.flatnonzero(statuses)[0])
            status = int(statuses[index])
            x_row = arguments[1][1][0]
            state = x_row if x_row.ndim == 1 else x_row[index]
            at = "the state" if rows is None else "state " + str(index) + " of " + str(rows)
            raise StatusError(where + ": status " + str(status) + " (" + status_meanings[status] + ") at " + at +
                              " x = " + _np.array2string(state, separator=", ") +
                              ("" if rows is None else "; " + str(bad) + " bad states"),
                              status, None if rows is None else index, statuses, result)
        return result

    return rhs_status


def _rk4_step():
    function = _bind("rk4_step", [_SIZE] + [_POINTER, _SIZE] * 6, None)
    where = name + ".rk4_step"

    def rk4_step(t, h, x, p=None, inputs=None):
        """One classical Runge-Kutta step of size h from (t, x), inputs held over the step (the package's rk4_step):
        returns the new state, (n_state,) or (N, n_state). t and h are numbers or (N,)."""
        rows, flat, keep = _state_arguments(where, t, x, p, inputs, n_parameters, default_parameters)
        h_row = _scalars_of(h, "h", where)
        rows = _batch_rows(where, [("rows", (None, 0, rows)), ("h", h_row)])
        out = _np.empty((1 if rows is None else rows, n_state), dtype=dtype)
        function(1 if rows is None else rows, *flat[:2], _pointer(h_row[0]), h_row[1], *flat[2:], out.ctypes.data,
                 n_state)
        del keep
        return out[0] if rows is None else out

    return rk4_step


def _prepare_parameters():
    function = _bind("prepare_parameters", [_SIZE] + [_POINTER, _SIZE] * 2, None)
    where = name + ".prepare_parameters"

    def prepare_parameters(p=None):
        """P = (p, then the parameter-only values) for the _prepared kernels: (n_prepared_parameters,), or
        (N, n_prepared_parameters) for p of shape (N, n_parameters). None: the default parameters."""
        a, step, rows = _optional_rows(p, n_parameters, default_parameters, "p", where)
        out = _np.empty((1 if rows is None else rows, n_prepared_parameters), dtype=dtype)
        function(1 if rows is None else rows, _pointer(a), step, out.ctypes.data, n_prepared_parameters)
        return out[0] if rows is None else out

    return prepare_parameters


default_parameters = _np.array(_default_parameters, dtype=dtype)
default_parameters.flags.writeable = False
output_names = {k: v[1] for k, v in kernels.items()}
for _k, (_shape, _names, _summary) in kernels.items():
    globals()["n_out_" + _k] = _math.prod(_shape)
# hamel emit: python_module end
