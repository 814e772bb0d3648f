"""Each kernel number the engine's switches take calls that number's kernel in its table, and every
kernel of the tables is one that a model or sensor factory binds."""

import numpy as np
import pytest

from quadlib.attitude.bias_model import additive_attitude_bias_model, attitude_bias_model
from quadlib.attitude.kesten import FILTERS, AttitudeNoise
from quadlib.engine.dispatch import SWITCHES, TABLES, kind_of
from quadlib.engine.kernel import MODEL_ROLES, SENSOR_ROLES, Kernel
from quadlib.fixedwing import fixedwing_accel_sensor, fixedwing_mag_sensor
from quadlib.geometry.quaternion import quat_from_rotvec
from quadlib.nav import InsParams, ins_baro_sensor, ins_gps_sensor
from quadlib.quad import quad3d_gps_sensor, quad3d_mag_sensor, quad3d_model, quad3d_ukf_options
from quadlib.sensors import gravity_sensor, heading_sensor, zero_rate_sensor

RANGE = 2.0
NOISE = AttitudeNoise(gyro_range_rad_s=RANGE)
KESTEN = [make(NOISE) for make in FILTERS.values()]
ATTITUDE = [attitude_bias_model(0.01, 1e-3, RANGE), additive_attitude_bias_model(0.01, 1e-3, RANGE),
            InsParams().model()]
QUAD3D = quad3d_model((2.0, 2.0, 0.5), 0.16)
SENSORS = [gravity_sensor(0.3), heading_sensor(0.1), heading_sensor(0.1, tilt_aware=True), zero_rate_sensor(0.01),
           fixedwing_accel_sensor(0.15), fixedwing_accel_sensor(0.15, 3.0), fixedwing_mag_sensor(0.05, 0.01, 1.1)]
INS_SENSORS = [ins_gps_sensor([1.0] * 3, [0.1] * 3), ins_gps_sensor([1.0] * 3, [0.1] * 3, use_height=False),
               ins_baro_sensor(0.5),
               heading_sensor(0.1, dim_x=16, gyro_bias_errors=(9, 10, 11))]


def _state(n: int, quad3d: bool = False) -> np.ndarray:
    """An orientation vector (3), a quaternion (4), a quaternion and a gyro bias (7), the INS's
    quaternion, velocity, position and biases (16), or the 3D quadrotor's position, velocity and a
    yaw near ±π."""
    if quad3d:
        return np.array([1.0, -2.0, -3.0, 0.5, 0.2, -0.1, 3.1])
    rotation = np.array([0.3, -0.2, 0.5])
    rest = [0.01, -0.02, 0.005] if n < 16 else [3.0, -1.0, 0.5, 10.0, 20.0, -5.0, 0.01, -0.02, 0.005, 0.1, -0.2, 0.05]
    return rotation if n == 3 else np.r_[quat_from_rotvec(rotation), rest[:n - 4]]


def _model_args(model, role: str) -> tuple:
    # u at the gyro's full scale (and the INS's accelerometer)
    x, u, dt = _state(model.dim_x, model is QUAD3D), np.array([1.999, 0.3, -0.4, 0.5, -0.2, -9.6])[:model.dim_u], 0.01
    if model is QUAD3D:  # specific force, yaw rate, roll and pitch
        u = np.array([0.3, -0.2, -9.7, 0.8, 0.1, -0.05])
    d = np.linspace(0.01, 0.03, model.dim_P)
    return {"g": (x, u, dt), "G": (x, u, dt), "Q": (dt,), "input_noise": (u, dt), "state_add": (x, d),
            "residual_x": (x + 0.01 * (model.dim_x == 3), x), "add_jacobian": (x,), "normalize": (1.1 * x,),
            "normalize_jacobian": (1.1 * x,)}[role]


def _cases():
    for model in ATTITUDE + [f.model for f in KESTEN] + [QUAD3D]:
        for role in MODEL_ROLES:
            f = getattr(model, role)
            if isinstance(f, Kernel):
                yield f, _model_args(model, role)
    x = _state(7, quad3d=True)
    options = quad3d_ukf_options()  # the yaw wrapped across ±π, averaged on the circle
    yield options["residual_x"], (x, x - np.r_[0.1 * np.ones(6), 6.2])
    yield options["x_mean_fn"], (np.array([x, -x, 0.5 * x]), np.array([0.5, 0.3, 0.2]))
    pairs = [(s, 7, False) for s in SENSORS] + [(s, f.model.dim_x, False) for f in KESTEN for s in f.sensors]
    pairs += [(s, 16, False) for s in INS_SENSORS]
    pairs += [(s, 7, True) for s in (quad3d_gps_sensor(), quad3d_mag_sensor())]
    for sensor, n, quad3d in pairs:
        x, c = _state(n, quad3d), np.array([0.2, 0.05, 0.45, 20.0])[:sensor.dim_c]
        z = np.asarray(sensor.h(x, c) if sensor.dim_c else sensor.h(x)) + 0.01
        for role in SENSOR_ROLES:
            f = getattr(sensor, role)
            if isinstance(f, Kernel):
                args = {"residual": (z, z - 0.02), "mean": (np.array([z, -z, z + 0.2]), np.array([0.5, 0.3, 0.2]))}
                yield f, args.get(role, (x, c if sensor.dim_c else np.zeros(0)))


CASES = list(_cases())


@pytest.mark.parametrize("kernel, args", CASES, ids=[f"{k.role}-{k.function.__name__}" for k, _ in CASES])
def test_each_number_calls_its_tables_kernel(kernel, args):
    kind = kind_of(kernel)
    assert kind >= 0, f"{kernel!r} is not in TABLES[{kernel.role!r}]"
    switched = SWITCHES[kernel.role].py_func(kind, *args, kernel.params)  # the switch's source, not compiled
    direct = kernel.function(*args, kernel.params)
    for a, b in zip(switched if isinstance(switched, tuple) else (switched,),
                    direct if isinstance(direct, tuple) else (direct,), strict=True):
        np.testing.assert_array_equal(a, b)


def test_every_kernel_in_the_tables_is_bound_by_a_factory():
    bound = {(k.role, k.function) for k, _ in CASES}
    unbound = [(role, f.__name__) for role, table in TABLES.items() for f in table if (role, f) not in bound]
    assert not unbound
    assert set(TABLES) == set(SWITCHES) == set(MODEL_ROLES + SENSOR_ROLES)
