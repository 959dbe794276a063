"""reference_sim.py's sampled loop (doc/math.md 'Follower command', 'Discretisation',
'Offline simulator') with the section world, formation.neighbours (N1)-(N3) and the barrier
filter (B1)-(B3), every agent at once; its summary lines."""

from __future__ import annotations

import math
import sys
import time

import numpy as np

import barrier_reference
from refsim_continuous import follower_csv_path, time_grid, write_csv
from refsim_format import PROG
from refsim_inputs import pulse_sum, sinusoid_sum
from refsim_layout import chain_layout, formation_targets, slot_layout
from refsim_parts import World
from refsim_projection import neighbour_halfspaces, project_command
from refsim_world import advance, ExactStep, gust_pulses, normal_draws, piecewise_inputs


def simulate_sampled(sc):
    """The sampled loop of doc/math.md ('Follower command', 'Discretisation', 'Offline
    simulator') with the section world and formation.neighbours (N1)-(N3), every agent at once.

    Returns (names, targets (F,), per-follower column dicts, pair minima (F+1, F+1), wall s).
    """
    wall0 = time.perf_counter()
    fm = sc.formation
    n, m, k = sc.n, sc.m, sc.k
    T = 1.0 / sc.control_rate
    grid = time_grid(sc)
    N = grid.size - 1
    targets = np.array(formation_targets(fm))
    F = targets.size
    if fm is None:
        D = np.array([sc.d])
    elif fm.topology == "chain":
        D = np.array(chain_layout(fm, sc.d, k))
    else:
        D = np.array(slot_layout(fm, sc.d, k))
    d_norm = np.linalg.norm(D, axis=1)
    xi_max = (1.0 - sc.alpha) * d_norm
    own_perimeter = sc.alpha * d_norm
    world = sc.world if sc.world is not None else World()
    nb = fm.neighbours if fm is not None else None

    # Agents: row 0 the leader, row i follower i; each follower starts with the scenario's xi_0.
    xi0 = sc.x1_0 - sc.x2_0 - sc.d
    X = np.zeros((F + 1, n))
    X[0] = sc.x1_0
    for i in range(1, F + 1):
        X[i] = X[targets[i - 1]] - D[i - 1] - xi0

    # The world of each follower: vehicle, pulses (its own and its gusts), sinusoids, noise.
    vehicles, pulses, sines = [], [], []
    for i in range(1, F + 1):
        fw = world.followers.get(i)
        vehicles.append(fw.vehicle if fw else world.vehicle)
        pulses.append((list(fw.disturbances) if fw else [])
                      + gust_pulses(world, i, sc.B, sc.duration))
        sines.append(list(fw.sinusoids) if fw else [])
    v_limit = np.array([v.acceleration_limit for v in vehicles])
    v_gain = np.array([v.input_gain for v in vehicles])
    v_lag = np.array([v.actuator_lag for v in vehicles])
    v_beta = np.where(v_lag > 0.0, -np.expm1(-T / np.where(v_lag > 0.0, v_lag, 1.0)), 1.0)
    sigma = np.where(np.arange(n) < k, world.noise_position, world.noise_velocity)
    if np.any(sigma > 0.0):
        counts = (np.arange(N + 1, dtype=np.uint64)[:, None] * np.uint64(n)
                  + np.arange(n, dtype=np.uint64)[None, :])
        noise = np.stack([sigma * normal_draws(world.seed, 4 * i + 1, counts)
                          for i in range(1, F + 1)])                    # (F, N + 1, n)
    else:
        noise = np.zeros((F, N + 1, n))
    follower_drive = [piecewise_inputs(pulses[i], sines[i], grid, n) for i in range(F)]
    leader_drive = piecewise_inputs(sc.disturbances, [], grid, n)
    u1_grid = (pulse_sum(sc.input_pulses, grid, m) + sinusoid_sum(sc.sinusoids, grid, m)).T
    ud_grid = pulse_sum(sc.disturbances, grid, n).T
    step = ExactStep(sc.A, sc.double_integrator)

    XH = np.zeros((F, n))
    U_prev = np.zeros((F, m))
    Z = np.zeros((F, m))                          # the vehicles' lag states, z_{-1} = 0
    Fm = sc.F                                     # A_c + L C
    delta = T / sc.substeps
    xm2 = xi_max ** 2
    rec = {key: np.zeros((N + 1, F, size)) for key, size in
           (("xi", n), ("xi_hat", n), ("x", n), ("target", n), ("u", m), ("u_baseline", m),
            ("u_tracker", m), ("u_applied", m), ("noise", n))}
    rec_f = {key: np.zeros((N + 1, F)) for key in ("f", "kept", "dropped", "projected",
                                                   "saturated", "rate_limited",
                                                   "barrier_infeasible")}
    pair_min = np.full((F + 1, F + 1), math.inf)
    leader_told = np.where(targets == 0, 1.0, 0.0)[:, None]

    def field_at(xh, c):
        hh = xh @ Fm.T + c
        fval = ((1.0 + sc.epsilon) * np.sum(xh * xh, axis=1) - xm2) / (sc.epsilon * xm2)
        grad_h = np.sum(xh * hh, axis=1)
        active = (fval > 0.0) & (grad_h > 0.0)
        gx = xh @ sc.Gamma_inv.T
        denom = np.sum(xh * gx, axis=1)
        scale = np.where(active, fval * grad_h / np.where(active, denom, 1.0), 0.0)
        return hh - gx * scale[:, None]

    for tick in range(N + 1):
        t = grid[tick]
        pos = X[:, :k]
        diff = pos[:, None, :] - pos[None, :, :]
        pair_min = np.minimum(pair_min, np.sqrt(np.sum(diff * diff, axis=2)))
        xi = X[targets] - X[1:] - D
        y = (xi + noise[:, tick]) @ sc.C.T
        if tick == 0:
            if sc.initial_estimate == "zero":
                XH = np.zeros((F, n))
            else:
                XH = y @ np.linalg.pinv(sc.C).T
                norm = np.linalg.norm(XH, axis=1)
                over = norm > xi_max
                XH[over] *= (xi_max[over] / norm[over])[:, None]
        rec["xi"][tick], rec["xi_hat"][tick] = xi, XH
        rec["x"][tick], rec["target"][tick], rec["noise"][tick] = X[1:], X[targets], noise[:, tick]
        rec_f["f"][tick] = (((1.0 + sc.epsilon) * np.sum(XH * XH, axis=1) - xm2)
                            / (sc.epsilon * xm2))

        u1 = u1_grid[tick]
        a1 = u1 + sc.B_pinv @ ud_grid[tick] if sc.info_disturbance else u1
        uff = leader_told * a1 if sc.info_command else np.zeros((F, m))
        w = (leader_told * a1 - uff) @ sc.B.T if sc.info_estimator else np.zeros((F, n))
        yh = XH @ sc.C.T
        ua = ((y - yh) @ sc.Ge.T + yh @ sc.S21.T) if sc.tracker else np.zeros((F, m))
        ub = y @ sc.G.T
        u = ub + ua + uff
        norm = np.linalg.norm(u, axis=1)
        saturated = norm > sc.acceleration_limit
        u[saturated] *= (sc.acceleration_limit / norm[saturated])[:, None]
        rate_limited = np.zeros(F, dtype=bool)
        if sc.jerk_limit < math.inf:
            du = u - U_prev
            dn = np.linalg.norm(du, axis=1)
            rate_limited = dn > sc.jerk_limit * T
            u[rate_limited] = (U_prev[rate_limited] + du[rate_limited]
                               * (sc.jerk_limit * T / dn[rate_limited])[:, None])
        projected = np.zeros(F, dtype=bool)
        if sc.safety_filter is not None:          # (B1)-(B3), barrier_reference.py
            sensed = None
            if nb is not None:
                _, _, urgency, dist, valid = neighbour_halfspaces(
                    nb, X[:, :k], X[:, k:2 * k], targets, own_perimeter, sc.acceleration_limit)
                sensed = (nb, valid, urgency, dist)
            u, projected, infeasible = barrier_reference.filter_commands(
                sc, sc.safety_filter, u, X, targets, own_perimeter, a1,
                sc.info_command or sc.info_estimator, sensed)
            rec_f["barrier_infeasible"][tick] = infeasible
        elif nb is not None:
            amax = sc.acceleration_limit
            normals, bounds, urgency, dist, valid = neighbour_halfspaces(
                nb, X[:, :k], X[:, k:2 * k], targets, own_perimeter, amax)
            along = np.einsum("ijk,ik->ij", normals, u)
            slack = 1e-12 * np.maximum(1.0, np.abs(bounds))
            for i in np.nonzero(np.any(valid & (along < bounds - slack), axis=1))[0]:
                idx = np.nonzero(valid[i])[0]
                order = np.lexsort((dist[i, idx], urgency[i, idx]))[:nb.max_neighbours]
                idx = idx[order]
                if not np.any(along[i, idx] < bounds[i, idx] - slack[i, idx]):
                    continue                          # only unkept half-spaces are violated
                x, dropped = project_command(u[i], normals[i, idx], bounds[i, idx], amax)
                rec_f["dropped"][tick, i] = dropped
                if not np.array_equal(x, u[i]):
                    u[i] = x
                    projected[i] = True
            rec_f["kept"][tick] = np.minimum(np.sum(valid, axis=1), nb.max_neighbours)
        U_prev = u.copy()
        acts = saturated | rate_limited | projected
        aug = np.where(acts[:, None], u - ub - uff, ua)        # the augmentation that acts
        rec["u"][tick], rec["u_baseline"][tick], rec["u_tracker"][tick] = u, ub, aug
        rec_f["projected"][tick], rec_f["saturated"][tick] = projected, saturated
        rec_f["rate_limited"][tick] = rate_limited

        # The true vehicles: saturation, lag, gain.
        s = u.copy()
        norm = np.linalg.norm(s, axis=1)
        over = norm > v_limit
        s[over] *= (v_limit[over] / norm[over])[:, None]
        Z = np.where((v_lag > 0.0)[:, None], Z + v_beta[:, None] * (s - Z), s)
        drive = v_gain[:, None] * Z
        rec["u_applied"][tick] = drive
        if tick == N:
            break

        # The estimator over the period: RK4 substeps with y, the augmentation and w held; an
        # estimate outside the hard sphere after a substep is scaled back onto it.
        c = w - aug @ sc.B.T - y @ sc.L.T
        for _ in range(sc.substeps):
            k1 = field_at(XH, c)
            k2 = field_at(XH + 0.5 * delta * k1, c)
            k3 = field_at(XH + 0.5 * delta * k2, c)
            k4 = field_at(XH + delta * k3, c)
            XH = XH + (delta / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
            norm = np.linalg.norm(XH, axis=1)
            out = norm > xi_max
            XH[out] *= (xi_max[out] / norm[out])[:, None]

        # The plants, exactly over [t_k, t_k+1]: inputs held, pulses cut at their edges.
        a, b = t, grid[tick + 1]
        value, cut, edges = leader_drive
        X_next = np.empty_like(X)
        X_next[0] = advance(X[0], u1, sc.disturbances, [], edges, a, b, step, sc.B,
                            value[tick], cut[tick])
        Phi, Psi = step(b - a)
        plain = [i for i in range(F) if not follower_drive[i][1][tick]]
        if plain:
            mids = np.array([follower_drive[i][0][tick] for i in plain])
            V = drive[plain] @ sc.B.T + mids
            X_next[np.array(plain) + 1] = X[np.array(plain) + 1] @ Phi.T + V @ Psi.T
        for i in range(F):
            if follower_drive[i][1][tick]:
                value, cut, edges = follower_drive[i]
                X_next[i + 1] = advance(X[i + 1], drive[i], pulses[i], sines[i], edges, a, b,
                                        step, sc.B, value[tick], True)
        X = X_next
    wall = time.perf_counter() - wall0

    names = [f"follower_{i}" for i in range(1, F + 1)] if fm is not None else [None]
    runs = []
    for i in range(F):
        cols = {"t": grid}
        for e in range(n):
            cols[f"xi_{e}"] = rec["xi"][:, i, e]
        for e in range(n):
            cols[f"xi_hat_{e}"] = rec["xi_hat"][:, i, e]
        cols["norm_xi"] = np.linalg.norm(rec["xi"][:, i], axis=1)
        cols["norm_xi_hat"] = np.linalg.norm(rec["xi_hat"][:, i], axis=1)
        cols["xi_max"] = np.full(N + 1, xi_max[i])
        cols["xi_soft"] = np.full(N + 1, xi_max[i] / math.sqrt(1.0 + sc.epsilon))
        cols["f"] = rec_f["f"][:, i]
        for e in range(k):
            cols[f"leader_p_{e}"] = rec["target"][:, i, e]
        for e in range(k):
            cols[f"follower_p_{e}"] = rec["x"][:, i, e]
        if sc.double_integrator:
            for e in range(k):
                cols[f"leader_v_{e}"] = rec["target"][:, i, k + e]
            for e in range(k):
                cols[f"follower_v_{e}"] = rec["x"][:, i, k + e]
        cols["separation"] = np.linalg.norm(rec["target"][:, i, :k] - rec["x"][:, i, :k], axis=1)
        cols["perimeter"] = np.full(N + 1, own_perimeter[i])
        for name in ("u", "u_baseline", "u_tracker", "u_applied"):
            for e in range(m):
                cols[f"{name}_{e}"] = rec[name][:, i, e]
        for e in range(m):
            cols[f"leader_u_{e}"] = u1_grid[:, e]
        for e in range(n):
            cols[f"noise_{e}"] = rec["noise"][:, i, e]
        for name in ("saturated", "rate_limited", "projected", "kept", "dropped"):
            cols[name] = rec_f[name][:, i]
        if sc.safety_filter is not None:
            cols["barrier_infeasible"] = rec_f["barrier_infeasible"][:, i]
        runs.append((names[i], cols, xi_max[i]))
    return runs, targets, pair_min, wall


def pair_figures(pair_min, targets, perimeter):
    """The formation line's figures from the pairs' smallest distances (agents 0 .. F, 0 the
    leader): min_pair_separation, perimeter, min_neighbour_separation (pairs of which neither
    looks at the other), pairs_inside_perimeter and neighbour_pairs_inside_perimeter (pairs that
    came closer than the perimeter at some tick)."""
    agents = pair_min.shape[0]
    target_of = {i: int(targets[i - 1]) for i in range(1, agents)}
    every, neighbours = [], []
    for b in range(1, agents):
        for a in range(b):
            every.append(pair_min[a, b])
            if target_of.get(a) != b and target_of.get(b) != a:
                neighbours.append(pair_min[a, b])
    return {"min_pair_separation": min(every, default=math.inf),
            "perimeter": perimeter,
            "min_neighbour_separation": min(neighbours, default=math.inf),
            "pairs_inside_perimeter": sum(1 for v in every if v < perimeter),
            "neighbour_pairs_inside_perimeter": sum(1 for v in neighbours if v < perimeter)}


def run_sampled(sc, csv_path=None):
    """Run the sampled loop and print cf_sim's lines; returns an exit status."""
    runs, targets, pair_min, wall = simulate_sampled(sc)
    for i, (name, cols, xi_max) in enumerate(runs):
        if csv_path:
            path = follower_csv_path(csv_path, name) if name else csv_path
            try:
                write_csv(path, cols)
            except OSError as exc:
                print(f"{PROG}: error: cannot write {path}: {exc.strerror}", file=sys.stderr)
                return 1
        norm_xi = cols["norm_xi"]
        figures = {"max_xi": float(np.max(norm_xi)),
                   "max_xi_hat": float(np.max(cols["norm_xi_hat"])), "xi_max": xi_max,
                   "min_separation": float(np.min(cols["separation"])),
                   "time_outside": int(np.count_nonzero(norm_xi > xi_max)) / sc.control_rate,
                   "wall_s": wall}
        if sc.safety_filter is not None:
            figures["barrier_ticks"] = int(np.count_nonzero(cols["projected"]))
            figures["barrier_infeasible_ticks"] = int(
                np.count_nonzero(cols["barrier_infeasible"]))
        line = " ".join(f"{key}={value}" if isinstance(value, int) else f"{key}={value:.9g}"
                        for key, value in figures.items())
        target = "leader" if targets[i] == 0 else f"follower_{targets[i]}"
        print(f"{name} target={target} {line}" if name else line, flush=True)
    if sc.formation is not None:
        print(formation_line(sc, pair_figures(pair_min, targets, sc.perimeter), wall))
    return 0


def formation_line(sc, figures, wall):
    fm = sc.formation
    text = " ".join(f"{key}={value:.9g}" if isinstance(value, float) else f"{key}={value}"
                    for key, value in figures.items())
    return (f"formation followers={fm.followers} topology={fm.topology} shape={fm.shape} "
            f"slots={fm.slots} {text} wall_s={wall:.9g}")
