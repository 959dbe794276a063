"""The world of reference_sim.py's sampled loop (doc/formations.md, "A world that can hurt"):
counter-based draws, gusts, and the exact step of an agent over a control period."""

from __future__ import annotations

import math

import numpy as np
from scipy.linalg import expm

from refsim_inputs import pulse_sum, sinusoid_sum


_MASK64 = (1 << 64) - 1


def splitmix64(x):
    """splitmix64 of an integer, mod 2^64."""
    z = (x + 0x9E3779B97F4A7C15) & _MASK64
    z = ((z ^ (z >> 30)) * 0xBF58476D1CE4E5B9) & _MASK64
    z = ((z ^ (z >> 27)) * 0x94D049BB133111EB) & _MASK64
    return z ^ (z >> 31)


def uniform_draw(seed, stream, count):
    """U(seed, stream, count) = (splitmix64(splitmix64(seed) ^ (stream << 40 | count)) >> 11)
    2^-53, in [0, 1)."""
    key = ((stream << 40) | count) & _MASK64
    return (splitmix64(splitmix64(seed) ^ key) >> 11) * 2.0 ** -53


def uniform_draws(seed, stream, counts):
    """uniform_draw() for an array of counts (numpy's uint64 arithmetic wraps mod 2^64)."""
    counts = np.asarray(counts, dtype=np.uint64)
    x = np.uint64(splitmix64(seed)) ^ (np.uint64((stream << 40) & _MASK64) | counts)
    with np.errstate(over="ignore"):
        z = x + np.uint64(0x9E3779B97F4A7C15)
        z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        z = z ^ (z >> np.uint64(31))
    return (z >> np.uint64(11)).astype(np.float64) * 2.0 ** -53


def normal_draws(seed, stream, counts):
    """N(seed, stream, c) = sqrt(-2 ln(1 - U(2c))) cos(2 pi U(2c + 1)) (Box-Muller)."""
    c = np.asarray(counts, dtype=np.uint64)
    ua = uniform_draws(seed, stream, np.uint64(2) * c)
    ub = uniform_draws(seed, stream, np.uint64(2) * c + np.uint64(1))
    return np.sqrt(-2.0 * np.log(1.0 - ua)) * np.cos(2.0 * math.pi * ub)


def gust_pulses(world, index, B, duration):
    """The gusts of follower `index` as pulses (start, end, n-vector B g), stream 4 index.

    Per gust, in this order of draws: the gap -ln(1 - U)/rate (from max(0, start)), the
    duration min + U (max - min), the strength U magnitude, then m entries
    sqrt(-2 ln(1 - U_a)) cos(2 pi U_b) of the direction (drawn again while of norm 0). A gust
    starting at or after min(end, duration) ends the list; the others are cut there.
    """
    g = world.gusts
    if not (g.rate > 0.0 and g.magnitude > 0.0):
        return []
    m = B.shape[1]
    count = 0

    def draw():
        nonlocal count
        value = uniform_draw(world.seed, 4 * index, count)
        count += 1
        return value

    stop = min(g.end, duration)
    t = max(0.0, g.start)
    out = []
    while True:
        t += -math.log(1.0 - draw()) / g.rate
        length = g.min_duration + draw() * (g.max_duration - g.min_duration)
        strength = draw() * g.magnitude
        while True:
            direction = np.empty(m)
            for e in range(m):
                ua = draw()
                ub = draw()
                direction[e] = math.sqrt(-2.0 * math.log(1.0 - ua)) * math.cos(2.0 * math.pi * ub)
            norm = float(np.linalg.norm(direction))
            if norm > 0.0:
                break
        if t >= stop:
            return out
        out.append((t, min(t + length, stop), B @ (strength * direction / norm)))


class ExactStep:
    """x(t + delta) = Phi(delta) x + Psi(delta) v for x' = A x + v, v constant (cached)."""

    def __init__(self, A, double_integrator):
        self.A, self.di, self.cache = A, double_integrator, {}

    def __call__(self, delta):
        hit = self.cache.get(delta)
        if hit is None:
            n = self.A.shape[0]
            if self.di:                      # A^2 = 0
                hit = (np.eye(n) + self.A * delta, np.eye(n) * delta + self.A * (0.5 * delta ** 2))
            else:
                big = np.zeros((2 * n, 2 * n))
                big[:n, :n], big[:n, n:] = self.A, np.eye(n)
                E = expm(big * delta)
                hit = (E[:n, :n], E[:n, n:])
            if len(self.cache) < 4096:
                self.cache[delta] = hit
        return hit


def piecewise_inputs(pulses, sinusoids, grid, n):
    """Per period [t_k, t_k+1): the pulses' and sinusoids' sum at its middle (N, n), whether a
    pulse edge lies inside it (N,), and the sorted edges."""
    edges = np.array(sorted({e for a, b, _ in pulses for e in (a, b)}))
    mids = 0.5 * (grid[:-1] + grid[1:])
    value = (pulse_sum(pulses, mids, n) + sinusoid_sum(sinusoids, mids, n)).T
    if edges.size:
        inside = (np.searchsorted(edges, grid[1:], "left")
                  > np.searchsorted(edges, grid[:-1], "right"))
    else:
        inside = np.zeros(mids.size, dtype=bool)
    return value, inside, edges


def _segments(edges, a, b):
    """[a, b] cut at the edges strictly inside it."""
    lo, hi = np.searchsorted(edges, a, "right"), np.searchsorted(edges, b, "left")
    return [a] + [float(e) for e in edges[lo:hi]] + [b]


def advance(x, drive, pulses, sinusoids, edges, a, b, step, B, value_mid, cut):
    """One agent over [a, b]: the input `drive` (m) held, the pulses and sinusoids (n) constant
    on each piece of the period cut at the pulse edges, at its middle."""
    if not cut:
        Phi, Psi = step(b - a)
        return Phi @ x + Psi @ (B @ drive + value_mid)
    cuts = _segments(edges, a, b)
    for lo, hi in zip(cuts[:-1], cuts[1:]):
        mid = 0.5 * (lo + hi)
        v = B @ drive + pulse_sum(pulses, mid, B.shape[0])[:, 0]
        if sinusoids:
            v = v + sinusoid_sum(sinusoids, mid, B.shape[0])[:, 0]
        Phi, Psi = step(hi - lo)
        x = Phi @ x + Psi @ v
    return x
