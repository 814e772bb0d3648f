"""The quadrotor's compiled derivative and step (:mod:`quadlib.kernels.vehicle`) against the model's
equations written independently here, with the quaternion kernels: bit for bit, because the
chapters' stored outputs depend on every bit of the simulated flight."""

import numpy as np

from quadlib.constants import GRAVITY_N
from quadlib.control.vehicle import QuadrotorParams, constants, motor_torques, quadrotor_derivative, quadrotor_step
from quadlib.kernels.quaternion import dcm, multiply, normalize


def _derivative(params, X, thrust_cmd):
    q, omega, T = X[6:10], X[10:13], X[13:17]
    inertia = np.broadcast_to(np.asarray(params.inertia_kg_m2, dtype=float), (3,))
    f_n = dcm(q)[:, 2] * (-T.sum() / params.mass_kg)  # the thrust along −body z, in NED
    h = inertia * omega
    gyroscopic = np.array([omega[1] * h[2] - omega[2] * h[1], omega[2] * h[0] - omega[0] * h[2],
                           omega[0] * h[1] - omega[1] * h[0]])  # ω × Iω
    out = np.empty(17)
    out[0:3] = X[3:6]
    out[3:6] = GRAVITY_N + f_n
    out[6:10] = 0.5 * multiply(q, np.array([0.0, omega[0], omega[1], omega[2]]))
    out[10:13] = (motor_torques(params, T) - gyroscopic) / inertia
    out[13:17] = (np.clip(thrust_cmd, 0.0, params.max_thrust_n) - T) / params.motor_tau_s
    return out


def _step(params, X, thrust_cmd, dt):
    k1 = _derivative(params, X, thrust_cmd)
    k2 = _derivative(params, X + 0.5 * dt * k1, thrust_cmd)
    k3 = _derivative(params, X + 0.5 * dt * k2, thrust_cmd)
    k4 = _derivative(params, X + dt * k3, thrust_cmd)
    out = X + dt / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4)
    out[6:10] = normalize(out[6:10])
    return out


def _states(rng, n):
    """Random states: positions, fast motion and rotation, any attitude, thrusts within range."""
    X = np.empty((n, 17))
    X[:, 0:6] = rng.normal(0.0, 5.0, (n, 6))
    q = rng.normal(size=(n, 4))
    X[:, 6:10] = q / np.linalg.norm(q, axis=1, keepdims=True)
    X[:, 10:13] = rng.normal(0.0, 3.0, (n, 3))
    X[:, 13:17] = rng.uniform(0.0, 6.0, (n, 4))
    return X


def test_the_compiled_derivative_and_step_equal_the_equations_bit_for_bit():
    rng = np.random.default_rng(4)
    for params in (QuadrotorParams(), QuadrotorParams(mass_kg=2.2, inertia_kg_m2=(0.02, 0.03, 0.05), max_thrust_n=9.0)):
        for X in _states(rng, 300):
            command = rng.uniform(-2.0, 12.0, 4)  # beyond both ends of the motors' range: clipped
            np.testing.assert_array_equal(quadrotor_derivative(params, X, command), _derivative(params, X, command))
            for dt in (0.004, 0.001):
                np.testing.assert_array_equal(quadrotor_step(params, X, command, dt), _step(params, X, command, dt))


def test_constants_broadcast_one_inertia_to_three_axes():
    mass, inertia, *_ = constants(QuadrotorParams(inertia_kg_m2=0.02))
    assert mass == 1.1 and inertia.tolist() == [0.02, 0.02, 0.02]
