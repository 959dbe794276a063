"""The control barrier function filter of doc/math.md ("A control barrier function filter (the
comparison)", (B1)-(B3)) for reference_sim.py's sampled loop, written from those equations.

With ``controller.safety_filter: {rate: lambda}`` (the tracker off), at every tick follower i's
command u (the baseline law after saturation and the jerk limit) is replaced by

    u* = argmin ||x - u||^2  s.t.  g_j^T x >= b_j for each barrier j,  ||x|| <= a_max     (B3)

with, for an agent j at p = p_i - p_j, v = v_i - v_j, acceleration a_j and perimeter rho,

    h = ||p||^2 - rho^2,  h' = 2 p^T v,  g_j = p,
    b_j = p^T a_j - ||v||^2 - 2 lambda p^T v - (lambda^2 / 2) h                            (B2)

The barriers, most urgent first: the target's (rho = alpha ||d_i||; a_j the leader's
acceleration a_1 when controller.leader_information shares it, else 0), then with
formation.neighbours every other agent (N3)'s sensing keeps, in its order (within the radius, b
of (N2) finite and > -a_max, the max_neighbours of smallest h of (N1), ties by distance; the
target counted among them, then left out), each at a_j = A_n p / ||p|| and rho = perimeter.
(N3)'s half-spaces themselves are not applied. An agent at p = 0 gives no barrier.

The QP is solved exactly by refsim_projection.nearest_point() on the unit normals p / ||p||. If
it is infeasible: when the first barrier alone does not meet the ball (b_0 / ||g_0|| > a_max),
u* = a_max g_0 / ||g_0|| (u itself if within 1e-9 a_max of it: the QP's tolerance); otherwise
the barriers are taken in priority order and each whose addition empties the set with the ball
is left out (refsim_projection.project_command()). A tick counts as a barrier tick when u*
differs from u, and as infeasible when some barrier was left out.
"""

import math

import numpy as np

from refsim_projection import nearest_point, project_command

SCHEMA = {"rate": None}
DEFAULT_RATE = 2.0  # 1/s


def parse(node, tracker, double_integrator, error):
    """lambda (1/s) of controller.safety_filter, or None without it; raises error(text)."""
    if node is None:
        return None
    if not isinstance(node, dict):
        raise error("controller.safety_filter: expected a mapping")
    if not double_integrator:
        raise error("controller.safety_filter: needs a double_integrator model")
    if tracker:
        raise error("controller.safety_filter: needs controller.tracker.enabled: false (the "
                    "filter's nominal command is the baseline law)")
    rate = node.get("rate", DEFAULT_RATE)
    if isinstance(rate, bool) or not isinstance(rate, (int, float)) \
            or not math.isfinite(rate) or not rate > 0.0:
        raise error(f"controller.safety_filter.rate: must be finite and > 0, got {rate!r}")
    return float(rate)


def barrier(p, v, a, rho, rate):
    """(B1), (B2): (g, b) of the half-space g^T u >= b."""
    h = float(p @ p) - rho * rho
    h_dot = 2.0 * float(p @ v)
    return p, float(p @ a) - float(v @ v) - rate * h_dot - 0.5 * rate * rate * h


def kept_agents(i, valid, urgency, distance, max_neighbours):
    """(N3)'s kept agents of follower i (indices into the agents, 0 the leader), most urgent
    first: the valid ones, by smaller h, ties by smaller distance, at most max_neighbours."""
    idx = np.nonzero(valid[i])[0]
    order = np.lexsort((distance[i, idx], urgency[i, idx]))[:max_neighbours]
    return [int(j) for j in idx[order]]


def filter_command(u, halfspaces, amax):
    """(B3) for one follower: (u*, infeasible). halfspaces: (g, b) most urgent first."""
    rows = [(g / np.linalg.norm(g), b / np.linalg.norm(g)) for g, b in halfspaces
            if np.linalg.norm(g) > 0.0]
    if not rows:
        return u, False
    normals = np.array([r[0] for r in rows])
    bounds = np.array([r[1] for r in rows])
    x = nearest_point(u, normals, bounds, amax)
    if x is not None:
        return x, False
    if bounds[0] > amax:
        best = amax * normals[0]
        return (best if np.linalg.norm(best - u) > 1e-9 * amax else u), True
    x, _ = project_command(u, normals, bounds, amax)
    return x, True


def filter_commands(sc, rate, u, X, targets, own_perimeter, a1, known, neighbours):
    """Every follower's filtered command this tick: (u* (F, m), changed (F,), infeasible (F,)).

    X (F + 1, n) the agents' true states (row 0 the leader); targets (F,) the agent each
    follower looks at; a1 the leader's acceleration (m,), used for a target that is the leader
    when known; neighbours None, or (N3)'s (params, valid, urgency, distance) of the tick.
    """
    k = sc.k
    amax = sc.acceleration_limit
    F = targets.size
    out = u.copy()
    changed = np.zeros(F, dtype=bool)
    infeasible = np.zeros(F, dtype=bool)
    for i in range(F):
        own = X[i + 1]
        t = int(targets[i])
        a_target = a1[:k] if (known and t == 0) else np.zeros(k)
        halfspaces = [barrier(own[:k] - X[t, :k], own[k:2 * k] - X[t, k:2 * k], a_target,
                              own_perimeter[i], rate)]
        if neighbours is not None:
            nb, valid, urgency, distance = neighbours
            for j in kept_agents(i, valid, urgency, distance, nb.max_neighbours):
                if j == t:
                    continue
                p = own[:k] - X[j, :k]
                c = float(np.linalg.norm(p))
                a = nb.neighbour_acceleration * p / c if c > 0.0 else np.zeros(k)
                halfspaces.append(barrier(p, own[k:2 * k] - X[j, k:2 * k], a, nb.perimeter,
                                          rate))
        x, infeasible[i] = filter_command(u[i], halfspaces, amax)
        if not np.array_equal(x, u[i]):
            out[i] = x
            changed[i] = True
    return out, changed, infeasible
