"""The compiled vehicle step equals the readable one bit for bit: the closed loops use it, and the
chapters' stored outputs depend on every bit of the simulated flight."""

import numpy as np

from quadlib.control.vehicle import (
    QuadrotorParams,
    constants,
    derivative_compiled,
    quadrotor_derivative,
    quadrotor_step,
    step_compiled,
)


def _states(rng, n):
    """Random states: positions, fast motion and rotation, any attitude, thrusts within range."""
    X = np.empty((n, 17))
    X[:, 0:6] = rng.normal(0.0, 5.0, (n, 6))
    q = rng.normal(size=(n, 4))
    X[:, 6:10] = q / np.linalg.norm(q, axis=1, keepdims=True)
    X[:, 10:13] = rng.normal(0.0, 3.0, (n, 3))
    X[:, 13:17] = rng.uniform(0.0, 6.0, (n, 4))
    return X


def test_the_compiled_derivative_and_step_equal_the_readable_ones_bit_for_bit():
    rng = np.random.default_rng(4)
    for params in (QuadrotorParams(), QuadrotorParams(mass_kg=2.2, inertia_kg_m2=(0.02, 0.03, 0.05), max_thrust_n=9.0)):
        vehicle = constants(params)
        for X in _states(rng, 300):
            command = rng.uniform(-2.0, 12.0, 4)  # beyond both ends of the motors' range: clipped
            np.testing.assert_array_equal(derivative_compiled(X, command, *vehicle),
                                          quadrotor_derivative(params, X, command))
            for dt in (0.004, 0.001):
                np.testing.assert_array_equal(step_compiled(X, command, dt, *vehicle),
                                              quadrotor_step(params, X, command, dt))


def test_constants_broadcast_one_inertia_to_three_axes():
    mass, inertia, *_ = constants(QuadrotorParams(inertia_kg_m2=0.02))
    assert mass == 1.1 and inertia.tolist() == [0.02, 0.02, 0.02]
