#!/usr/bin/python3
"""The target's path (C1) and the goal on it (C2) of doc/math.md, "Convoys on the target's path".

Written from doc/math.md alone (not from core/TargetPath or core/ConvoyReference), for
convoy_reference.py. The follower records its target's position p_t at each tick:

(C1) P(sigma) is the polyline through the recorded points, `spacing` apart (a point is added
     when p_t is at least `spacing` from the latest one), at most `capacity` of them (the
     oldest is dropped); sigma is its arc length, 0 at the target's first position. The
     target's progress s is the arc of p_t itself: s = arc(latest point) + |p_t - latest|.
     - From the latest point P goes straight to the target.
     - Before the oldest point P goes on straight backward (the virtual road): along the
       direction given at the start (d_i's position part: the road lies behind the target)
       while the start is the oldest point, then along the oldest segment's direction.
     - Retrace: while p_t is behind the latest point along the latest segment and within
       `retrace_width` of that segment's line, the latest point is taken off, so s goes down
       while the target reverses. With one point left, behind it along the road, the point
       itself moves back along the road to the foot of p_t. While retracing, a p_t less than
       `spacing` ahead of the latest point along the latest segment and within
       `retrace_width` of its line adds no point; retracing ends once a point is added.

(C2) sigma*_k = walkBack(min(s_k - g, sigma*_{k-1} + max(0, s_k - s_{k-1}) + c T), p_t, c_q),
     q_k = P(sigma*_k), where walkBack(sigma, p, c) is the largest sigma' <= sigma with
     |p - P(sigma')| >= c, found exactly: |p - P|^2 is convex along each straight piece.
"""

import math

import numpy as np


def unit(v):
    """v / |v|, or None for a zero vector."""
    norm = math.sqrt(float(v @ v))
    return v / norm if norm > 0.0 else None


class TargetPath:
    """(C1): the recorded points in a window [lo, hi) of preallocated arrays."""

    def __init__(self, p0, direction, spacing, capacity, retrace_width, max_points):
        k = p0.size
        self.spacing, self.capacity, self.retrace_width = spacing, capacity, retrace_width
        self.pts = np.empty((max_points + 2, k))
        self.arc = np.empty(max_points + 2)
        self.pts[0], self.arc[0] = p0, 0.0
        self.lo, self.hi = 0, 1
        self.start_direction = direction        # the road's direction with one point
        self.target = np.array(p0, dtype=float)
        self.s = 0.0
        self.retracing = False

    def _direction(self, i):
        """Unit direction of the segment from point i to point i + 1."""
        return unit(self.pts[i + 1] - self.pts[i])

    def road_direction(self):
        """Forward direction of the virtual road before the oldest point: the start's while the
        start is kept, then the oldest segment's."""
        if self.lo > 0 and self.hi - self.lo >= 2:
            return self._direction(self.lo)
        return self.start_direction

    def latest_direction(self):
        if self.hi - self.lo >= 2:
            return self._direction(self.hi - 2)
        return self.start_direction

    def record(self, p):
        """One tick of (C1): retrace, then add p if it is `spacing` from the latest point."""
        self.target = p
        while True:
            last = self.hi - 1
            u = self.latest_direction()
            rel = p - self.pts[last]
            along = float(rel @ u)
            lateral = rel - along * u
            beside = math.sqrt(float(lateral @ lateral)) <= self.retrace_width
            if not (along < 0.0 and beside):
                break
            self.retracing = True
            if self.hi - self.lo >= 2:
                self.hi -= 1                        # drove back over the latest point
                continue
            self.pts[last] = self.pts[last] + along * u   # back along the road: to p's foot
            self.arc[last] += along
            along = 0.0
            break
        gap = math.sqrt(float((p - self.pts[self.hi - 1]) @ (p - self.pts[self.hi - 1])))
        if self.retracing and along < self.spacing and beside:
            self.s = self.arc[self.hi - 1] + gap    # beside the path while retracing: no point
            return self.s
        self.retracing = False
        if gap >= self.spacing:
            self.pts[self.hi] = p
            self.arc[self.hi] = self.arc[self.hi - 1] + gap
            self.hi += 1
            if self.hi - self.lo > self.capacity:
                self.lo += 1
            gap = 0.0
        self.s = self.arc[self.hi - 1] + gap
        return self.s

    def _piece(self, i):
        """(start point, start arc, unit direction) of piece i: -1 the road, hi - 1 the piece
        from the latest point to the target, else the segment from point i."""
        if i < self.lo:
            return self.pts[self.lo], self.arc[self.lo], self.road_direction()
        if i == self.hi - 1:
            u = unit(self.target - self.pts[i])
            return self.pts[i], self.arc[i], (u if u is not None else self.latest_direction())
        return self.pts[i], self.arc[i], self._direction(i)

    def _piece_index(self, sigma):
        """The piece holding sigma: lo - 1 (the road), lo .. hi - 2, or hi - 1."""
        if sigma < self.arc[self.lo]:
            return self.lo - 1
        j = int(np.searchsorted(self.arc[self.lo:self.hi], sigma, side="right")) - 1
        return self.lo + j

    def point(self, sigma):
        """P(sigma)."""
        a, a_arc, u = self._piece(self._piece_index(sigma))
        return a + (sigma - a_arc) * u

    def walk_back(self, sigma, p, c):
        """The largest sigma' <= sigma with |p - P(sigma')| >= c (C2)."""
        rel = p - self.point(sigma)
        if float(rel @ rel) >= c * c:
            return sigma
        i = self._piece_index(sigma)
        # The last recorded point at or below sigma that is c away from p: between it and
        # sigma every piece is inside the circle (convexity), so the crossing is on its piece.
        j = self.lo - 1
        top = min(i, self.hi - 1)
        while top >= self.lo:
            bottom = max(self.lo, top - 63)
            d2 = np.sum((self.pts[bottom:top + 1] - p) ** 2, axis=1)
            far = np.nonzero(d2 >= c * c)[0]
            if far.size:
                j = bottom + int(far[-1])
                break
            top = bottom - 1
        a, a_arc, u = self._piece(j)
        w = p - a
        wu = float(w @ u)
        disc = max(wu * wu - float(w @ w) + c * c, 0.0)
        return a_arc + wu - math.sqrt(disc)       # the smaller root of |w - tau u| = c

    def distance(self, x):
        """Distance from x to the path: the recorded polyline, the piece to the target and
        the virtual road."""
        a = self.pts[self.lo:self.hi]
        seg = np.vstack([a[1:], self.target[None, :]]) - a
        rel = x - a
        len2 = np.einsum("ij,ij->i", seg, seg)
        tau = np.clip(np.einsum("ij,ij->i", rel, seg) / np.where(len2 > 0.0, len2, 1.0), 0.0, 1.0)
        off = rel - tau[:, None] * seg
        best = float(np.min(np.einsum("ij,ij->i", off, off)))
        u = self.road_direction()
        back = rel[0] - min(float(rel[0] @ u), 0.0) * u
        return math.sqrt(min(best, float(back @ back)))


class Goal:
    """(C2): the goal sigma*, q on the path, with its memory of the previous tick."""

    def __init__(self, gap, chord, catch_up_speed, period):
        self.gap, self.chord, self.catch_up, self.period = gap, chord, catch_up_speed, period
        self.sigma = self.s = None

    def tick(self, path, p):
        s = path.s
        sigma = s - self.gap
        if self.sigma is not None:
            sigma = min(sigma, self.sigma + max(0.0, s - self.s) + self.catch_up * self.period)
        sigma = path.walk_back(sigma, p, self.chord)
        self.sigma, self.s = sigma, s
        return sigma, path.point(sigma)
