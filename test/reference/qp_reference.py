"""The reference solution of compare_qp.py's problems: cvxopt (coneqp, conelp) on the scaled
problem, polished onto its active set and certified by the KKT conditions."""

import math
import sys
from dataclasses import dataclass

import numpy as np
from cvxopt import matrix, solvers
from scipy.optimize import nnls

from qp_problems import vnorm


FEASIBILITY = 1e-9      # half-space violation / max(s, ||u*||)
ROUNDING = 4 * sys.float_info.epsilon  # ||u*|| <= a_max (1 + ROUNDING)
CERTIFY = 1e-12         # the polished point's feasibility (scaled)
STATIONARITY = 1e-10    # the polished point's KKT residual (scaled)
BIG_RADIUS = 1e4        # the depth LP's ball when a_max is infinite (scaled)
QP_TOLERANCES = (1e-12, 1e-10, 1e-8)     # cvxopt's abstol = reltol = feastol, tried in turn
DEPTH_TOLERANCES = (1e-10, 1e-9, 1e-8)
COUNTS = {"coneqp did not converge": 0, "nor did the epigraph form": 0}


@dataclass
class Scaled:
    """The problem divided by s, with unit normals: n_j^T u >= c_j, ||u|| <= a."""
    n: np.ndarray
    c: np.ndarray
    u0: np.ndarray
    a: float
    s: float


def scaled(p):
    g = np.array(p.g, dtype=float).reshape(len(p.b), p.k)
    norms = np.array([vnorm(gj) for gj in g])
    n = g / norms[:, None] if len(norms) else g
    c = np.array(p.b, dtype=float) / norms if len(norms) else np.zeros(0)
    u0 = np.array(p.u_nom, dtype=float)
    s = max([vnorm(u0)] + ([p.a_max] if math.isfinite(p.a_max) else []) + list(np.abs(c)))
    s = s if s > 0.0 else 1.0
    return Scaled(n, c / s, u0 / s, p.a_max / s, s)


def cone(sc, idx, with_t, radius):
    """G, h, dims of n_j^T u (- t) >= c_j for j in idx and ||u|| (+ t) <= radius."""
    k = len(sc.u0)
    cols = k + (1 if with_t else 0)
    rows, h = [], []
    for j in idx:
        row = np.zeros(cols)
        row[:k] = -sc.n[j]
        if with_t:
            row[k] = 1.0
        rows.append(row)
        h.append(-sc.c[j])
    q = []
    if math.isfinite(radius):
        row = np.zeros(cols)
        if with_t:
            row[k] = 1.0
        rows.append(row)
        h.append(radius)
        for i in range(k):
            row = np.zeros(cols)
            row[i] = -1.0
            rows.append(row)
            h.append(0.0)
        q = [k + 1]
    return (matrix(np.array(rows, dtype=float).reshape(len(rows), cols)),
            matrix(np.array(h, dtype=float)), {"l": len(idx), "q": q, "s": []})


def cvxopt_solve(solver, tolerances, **kwargs):
    """cvxopt's result at the first of TOLERANCES it reaches 'optimal' at, else its last
    'unknown' one, else None (every attempt raised: cvxopt's domain errors near degenerate
    optima)."""
    last = None
    for tol in tolerances:
        options = {"show_progress": False, "abstol": tol, "reltol": tol, "feastol": tol,
                   "maxiters": 100}
        try:
            result = solver(options=options, **kwargs)
        except (ValueError, ArithmeticError):
            continue
        if result["status"] == "optimal":
            return result
        last = last or (result if result["x"] is not None else None)
    return last


def depth(sc, idx):
    """max t s.t. n_j^T u - t >= c_j (j in idx), ||u|| + t <= a (BIG_RADIUS for a = inf)."""
    k = len(sc.u0)
    radius = sc.a if math.isfinite(sc.a) else BIG_RADIUS
    G, h, dims = cone(sc, idx, True, radius)
    cost = np.zeros(k + 1)
    cost[k] = -1.0
    result = cvxopt_solve(solvers.conelp, DEPTH_TOLERANCES, c=matrix(cost), G=G, h=h, dims=dims)
    return None if result is None else float(result["x"][k])


def cvxopt_projection(sc, idx):
    """cvxopt's u* for the half-spaces idx and the ball, or None: coneqp, or, where coneqp does not
    converge (it can cycle, even where u_nom is feasible), conelp on the epigraph form
    min tau s.t. ||u - u_nom|| <= tau."""
    if not idx and not math.isfinite(sc.a):
        return sc.u0.copy()
    k = len(sc.u0)
    G, h, dims = cone(sc, idx, False, sc.a)
    result = cvxopt_solve(solvers.coneqp, QP_TOLERANCES, P=matrix(np.eye(k)), q=matrix(-sc.u0),
                          G=G, h=h, dims=dims)
    if result is not None and result["status"] == "optimal":
        return np.array(result["x"]).ravel()
    COUNTS["coneqp did not converge"] += 1
    # The epigraph: x = (u, tau), the cone [tau; u - u_nom] first, then those of cone().
    G = np.hstack([np.array(G), np.zeros((G.size[0], 1))])
    top = np.zeros((k + 1, k + 1))
    top[0, k] = -1.0
    top[1:, :k] = -np.eye(k)
    h = np.array(h).ravel()
    G = np.vstack([G[:len(idx)], top, G[len(idx):]])
    h = np.concatenate([h[:len(idx)], [0.0], -sc.u0, h[len(idx):]])
    cost = np.zeros(k + 1)
    cost[k] = 1.0
    epigraph = cvxopt_solve(solvers.conelp, DEPTH_TOLERANCES, c=matrix(cost), G=matrix(G),
                            h=matrix(h), dims={"l": len(idx), "q": [k + 1] + dims["q"], "s": []})
    if epigraph is not None and epigraph["x"] is not None:
        if epigraph["status"] != "optimal":
            COUNTS["nor did the epigraph form"] += 1
        return np.array(epigraph["x"]).ravel()[:k]
    return None if result is None else np.array(result["x"]).ravel()


def kkt_residual(sc, idx, u, active, ball, feasibility=CERTIFY):
    """The KKT residual of u for the half-spaces idx and the ball: min over lambda >= 0 of
    ||u0 - u - sum lambda_j (-n_j) - lambda_ball u|| over the ACTIVE ones (nnls); infinite when
    u violates one by more than FEASIBILITY."""
    slack = sc.n[list(idx)] @ u - sc.c[list(idx)] if idx else np.zeros(0)
    if np.any(slack < -feasibility) or (math.isfinite(sc.a) and
                                         vnorm(u) > sc.a * (1 + feasibility)):
        return math.inf
    columns = [-sc.n[j] for j in active] + ([u] if ball else [])
    r = sc.u0 - u
    if not columns:
        return vnorm(r)
    return float(nnls(np.column_stack(columns), r)[1])


def affine_sphere_projection(sc, active, ball):
    """u0 projected onto {n_j^T u = c_j, j in active} (and the sphere ||u|| = a if BALL and the
    projection is outside it), or None."""
    k = len(sc.u0)
    p0, null = np.zeros(k), np.eye(k)
    if active:
        pinv = np.linalg.pinv(sc.n[active], rcond=1e-10)
        p0 = pinv @ sc.c[active]
        null = np.eye(k) - pinv @ sc.n[active]
    w = null @ sc.u0
    u = p0 + w
    if not ball or vnorm(u) <= sc.a:
        return u
    d = vnorm(p0)
    if d > sc.a * (1 + CERTIFY) or vnorm(w) == 0.0:
        return None
    return p0 + math.sqrt(max(0.0, (sc.a - d) * (sc.a + d))) * w / vnorm(w)


def reference(sc, idx):
    """(u*, kind, cvxopt's point) for the half-spaces idx and the ball: kind 'polished'
    (certified), 'raw' (cvxopt's point) or 'none' (cvxopt failed)."""
    x = cvxopt_projection(sc, idx)
    if x is None:
        return None, "none", None
    for theta in (1e-10, 1e-8, 1e-6, 1e-4):
        active = [j for j in idx if sc.n[j] @ x - sc.c[j] <= theta]
        ball = math.isfinite(sc.a) and sc.a - vnorm(x) <= theta
        u = affine_sphere_projection(sc, active, ball)
        if u is not None and kkt_residual(sc, idx, u, active, ball) <= STATIONARITY:
            return u, "polished", x
    return x, "raw", x


def ours_kkt(sc, idx, u):
    """The KKT residual of our u* (active: within FEASIBILITY)."""
    tol = FEASIBILITY * max(1.0, vnorm(u))
    active = [j for j in idx if sc.n[j] @ u - sc.c[j] <= tol]
    ball = math.isfinite(sc.a) and vnorm(u) >= sc.a * (1 - FEASIBILITY)
    return kkt_residual(sc, idx, u, active, ball, max(tol, ROUNDING))
