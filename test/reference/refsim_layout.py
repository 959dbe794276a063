"""Where the followers of a formation sit and whom they look at (doc/formations.md), for
reference_sim.py."""

from __future__ import annotations

import math

import numpy as np


def slot_layout(formation, d, k):
    """d_i of followers 1 .. N (doc/formations.md): line i d; V ceil(i/2) R(+-half_angle) d.

    R turns the x-y part of d's position part, + for odd i and - for even i.
    """
    if formation is None:
        return [d]
    out = []
    for i in range(1, formation.followers + 1):
        if formation.shape == "line":
            out.append(i * d)
            continue
        angle = formation.half_angle if i % 2 else -formation.half_angle
        di = d.copy()
        di[:k] = rotate_z(d[:k], angle)
        out.append(math.ceil(i / 2) * di)
    return out


def rotate_z(p, angle):
    """R(angle) p: the x-y part (first two entries) turned by angle, the rest kept."""
    c, s = math.cos(angle), math.sin(angle)
    out = np.array(p, dtype=float)
    out[0] = c * p[0] - s * p[1]
    out[1] = s * p[0] + c * p[1]
    return out


def chain_layout(formation, d, k):
    """d_i of a chain (doc/formations.md): d for a line; R(+-half_angle) d for a V."""
    out = []
    for i in range(1, formation.followers + 1):
        if formation.shape == "line":
            out.append(d.copy())
            continue
        di = d.copy()
        di[:k] = rotate_z(d[:k], formation.half_angle if i % 2 else -formation.half_angle)
        out.append(di)
    return out


def formation_targets(formation):
    """The agent each follower looks at (0 the leader, i follower i)."""
    if formation is None:
        return [0]
    N = formation.followers
    if formation.topology == "star":
        return [0] * N
    lag = 1 if formation.shape == "line" else 2
    return [max(0, i - lag) for i in range(1, N + 1)]
