"""The attitude-and-gyro-bias model and its sensors as numba kernels (:mod:`quadlib.kernels`).

State ``x = [q_nb (4), b (3)]`` (or the quaternion alone), input the gyro ``ω`` [rad/s], error
``δx = [δθ, δb]`` with ``q ⊗ exp(δθ)``. The readable descriptions, with their equations, are
:func:`~quadlib.attitude.bias_model.attitude_bias_model` and
:func:`~quadlib.attitude.bias_model.additive_attitude_bias_model` (the model) and
:func:`~quadlib.sensors.gravity_sensor`, :func:`~quadlib.sensors.heading_sensor` and
:func:`~quadlib.sensors.zero_rate_sensor` (the sensors), which bind these.
Besides them, the pieces any model uses: an identity Jacobian and a linear measurement ``A x``
(a selection of states, say) with its Jacobian.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from quadlib.constants import SATURATED
from quadlib.kernels.linalg import product, wrap
from quadlib.kernels.quaternion import (
    body_vector_jacobian,
    dcm_entries,
    exp_rotvec,
    matrix,
    multiply,
    rate_entries,
    rate_matrix,
    rotvec,
    skew_entries,
)

__all__: list[str] = []  # bound by the model factories; see the module docstring


# --- the model: g, G, Q, input noise, ⊞, ⊟, ∂⊞/∂δ, normalize --------------------------------

@njit(cache=True)
def attitude_bias_jacobian(phi, dt):
    """``∂δx⁺/∂δx`` over ``[δθ, δb]`` of one gyro step ``φ = (ω − b) Δt``
    (:func:`~quadlib.attitude.bias_model.gyro_error_jacobians`)."""
    theta = math.sqrt(phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2])
    K = skew_entries(phi)  # [φ]×, K[i, j] is K[3 i + j]
    if theta > 1e-6:
        a, b = (1.0 - math.cos(theta)) / theta**2, (theta - math.sin(theta)) / theta**3
    else:
        a, b = 0.5 - theta**2 / 24.0, 1.0 / 6.0 - theta**2 / 120.0
    R = dcm_entries(exp_rotvec(phi))
    G = np.eye(6)
    for i in range(3):
        for j in range(3):
            K2 = 0.0  # [φ]×² summed as product() sums it
            for m in range(3):
                K2 += K[3 * i + m] * K[3 * m + j]
            G[i, j] = R[3 * j + i]
            G[i, 3 + j] = -dt * ((1.0 if i == j else 0.0) - a * K[3 * i + j] + b * K2)
    return G


@njit(cache=True)
def saturated(u, gyro_range):
    """The gyro sample ``u`` is at its full scale (:func:`~quadlib.imu.saturated_step_variance`);
    ``gyro_range ≤ 0``: a gyro that never saturates."""
    if gyro_range <= 0.0:
        return False
    for i in range(u.shape[0]):
        if abs(u[i]) >= SATURATED * gyro_range:
            return True
    return False


@njit(cache=True)
def turn_into(out, q, vx, vy, vz):
    """``out[:4] = q ⊗ exp(v)``, as :func:`~quadlib.kernels.quaternion.multiply` of
    :func:`~quadlib.kernels.quaternion.exp_rotvec` computes it, without their two arrays."""
    angle = math.sqrt(vx * vx + vy * vy + vz * vz)
    half_sinc = math.sin(0.5 * angle) / angle if angle > 1e-8 else 0.5 - angle * angle / 48.0
    e0, e1, e2, e3 = math.cos(0.5 * angle), half_sinc * vx, half_sinc * vy, half_sinc * vz
    q0, q1, q2, q3 = q[0], q[1], q[2], q[3]
    out[0] = q0 * e0 - q1 * e1 - q2 * e2 - q3 * e3
    out[1] = q0 * e1 + q1 * e0 + q2 * e3 - q3 * e2
    out[2] = q0 * e2 - q1 * e3 + q2 * e0 + q3 * e1
    out[3] = q0 * e3 + q1 * e2 - q2 * e1 + q3 * e0


@njit(cache=True)
def attitude_bias_step(x, u, dt, p):
    """``g``: ``[q ⊗ exp((ω − b) Δt), b]``."""
    out = x.copy()
    turn_into(out, x, (u[0] - x[4]) * dt, (u[1] - x[5]) * dt, (u[2] - x[6]) * dt)
    return out


@njit(cache=True)
def attitude_error_jacobian(x, u, dt, p):
    """``G`` of the error ``[δθ, δb]``, ``(6, 6)``: ``R(φ)ᵀ`` and ``−Δt J_r(φ)``, ``φ = (ω − b) Δt``."""
    phi = np.empty(3)
    for i in range(3):
        phi[i] = (u[i] - x[4 + i]) * dt
    return attitude_bias_jacobian(phi, dt)


@njit(cache=True)
def attitude_step_jacobian(x, u, dt, p):
    """``G`` of the additive 7-state, ``∂[q ⊗ exp(φ), b]/∂[q, b]``, exact."""
    q, phi = x[:4], (u[:3] - x[4:7]) * dt
    theta = math.sqrt(phi[0] * phi[0] + phi[1] * phi[1] + phi[2] * phi[2])
    c = math.cos(theta / 2.0)
    sinc = math.sin(0.5 * theta) / theta if theta > 1e-6 else 0.5 - theta**2 / 48.0  # sin(θ/2)/θ
    k = (0.5 * c - sinc) / theta**2 if theta > 1e-3 else -1.0 / 24.0 + theta**2 / 960.0
    v0, v1, v2 = sinc * phi[0], sinc * phi[1], sinc * phi[2]
    J = np.eye(7)
    J[:4, :4] = matrix(4, 4, (c, -v0, -v1, -v2, v0, c, v2, -v1, v1, -v2, c, v0, v2, v1, -v0, c))
    d_w = -0.5 * sinc * phi  # ∂cos(θ/2)/∂φ
    d_v = sinc * np.eye(3) + k * np.outer(phi, phi)  # ∂(sin(θ/2)/θ · φ)/∂φ
    J[:4, 4:] = -dt * (np.outer(q, d_w) + product(rate_matrix(q), d_v))
    return J


@njit(cache=True)
def identity_jacobian(x, u, dt, p):
    """``G = I`` of size ``p[0]``."""
    return np.eye(int(p[0]))


@njit(cache=True)
def gyro_noise(dt, p):
    """``Q(Δt) = diag(s·v(Δt) I_a, σ_b² Δt I_b)``, ``p = [σ_ω, thesis, s, a, σ_b, b]``: the attitude's
    ``v = (σ_ω Δt)²``, or the thesis's ``Δt σ_ω²`` when ``thesis`` is 1 (Kesten's E15)."""
    sigma, scale, n_att, sigma_b, n_bias = p[0], p[2], int(p[3]), p[4], int(p[5])
    var = dt * sigma**2 if p[1] != 0.0 else (sigma * dt) ** 2
    Q = np.zeros((n_att + n_bias, n_att + n_bias))
    for i in range(n_att):
        Q[i, i] = scale * var
    for i in range(n_att, n_att + n_bias):
        Q[i, i] = sigma_b**2 * dt
    return Q


@njit(cache=True)
def gyro_input_noise(u, dt, p):
    """The input noise of a gyro sample that cannot be trusted, ``p = [range, n, s₁ … s_n, α]``:
    ``(range Δt)² diag(s)`` when ``u[:3]`` is at the full scale (:func:`~quadlib.imu.saturated_step_variance`;
    ``range ≤ 0``: never), and ``(α τ Δt)² diag(s)`` when the sample is a held one, ``u[3] = τ`` seconds
    after the last real sample (:func:`~quadlib.imu.gyro_with_gaps`; the rate may have changed by
    ``α τ`` since, ``α`` [rad/s²]). Returns ``(added, M)``."""
    n = int(p[1])
    M = np.zeros((n, n))
    v = 0.0
    if saturated(u[:3], p[0]):
        v += (p[0] * dt) ** 2
    if u.shape[0] > 3 and u[3] > 0.0:
        v += (p[2 + n] * u[3] * dt) ** 2
    if v == 0.0:
        return False, M
    for i in range(n):
        M[i, i] = v * p[2 + i]
    return True, M


@njit(cache=True)
def attitude_bias_add(x, d, p):
    """``x ⊞ δx = [q ⊗ exp(δθ), b + δb]``."""
    out = x.copy()
    turn_into(out, x, d[0], d[1], d[2])
    for i in range(4, x.shape[0]):
        out[i] = x[i] + d[i - 1]
    return out


@njit(cache=True)
def attitude_bias_difference(x1, x0, p):
    """``x₁ ⊟ x₀ = [rotvec(q₀* ⊗ q₁), b₁ − b₀]``."""
    out = np.empty(x1.shape[0] - 1)
    q0 = x0[:4]
    out[:3] = rotvec(multiply(np.array([q0[0], -q0[1], -q0[2], -q0[3]]), x1[:4]))
    out[3:] = x1[4:] - x0[4:]
    return out


@njit(cache=True)
def attitude_bias_add_jacobian(x, p):
    """``∂(x ⊞ δx)/∂δx`` at 0: ``½ Ξ(q)`` for the quaternion, the identity for the rest."""
    n = x.shape[0]
    J = np.zeros((n, n - 1))
    Xi = rate_entries(x)
    for i in range(4):
        for j in range(3):
            J[i, j] = 0.5 * Xi[3 * i + j]
    for i in range(4, n):
        J[i, i - 1] = 1.0
    return J


@njit(cache=True)
def normalize_quaternion(x, p):
    """The quaternion ``x[:4]`` to unit norm, the other states unchanged."""
    out = x.copy()
    norm = math.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3])
    for i in range(4):
        out[i] = x[i] / norm
    return out


@njit(cache=True)
def normalize_quaternion_jacobian(x, p):
    """``∂(normalised x)/∂x``: ``(I − q̂ q̂ᵀ)/|q|`` on the quaternion, the identity on the rest."""
    J = np.eye(x.shape[0])
    norm = math.sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2] + x[3] * x[3])
    for i in range(4):
        for j in range(4):
            J[i, j] = ((1.0 if i == j else 0.0) - (x[i] / norm) * (x[j] / norm)) / norm
    return J


# --- the sensors: h, H, residuals ------------------------------------------------------------

@njit(cache=True)
def body_vector(x, c, p):
    """``h = R(q)ᵀ r``, the earth vector ``r = p[:3]`` seen in the body (gravity's ``−g_n``, the field)."""
    R = dcm_entries(x)  # R[i, j] is R[3 i + j]
    return np.array([R[0] * p[0] + R[3] * p[1] + R[6] * p[2],
                     R[1] * p[0] + R[4] * p[1] + R[7] * p[2],
                     R[2] * p[0] + R[5] * p[1] + R[8] * p[2]])


@njit(cache=True)
def body_vector_H(x, c, p):
    """``∂(R(q)ᵀ r)/∂x``, ``(3, n)`` with ``n = p[3]``: the quaternion's columns, zero for the rest."""
    J = np.zeros((3, int(p[3])))
    entries = body_vector_jacobian(x, p)
    for i in range(3):
        for j in range(4):
            J[i, j] = entries[4 * i + j]
    return J


@njit(cache=True)
def field_heading(x, c, p):
    """The heading of the body field ``c`` turned into the earth frame, east of north [rad]."""
    R = dcm_entries(x)
    return np.array([math.atan2(R[3] * c[0] + R[4] * c[1] + R[5] * c[2], R[0] * c[0] + R[1] * c[1] + R[2] * c[2])])


@njit(cache=True)
def heading_only_H(x, c, p):
    """The heading's Jacobian about the vertical only, ``(1, n)``, ``n = p[0]``: ``R(q)[2] · 2 Ξ(q)ᵀ``."""
    R, Xi = dcm_entries(x), rate_entries(x)  # R[i, j] is R[3 i + j], Ξ[i, j] is Xi[3 i + j]
    J = np.zeros((1, int(p[0])))
    for i in range(4):
        J[0, i] = 2.0 * (R[6] * Xi[3 * i] + R[7] * Xi[3 * i + 1] + R[8] * Xi[3 * i + 2])
    return J


@njit(cache=True)
def tilt_aware_heading_H(x, c, p):
    """The heading's full Jacobian, ``(1, n)``, ``n = p[0]``: ``−∂ψ/∂m_n · R [m_b]× · 2 Ξ(q)ᵀ``, as
    sums (a BLAS call per small product costs more than the product)."""
    R, Xi = dcm_entries(x), rate_entries(x)  # R[i, j] is R[3 i + j], Ξ[i, j] is Xi[3 i + j]
    m0 = R[0] * c[0] + R[1] * c[1] + R[2] * c[2]  # m_n = R m_b, its horizontal part
    m1 = R[3] * c[0] + R[4] * c[1] + R[5] * c[2]
    h2 = m0 * m0 + m1 * m1
    w0 = (m1 * R[0] - m0 * R[3]) / h2  # w = −∂ψ/∂m_n · R
    w1 = (m1 * R[1] - m0 * R[4]) / h2
    w2 = (m1 * R[2] - m0 * R[5]) / h2
    v = (w1 * c[2] - w2 * c[1], w2 * c[0] - w0 * c[2], w0 * c[1] - w1 * c[0])  # w [m_b]×
    J = np.zeros((1, int(p[0])))
    for i in range(4):
        J[0, i] = 2.0 * (v[0] * Xi[3 * i] + v[1] * Xi[3 * i + 1] + v[2] * Xi[3 * i + 2])
    return J


@njit(cache=True)
def linear_map(x, c, p):
    """``h = A x``, ``p = [m, n, A (m × n) row by row]``, as
    :func:`~quadlib.engine.kernel.linear_kernels` binds it."""
    m, n = int(p[0]), int(p[1])
    out = np.zeros(m)
    for i in range(m):
        for j in range(n):
            out[i] += p[2 + i * n + j] * x[j]
    return out


@njit(cache=True)
def linear_map_H(x, c, p):
    """``H = A`` of :func:`linear_map`."""
    m, n = int(p[0]), int(p[1])
    return p[2:2 + m * n].copy().reshape(m, n)


@njit(cache=True)
def wrapped_difference(z, z_hat, p):
    """``z − ẑ`` wrapped to (−π, π] (an angle's residual), element by element: the array form builds
    three temporaries, and a UKF calls it once per sigma point."""
    out = np.empty(z.shape[0])
    for i in range(z.shape[0]):
        out[i] = wrap(z[i] - z_hat[i])
    return out


@njit(cache=True)
def angle_difference(x1, x0, p):
    """``x₁ − x₀`` with component ``p[0]`` (an angle) wrapped to (−π, π]: an additive UKF's ``⊟``."""
    d = x1 - x0
    i = int(p[0])
    d[i] = wrap(d[i])
    return d


@njit(cache=True)
def circular_mean(Z, w, p):
    """The weighted mean of the rows of ``Z`` with column ``p[0]`` (an angle) averaged on the circle."""
    i = int(p[0])
    mean = np.zeros(Z.shape[1])
    s, c = 0.0, 0.0
    for r in range(Z.shape[0]):
        for j in range(Z.shape[1]):
            mean[j] += w[r] * Z[r, j]
        s += w[r] * math.sin(Z[r, i])
        c += w[r] * math.cos(Z[r, i])
    mean[i] = math.atan2(s, c)
    return mean
