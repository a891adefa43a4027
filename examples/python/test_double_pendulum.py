"""What a user's test suite does with an emitted package: check it against a model of one's own, then use it.

The double pendulum of models/double_pendulum.yaml (point masses m1, m2 on massless rods l1, l2, angles from the
downward vertical, gravity g) written here by hand from its Euler-Lagrange equations with NumPy, not from anything
hamel prints; its Jacobian by complex-step differentiation of that hand-written right-hand side (exact to rounding,
no step-size trade-off). The emitted rhs and jacobian must agree with both to 1e-12 on a batch of random states and
parameters, and scipy.integrate.solve_ivp (Radau, with the emitted Jacobian) must keep the energy and follow the
hand-written model integrated by DOP853.

Run it after `bash tools/quickstart.sh`, which builds the module into build/python/double_pendulum:

    PYTHONPATH=build/python/double_pendulum /usr/bin/python3 -m pytest examples/python

(the test suite runs it too: tests/python/run_pytest.py).
"""

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import double_pendulum as dp


def hand_rhs(x, p):
    """x' for states x (N, 4) = (theta1, theta2, omega1, omega2) and parameters p (N, 5) = (m1, m2, l1, l2, g).

    L = (m1 + m2) l1^2 w1^2 / 2 + m2 l2^2 w2^2 / 2 + m2 l1 l2 cos(theta1 - theta2) w1 w2
        + (m1 + m2) g l1 cos(theta1) + m2 g l2 cos(theta2),
    whose Euler-Lagrange equations are M(theta) w' = f(theta, w) with
    M = [[(m1 + m2) l1^2, m2 l1 l2 c], [m2 l1 l2 c, m2 l2^2]],  c = cos(theta1 - theta2), s = sin(theta1 - theta2),
    f = [-m2 l1 l2 s w2^2 - (m1 + m2) g l1 sin(theta1),  m2 l1 l2 s w1^2 - m2 g l2 sin(theta2)].
    Written with NumPy functions only, so that it also evaluates at complex x (complex-step derivatives)."""
    th1, th2, w1, w2 = x.T
    m1, m2, l1, l2, g = p.T
    c, s = np.cos(th1 - th2), np.sin(th1 - th2)
    M = np.empty(x.shape[:1] + (2, 2), dtype=x.dtype)
    M[:, 0, 0] = (m1 + m2) * l1**2
    M[:, 0, 1] = M[:, 1, 0] = m2 * l1 * l2 * c
    M[:, 1, 1] = m2 * l2**2
    f = np.stack([-m2 * l1 * l2 * s * w2**2 - (m1 + m2) * g * l1 * np.sin(th1),
                  m2 * l1 * l2 * s * w1**2 - m2 * g * l2 * np.sin(th2)], axis=1)
    acceleration = np.linalg.solve(M, f[:, :, None])[:, :, 0]
    return np.concatenate([x[:, 2:], acceleration], axis=1)


def hand_jacobian(x, p, h=1e-30):
    """d(x')/dx by the complex step: Im f(x + i h e_k) / h is df/dx_k with no cancellation, to rounding."""
    n = x.shape[1]
    J = np.empty((x.shape[0], n, n))
    for k in range(n):
        z = x.astype(complex)
        z[:, k] += 1j * h
        J[:, :, k] = hand_rhs(z, p).imag / h
    return J


def hand_energy(x, p):
    th1, th2, w1, w2 = x.T
    m1, m2, l1, l2, g = p.T
    T = 0.5 * (m1 + m2) * l1**2 * w1**2 + 0.5 * m2 * l2**2 * w2**2 + m2 * l1 * l2 * np.cos(th1 - th2) * w1 * w2
    V = -(m1 + m2) * g * l1 * np.cos(th1) - m2 * g * l2 * np.cos(th2)
    return T + V


@pytest.fixture
def batch():
    rng = np.random.default_rng(49)
    n = 1000
    x = np.column_stack([rng.uniform(-np.pi, np.pi, (n, 2)), rng.uniform(-3, 3, (n, 2))])
    p = np.column_stack([rng.uniform(0.5, 2, (n, 4)), rng.uniform(5, 15, n)])  # m1, m2, l1, l2, g
    return x, p


def test_the_package_is_the_double_pendulum():
    assert dp.state_names == ("theta1", "theta2", "omega1", "omega2")
    assert dp.parameter_names == ("m1", "m2", "l1", "l2", "g")
    assert dp.kernels["jacobian"][0] == (4, 4)


def test_rhs_and_jacobian_match_the_hand_written_model(batch):
    x, p = batch
    f, J = dp.rhs(0.0, x, p), dp.jacobian(0.0, x, p)
    assert f.shape == (len(x), 4) and J.shape == (len(x), 4, 4)
    np.testing.assert_allclose(f, hand_rhs(x, p), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(J, hand_jacobian(x, p), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(dp.energy(0.0, x, p)[:, 0], hand_energy(x, p), rtol=1e-12, atol=1e-12)


def test_solve_ivp_with_the_emitted_jacobian_keeps_the_energy_and_follows_the_hand_written_model():
    x0 = np.array([1.0, 0.5, 0.0, 0.0])
    p = dp.default_parameters
    radau = solve_ivp(dp.rhs, (0.0, 2.0), x0, method="Radau", jac=dp.jacobian, rtol=1e-9, atol=1e-11)
    assert radau.success and radau.njev > 0
    reference = solve_ivp(lambda t, x: hand_rhs(x[None, :], p[None, :])[0], (0.0, 2.0), x0, method="DOP853",
                          rtol=1e-12, atol=1e-12)
    assert reference.success
    energy = hand_energy(radau.y.T, np.broadcast_to(p, (radau.y.shape[1], 5)))
    assert np.max(np.abs(energy - energy[0])) < 1e-7 * abs(energy[0])
    np.testing.assert_allclose(radau.y[:, -1], reference.y[:, -1], rtol=0, atol=1e-6)
