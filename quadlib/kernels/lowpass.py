"""The low-passes of rest detection, of the accelerometer and of the magnetometer's checks, compiled.

Their readable descriptions are :func:`~quadlib.attitude.lowpass.rest_mask`,
:func:`~quadlib.attitude.lowpass.inertial_lowpass` and
:func:`~quadlib.attitude.checks.undisturbed_field`, which call them; ``py_func`` is each loop
uncompiled (tested equal).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadlib.kernels import called_from_python
from quadlib.kernels.linalg import times
from quadlib.kernels.quaternion import dcm, exp_rotvec, multiply

__all__: list[str] = []  # internal: orientation.py is the interface


@called_from_python
@njit(cache=True)
def calm_samples(t, gyro, accel, gyro_th, accel_th, tau):
    """:func:`~quadlib.attitude.lowpass.rest_mask`'s first step: each sample within the
    thresholds of its stream's first-order low-pass."""
    n = t.shape[0]
    calm = np.zeros(n, np.bool_)
    lp_g, lp_a = np.zeros(3), np.zeros(3)
    started = False
    for k in range(n):
        g, a = gyro[k], accel[k]
        if np.isnan(g).any() or np.isnan(a).any():
            continue
        if not started:
            lp_g, lp_a, started = g.copy(), a.copy(), True
        else:
            w = (t[k] - t[k - 1]) / (tau + t[k] - t[k - 1])
            lp_g, lp_a = lp_g + w * (g - lp_g), lp_a + w * (a - lp_a)
        dg, da = 0.0, 0.0
        for j in range(3):
            dg += (g[j] - lp_g[j]) ** 2
            da += (a[j] - lp_a[j]) ** 2
        calm[k] = math.sqrt(dg) < gyro_th and math.sqrt(da) < accel_th
    return calm


@njit(cache=True)
def butterworth(tau, dt):
    """``(b₀, a₁, a₂)`` of VQF's second-order Butterworth low-pass of time constant ``tau`` at step
    ``dt`` (cut-off ``√2 / (2π τ)``; ``b₁ = 2 b₀``, ``b₂ = b₀``)."""
    c = math.tan(math.sqrt(2.0) / (2.0 * tau) * dt)
    d = c * c + math.sqrt(2.0) * c + 1.0
    return c * c / d, 2.0 * (c * c - 1.0) / d, (1.0 - math.sqrt(2.0) * c + c * c) / d


@called_from_python
@njit(cache=True)
def inertial_lowpass_pass(t, gyro, accel, usable, lost, tau, backward, second_order):
    """One direction of :func:`~quadlib.attitude.lowpass.inertial_lowpass`: the frame is
    integrated from the gyro over each step, forwards or backwards in time, and the average starts
    afresh after a step whose turn is lost (``lost[k]``: the step from sample ``k − 1`` to ``k``).
    The average is first-order, or with ``second_order`` VQF's Butterworth (:func:`butterworth`),
    which until ``tau`` seconds of samples have passed is their mean and then starts from it."""
    n = t.shape[0]
    out = np.full_like(accel, np.nan)
    q = np.array([1.0, 0.0, 0.0, 0.0])
    mean, s1, s2 = np.zeros(3), np.zeros(3), np.zeros(3)  # s1, s2: the Butterworth's state
    count, span, warm = 0, 0.0, False  # samples and seconds averaged since the start; the filter running
    previous = -1
    for i in range(n):
        k = n - 1 - i if backward else i
        dt = 0.0
        if previous >= 0:  # turn the frame from the previous sample to this one
            step = t[k] - t[previous]
            rate = gyro[previous] if step > 0 else -gyro[k]
            q = multiply(q, exp_rotvec(rate * abs(step)))
            dt = abs(step)
            if lost[max(k, previous)]:
                count = 0
        R = dcm(q)
        if usable[k]:
            a_i = times(R, accel[k])  # sums: a BLAS call costs more than a 3×3 product
            if count == 0:
                mean, count, span, warm = a_i, 1, 0.0, False
            elif not second_order:
                mean = mean + dt / (tau + dt) * (a_i - mean)
            elif not warm:  # the mean of the first tau seconds, then the filter's steady state at it
                count, span = count + 1, span + dt
                mean = mean + (a_i - mean) / count
                if span >= tau:
                    b0, a1, a2 = butterworth(tau, dt)
                    s1, s2, warm = mean * (1.0 - b0), mean * (b0 - a2), True
            else:  # direct form II transposed
                b0, a1, a2 = butterworth(tau, dt)
                mean = b0 * a_i + s1
                s1, s2 = 2.0 * b0 * a_i - a1 * mean + s2, b0 * a_i - a2 * mean
        if count > 0:
            out[k] = times(R.T, mean)
        previous = k
    return out


@called_from_python
@njit(cache=True)
def undisturbed_field_pass(t, mag, down, gyro, ref_norm, ref_dip, norm_tol, dip_tol, settle_s, tau, learn_tau,
                           new_s, new_rate, first_s):
    """:func:`~quadlib.attitude.checks.undisturbed_field`: the norm and dip low-passed (``tau``),
    checked against a reference that follows them (``learn_tau``) while the field is trusted, and
    replaced by a candidate that has held steady for ``new_s`` seconds of turning faster than
    ``new_rate`` (the gyro low-passed over 0.5 s) while the field was refused; until the reference has
    been trusted for ``first_s`` seconds in all, a candidate replaces it after ``first_s`` seconds,
    turning or not. Without a reference (``ref_norm`` NaN) the first reading's is taken."""
    n = t.shape[0]
    ok = np.zeros(n, np.bool_)
    norm_lp, dip_lp, last = 0.0, 0.0, -1
    calm, calm_since = True, -np.inf  # trusted from the start until a reading fails
    rate_lp, rate_last = np.zeros(3), -1
    cand_norm, cand_dip, cand_s = 0.0, 0.0, 0.0
    trusted_s = 0.0  # how long the reference has been trusted: below first_s it is still on trial
    for k in range(n):
        g = gyro[k]
        if not np.isnan(g).any():
            w = 1.0 if rate_last < 0 else (t[k] - t[rate_last]) / (0.5 + t[k] - t[rate_last])
            rate_lp += w * (g - rate_lp)
            rate_last = k
        m, d = mag[k], down[k]
        norm = math.sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2])
        if not norm > 0.0:  # NaN or zero: no reading
            continue
        dip_known = not np.isnan(d).any()
        dip = math.asin(min(1.0, max(-1.0, (m[0] * d[0] + m[1] * d[1] + m[2] * d[2]) / norm))) if dip_known else 0.0
        step = t[k] - t[last] if last >= 0 else 0.0
        if last < 0:
            norm_lp, dip_lp, cand_norm, cand_dip = norm, dip, norm, dip
            if np.isnan(ref_norm):  # no reference given: the first reading's
                ref_norm, ref_dip = norm, dip
        else:
            w = 1.0 if tau == 0.0 else step / (tau + step)  # tau 0: each reading alone
            norm_lp += w * (norm - norm_lp)
            if dip_known:
                dip_lp += w * (dip - dip_lp)
        last = k
        if abs(norm_lp / ref_norm - 1.0) <= norm_tol and (not dip_known or abs(dip_lp - ref_dip) <= dip_tol):
            if not calm:
                calm, calm_since = True, t[k]
        else:
            calm = False
        # a refused field that holds steady while the sensor turns is the Earth's, not a magnet's on the board
        if calm or abs(norm_lp / cand_norm - 1.0) > norm_tol or (dip_known and abs(dip_lp - cand_dip) > dip_tol):
            cand_norm, cand_dip, cand_s = norm_lp, dip_lp, 0.0  # a candidate starts afresh
        else:
            if trusted_s < first_s or math.sqrt(rate_lp[0] ** 2 + rate_lp[1] ** 2 + rate_lp[2] ** 2) >= new_rate:
                cand_s += step
            w = step / (learn_tau + step)
            cand_norm += w * (norm_lp - cand_norm)
            if dip_known:
                cand_dip += w * (dip_lp - cand_dip)
            if cand_s >= (first_s if trusted_s < first_s else new_s):
                ref_norm, ref_dip = cand_norm, cand_dip
                calm, calm_since = True, -np.inf
        ok[k] = calm and t[k] - calm_since >= settle_s
        if calm:
            trusted_s += step
        if ok[k]:
            w = step / (learn_tau + step)
            ref_norm += w * (norm_lp - ref_norm)
            if dip_known:
                ref_dip += w * (dip_lp - ref_dip)
    return ok
