"""Runs the Python tests of emitted packages (tests/python) and the user example (examples/python) under pytest.

First emits the packages the tests use with `hamel emit --python` into WORK/src, builds their Python modules with
CMake into WORK/build as a user would (under -Wall -Wextra -Werror -pedantic, so the emitted files stay warning-free),
and puts the module folders on sys.path. Exits 77 (ctest: skipped) with a message when NumPy, SciPy or pytest is
missing; tools/install-deps.sh installs them, so in CI they run.

    python3 tests/python/run_pytest.py --hamel build/bin/hamel --source . --work build/tests/python [pytest args]
"""

import argparse
import os
import shutil
import subprocess
import sys

# model name -> (model file, extra emit flags). double_pendulum: symbolic parameters and prepared kernels;
# chaplygin_sleigh: inputs, a constraint and Hamel coefficients; its default kernels and the two built only when named,
# input_jacobian and parameter_jacobian.
PACKAGES = {
    "double_pendulum": ("models/double_pendulum.yaml", []),
    "chaplygin_sleigh": ("models/chaplygin_sleigh.yaml",
                         ["--kernels", "kinematics,mass_matrix,forcing,hamel_coefficients,rhs,jacobian,energy,"
                          "constraint_residual,rhs_prepared,jacobian_prepared,input_jacobian,parameter_jacobian"]),
}


def missing_modules():
    missing = []
    for module in ("numpy", "scipy", "pytest"):
        try:
            __import__(module)
        except ImportError:
            missing.append(module)
    return missing


def run(command, log):
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if result.returncode != 0:
        sys.stderr.write(log + " failed (" + " ".join(command) + "):\n" + result.stdout)
        sys.exit(1)


def build(hamel, source, work, cmake):
    src, out = os.path.join(work, "src"), os.path.join(work, "build")
    os.makedirs(src, exist_ok=True)
    for name, (model, flags) in PACKAGES.items():
        run([hamel, "-q", "emit", os.path.join(source, model), "-o", os.path.join(src, name), "--python"] + flags,
            "hamel emit " + name)
    with open(os.path.join(src, "CMakeLists.txt"), "w") as f:
        f.write("cmake_minimum_required(VERSION 3.13)\nproject(python_packages LANGUAGES CXX)\n" +
                "".join("add_subdirectory(" + name + ")\n" for name in PACKAGES))
    run([cmake, "-S", src, "-B", out, "-DCMAKE_BUILD_TYPE=Release", "-DCMAKE_CXX_FLAGS=-Wall -Wextra -Werror -pedantic"],
        "cmake configure")
    run([cmake, "--build", out, "-j2", "--target"] + [name + "_python" for name in PACKAGES], "cmake --build")
    return {name: os.path.join(out, name) for name in PACKAGES}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--hamel", required=True)
    parser.add_argument("--source", required=True)
    parser.add_argument("--work", required=True)
    parser.add_argument("--cmake", default=shutil.which("cmake") or "cmake")
    args, pytest_args = parser.parse_known_args()
    missing = missing_modules()
    if missing:
        print("SKIPPED: the Python tests need " + ", ".join(missing) + " in " + sys.executable +
              " (Debian: apt-get install python3-numpy python3-scipy python3-pytest, or bash tools/install-deps.sh)")
        return 77
    folders = build(os.path.abspath(args.hamel), os.path.abspath(args.source), os.path.abspath(args.work), args.cmake)
    for folder in folders.values():
        sys.path.insert(0, folder)
    os.environ["HAMEL_BINARY"] = os.path.abspath(args.hamel)
    os.environ["HAMEL_SOURCE_DIR"] = os.path.abspath(args.source)
    os.environ["HAMEL_PYTHON_PACKAGES"] = os.path.join(os.path.abspath(args.work), "src")
    os.environ["HAMEL_PYTHON_BUILD"] = os.path.join(os.path.abspath(args.work), "build")
    sys.dont_write_bytecode = True  # no __pycache__ in the source tree (tests/python, examples/python)
    import pytest
    here = os.path.dirname(os.path.abspath(__file__))
    return pytest.main(["-q", "-p", "no:cacheprovider", here, os.path.join(args.source, "examples", "python")] +
                       pytest_args)


if __name__ == "__main__":
    sys.exit(main())
