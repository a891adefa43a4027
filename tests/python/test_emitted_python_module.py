"""The Python module of an emitted package (hamel emit --python), against what does not share its code path: the
package's C++ header (names, sizes), hand-written NumPy models (the Chaplygin sleigh with inputs), complex-step
derivatives of them (jacobian), the generator's own GiNaC evaluation (`hamel derive --json --at`), a NumPy RK4,
and the runtime's integrator (`hamel simulate`). run_pytest.py builds the packages and puts them on sys.path."""

import importlib.util
import io
import json
import os
import re
import shutil
import subprocess

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import chaplygin_sleigh as sleigh
import double_pendulum as dp

HAMEL = os.environ.get("HAMEL_BINARY", "")
SOURCE = os.environ.get("HAMEL_SOURCE_DIR", "")
PACKAGES = os.environ.get("HAMEL_PYTHON_PACKAGES", "")
BUILD = os.environ.get("HAMEL_PYTHON_BUILD", "")


def header_constants(name):
    """constexpr ints and name tables of the package's C++ header, read from its text."""
    with open(os.path.join(PACKAGES, name, name + ".hpp")) as f:
        text = f.read()
    ints = {k: int(v) for k, v in re.findall(r"constexpr int (\w+) = (-?\d+);", text)}
    tables = {k: tuple(re.findall(r'"([^"]*)"', v)) for k, v in re.findall(r"constexpr const char\* (\w+)\[\d+\] = \{([^}]*)\}", text)}
    for k in re.findall(r"constexpr const char\* const\* (\w+) = nullptr;", text):
        tables[k] = ()
    return ints, tables


@pytest.mark.parametrize("module", [dp, sleigh], ids=["double_pendulum", "chaplygin_sleigh"])
def test_names_and_sizes_are_the_headers(module):
    ints, tables = header_constants(module.name)
    for key in ("n_coordinates", "n_independent", "n_state", "n_parameters", "n_inputs", "n_constraints", "n_hamel"):
        assert getattr(module, key) == ints[key], key
    for key in ("state_names", "parameter_names", "input_names", "constraint_names", "quasi_velocity_names"):
        assert getattr(module, key) == tables[key], key
    kernels = [k for k in re.findall(r"n_out_(\w+) = ", open(os.path.join(PACKAGES, module.name, module.name + ".hpp")).read()) if k != "max"]
    assert set(kernels) == {k for k in module.kernels if not k.endswith("_prepared")}
    for k in kernels:
        assert getattr(module, "n_out_" + k) == ints["n_out_" + k], k
        assert int(np.prod(module.kernels[k][0])) == ints["n_out_" + k], k
        assert len(module.output_names[k]) == ints["n_out_" + k], k
    if "n_prepared_parameters" in ints:
        assert module.n_prepared_parameters == ints["n_prepared_parameters"]
    assert module.dtype == np.float64 and module.real_type == "double"


def sleigh_hand_rhs(x, p, u):
    """The Chaplygin sleigh with a torque tau and a push F (models/chaplygin_sleigh.yaml's description): T = m (v^2 +
    a^2 w^2) / 2 + J w^2 / 2 in the forward speed v of the knife edge and the yaw rate w; Neimark and Fufaev's
    equations m (v' - a w^2) = F, (J + m a^2) w' + m a v w = tau, and x' = v cos(theta), y' = v sin(theta)."""
    X, Y, th, v, w = x.T
    m, J, a = p.T
    tau, F = u.T
    return np.stack([v * np.cos(th), v * np.sin(th), w, a * w**2 + F / m, (tau - m * a * v * w) / (J + m * a**2)],
                    axis=1)


def complex_step_jacobian(f, x, h=1e-30):
    J = np.empty((x.shape[0], x.shape[1], x.shape[1]))
    for k in range(x.shape[1]):
        z = x.astype(complex)
        z[:, k] += 1j * h
        J[:, :, k] = f(z).imag / h
    return J


def random_sleigh(n, seed=7):
    rng = np.random.default_rng(seed)
    x = rng.uniform(-2, 2, (n, 5))
    p = np.column_stack([rng.uniform(0.5, 2, n), rng.uniform(0.01, 0.1, n), rng.uniform(-0.3, 0.3, n)])
    u = rng.uniform(-1, 1, (n, 2))
    return x, p, u


def test_sleigh_rhs_and_jacobian_with_inputs_match_the_hand_written_model():
    x, p, u = random_sleigh(500)
    f = sleigh.rhs(0.0, x, p, u)
    np.testing.assert_allclose(f, sleigh_hand_rhs(x, p, u), rtol=1e-12, atol=1e-12)
    J = sleigh.jacobian(0.0, x, p, u)
    assert J.shape == (500, 5, 5)
    np.testing.assert_allclose(J, complex_step_jacobian(lambda z: sleigh_hand_rhs(z, p, u), x), rtol=1e-12,
                               atol=1e-12)


def complex_step_columns(f, w, h=1e-30):
    """d f / d w for a batch: w of shape (N, k), f(w) of shape (N, n); (N, n, k)."""
    columns = []
    for k in range(w.shape[1]):
        z = w.astype(complex)
        z[:, k] += 1j * h
        columns.append(f(z).imag / h)
    return np.stack(columns, axis=2)


def test_sleigh_input_and_parameter_jacobians_are_the_hand_written_models_derivatives():
    x, p, u = random_sleigh(300, seed=11)
    B = sleigh.input_jacobian(0.0, x, p, u)
    assert B.shape == (300, sleigh.n_state, sleigh.n_inputs)
    np.testing.assert_allclose(B, complex_step_columns(lambda z: sleigh_hand_rhs(x, p, z), u), rtol=1e-12, atol=1e-12)
    assert sleigh.parameter_jacobian_parameters == (0, 1, 2)
    P = sleigh.parameter_jacobian(0.0, x, p, u)
    assert P.shape == (300, sleigh.n_state, 3)
    np.testing.assert_allclose(P, complex_step_columns(lambda z: sleigh_hand_rhs(x, z, u), p), rtol=1e-12, atol=1e-12)
    # One state: (n_state, n_inputs); the q_dot rows do not depend on the inputs.
    one = sleigh.input_jacobian(0.0, x[0], p[0], u[0])
    assert one.shape == (sleigh.n_state, sleigh.n_inputs)
    assert np.all(one[:sleigh.n_coordinates] == 0)


def test_mass_matrix_and_forcing_equal_the_generators_evaluation():
    point = {"x": 0.3, "y": -0.2, "theta": 0.7, "v": 1.1, "omega": -0.4}
    values = {"tau": 0.25, "F": -0.5}
    derived = json.loads(subprocess.run(
        [HAMEL, "-q", "derive", os.path.join(SOURCE, "models/chaplygin_sleigh.yaml"), "--json", "--at",
         ",".join(k + "=" + repr(v) for k, v in {**point, **values}.items())],
        check=True, stdout=subprocess.PIPE, text=True).stdout)
    x = np.array([point[n] for n in sleigh.state_names])
    u = np.array([values[n] for n in sleigh.input_names])
    M = sleigh.mass_matrix(0.0, x, None, u)
    f = sleigh.forcing(0.0, x, None, u)
    names = sleigh.state_names[sleigh.n_coordinates:]
    for e in derived["mass_matrix"]:
        assert M[names.index(e["row"]), names.index(e["col"])] == pytest.approx(e["value"], rel=1e-12, abs=1e-12)
    for e in derived["forcing"]:
        assert f[names.index(e["row"])] == pytest.approx(e["value"], rel=1e-12, abs=1e-12)


def test_each_row_of_a_batch_is_the_call_for_that_state():
    x, p, u = random_sleigh(64)
    t = np.linspace(0, 1, 64)
    for kernel in ("rhs", "jacobian", "mass_matrix", "kinematics", "energy", "hamel_coefficients"):
        batch = getattr(sleigh, kernel)(t, x, p, u)
        single = np.array([getattr(sleigh, kernel)(t[i], x[i], p[i], u[i]) for i in range(64)])
        assert batch.shape == (64,) + sleigh.kernels[kernel][0]
        assert np.array_equal(batch, single), kernel
    # One value for all states (step 0) is the same as that value repeated per state.
    assert np.array_equal(sleigh.rhs(0.5, x, p[0], u[0]), sleigh.rhs(np.full(64, 0.5), x, np.tile(p[0], (64, 1)),
                                                                  np.tile(u[0], (64, 1))))
    # A batch of inputs at one state gives as many rows.
    assert sleigh.rhs(0.0, x[0], p[0], u).shape == (64, 5)
    # out=: the same values written into the caller's array, which is returned.
    buffer = np.full((64, 5, 5), np.nan)
    assert sleigh.jacobian(t, x, p, u, out=buffer) is buffer
    assert np.array_equal(buffer, sleigh.jacobian(t, x, p, u))
    one = np.empty(5)
    assert sleigh.rhs(t[3], x[3], p[3], u[3], out=one) is one and np.array_equal(one, sleigh.rhs(t, x, p, u)[3])


def test_prepared_kernels_equal_the_plain_ones():
    rng = np.random.default_rng(3)
    x = rng.uniform(-2, 2, (200, 4))
    p = np.column_stack([rng.uniform(0.5, 2, (200, 4)), rng.uniform(5, 15, 200)])
    P = dp.prepare_parameters(p)
    assert P.shape == (200, dp.n_prepared_parameters)
    assert np.array_equal(P[:, :dp.n_parameters], p)
    np.testing.assert_allclose(dp.rhs_prepared(0.0, x, P), dp.rhs(0.0, x, p), rtol=1e-13, atol=1e-13)
    np.testing.assert_allclose(dp.jacobian_prepared(0.0, x, P), dp.jacobian(0.0, x, p), rtol=1e-13, atol=1e-12)
    np.testing.assert_allclose(dp.rhs_prepared(0.0, x), dp.rhs(0.0, x), rtol=1e-13, atol=1e-13)  # defaults


def test_rhs_status_raises_with_the_status_for_bad_states():
    x = np.array([[0.1, 0.2, 0.3, 0.4], [0.1, 0.2, np.nan, 0.4], [0.1, 0.2, 0.3, 0.4], [np.nan, 0.2, 0.3, 0.4]])
    good = dp.rhs_status(0.0, x[0])
    assert np.array_equal(good, dp.rhs(0.0, x[0]))
    with pytest.raises(dp.StatusError) as e:
        dp.rhs_status(0.0, x)
    # An angular velocity NaN leaves M fine and makes a result NaN (2); an angle NaN reaches M's pivots (1).
    assert e.value.status == 2 and e.value.index == 1
    assert list(e.value.statuses) == [0, 2, 0, 1]
    assert "status 2" in str(e.value) and "state 1 of 4" in str(e.value)
    assert np.array_equal(e.value.result[0], good) and np.isnan(e.value.result[1]).all()
    assert isinstance(e.value, ArithmeticError)
    # A negative mass makes M indefinite: pivot (m1 + m2) l1^2 < 0, status 1, for one state without an index.
    p = dp.default_parameters.copy()
    p[0] = -3.0
    with pytest.raises(dp.StatusError) as e:
        dp.rhs_status(0.0, x[0], p)
    assert e.value.status == 1 and e.value.index is None and "not positive definite" in str(e.value)


def test_rk4_step_is_a_numpy_rk4_on_rhs():
    x, p, u = random_sleigh(32)
    t, h = 0.3, 0.01
    f = lambda s, y: sleigh.rhs(s, y, p, u)  # noqa: E731
    k1 = f(t, x)
    k2 = f(t + h / 2, x + h / 2 * k1)
    k3 = f(t + h / 2, x + h / 2 * k2)
    k4 = f(t + h, x + h * k3)
    np.testing.assert_allclose(sleigh.rk4_step(t, h, x, p, u), x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4), rtol=1e-14,
                               atol=1e-15)


def test_solve_ivp_with_the_emitted_jacobian_agrees_with_hamel_simulate():
    x0 = {"x": 0.0, "y": 0.0, "theta": 0.2, "v": 1.0, "omega": 2.0}
    u = {"tau": 0.05, "F": 0.1}
    out = subprocess.run(
        [HAMEL, "-q", "simulate", os.path.join(SOURCE, "models/chaplygin_sleigh.yaml"), "--t-end", "3", "--integrator",
         "dop853", "--tol", "1e-12", "--init", ",".join(k + "=" + repr(v) for k, v in x0.items()), "--input",
         ",".join(k + "=" + repr(v) for k, v in u.items()), "--out", "-"],
        check=True, stdout=subprocess.PIPE, text=True).stdout
    table = np.genfromtxt(io.StringIO(out), delimiter=",", names=True)
    last = table[-1]
    assert last["t"] == pytest.approx(3.0)
    inputs = np.array([u[n] for n in sleigh.input_names])
    sol = solve_ivp(sleigh.rhs, (0.0, 3.0), np.array([x0[n] for n in sleigh.state_names]), method="Radau",
                    jac=sleigh.jacobian, args=(None, inputs), rtol=1e-11, atol=1e-12)
    assert sol.success and sol.njev > 0
    np.testing.assert_allclose(sol.y[:, -1], [last[n] for n in sleigh.state_names], rtol=0, atol=1e-8)


def test_bad_arguments_are_clear_errors():
    with pytest.raises(ValueError, match=r"double_pendulum.rhs: x has shape \(3,\); expected \(4,\) or \(N, 4\)"):
        dp.rhs(0.0, [1.0, 2.0, 3.0])
    with pytest.raises(TypeError, match=r"chaplygin_sleigh.rhs: the model has inputs \(tau, F\)"):
        sleigh.rhs(0.0, np.zeros(5))
    with pytest.raises(ValueError, match=r"has 3 rows, an argument before it 2"):
        sleigh.rhs(np.zeros(2), np.zeros((3, 5)), None, np.zeros(2))
    with pytest.raises(TypeError, match="complex"):
        dp.rhs(0.0, np.zeros(4, dtype=complex))
    with pytest.raises(ValueError, match=r"p has shape \(4,\)"):
        dp.jacobian(0.0, np.zeros(4), np.ones(4))
    with pytest.raises(ValueError, match=r"out must be a writable C-contiguous float64 array of shape \(4, 4\)"):
        dp.jacobian(0.0, np.zeros(4), out=np.empty(16))
    with pytest.raises(ValueError, match=r"out must be .* of shape \(2, 4\); got float32"):
        dp.rhs(0.0, np.zeros((2, 4)), out=np.empty((2, 4), dtype=np.float32))


def test_a_library_from_another_emit_is_refused(tmp_path):
    # The module compares its stamp with the library's: a module copied beside a library of another emit fails.
    source = os.path.join(BUILD, "double_pendulum", "double_pendulum.py")
    text = open(source).read()
    changed = tmp_path / "double_pendulum.py"
    changed.write_text(text.replace("stamp = \"Generated by hamel", "stamp = \"Generated by another hamel", 1))
    library = [f for f in os.listdir(os.path.dirname(source)) if f.startswith("libdouble_pendulum_python")][0]
    shutil.copy(os.path.join(os.path.dirname(source), library), tmp_path / library)
    spec = importlib.util.spec_from_file_location("double_pendulum_other", changed)
    with pytest.raises(ImportError, match="was built from another emit"):
        spec.loader.exec_module(importlib.util.module_from_spec(spec))
