"""The inputs of reference_sim.py's loops over time: pulses and sinusoids, and the turning
slot's heading (doc/math.md, (T1)-(T3))."""

from __future__ import annotations

import math

import numpy as np


def pulse_sum(pulses, t, size):
    """Sum of the pulse vectors active at times t (start <= t < end); t: (K,) -> (size, K)."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    out = np.zeros((size, t.size))
    for start, end, vec in pulses:
        on = (t >= start) & (t < end)
        out += np.outer(vec, on)
    return out


def sinusoid_sum(sinusoids, t, size):
    """Sum of amplitude * sin(2 pi f t + phase); t: (K,) -> (size, K)."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    out = np.zeros((size, t.size))
    for amp, freq, phase in sinusoids:
        out += np.outer(amp, np.sin(2.0 * math.pi * freq * t + phase))
    return out


def wrap_angle(x):
    """x wrapped to (-pi, pi]."""
    return x - 2.0 * math.pi * np.ceil((x - math.pi) / (2.0 * math.pi))


def target_heading(sc, x1, a1):
    """The leader's heading psi, its exact rate psi' and where it is defined; (K,) arrays each.

    psi = atan2(v_y, v_x) of the leader's velocity and psi' = (v_x a_y - v_y a_x) /
    (v_x^2 + v_y^2) its time derivative, a1 the leader's true acceleration (m = k entries).
    Defined where the horizontal speed ||(v_x, v_y)|| >= min_speed (doc/math.md, (T1)) and is
    not zero.
    """
    k = sc.k
    vx, vy = x1[k], x1[k + 1]
    vxy2 = vx * vx + vy * vy
    speed = np.sqrt(vxy2)
    defined = (speed >= sc.turning.min_speed) & (vxy2 > 0.0)
    psi = np.arctan2(vy, vx)
    psi_dot = (vx * a1[1] - vy * a1[0]) / np.where(vxy2 > 0.0, vxy2, 1.0)
    return psi, psi_dot, defined


def slot_heading_drive(tg, theta, theta_dot, psi, psi_dot, defined):
    """theta'' of (T1) before the rate limit: clamp(w^2 wrap(psi - theta) + 2 zeta w (psi' -
    theta'), +-beta), with psi := theta and psi' := 0 where psi is undefined (the slot stops
    turning and holds)."""
    psi = np.where(defined, psi, theta)
    psi_dot = np.where(defined, psi_dot, 0.0)
    w, zeta = tg.natural_frequency, tg.damping
    acc = w * w * wrap_angle(psi - theta) + 2.0 * zeta * w * (psi_dot - theta_dot)
    return np.clip(acc, -tg.max_yaw_acceleration, tg.max_yaw_acceleration)


def rate_limit_mode(tg, theta_dot):
    """+1 where theta' >= max_yaw_rate, -1 where theta' <= -max_yaw_rate, else 0."""
    return np.where(theta_dot >= tg.max_yaw_rate, 1,
                    np.where(theta_dot <= -tg.max_yaw_rate, -1, 0))


def slot_heading_acceleration(drive, rate_mode):
    """theta'' of (T1): the drive, with no further acceleration beyond the rate limit.

    rate_mode +1 (theta' at +max_yaw_rate) allows theta'' <= 0 only, -1 theta'' >= 0 only,
    0 (|theta'| below the limit) the drive as it is.
    """
    acc = np.where(rate_mode > 0, np.minimum(drive, 0.0), drive)
    return np.where(rate_mode < 0, np.maximum(acc, 0.0), acc)


def turned_slot(sc, theta, theta_dot, theta_ddot):
    """R(theta) d_p, the turned slot D of (T2) and u_r of (T3); (K,) arrays in.

    R turns the x-y part of d_p by theta about z; J = [[0, -1], [1, 0]] on x-y, 0 on z:
    D = [R d_p; theta' J R d_p], u_r = -(theta'' J + theta'^2 J^2) R d_p.
    Returns (k, K), (n, K), (m, K) arrays.
    """
    k = sc.k
    dp = sc.d[:k]
    c, s = np.cos(theta), np.sin(theta)
    r = np.tile(dp[:, None], (1, theta.size))                 # z part kept
    r[0] = c * dp[0] - s * dp[1]
    r[1] = s * dp[0] + c * dp[1]
    jr = np.zeros_like(r)                                     # J R d_p
    jr[0], jr[1] = -r[1], r[0]
    jjr = np.zeros_like(r)                                    # J^2 R d_p
    jjr[:2] = -r[:2]
    D = np.vstack([r, theta_dot * jr])
    ur = -(theta_ddot * jr + theta_dot * theta_dot * jjr)
    return r, D, ur
