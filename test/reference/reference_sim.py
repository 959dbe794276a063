#!/usr/bin/python3
"""Continuous-time reference simulation of the projection-based collision avoidance loop.

This is an independent implementation of the closed loop of Gehlot et al.,
"Projection-Based Inter-Agent Collision Avoidance in Dual Agent Systems", in the
form fixed by doc/math.md of the shared notes. It exists to cross-check the
sampled C++ simulator ``cf_sim``: it reads the same scenario YAML
(doc/cf_sim.md, section 'Scenario files'), integrates leader, follower and CF estimator together
as one ODE with ``scipy.integrate.solve_ivp`` (no sampling, no zero-order hold)
and prints the same summary line.

State and equations (all continuous in time)::

    xi     = x_1 - x_2 - d,   y = C xi,   y_hat = C xi_hat
    u_a    = G_e (y - y_hat) + S_21 y_hat         (tracker enabled, else 0)
    a_1    = u_1 + pinv(B) u_d(t)                 (leader_information.disturbance, else u_1)
    u_ff   = a_1                                  (leader_information.command, else 0)
    u_2    = G y + u_a + u_ff
    x_1'   = A x_1 + B u_1(t) + u_d(t)
    x_2'   = A x_2 + B u_2
    h      = A_c xi_hat - B u_a + L (y_hat - y)   [+ B (a_1 - u_ff) if
                                                   leader_information.estimator]
    xi_hat' = h - f Gamma^-1 grad_f (grad_f^T h) / (grad_f^T Gamma^-1 grad_f)
                                                  if f > 0 and grad_f^T h > 0
            = h                                   otherwise

with A_c = A - B G C, Gamma (A_c + L C) + (A_c + L C)^T Gamma = -Q and
f = ((1 + eps) ||xi_hat||^2 - xi_max^2) / (eps xi_max^2), xi_max = (1 - alpha) ||d||.

a_1 is the leader acceleration that the follower is told (leader_information):
with ``disturbance: true`` it includes the part of the leader's disturbance
that acts through B, pinv(B) u_d (for a double integrator the velocity-rate
half of u_d); the rest, (I - B pinv(B)) u_d (the position-rate half), reaches
the follower through xi only. The flag matters only when ``command`` or
``estimator`` is on. With both on, B (a_1 - u_ff) = 0: the estimator then
needs no model of the fed-forward acceleration, which cancels in xi'.

Turning slots (doc/math.md, section 'Turning slots', (T1)-(T3); ``formation.slots:
turning``, a double integrator of 2 or 3 axes). The slot d = [d_p; 0] is given in the
leader's body frame and turned about z by the slot heading theta, two more states
integrated with the rest::

    psi     = atan2(v_y, v_x)  of the leader's velocity v (its heading)
    psi'    = (v_x a_y - v_y a_x) / (v_x^2 + v_y^2),  a = u_1 + pinv(B) u_d (its true
              acceleration); psi := theta, psi' := 0 where ||v|| < min_speed
    theta'' = clamp(w^2 wrap(psi - theta) + 2 zeta w (psi' - theta'), +-beta),
              and theta'' <= 0 at theta' >= max_yaw_rate (>= 0 at <= -max_yaw_rate)   (T1)
    D       = [R(theta) d_p; theta' J R(theta) d_p]                                 (T2)
    xi      = x_1 - x_2 - D
    u_r     = -(theta'' J + theta'^2 J^2) R(theta) d_p                              (T3)
    u_2     = G y + u_a + u_ff + u_r

with wrap() to (-pi, pi], R(theta) the turn of the x-y part by theta (z kept) and
J = [[0, -1], [1, 0]] on x-y (0 on z). u_r is a known input that cancels between the
plant and the estimator's model (the augmentation that acts, u_2 - G y - u_ff - u_r, is
u_a), so h above is unchanged. theta(0) = psi(0) (0 if the leader starts below
min_speed), theta'(0) = 0, and the follower starts at x_2(0) = x_1(0) - D(theta(0), 0)
- xi_0 with xi_0 = x_1(0) - x_2(0) - d from the scenario: on its turned slot if the
scenario puts it on its slot. In 3-D the threshold is on the whole speed ||v||, as
doc/math.md writes it. Where cf_sim holds theta'' and u_r over a control period and
takes psi' as a difference quotient, this is exact in time: the two agree to O(T).

``formation.turning.reversing`` (cf_sim.md) is not in (T1): only ``false`` is accepted.

Formations: a ``formation`` section (keys as cf_sim's) is covered when every follower
looks at the leader, i.e. ``followers: 1`` (either topology) or ``topology: star``; a
chain of more followers is refused (exit 2) but by the sampled loop (below). Follower i
runs the pair's loop on its own d_i (doc/formations.md: line i d; V ceil(i/2) R(+-half_angle) d, + for odd i), with its
own xi_max, and starts with the scenario's xi_0; the followers do not interact, so each
is simulated alone. The output is then cf_sim's: a line
``follower_<i> target=leader max_xi=..`` per follower, then
``formation followers=.. topology=.. shape=.. slots=.. min_pair_separation=.. wall_s=..``
(the smallest distance between any two agents, leader included, on the grid); --csv FILE
writes FILE with _follower_<i> before its extension, per follower.

The formation line also gives ``perimeter=`` (alpha ||d|| of the scenario's d),
``min_neighbour_separation=`` (over the pairs of which neither looks at the other),
``pairs_inside_perimeter=`` and ``neighbour_pairs_inside_perimeter=`` (the pairs whose smallest
distance on the grid is below the perimeter), as cf_sim's does.

World and neighbours: the sampled loop. The section ``world`` (doc/formations.md, "A world that
can hurt") and ``formation.neighbours`` ((N1)-(N3) of doc/formations.md, "Neighbours") act per
control tick, so a scenario with either (or any scenario with --sampled) is not integrated in
continuous time but run as the sampled recursion of doc/math.md ("Follower command",
"Discretisation", "Offline simulator (cf_sim)"), every agent together (a star or a chain of
world slots; turning slots are refused). At tick t_k = k T, T = 1 / control_rate, with every
agent's true state x_j(t_k) and follower i looking at agent t(i) (0 the leader)::

    xi_i   = x_t(i) - x_i - d_i,   y = C (xi_i + noise_k)        noise entry e: sigma_e
             N(seed, 4 i + 1, k n + e) (sigma: position on the k position entries, else velocity)
    xi_hat = pinv(C) y moved into ||.|| <= xi_max at k = 0 (or 0: initial_estimate: zero)
    u      = sat(G y + u_a + u_ff, controller.acceleration_limit), u_a as above (0 tracker off)
    u      = u_prev + clamp(u - u_prev, jerk_limit T)            (controller.jerk_limit)
    u      = the projection (N3) of u (formation.neighbours), below
    xi_hat over [t_k, t_k+1]: `substeps` RK4 steps of the projected drift above with y, w and
           the augmentation held (u_a, or u - G y - u_ff where saturation, the rate limit or the
           projection changed the command), after each step moved back into ||.|| <= xi_max
    s_k    = sat(u, a_max of the vehicle);  z_k = z_k-1 + (1 - exp(-T / tau)) (s_k - z_k-1)
             (z_k = s_k for tau = 0, z_-1 = 0);  the plant is driven by g z_k over [t_k, t_k+1)
    plants exactly over [t_k, t_k+1] (x(t + h) = Phi(h) x + Psi(h) v, v constant), the period
           cut at the agent's own pulse edges: the leader's u_1(t_k) held and its disturbance
           pulses; follower i's pulses (world.followers and its gusts) and its sinusoids, these
           taken at the middle of each piece

u_prev is the command of the tick before (0 before the first). Gusts of follower i are drawn
from stream 4 i in the order of doc/formations.md (gust_pulses()); U and N as there
(uniform_draw(), normal_draws()). The summary figures use the true xi_i.

(N1)-(N3): follower i senses every other agent j within `radius` (its own target included, with
rho_j = alpha ||d_i||, every other with rho = perimeter); with p = p_i - p_j, v = v_i - v_j,
c = ||p||, n = p / c (the x axis at c = 0), s = -n.v and v_perp^2 = max(0, ||v||^2 - (n.v)^2):
beyond rho_j h = sqrt(2 a_b (c - rho_j)) - s and b = a_b s / sqrt(2 a_b (c - rho_j)) - v_perp^2 / c
+ A_n - omega h, else h = -inf and b = a_b + A_n. The half-space n.u >= b is dropped where b is
not finite or b <= -a_max (a_max = controller.acceleration_limit), and of the rest the
max_neighbours most urgent are kept (smaller h first, ties by smaller c). u is replaced by its
Euclidean projection onto the ball ||u|| <= a_max and the kept half-spaces, computed exactly by
enumerating active sets (nearest_point()); if that set is empty, the half-spaces are added in
priority order and any whose addition empties it is dropped (project_command()). Its CSV adds
u_applied_* (g z), noise_*, and per tick saturated, rate_limited, projected, kept, dropped.

The input and disturbance pulses make the right-hand side discontinuous in time,
so the integration is restarted at every pulse edge. Inside a segment the
right-hand side is Lipschitz (the projection term vanishes continuously at
f = 0 and at grad_f^T h = 0), except with turning slots. There theta'' switches where
theta' reaches +-max_yaw_rate, and the yaw rate then slides on that surface; the solver
would step to and fro across it (LSODA stalls), so the rate limit is a discrete mode and
the integration is also restarted where it switches (terminal events,
rate_limit_events()). Where ||v|| crosses min_speed and where psi - theta crosses
+-pi, theta'' jumps once, and the solver's error control crosses it (the summary of the
figure eight, with the rate limit active for 63 of its 120 s, moves by < 3e-7 m from
rtol 1e-6 to 1e-9).
The solution is reported on the grid
t_k = k / control_rate, k = 0 .. N with N = floor(duration * control_rate), the
rows of the CSV of cf_sim; with turning slots the CSV adds cf_sim's columns
slot_heading, slot_yaw_rate, slot_yaw_acceleration, slot_p_* (R(theta) d_p) and
u_slot_* (u_r).

The barrier filter: with controller.safety_filter (the tracker off) the sampled loop replaces
the projection (N3) by the filter (B1)-(B3) of doc/math.md, barrier_reference.py; its summary
line adds barrier_ticks and barrier_infeasible_ticks, its CSV barrier_infeasible.

Usage::

    reference_sim.py SCENARIO.yaml [--set key=value]... [--method LSODA]
                     [--rtol 1e-6] [--atol 1e-9] [--max-step S] [--csv FILE] [--sampled]

(--method, --rtol, --atol and --max-step are the continuous loop's; the sampled loop has none.)
controller.acceleration_limit and controller.jerk_limit are accepted by the sampled loop only.

Exit codes: 0 success, 1 integration failure, 2 bad command line or scenario.

The modules beside this file (installed with it): refsim_format (the allowed keys, --set, value
checks), refsim_parts and refsim_scenario (parsing the scenario), refsim_layout (slots and
targets), refsim_inputs (pulses, sinusoids, the turning slot's heading), refsim_continuous (the
continuous loop), refsim_world, refsim_projection and refsim_sampled (the sampled loop), and
barrier_reference (the barrier filter).
"""

from __future__ import annotations

import argparse
import dataclasses
import math
import os
import sys

import numpy as np

# The modules beside this file (installed with it).
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from refsim_continuous import (follower_csv_path, signals_on_grid, simulate,  # noqa: E402
                               summary, write_csv)
from refsim_format import PROG, ScenarioError  # noqa: E402
from refsim_layout import slot_layout  # noqa: E402
from refsim_sampled import formation_line, pair_figures, run_sampled  # noqa: E402
from refsim_scenario import load_scenario  # noqa: E402


def parse_args(argv):
    ap = argparse.ArgumentParser(
        prog="reference_sim.py",
        description="Continuous-time reference simulation of a scenario (see module docstring).")
    ap.add_argument("scenario", help="scenario YAML (doc/cf_sim.md, section 'Scenario files')")
    ap.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                    help="override a scenario entry by dotted path; VALUE is YAML "
                         "(a numeric path element indexes a list); repeatable")
    ap.add_argument("--method", default="LSODA", help="solve_ivp method (default LSODA)")
    ap.add_argument("--rtol", type=float, default=1e-6, help="relative tolerance (default 1e-6)")
    ap.add_argument("--atol", type=float, default=1e-9, help="absolute tolerance (default 1e-9)")
    ap.add_argument("--max-step", type=float, default=math.inf,
                    help="largest step, s (default: no limit)")
    ap.add_argument("--csv", metavar="FILE", help="write the sampled signals to FILE")
    ap.add_argument("--sampled", action="store_true",
                    help="run the sampled loop (as with a section world or formation.neighbours)")
    return ap.parse_args(argv)


def follower_scenarios(sc):
    """(name, scenario) per follower; name None for the pair without a formation section.

    Every follower looks at the leader (a star, or a single follower), so each runs
    the pair's loop on its own d_i and is simulated alone. It starts with the relative
    error the scenario gives its single follower, xi_0 = x_1(0) - x_2(0) - d.
    """
    if sc.formation is None:
        return [(None, sc)]
    return [(f"follower_{i}", dataclasses.replace(sc, d=di, x2_0=sc.x2_0 + (sc.d - di)))
            for i, di in enumerate(slot_layout(sc.formation, sc.d, sc.k), start=1)]

def pair_minima(runs, k):
    """(F + 1, F + 1): the smallest distance between each two agents (0 the leader, i follower
    i) on the grid."""
    points = [np.vstack([runs[0][2][f"leader_p_{i}"] for i in range(k)])]
    points += [np.vstack([cols[f"follower_p_{i}"] for i in range(k)]) for _, _, cols, _ in runs]
    out = np.full((len(points), len(points)), math.inf)
    for j in range(1, len(points)):
        for i in range(j):
            out[i, j] = out[j, i] = float(np.min(np.linalg.norm(points[j] - points[i], axis=0)))
    return out


def main(argv=None):
    args = parse_args(argv)
    try:
        sc = load_scenario(args.scenario, args.overrides, args.sampled)
    except ScenarioError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 2
    if sc.sampled:
        return run_sampled(sc, args.csv)
    runs = []
    for name, fsc in follower_scenarios(sc):
        try:
            grid, Z, modes, wall, _ = simulate(fsc, args.method, args.rtol, args.atol,
                                               args.max_step)
        except (RuntimeError, ValueError) as exc:
            print(f"{PROG}: error: {name + ': ' if name else ''}{exc}", file=sys.stderr)
            return 1
        cols = signals_on_grid(fsc, grid, Z, modes)
        if args.csv:
            path = follower_csv_path(args.csv, name) if name else args.csv
            try:
                write_csv(path, cols)
            except OSError as exc:
                print(f"{PROG}: error: cannot write {path}: {exc.strerror}", file=sys.stderr)
                return 1
        line = " ".join(f"{key}={value:.9g}" for key, value in summary(fsc, cols, wall).items())
        print(f"{name} target=leader {line}" if name else line, flush=True)
        runs.append((name, fsc, cols, wall))
    if sc.formation is not None:
        figures = pair_figures(pair_minima(runs, sc.k), [0] * len(runs), sc.perimeter)
        print(formation_line(sc, figures, sum(r[3] for r in runs)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
