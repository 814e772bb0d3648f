"""Each filter's loop is generated from its own kernels: a model from outside quadlib runs compiled.

The model here is a user's: a cart on a line (position and speed) seen by a range sensor beside the
track, its kernels written with ``@njit`` in this file and held as :class:`~quadlib.engine.Kernel`s.
Nothing in quadlib names them. The engine must run it, equal to the readable loop to 1e-10, keep its
compiled copy in the cache folder under a name made of its kernels, and say once that it compiles.
"""

import warnings
from dataclasses import replace

import numpy as np
import pytest
from numba import njit

from quadlib import Measurements, Model, ModelEKF, ModelUKF, Sensor, rts_smooth, run_filter
from quadlib.engine import Kernel, build, runner

MAST_M = 4.0  # the range sensor stands this far beside the track


@njit(cache=True)
def cart_g(x, u, dt, p):
    return np.array([x[0] + dt * x[1], x[1] + dt * u[0]])


@njit(cache=True)
def cart_G(x, u, dt, p):
    out = np.eye(2)
    out[0, 1] = dt
    return out


@njit(cache=True)
def cart_G_copy(x, u, dt, p):
    out = np.eye(2)
    out[0, 1] = dt
    return out


@njit(cache=True)
def cart_Q(dt, p):
    q = p[0] ** 2  # white acceleration of density p[0]² [m²/s³]
    return q * np.array([[dt**3 / 3.0, dt**2 / 2.0], [dt**2 / 2.0, dt]])


@njit(cache=True)
def range_h(x, c, p):
    return np.array([np.sqrt(x[0] ** 2 + p[0] ** 2)])


@njit(cache=True)
def range_H(x, c, p):
    out = np.zeros((1, 2))
    out[0, 0] = x[0] / np.sqrt(x[0] ** 2 + p[0] ** 2)
    return out


def plain_Q(dt, p):
    return cart_Q(dt, p)  # the kernel's signature, but numba did not compile it


CART = Model(state_names=("p", "v"), input_names=("a",), g=Kernel("g", cart_g), G=Kernel("G", cart_G),
             Q=Kernel("Q", cart_Q, [0.3]), name="cart")
RANGE = Sensor(name="range", measurement_names=("r",), h=Kernel("h", range_h, [MAST_M]),
               H=Kernel("H", range_H, [MAST_M]), R=np.array([[0.05**2]]))


def _log(jitter: float = 0.0):
    """20 s at 50 Hz of the cart pushed back and forth, ranges at every step with 5 % missing and a
    0.5 s stretch 3 m off (which a gate refuses and a reset takes), on a clock jittered by ``jitter``."""
    rng = np.random.default_rng(3)
    t = np.arange(1001) * 0.02 + jitter * rng.uniform(-1, 1, 1001) * 0.02
    u = np.sin(0.5 * t)[:, None]
    x = np.zeros((t.size, 2))
    x[0] = (-5.0, 1.0)
    for k in range(1, t.size):
        x[k] = cart_g(x[k - 1], u[k - 1], t[k] - t[k - 1], np.zeros(0))
    z = np.sqrt(x[:, :1] ** 2 + MAST_M**2) + 0.05 * rng.standard_normal((t.size, 1))
    z[rng.random(t.size) < 0.05] = np.nan
    z[300:325] += 3.0
    return t, u, z


@pytest.mark.parametrize("make", [ModelEKF, ModelUKF], ids=["EKF", "UKF"])
def test_a_model_from_outside_quadlib_runs_compiled_equal_to_the_readable_loop(make, assert_same_run):
    t, u, z = _log()
    # a reset widens P by central differences, which magnify the last bits: the UKF's sigma points
    # carry that to 3e-8 in S, so the UKF is compared gated without resets (as in test_ekf.py)
    sensor = replace(RANGE, reset_after_s=0.3 if make is ModelEKF else None)
    runs = {}
    for engine in ("compiled", "readable"):
        filt = make(CART, [-4.0, 0.5], np.diag([1.0, 1.0]), 0.02)
        runs[engine] = run_filter(filt, t, u, [Measurements(sensor, t, z)], gate_probability=0.999, engine=engine)
    assert runs["compiled"].engine == "compiled"
    trace = runs["compiled"].sensors["range"]
    assert trace.rejected.sum() >= 5 and trace.missing.sum() > 20  # every branch taken
    assert trace.reset.any() == (make is ModelEKF)
    assert_same_run(runs["compiled"], runs["readable"])
    if make is ModelEKF:
        smoothed = rts_smooth(CART, runs["compiled"], u, engine="compiled")
        assert smoothed.engine == "compiled"
        assert_same_run(smoothed, rts_smooth(CART, runs["compiled"], u, engine="readable"))


def test_the_copy_is_named_by_its_kernels_and_says_once_that_it_compiles(tmp_path, monkeypatch, capsys):
    monkeypatch.setenv("QUADLIB_CACHE_DIR", str(tmp_path))
    monkeypatch.setenv("QUADLIB_PROGRESS", "on")  # the test suite switches notices off
    monkeypatch.setattr(runner, "_LOOPS", {})  # as in a new process
    monkeypatch.setattr(build, "_LOADED", {})
    t, u, z = _log()

    def run(model):
        filt = ModelEKF(model, [-4.0, 0.5], np.eye(2), 0.02)
        return run_filter(filt, t, u, [Measurements(RANGE, t, z)], engine="compiled")

    run(CART)
    assert capsys.readouterr().err.count("quadlib: compiling the cart EKF, once") == 1
    copies = sorted(p.name for p in (tmp_path / "filters").glob("quadlib_ekf_*.py"))
    assert len(copies) == 1
    source = (tmp_path / "filters" / copies[0]).read_text()
    assert "model_g = tests.engine.test_build.cart_g" in source
    assert "sensor_0_h = tests.engine.test_build.range_h" in source
    run(CART)
    assert capsys.readouterr().err == ""  # compiled: silent
    monkeypatch.setattr(build, "_LOADED", {})
    monkeypatch.setattr(runner, "_LOOPS", {})
    run(CART)
    assert capsys.readouterr().err == ""  # and silent in a new process, which finds it on disk
    # other parameters are data, not code: the same copy; another kernel is another copy
    run(replace(CART, Q=Kernel("Q", cart_Q, [3.0]), name="windy cart"))
    assert len(list((tmp_path / "filters").glob("quadlib_ekf_*.py"))) == 1
    run(replace(CART, G=Kernel("G", cart_G_copy)))
    assert len(list((tmp_path / "filters").glob("quadlib_ekf_*.py"))) == 2


def test_a_kernel_numba_did_not_compile_runs_readable_and_says_why():
    plain = replace(CART, Q=Kernel("Q", plain_Q, [0.3]))
    t, u, z = _log()
    filt = ModelEKF(plain, [-4.0, 0.5], np.eye(2), 0.02)
    run = run_filter(filt, t, u, [Measurements(RANGE, t, z)])
    assert run.engine == "readable" and "numba did not compile" in run.engine_note
    with pytest.raises(ValueError, match="engine: expected a filter the compiled engine can run.*plain_Q"):
        run_filter(ModelEKF(plain, [-4.0, 0.5], np.eye(2), 0.02), t, u, [], engine="compiled")


def test_a_loop_numba_cannot_compile_warns_once_and_runs_readable(monkeypatch):
    monkeypatch.setattr(runner, "_LOOPS", {})
    monkeypatch.setattr(runner, "_WARNED", set())

    @njit
    def untyped_h(x, c, p):
        return "a range"  # a string where the loop needs an array: numba refuses the loop

    sensor = replace(RANGE, h=Kernel("h", untyped_h), name="bad range")
    t, u, z = _log()
    filt = ModelEKF(CART, [-4.0, 0.5], np.eye(2), 0.02)
    with pytest.warns(RuntimeWarning, match="model 'cart' runs on the readable loop: numba could not compile"):
        with pytest.raises((TypeError, ValueError)):  # the readable loop then meets the string and names it
            run_filter(filt, t, u, [Measurements(sensor, t, z)])
    with warnings.catch_warnings():  # once: the second run neither warns nor tries to compile again
        warnings.simplefilter("error")
        with pytest.raises((TypeError, ValueError)):
            run_filter(ModelEKF(CART, [-4.0, 0.5], np.eye(2), 0.02), t, u, [Measurements(sensor, t, z)])


def test_the_cache_folder_is_the_packages_unless_told(monkeypatch, tmp_path):
    monkeypatch.setenv("QUADLIB_CACHE_DIR", str(tmp_path))
    assert build.cache_dir() == tmp_path / "filters"
    monkeypatch.delenv("QUADLIB_CACHE_DIR")
    assert build.cache_dir().name == "filters"
