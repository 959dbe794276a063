"""The neighbours' command projection (N1)-(N3) of reference_sim.py's sampled loop, solved
exactly by enumerating active sets."""

from __future__ import annotations

import itertools
import math

import numpy as np


_SUBSETS = {}


def _subsets(q, k):
    """Index arrays (C, s) of the subsets of s of q half-spaces, s = 1 .. min(k, q)."""
    key = (q, k)
    if key not in _SUBSETS:
        _SUBSETS[key] = [np.array(list(itertools.combinations(range(q), size)),
                                  dtype=int).reshape(-1, size)
                         for size in range(1, min(k, q) + 1)]
    return _SUBSETS[key]


def nearest_point(u, normals, bounds, amax, tol=1e-10):
    """The point of {||x|| <= amax} cap {normals x >= bounds} (unit normals) nearest to u, or
    None if the set is empty.

    Exact, by enumerating active sets: the nearest point satisfies its KKT conditions with a
    linearly independent set S of active half-spaces (|S| <= k) and the ball active or not, so
    it is the candidate of one of them: u's projection onto the affine set {N_S x = b_S}
    (x0 + P u, x0 the set's point nearest 0, P the projector onto N_S's null space), or the
    point of that set on the sphere along P u, x0 + sqrt(amax^2 - |x0|^2) P u / |P u|. Every
    feasible candidate is at least as far from u as the nearest point, so the nearest feasible
    candidate is it (feasible: within tol, relative, of every half-space and the sphere).
    """
    k = u.size
    ball = amax < math.inf
    cands = [u[None, :]]
    nu = float(np.linalg.norm(u))
    if ball and nu > 0.0:
        cands.append((u * (amax / nu))[None, :])
    for idx in _subsets(bounds.size, k):
        size = idx.shape[1]
        Ns, bs = normals[idx], bounds[idx]                              # (C, s, k), (C, s)
        if size == k:                                                   # vertices
            ok = np.abs(np.linalg.det(Ns)) > 1e-7 if size > 1 else np.ones(len(idx), bool)
            if np.any(ok):
                cands.append(np.linalg.solve(Ns[ok], bs[ok][:, :, None])[:, :, 0])
            continue
        if size == 1:
            Minv = np.ones((len(idx), 1, 1))
        else:
            M = Ns @ Ns.transpose(0, 2, 1)
            ok = np.abs(np.linalg.det(M)) > 1e-14
            Ns, bs, M = Ns[ok], bs[ok], M[ok]
            if not len(M):
                continue
            Minv = np.linalg.inv(M)
        x0 = np.einsum("csk,cs->ck", Ns, np.einsum("cst,ct->cs", Minv, bs))
        Pu = u - np.einsum("csk,cs->ck", Ns, np.einsum("cst,ct->cs", Minv, Ns @ u))
        cands.append(x0 + Pu)
        if ball:
            r2 = amax * amax - np.sum(x0 * x0, axis=1)
            nw = np.linalg.norm(Pu, axis=1)
            good = (r2 >= 0.0) & (nw > 0.0)
            if np.any(good):
                cands.append(x0[good] + (np.sqrt(r2[good]) / nw[good])[:, None] * Pu[good])
    X = np.vstack(cands)
    feasible = np.all(X @ normals.T >= bounds - tol * np.maximum(1.0, np.abs(bounds)), axis=1)
    if ball:
        feasible &= np.linalg.norm(X, axis=1) <= amax * (1.0 + tol)
    if not np.any(feasible):
        return None
    X = X[feasible]
    return X[int(np.argmin(np.linalg.norm(X - u, axis=1)))]


def project_command(u, normals, bounds, amax):
    """(N3): u's Euclidean projection onto the ball ||x|| <= amax and the half-spaces (rows in
    priority order). If that set is empty, the half-spaces are taken in priority order, each
    dropped whose addition empties the set with the ball; the projection is onto the rest.
    Returns (projection, how many half-spaces were dropped)."""
    x = nearest_point(u, normals, bounds, amax)
    if x is not None:
        return x, 0
    keep = []
    witness = np.zeros_like(u)          # a point of the ball and the kept half-spaces
    for j in range(bounds.size):
        if bounds[j] > amax * (1.0 + 1e-10):
            continue                    # outside the ball
        if normals[j] @ witness >= bounds[j] - 1e-10 * max(1.0, abs(bounds[j])):
            keep.append(j)              # the witness is in it too
            continue
        trial = keep + [j]
        point = nearest_point(np.zeros_like(u), normals[trial], bounds[trial], amax)
        if point is not None:
            keep, witness = trial, point
    x = nearest_point(u, normals[keep], bounds[keep], amax)
    return x, bounds.size - len(keep)


def neighbour_halfspaces(nb, P, V, targets, own_perimeter, amax):
    """(N1), (N2) for every follower against every other agent, at once.

    P, V (F + 1, k) the agents' true positions and velocities (row 0 the leader); targets (F,)
    the agent each follower looks at. Returns (normals (F, F + 1, k), bounds b, urgency h,
    distance c, valid (F, F + 1)): follower i's half-space against agent j is normals.u >= b,
    valid where j is sensed (not i, c <= radius) and b is finite and > -amax.
    """
    F = len(targets)
    dp = P[1:, None, :] - P[None, :, :]
    dv = V[1:, None, :] - V[None, :, :]
    c = np.sqrt(np.sum(dp * dp, axis=2))
    safe_c = np.where(c > 0.0, c, 1.0)
    x_axis = np.zeros(P.shape[1])
    x_axis[0] = 1.0
    normals = np.where((c > 0.0)[:, :, None], dp / safe_c[:, :, None], x_axis)
    nv = np.sum(normals * dv, axis=2)
    closing = -nv                                                    # s
    v_perp2 = np.maximum(0.0, np.sum(dv * dv, axis=2) - nv * nv)
    rho = np.full(c.shape, nb.perimeter)
    rho[np.arange(F), targets] = own_perimeter
    outside = c > rho
    root = np.sqrt(2.0 * nb.braking_acceleration * np.where(outside, c - rho, 1.0))
    h = np.where(outside, root - closing, -math.inf)                                    # (N1)
    with np.errstate(invalid="ignore"):
        b = np.where(outside,
                     nb.braking_acceleration * closing / root - v_perp2 / safe_c
                     + nb.neighbour_acceleration - nb.rate * h,                         # (N2)
                     nb.braking_acceleration + nb.neighbour_acceleration)
    not_self = np.ones(c.shape, dtype=bool)
    not_self[np.arange(F), np.arange(1, F + 1)] = False
    valid = not_self & (c <= nb.radius) & np.isfinite(b) & (b > -amax)
    return normals, b, h, c, valid
