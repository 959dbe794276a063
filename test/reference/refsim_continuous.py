"""reference_sim.py's continuous-time loop: leader, follower and CF estimator as one ODE
(solve_ivp), its signals on the control grid and its summary."""

from __future__ import annotations

import math
import os
import time
from types import SimpleNamespace

import numpy as np
from scipy.integrate import solve_ivp

from refsim_inputs import (pulse_sum, rate_limit_mode, sinusoid_sum, slot_heading_acceleration,
                           slot_heading_drive, target_heading, turned_slot)


def closed_loop(sc, Z, u1, ud, rate_mode=None):
    """Every signal of the loop for K states at once.

    Z is (3n, K) with rows [x_1; x_2; xi_hat], or (3n + 2, K) with rows [x_1; x_2; xi_hat;
    theta; theta'] with turning slots; u1 is (m, K), ud is (n, K). rate_mode (turning slots)
    is the rate limit's mode (slot_heading_acceleration()), a number or (K,); None: read
    off theta' (rate_limit_mode()).
    Returns a namespace with the signals as (., K) arrays and zdot = dZ/dt.
    """
    n = sc.n
    K = Z.shape[1]
    x1, x2, xh = Z[:n], Z[n:2 * n], Z[2 * n:3 * n]
    if sc.turning is not None:
        theta, theta_dot = Z[3 * n], Z[3 * n + 1]
        a_true = u1 + sc.B_pinv @ ud                   # the leader's true acceleration
        psi, psi_dot, defined = target_heading(sc, x1, a_true)
        drive = slot_heading_drive(sc.turning, theta, theta_dot, psi, psi_dot, defined)
        if rate_mode is None:
            rate_mode = rate_limit_mode(sc.turning, theta_dot)
        theta_ddot = slot_heading_acceleration(drive, rate_mode)
        slot_p, D, ur = turned_slot(sc, theta, theta_dot, theta_ddot)
    else:
        D = sc.d[:, None]
        ur = np.zeros((sc.m, K))
    xi = x1 - x2 - D
    y = sc.C @ xi
    yh = sc.C @ xh
    if sc.tracker:
        ua = sc.Ge @ (y - yh) + sc.S21 @ yh
    else:
        ua = np.zeros((sc.m, K))
    a1 = u1 + sc.B_pinv @ ud if sc.info_disturbance else u1   # leader acceleration told
    uff = a1 if sc.info_command else np.zeros_like(u1)
    ub = sc.G @ y
    u2 = ub + ua + uff + ur

    # u_r is a known input, cancelled between plant and model: the estimator's
    # augmentation is u_2 - G y - u_ff - u_r = u_a, so h is the pair's.
    h = sc.Ac @ xh - sc.B @ ua + sc.L @ (yh - y)
    if sc.info_estimator:
        h = h + sc.B @ (a1 - uff)

    xm2 = sc.xi_max ** 2
    f = ((1.0 + sc.epsilon) * np.sum(xh * xh, axis=0) - xm2) / (sc.epsilon * xm2)
    grad = (2.0 * (1.0 + sc.epsilon) / (sc.epsilon * xm2)) * xh
    grad_h = np.sum(grad * h, axis=0)
    active = (f > 0.0) & (grad_h > 0.0)
    gi_grad = sc.Gamma_inv @ grad
    denom = np.sum(grad * gi_grad, axis=0)          # > 0 wherever f > 0
    scale = np.where(active, f * grad_h / np.where(active, denom, 1.0), 0.0)
    xh_dot = h - gi_grad * scale

    x1_dot = sc.A @ x1 + sc.B @ u1 + ud
    x2_dot = sc.A @ x2 + sc.B @ u2
    out = SimpleNamespace(xi=xi, xi_hat=xh, x1=x1, x2=x2, u=u2, u_baseline=ub,
                          u_tracker=ua, f=f, active=active,
                          zdot=np.vstack([x1_dot, x2_dot, xh_dot]))
    if sc.turning is not None:
        out.theta, out.theta_dot, out.theta_ddot = theta, theta_dot, theta_ddot
        out.theta_drive = drive
        out.slot_p, out.u_slot = slot_p, ur
        out.zdot = np.vstack([out.zdot, theta_dot, theta_ddot])
    return out


def initial_estimate(sc, xi0):
    if sc.initial_estimate == "zero":
        return np.zeros(sc.n)
    est = np.linalg.pinv(sc.C) @ (sc.C @ xi0)
    norm = np.linalg.norm(est)
    if norm > sc.xi_max:
        est *= sc.xi_max / norm
    return est


def initial_state(sc):
    """z(0) = [x_1(0); x_2(0); xi_hat(0)], with turning slots also theta(0), theta'(0) = 0.

    xi_0 = x_1(0) - x_2(0) - d from the scenario. With turning slots theta(0) = psi(0)
    (0 if the leader starts below min_speed) and the follower starts at
    x_1(0) - D(theta(0), 0) - xi_0: a follower on its world slot starts on its turned slot.
    """
    xi0 = sc.x1_0 - sc.x2_0 - sc.d
    z = [sc.x1_0, sc.x2_0, initial_estimate(sc, xi0)]
    if sc.turning is not None:
        x1 = sc.x1_0[:, None]
        psi, _, defined = target_heading(sc, x1, np.zeros((sc.m, 1)))
        theta0 = float(psi[0]) if defined[0] else 0.0
        _, D0, _ = turned_slot(sc, np.array([theta0]), np.zeros(1), np.zeros(1))
        z[1] = sc.x1_0 - D0[:, 0] - xi0
        z.append(np.array([theta0, 0.0]))
    return np.concatenate(z)


def time_grid(sc):
    """t_k = k / control_rate, k = 0 .. N, N = floor(duration * control_rate).

    One sample per control tick, the final state at t_N = duration included
    (as cf_sim writes its CSV).
    """
    periods = int(math.floor(sc.duration * sc.control_rate + 1e-9))
    return np.arange(periods + 1, dtype=float) / sc.control_rate


def segment_edges(sc):
    """0, duration and every pulse edge strictly between them, sorted."""
    edges = {0.0, sc.duration}
    for start, end, _ in sc.input_pulses + sc.disturbances:
        edges.update(e for e in (start, end) if 0.0 < e < sc.duration)
    return sorted(edges)


def rate_limit_events(sc, mode, u1_at, ud):
    """Terminal events that end a piece of constant rate-limit mode (turning slots).

    theta'' switches where theta' reaches +-max_yaw_rate and the drive still pushes on:
    integrated as it is, the solver would step to and fro across that surface (the
    slot's yaw rate slides on it). So the mode is a discrete state: in mode 0 the drive
    acts unlimited and the pieces end where theta' reaches +-max_yaw_rate; in mode +-1
    theta' stays at +-max_yaw_rate (theta'' = 0) until the drive turns back. Each piece's
    right-hand side is then Lipschitz in the state (but for psi's switches, which the
    solver's error control crosses).
    """
    rate = 3 * sc.n + 1
    wmax = sc.turning.max_yaw_rate

    def drive(t, z):
        return closed_loop(sc, z[:, None], u1_at(t), ud, mode).theta_drive[0]

    def event(fn, direction):
        fn.terminal, fn.direction = True, direction
        return fn

    if mode == 0:
        return [event(lambda t, z: z[rate] - wmax, 1.0), event(lambda t, z: z[rate] + wmax, -1.0)]
    return [event(drive, -float(mode))]


def simulate(sc, method="LSODA", rtol=1e-6, atol=1e-9, max_step=math.inf):
    """Integrate the closed loop; return (grid, Z on the grid, rate_mode on the grid,
    wall seconds, nfev).

    Z is (3n, K), or (3n + 2, K) with turning slots (rows as in closed_loop()); rate_mode
    (K,) is the rate limit's mode at each sample (0 without turning slots).
    """
    grid = time_grid(sc)
    z = initial_state(sc)
    Z = np.empty((z.size, grid.size))
    modes = np.zeros(grid.size, dtype=int)
    turning = sc.turning is not None
    rate = 3 * sc.n + 1
    mode = 0                                  # theta'(0) = 0: below the rate limit
    edges = segment_edges(sc)
    nfev = 0
    wall0 = time.perf_counter()
    for a, b in zip(edges[:-1], edges[1:]):
        mid = 0.5 * (a + b)
        u1_pulse = pulse_sum(sc.input_pulses, mid, sc.m)          # constant on [a, b)
        ud = pulse_sum(sc.disturbances, mid, sc.n)
        sins = sc.sinusoids

        def u1_at(t, u1_pulse=u1_pulse):
            return u1_pulse + sinusoid_sum(sins, t, sc.m) if sins else u1_pulse

        # Samples in [a, b); the last segment also takes a sample at b = duration.
        # The state is continuous, so an edge sample may come from either side.
        in_segment = (grid >= a) & ((grid < b) | (b == edges[-1]))
        idx = np.nonzero(in_segment)[0]
        t0, done, stalled = a, 0, 0
        while True:                           # pieces of constant rate-limit mode
            def rhs(t, zz, mode=mode, ud=ud):
                return closed_loop(sc, zz[:, None], u1_at(t), ud, mode).zdot[:, 0]

            t_eval = grid[idx[done:]]
            if t_eval.size == 0 or t_eval[-1] < b:
                t_eval = np.append(t_eval, b)          # also ask for the end state
            events = rate_limit_events(sc, mode, u1_at, ud) if turning else None
            sol = solve_ivp(rhs, (t0, b), z, method=method, t_eval=t_eval, events=events,
                            rtol=rtol, atol=atol, max_step=max_step)
            if not sol.success:
                raise RuntimeError(f"integration failed on [{t0:g}, {b:g}] s: {sol.message}")
            nfev += sol.nfev
            got = min(sol.t.size, idx.size - done)
            Z[:, idx[done:done + got]] = sol.y[:, :got]
            modes[idx[done:done + got]] = mode
            done += got
            if sol.status != 1:               # reached b
                z = sol.y[:, -1]
                break
            # A rate-limit event ended the piece: switch the mode and go on from there.
            fired = next(i for i, te in enumerate(sol.t_events) if te.size)
            t_event, z = sol.t_events[fired][0], sol.y_events[fired][0].copy()
            stalled = stalled + 1 if t_event - t0 <= 1e-12 * max(1.0, abs(t0)) else 0
            if stalled > 100:
                raise RuntimeError(f"the slot's rate limit switches without end at {t0:g} s")
            t0 = t_event
            if mode == 0:                     # theta' reached +-max_yaw_rate
                z[rate] = math.copysign(sc.turning.max_yaw_rate, z[rate])
                u1 = u1_at(t0)
                drive = closed_loop(sc, z[:, None], u1, ud, 0).theta_drive[0]
                mode = int(np.sign(z[rate])) if drive * z[rate] > 0.0 else 0
            else:                             # the drive turned back
                mode = 0
    wall = time.perf_counter() - wall0
    return grid, Z, modes, wall, nfev


def signals_on_grid(sc, grid, Z, rate_mode=None):
    """All CSV signals on the grid as a dict of column name -> 1-D array (in CSV order)."""
    u1 = pulse_sum(sc.input_pulses, grid, sc.m) + sinusoid_sum(sc.sinusoids, grid, sc.m)
    ud = pulse_sum(sc.disturbances, grid, sc.n)
    s = closed_loop(sc, Z, u1, ud, rate_mode)
    n, k = sc.n, sc.k
    K = grid.size
    cols = {"t": grid}
    for i in range(n):
        cols[f"xi_{i}"] = s.xi[i]
    for i in range(n):
        cols[f"xi_hat_{i}"] = s.xi_hat[i]
    cols["norm_xi"] = np.linalg.norm(s.xi, axis=0)
    cols["norm_xi_hat"] = np.linalg.norm(s.xi_hat, axis=0)
    cols["xi_max"] = np.full(K, sc.xi_max)
    cols["xi_soft"] = np.full(K, sc.xi_soft)
    cols["f"] = s.f
    cols["projection_active"] = s.active.astype(float)
    for i in range(k):
        cols[f"leader_p_{i}"] = s.x1[i]
    for i in range(k):
        cols[f"follower_p_{i}"] = s.x2[i]
    if sc.double_integrator:
        for i in range(k):
            cols[f"leader_v_{i}"] = s.x1[k + i]
        for i in range(k):
            cols[f"follower_v_{i}"] = s.x2[k + i]
    cols["separation"] = np.linalg.norm(s.x1[:k] - s.x2[:k], axis=0)
    cols["perimeter"] = np.full(K, sc.perimeter)
    for name, arr in (("u", s.u), ("u_baseline", s.u_baseline), ("u_tracker", s.u_tracker),
                      ("leader_u", u1)):
        for i in range(sc.m):
            cols[f"{name}_{i}"] = arr[i]
    for i in range(n):
        cols[f"ud_{i}"] = ud[i]
    if sc.turning is not None:
        cols["slot_heading"] = s.theta
        cols["slot_yaw_rate"] = s.theta_dot
        cols["slot_yaw_acceleration"] = s.theta_ddot
        for i in range(k):
            cols[f"slot_p_{i}"] = s.slot_p[i]
        for i in range(sc.m):
            cols[f"u_slot_{i}"] = s.u_slot[i]
    return cols


def write_csv(path, cols):
    names = list(cols)
    data = np.column_stack([cols[c] for c in names])
    np.savetxt(path, data, fmt="%.17g", delimiter=",", header=",".join(names), comments="")


def summary(sc, cols, wall):
    norm_xi = cols["norm_xi"]
    return {
        "max_xi": float(np.max(norm_xi)),
        "max_xi_hat": float(np.max(cols["norm_xi_hat"])),
        "xi_max": sc.xi_max,
        "min_separation": float(np.min(cols["separation"])),
        "time_outside": int(np.count_nonzero(norm_xi > sc.xi_max)) / sc.control_rate,
        "wall_s": wall,
    }


def follower_csv_path(path, name):
    """FILE with _<name> before its extension, as cf_sim names a formation's files."""
    root, ext = os.path.splitext(path)
    return f"{root}_{name}{ext}"
