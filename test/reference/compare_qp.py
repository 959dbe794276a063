#!/usr/bin/python3
"""Cross-check the control barrier function filter's QP (doc/math.md, "A control barrier function
filter (the comparison)", (B3); core/SafetyFilter on core/CommandProjection) against cvxopt.

Usage::

    compare_qp.py --qp-solve PATH [--seed S] [--count N] [--tolerance T] [--xunit FILE]
                  [--family NAME]... [--skip-family NAME]... [--list]

PATH is test/tools/qp_solve (built from test/tools/qp_solve.cpp). Needs python3-cvxopt,
python3-scipy and python3-numpy (Debian 12). --list prints the qp_solve input and exits. The
problems

    u* = argmin ||u - u_nom||^2  s.t.  g_j^T u >= b_j (j = 0..N-1, priority order),  ||u|| <= a_max

(u in R^k, k = 1, 2, 3; a_max finite or infinite) are generated here, seeded: --count random ones
(families random_k1, random_k2, random_k3: N = 0..8, a_max finite in 70 %, the half-spaces
either built around a point of the ball, with the nominal at that point or outside, or drawn at
random, so often infeasible) and the degenerate families of DEGENERATE (parallel, anti-parallel,
duplicate and redundant half-spaces, a half-space through the nominal exactly, a_max exactly
touching a half-space, a feasible set of a single point, scales from 1e-12 to 1e12, extreme ones
(u and a_max to 1e+-140, normals to 1e+-170), infeasible pairs and half-spaces out of reach).
qp_solve solves them all in one process call with SafetyFilter; each is then solved here with
cvxopt, on the problem divided by
its scale s = max(||u_nom||, a_max if finite, |b_j| / ||g_j||) and with unit normals (the same
solution, times s):

  * classification: the depth LP max t s.t. n_j^T u - t >= c_j, ||u|| + t <= a_max (conelp; a
    ball of radius 1e4 s when a_max is infinite) gives the margin t* of the whole set: feasible
    when t* > 1e-7 (scaled), infeasible when t* < -1e-7, else borderline;
  * the reference u*: coneqp (P = I, the half-spaces as the linear cone, ||u|| <= a_max as a
    second-order cone; only the linear cone when a_max is infinite; tolerances 1e-12, then 1e-10
    and 1e-8 where cvxopt raises, as it does near degenerate optima; where coneqp does not
    converge, which it sometimes does not even with u_nom feasible (its gap cycles), conelp on
    the epigraph form min tau s.t. ||u - u_nom|| <= tau), then polished: the set cvxopt finds
    active (slack <= theta, theta = 1e-10 .. 1e-4) is solved exactly (the projection onto its
    affine set, or onto that set's circle or points on the sphere) and kept only if it passes a
    KKT certificate (feasible within 1e-12, and u_nom - u in the cone of the active outward
    normals, by scipy's nnls, to 1e-10): KKT points are optimal, so a certified point is u*. The
    interior point's own answer is only about sqrt(1e-12) accurate where an active half-space has
    a zero multiplier (a half-space through u_nom), hence the polishing; when no set certifies,
    cvxopt's point is the reference ("raw" in the report).

A feasible problem (or a borderline one the generator knows to be feasible) passes when ours is
flagged feasible with nothing dropped, ||u*_ours - u*_ref|| <= tol s (tol = --tolerance, default
1e-6), every half-space holds at ours within 1e-9 max(s, ||u*||), ||u*|| <= a_max (1 + 4 eps),
ours passes the same KKT certificate to tol (active: within 1e-9), its active_count lies between
the half-spaces active at a polished reference (within 1e-11 s) and those within the difference
plus 2e-9 s of it, and, where the generator knows u* exactly, ||u*_ours - u*_exact|| <= tol s.
In a borderline set a raw reference is not required to agree (the interior point method loses
accuracy without an interior), and where the ball is active there the KKT residual is not
required either (without a Slater point KKT multipliers need not exist: a ball tangent to a
half-space). An infeasible one passes when ours is flagged infeasible (dropped >= 1, feasible 0),
||u*|| <= a_max (1 + 4 eps), and the documented fallback holds where it can be decided
independently: if barrier 0 alone is out of reach (b_0 / ||g_0|| > a_max (1 + 1e-7)),
u* = a_max g_0 / ||g_0|| within tol s with active_count 0; and when every step of the priority
rule (keep j if the ball, the half-spaces kept before and j intersect: a depth LP each, all
clear of the 1e-7 band) is decided, the same number is dropped and u* is the reference
projection onto the ball and the half-spaces kept (the checks of a feasible problem, on those).
A borderline problem the generator does not know is checked for the ball and, if ours calls it
feasible, for its half-spaces and KKT residual.

Measured (2026-12-07, 2 cores, SafetyFilter and CommandProjection of that date). Seed 1, 2000
random + 393 degenerate problems, 21 s (qp_solve 0.4 s of it, the rest cvxopt): every family but
extreme_scales passes; the largest ||u*_ours - u*_ref|| / s is 1.0e-13 (random_k3) outside
ball_touching and 1.4e-8 there (to the exact point a_max g / ||g||: the sphere tangent to a plane
turns the 1e-16 rounding of the unit normal into sqrt(1e-16) of position, as it would for the
exact solution of the rounded data); the largest half-space violation 4.4e-16 max(s, ||u*||), the
largest KKT residual of ours 2.7e-14; cvxopt's raw points differ from ours by up to 4.1e-6 s
(0.12 s where coneqp cycles), and coneqp did not converge on 17 problems. Seeds 2-4 (2327
problems each, without extreme_scales): all pass, at most 2.0e-13 outside ball_touching, 1.9e-8
in it. Seed 11, 15000 random problems: all pass, at most 3.4e-11 (planes at small angles), 160 s.
extreme_scales fails (17 problems): when barrier 0 is out of reach, SafetyFilter::filter
returns (a_max / first_normal_.norm()) g_0 with Eigen's norm(), whose squared norm underflows
or overflows: ||g_0|| = 1e-170 gives u* = (inf, nan), 1e-160 gives ||u*|| = 1.0000056 a_max,
1e155 and more give u* = 0 (CommandProjection::add itself accepts these normals, with
euclideanNorm). The same expression, unclamped, exceeds a_max by up to 2 ulps at ordinary
scales (in about a fifth of such fallbacks), which the 4 eps allowance accepts.

One line per family, then the figures; each failing problem is printed with its qp_solve input
line, both solutions, the depth, and the residuals n_j^T u - b_j / ||g_j|| of each. Exit status
1 if any problem failed, 2 for a bad command line or a qp_solve that could not be run. --xunit
writes one JUnit test case per family (compare_common.write_xunit).
"""

import argparse
import math
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np
from cvxopt import matrix, solvers
from scipy.optimize import nnls

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_common import tool_command, write_xunit  # noqa: E402  (beside this file)

TOLERANCE = 1e-6        # ||u*_ours - u*_ref|| / s
FEASIBILITY = 1e-9      # half-space violation / max(s, ||u*||)
BAND = 1e-7             # |depth| / s below which feasibility is not decided by cvxopt
ROUNDING = 4 * sys.float_info.epsilon  # ||u*|| <= a_max (1 + ROUNDING)
CERTIFY = 1e-12         # the polished point's feasibility (scaled)
STATIONARITY = 1e-10    # the polished point's KKT residual (scaled)
BIG_RADIUS = 1e4        # the depth LP's ball when a_max is infinite (scaled)
QP_TOLERANCES = (1e-12, 1e-10, 1e-8)     # cvxopt's abstol = reltol = feastol, tried in turn
DEPTH_TOLERANCES = (1e-10, 1e-9, 1e-8)
TIMEOUT_S = 300
COUNTS = {"coneqp did not converge": 0, "nor did the epigraph form": 0}


@dataclass(frozen=True)
class Problem:
    """One QP; expected: u* known exactly; expect_feasible: the answer required of a borderline
    set (within the solver's tolerance)."""
    family: str
    k: int
    a_max: float
    u_nom: Tuple[float, ...]
    g: Tuple[Tuple[float, ...], ...]
    b: Tuple[float, ...]
    expected: Optional[Tuple[float, ...]] = None
    expect_feasible: Optional[bool] = None
    note: str = ""

    def line(self):
        """The qp_solve input line (repr: the shortest text that reads back bit for bit)."""
        words = [str(self.k), repr(self.a_max)] + [repr(x) for x in self.u_nom] + [str(len(self.b))]
        for gj, bj in zip(self.g, self.b):
            words += [repr(x) for x in gj] + [repr(bj)]
        return " ".join(words)


def problem(family, k, a_max, u_nom, g=(), b=(), expected=None, expect_feasible=None, note=""):
    """A Problem from arrays."""
    return Problem(family, k, float(a_max), tuple(float(x) for x in np.ravel(u_nom)),
                   tuple(tuple(float(x) for x in np.ravel(gj)) for gj in g),
                   tuple(float(x) for x in b),
                   None if expected is None else tuple(float(x) for x in np.ravel(expected)),
                   expect_feasible, note)


def vnorm(v):
    """Euclidean norm without overflow or underflow."""
    v = np.asarray(v, dtype=float).ravel()
    m = float(np.max(np.abs(v))) if v.size else 0.0
    if m == 0.0 or not math.isfinite(m):
        return m
    return m * math.sqrt(float(np.sum((v / m) ** 2)))


# --- The problems ---------------------------------------------------------------------------

def unit(rng, k):
    v = rng.normal(size=k)
    return v / np.linalg.norm(v)


def around(rng, k, n, point, radius, exact_fraction=0.1):
    """N half-spaces (random normals and lengths) that POINT satisfies, some exactly."""
    g = [unit(rng, k) * math.exp(rng.uniform(-1.0, 1.0)) for _ in range(n)]
    b = [float(gj @ point) - (0.0 if rng.random() < exact_fraction else
                              rng.exponential(0.3 * radius) * np.linalg.norm(gj)) for gj in g]
    return g, b


def random_problem(rng, family, k, n=None):
    """A random problem: built around a point of the ball (60 %; the nominal there in a third of
    them) or with random bounds, the nominal anywhere within 3 a_max."""
    n = int(rng.integers(0, 9)) if n is None else n
    a_max = math.inf if rng.random() < 0.3 else math.exp(rng.uniform(math.log(0.5), math.log(5)))
    radius = a_max if math.isfinite(a_max) else 3.0
    u_nom = unit(rng, k) * rng.uniform(0.0, 3.0 * radius)
    if rng.random() < 0.6:
        point = unit(rng, k) * rng.uniform(0.0, 0.95 * radius)
        g, b = around(rng, k, n, point, radius)
        if rng.random() < 1.0 / 3.0:
            u_nom = point
        note = "built around a point"
    else:
        g = [unit(rng, k) * math.exp(rng.uniform(-1.0, 1.0)) for _ in range(n)]
        b = [float(rng.normal() * radius * np.linalg.norm(gj)) for gj in g]
        note = "random bounds"
    return problem(family, k, a_max, u_nom, g, b, note=note)


def random_problems(rng, count):
    return [random_problem(rng, f"random_k{1 + i % 3}", 1 + i % 3) for i in range(count)]


def plane_ball_projection(u_nom, n, c, a_max):
    """The projection of u_nom onto {n^T u = c, ||u|| <= a_max} (n a unit vector), exactly."""
    p0 = c * n
    along = u_nom - (n @ u_nom) * n
    x = p0 + along
    if not math.isfinite(a_max) or np.linalg.norm(x) <= a_max:
        return x
    r = math.sqrt(max(0.0, a_max * a_max - c * c))
    if np.linalg.norm(along) == 0.0:
        return None  # a circle of nearest points
    return p0 + r * along / np.linalg.norm(along)


def degenerate_problems(rng):
    """The degenerate families, every k."""
    out = []
    add = out.append
    for k in (1, 2, 3):
        # Parallel normals: the same direction, other lengths and bounds (delta 0: the same set).
        for rep in range(9):
            g0 = unit(rng, k) * math.exp(rng.uniform(-1, 1))
            n0, c0 = g0 / np.linalg.norm(g0), rng.uniform(-1, 1)
            lam, delta = math.exp(rng.uniform(-2, 2)), (-0.5, 0.0, 0.5)[rep % 3]
            a_max = math.inf if rep < 3 else 2.5
            u = n0 * (c0 - 1.0) + (unit(rng, k) if k > 1 else 0.0) * 0.7
            b0 = c0 * np.linalg.norm(g0)
            g, b = [g0, lam * g0], [b0, lam * (c0 + delta) * np.linalg.norm(g0)]
            if rep >= 6:
                g2, b2 = around(rng, k, 2, n0 * (c0 + 0.6), 2.5)
                g, b = g + g2, b + b2
            add(problem("parallel", k, a_max, u, g, b))
        # Anti-parallel normals: a slab of width w (0: a plane, or a single point in 1-D).
        for rep in range(12):
            g0 = unit(rng, k) * math.exp(rng.uniform(-1, 1))
            norm0 = np.linalg.norm(g0)
            n0, c0, lam = g0 / norm0, rng.uniform(-0.5, 0.5), math.exp(rng.uniform(-2, 2))
            w = 0.3 if rep < 6 else 0.0
            a_max = (math.inf, 2.0)[rep % 2]
            t = (-2.0, 0.5, 3.0)[(rep // 2) % 3]
            u = n0 * (c0 + w * t if w else c0 + t) + (unit(rng, k) if k > 1 else 0.0) * 1.5
            g, b = [g0, -lam * g0], [c0 * norm0, -lam * (c0 + w) * norm0]
            expected = plane_ball_projection(u, n0, c0, a_max) if w == 0.0 else None
            add(problem("antiparallel", k, a_max, u, g, b, expected,
                        True if w == 0.0 else None, f"slab of width {w}"))
        # Duplicates: the same half-space twice, or times 3, around another one.
        for rep in range(6):
            g0 = unit(rng, k) * math.exp(rng.uniform(-1, 1))
            n0, c0 = g0 / np.linalg.norm(g0), rng.uniform(-1, 1)
            b0 = c0 * np.linalg.norm(g0)
            u = n0 * (c0 - 1.5) + (unit(rng, k) if k > 1 else 0.0)
            g2, b2 = around(rng, k, 1, n0 * (c0 + 0.2), 2.5)
            g, b = ([g0, g0], [b0, b0]) if rep % 2 == 0 else ([g0, 3.0 * g0], [b0, 3.0 * b0])
            g, b = (g + g2, b + b2) if rep < 4 else (g2 + g + [g0], b2 + b + [b0])
            add(problem("duplicate", k, (math.inf, 2.5)[rep % 2], u, g, b))
        # Half-spaces through the nominal exactly (dyadic data: g^T u_nom is exact).
        for rep in range(9):
            u = rng.integers(-8, 9, size=k) / 8.0
            g = [rng.integers(-4, 5, size=k).astype(float) for _ in range(1 + rep % (k + 1))]
            g = [gj if np.any(gj) else np.ones(k) for gj in g]
            b = [float(gj @ u) for gj in g]
            norm = float(np.linalg.norm(u))
            if rep < 3:  # u_nom feasible: u* = u_nom
                add(problem("through_nominal", k, (math.inf, 2 * norm + 1)[rep % 2], u, g, b, u))
            elif rep < 6:  # and one violated
                gv = unit(rng, k)
                add(problem("through_nominal", k, (math.inf, 2 * norm + 1)[rep % 2], u,
                            g + [gv], b + [float(gv @ u) + 0.5]))
            elif norm > 0:  # and u_nom outside the ball
                add(problem("through_nominal", k, norm / 2, u, g, b))
        # a_max exactly touching a half-space: the feasible set is the point a_max g / ||g||.
        touching = {1: ([1.0], [-2.0]), 2: ([3.0, 4.0], [0.0, -2.0], [-5.0, 12.0]),
                    3: ([2.0, 3.0, 6.0], [1.0, -2.0, 2.0], [0.0, 0.0, 1.0])}[k]
        for rep, gt in enumerate(touching * 3):
            gt = np.array(gt)
            norm = float(round(np.linalg.norm(gt)))
            a_max = (1.0, 2.5, 0.75)[rep % 3]
            point = a_max * gt / norm
            g, b = [gt], [a_max * norm]
            if rep >= len(touching):
                g2, b2 = around(rng, k, 1 + rep % 3, point, a_max, exact_fraction=0.3)
                g, b = (g + g2, b + b2) if rep % 2 else (g2 + g, b2 + b)
            u = unit(rng, k) * rng.uniform(0, 3 * a_max)
            add(problem("ball_touching", k, a_max, u, g, b, point, True))
        # A single feasible point: k + 1 half-spaces around it (axis-aligned and exact, or
        # rotated and scaled).
        for rep in range(8):
            p = rng.integers(-8, 9, size=k) / 4.0
            normals = [np.eye(k)[i] for i in range(k)] + [-np.ones(k)]
            if rep >= 4 and k > 1:
                q, _ = np.linalg.qr(rng.normal(size=(k, k)))
                normals = [q @ nj * math.exp(rng.uniform(-1, 1)) for nj in normals]
            b = [float(nj @ p) for nj in normals]
            a_max = (math.inf, 2 * float(np.linalg.norm(p)) + 1)[rep % 2]
            u = p + unit(rng, k) * rng.uniform(0.5, 3)
            add(problem("single_point", k, a_max, u, normals, b, p, True))
        # Redundant half-spaces: implied by two others, containing the ball, or far away.
        for rep in range(9):
            a_max = 2.0
            g, b = around(rng, k, 2, unit(rng, k) * 0.5, a_max, exact_fraction=0.0)
            kind = rep % 3
            if kind == 0:
                gr, br = g[0] + g[1], b[0] + b[1] - (0.0, 0.5)[rep % 2]
                if not np.any(gr):
                    gr, br = g[0], b[0]
            elif kind == 1:
                gr = unit(rng, k) * math.exp(rng.uniform(-1, 1))
                br = -(1.0, 1.5)[rep % 2] * a_max * float(np.linalg.norm(gr))
            else:
                gr = unit(rng, k)
                br = -1e3
            at = rep % 3
            g, b = g[:at] + [gr] + g[at:], b[:at] + [br] + b[at:]
            u = unit(rng, k) * rng.uniform(0, 6)
            add(problem("redundant", k, (a_max, math.inf)[rep % 2 and kind != 1], u, g, b))
        # Infeasible pairs and half-spaces out of reach.
        for rep in range(12):
            kind = rep % 6
            a_max = (2.0, math.inf)[rep >= 6 and kind == 0]
            n0 = unit(rng, k)
            u = unit(rng, k) * rng.uniform(0, 3)
            if kind == 0:  # anti-parallel with a gap
                c0 = rng.uniform(-0.5, 0.5)
                g, b = [n0, -2.0 * n0], [c0, -2.0 * (c0 - 0.3)]
            elif kind == 1:  # barrier 0 out of reach
                g, b = [n0 * 3.0], [3.0 * 1.5 * a_max]
            elif kind == 2:  # barrier 0 just out of reach
                g, b = [n0], [a_max * (1 + 1e-6)]
            elif kind == 3:  # a later barrier out of reach
                g, b = around(rng, k, 2, n0 * 0.5, a_max)
                g, b = g + [n0], b + [1.2 * a_max]
            elif kind == 4:  # each within reach, not both (caps 120 degrees apart; 1-D: opposite)
                n1 = -n0
                if k > 1:
                    perp = unit(rng, k)
                    perp -= (perp @ n0) * n0
                    perp /= np.linalg.norm(perp)
                    n1 = -0.5 * n0 + math.sqrt(0.75) * perp
                g, b = [n0, n1], [0.8 * a_max, 0.8 * a_max]
            else:  # a feasible pair, then one that fits neither
                g, b = around(rng, k, 2, n0 * 0.7 * a_max, a_max, exact_fraction=0.0)
                g, b = g + [-n0], b + [0.5 * a_max]
            if rep >= 6 and kind != 0:
                g2, b2 = around(rng, k, 2, u * 0 + n0 * 0.2, a_max)
                g, b = g + g2, b + b2
            add(problem("infeasible", k, a_max, u, g, b, note=f"kind {kind}"))
    # Scales: random problems times s (u_nom, a_max, b) and normals times sg (g, b).
    for family, scales, normal_scales in (
            ("scales", (1e-12, 1e-6, 1e6, 1e12), (1.0, 1e-8, 1e8)),
            ("extreme_scales", (1e-140, 1e140), (1e-160, 1.0, 1e160))):
        for s in scales:
            for sg in normal_scales:
                for k in (1, 2, 3):
                    for rep in range(3):
                        base = random_problem(rng, family, k, n=int(rng.integers(1, 6)))
                        if rep == 2 and math.isfinite(base.a_max):  # barrier 0 out of reach
                            n0 = unit(rng, k)
                            base = problem(family, k, base.a_max, base.u_nom,
                                           (n0,) + base.g, (1.5 * base.a_max,) + base.b,
                                           note=base.note + ", barrier 0 out of reach")
                        add(problem(family, k, base.a_max * s, np.array(base.u_nom) * s,
                                    [np.array(gj) * sg for gj in base.g],
                                    [bj * s * sg for bj in base.b],
                                    note=f"{base.note}, times {s:g}, normals times {sg:g}"))
    # Barrier 0 out of reach with a normal whose squared norm underflows or overflows.
    for k in (1, 2, 3):
        for length in (1e-170, 1e-160, 1e160, 1e170):
            n0 = unit(rng, k)
            add(problem("extreme_scales", k, 1.0, unit(rng, k), [n0 * length], [2.0 * length],
                        note=f"barrier 0 out of reach, ||g_0|| = {length:g}"))
    return out


FAMILIES = ("random_k1", "random_k2", "random_k3", "parallel", "antiparallel", "duplicate",
            "through_nominal", "ball_touching", "single_point", "redundant", "infeasible",
            "scales", "extreme_scales")
DEGENERATE = FAMILIES[3:]


# --- cvxopt ---------------------------------------------------------------------------------

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


# --- The comparison -------------------------------------------------------------------------

@dataclass
class Outcome:
    ok: bool
    kind: str = ""            # feasible / infeasible / borderline
    ref: str = ""             # polished / raw / none / exact / fallback
    diff: float = 0.0         # ||ours - ref|| / s
    raw_diff: float = 0.0     # ||ours - cvxopt's raw point|| / s (feasible ones)
    violation: float = 0.0    # the largest half-space violation / max(s, ||u*||)
    kkt: float = 0.0
    text: str = ""


def parse_output(line, k):
    """(feasible, infeasible, dropped, u, active) of a qp_solve line; raises ValueError."""
    words = line.split()
    if not words or words[0] == "error" or len(words) != 4 + k:
        raise ValueError(f"qp_solve: {line!r}")
    return (int(words[0]), int(words[1]), int(words[2]),
            np.array([float(x) for x in words[3:3 + k]]), int(words[3 + k]))


def residuals(sc, u):
    """n_j^T u - c_j and ||u|| - a, unscaled (units of u)."""
    parts = [f"{(sc.n[j] @ u - sc.c[j]) * sc.s:.3g}" for j in range(len(sc.c))]
    ball = f", ||u||-a_max {(vnorm(u) - sc.a) * sc.s:.3g}" if math.isfinite(sc.a) else ""
    return "[" + ", ".join(parts) + "]" + ball


def check_kkt(sc, idx, us, tol, borderline):
    """(problems, the KKT residual of ours). Where the set has no interior (borderline) and the
    ball is active, KKT points need not exist (no Slater point): reported, not required."""
    kkt = ours_kkt(sc, idx, us)
    exempt = borderline and math.isfinite(sc.a) and vnorm(us) >= sc.a * (1 - FEASIBILITY)
    if not kkt <= tol and not exempt:
        return [f"KKT residual of ours {kkt:.3g} > {tol:g}"], kkt
    return [], (0.0 if exempt else kkt)


def check_solution(sc, idx, us, active_count, tol, expected=None, borderline=False):
    """The checks of a feasible set idx: (problems, diff, raw_diff, kkt, ref kind, ref u). In a
    borderline set cvxopt's raw point is not required to agree (the interior point method's
    accuracy degrades without an interior), a polished one is (though it is only certified to
    about sqrt(CERTIFY) there: a point within CERTIFY of a set without interior can be that far
    from it)."""
    problems = []
    ref, kind, raw = reference(sc, idx)
    diff = vnorm(us - ref) if ref is not None else 0.0
    raw_diff = vnorm(us - raw) if raw is not None else 0.0
    if ref is not None and not diff <= tol and (kind == "polished" or not borderline):
        problems.append(f"||u_ours - u_cvxopt|| = {diff:.3g} s > {tol:g} s ({kind})")
    if borderline:  # the figure is the difference to the exact u*, where known
        diff = 0.0
    if expected is not None:
        de = vnorm(us - expected)
        diff = max(diff, de)
        if not de <= tol:
            problems.append(f"||u_ours - u_exact|| = {de:.3g} s > {tol:g} s")
    more, kkt = check_kkt(sc, idx, us, tol, borderline)
    problems += more
    if kind == "polished" and diff <= tol:
        slack = sc.n[idx] @ ref - sc.c[idx] if idx else np.zeros(0)
        low = int(np.sum(slack <= 1e-11)) if diff <= 1e-10 else 0
        high = int(np.sum(slack <= diff + 2 * FEASIBILITY * max(1.0, vnorm(us))))
        if not low <= active_count <= high:
            problems.append(f"active_count {active_count} not in [{low}, {high}]")
    return problems, diff, raw_diff, kkt, kind, ref


def check_problem(p, line, tol):
    sc = scaled(p)
    try:
        feasible, infeasible, dropped, u, active_count = parse_output(line, p.k)
    except ValueError as exc:
        return Outcome(False, text=str(exc))
    us = u / sc.s
    idx = list(range(len(p.b)))
    out = Outcome(True)
    problems = []
    t = depth(sc, idx)
    if t is None:
        return Outcome(False, text="cvxopt failed on the depth LP")
    out.kind = "feasible" if t > BAND else "infeasible" if t < -BAND else "borderline"
    if math.isfinite(p.a_max) and not vnorm(u) <= p.a_max * (1 + ROUNDING):
        problems.append(f"||u*|| = {vnorm(u):.17g} > a_max = {p.a_max:.17g}")
    tolerance_u = FEASIBILITY * max(1.0, vnorm(us))
    slack = sc.n @ us - sc.c if idx else np.zeros(0)
    out.violation = max([0.0] + list(-slack)) / max(1.0, vnorm(us))
    ref = None
    expected = None if p.expected is None else np.array(p.expected) / sc.s
    treat = out.kind  # borderline: feasible if the generator says so, else as ours finds it
    if out.kind == "borderline":
        treat = "feasible" if p.expect_feasible else "" if infeasible else "feasible-ours"
    if treat in ("feasible", "feasible-ours"):
        if infeasible or dropped or not feasible:
            problems.append(f"flagged feasible {feasible}, infeasible {infeasible}, dropped "
                            f"{dropped}; expected 1, 0, 0")
        if np.any(slack < -tolerance_u):
            problems.append(f"a half-space is violated by {out.violation:.3g} max(s, ||u*||)")
        if treat == "feasible-ours":
            more, out.kkt = check_kkt(sc, idx, us, tol, True)
            problems += more
            out.ref = "kkt"
        else:
            more, out.diff, out.raw_diff, out.kkt, out.ref, ref = check_solution(
                sc, idx, us, active_count, tol, expected, out.kind == "borderline")
            problems += more
    elif out.kind == "infeasible":
        out.violation = 0.0
        if not infeasible or dropped < 1 or feasible:
            problems.append(f"flagged feasible {feasible}, infeasible {infeasible}, dropped "
                            f"{dropped}; expected 0, 1, >= 1")
        kept, dropped_ref, decided = [], [], True
        for j in idx:
            tj = depth(sc, kept + [j])
            if tj is None or abs(tj) <= BAND:
                decided = False
                break
            (kept if tj > 0 else dropped_ref).append(j)
        n0_out = idx and math.isfinite(sc.a) and sc.c[0] > sc.a * (1 + BAND)
        if n0_out or (decided and 0 in dropped_ref):
            ref, out.ref = sc.a * sc.n[0], "fallback"
            out.diff = vnorm(us - ref)
            if not out.diff <= tol:
                problems.append(f"barrier 0 out of reach: ||u_ours - a_max g0/||g0|||| = "
                                f"{out.diff:.3g} s > {tol:g} s")
            if active_count != 0:
                problems.append(f"barrier 0 out of reach: active_count {active_count} != 0")
        if decided:
            if dropped != len(dropped_ref):
                problems.append(f"dropped {dropped}, the priority rule drops {dropped_ref}")
            elif 0 not in dropped_ref:
                if np.any(slack[kept] < -tolerance_u):
                    problems.append("a kept half-space is violated")
                more, out.diff, out.raw_diff, out.kkt, out.ref, ref = check_solution(
                    sc, kept, us, active_count, tol)
                problems += [m + f" (kept {kept})" for m in more]
        elif not n0_out:
            out.ref = "undecided"
    if problems:
        def fmt(v):
            return "[" + ", ".join(f"{x:.17g}" for x in v) + "]"
        out.ok = False
        out.text = (f"{p.family} ({p.note or 'no note'}; depth {t:.3g} s: {out.kind}): "
                    + "; ".join(problems)
                    + f"\n    input:     {p.line()}\n    qp_solve:  {line}"
                    + f"\n    ours:      {fmt(u)} residuals {residuals(sc, us)}"
                    + (f"\n    reference: {fmt(ref * sc.s)} ({out.ref}) residuals "
                       f"{residuals(sc, ref)}" if ref is not None else "")
                    + (f"\n    exact:     {fmt(p.expected)}" if p.expected is not None else ""))
    return out


def run_qp_solve(path, problems):
    """qp_solve's output lines for PROBLEMS, in one process call; raises RuntimeError."""
    text = "".join(p.line() + "\n" for p in problems)
    try:
        proc = subprocess.run(tool_command(path), input=text, capture_output=True, text=True,
                              timeout=TIMEOUT_S)
    except (OSError, subprocess.TimeoutExpired) as exc:
        raise RuntimeError(f"qp_solve: {exc}") from exc
    lines = proc.stdout.splitlines()
    if len(lines) != len(problems):
        raise RuntimeError(f"qp_solve printed {len(lines)} lines for {len(problems)} problems "
                           f"(exit {proc.returncode}): {proc.stderr.strip()[-500:]}")
    return lines


def main(argv=None):
    ap = argparse.ArgumentParser(prog="compare_qp.py", description="Compare SafetyFilter's QP "
                                 "with cvxopt (see the module docstring).")
    ap.add_argument("--qp-solve", required=True, metavar="PATH")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--count", type=int, default=2000, help="random problems")
    ap.add_argument("--tolerance", type=float, default=TOLERANCE, metavar="T",
                    help="||u*_ours - u*_cvxopt|| / scale allowed")
    ap.add_argument("--xunit", metavar="FILE", help="also write a JUnit XML file")
    ap.add_argument("--family", action="append", default=[], choices=FAMILIES,
                    help="only these families")
    ap.add_argument("--skip-family", action="append", default=[], choices=FAMILIES)
    ap.add_argument("--list", action="store_true", help="print the qp_solve input and exit")
    args = ap.parse_args(argv)
    start = time.monotonic()
    rng = np.random.default_rng(args.seed)
    problems = random_problems(rng, args.count) + degenerate_problems(
        np.random.default_rng([args.seed, 1]))
    families = [f for f in FAMILIES if (not args.family or f in args.family)
                and f not in args.skip_family]
    problems = [p for p in problems if p.family in families]
    if args.list:
        for p in problems:
            print(p.line())
        return 0
    try:
        lines = run_qp_solve(args.qp_solve, problems)
    except RuntimeError as exc:
        print(f"compare_qp: error: {exc}", file=sys.stderr)
        return 2
    solved = time.monotonic()
    outcomes = [check_problem(p, line, args.tolerance) for p, line in zip(problems, lines)]
    results, total_failed = [], 0
    worst = {"diff": 0.0, "raw_diff": 0.0, "violation": 0.0, "kkt": 0.0}
    for family in families:
        mine = [(p, o) for p, o in zip(problems, outcomes) if p.family == family]
        failed = [o for _, o in mine if not o.ok]
        total_failed += len(failed)
        kinds = {kind: sum(1 for _, o in mine if o.kind == kind)
                 for kind in ("feasible", "infeasible", "borderline")}
        refs = {}
        for _, o in mine:
            refs[o.ref or "-"] = refs.get(o.ref or "-", 0) + 1
        figures = {key: max([0.0] + [getattr(o, key) for _, o in mine if o.ok])
                   for key in worst}
        for key in worst:
            worst[key] = max(worst[key], figures[key])
        line = (f"{'FAIL' if failed else 'ok  '} {family:<16} {len(mine):5d} problems "
                f"({', '.join(f'{v} {k}' for k, v in kinds.items())}; reference "
                f"{', '.join(f'{v} {k}' for k, v in sorted(refs.items()))}) max |du|/s "
                f"{figures['diff']:.2g} (raw cvxopt {figures['raw_diff']:.2g}), violation "
                f"{figures['violation']:.2g}, KKT {figures['kkt']:.2g}"
                + (f", {len(failed)} failed" if failed else ""))
        print(line, flush=True)
        for o in failed:
            print("  FAIL " + o.text)
        results.append((family, not failed, line + "".join("\n" + o.text for o in failed)))
    print(f"{len(problems) - total_failed} of {len(problems)} problems passed; max |du|/s "
          f"{worst['diff']:.3g} (against raw cvxopt points {worst['raw_diff']:.3g}), max "
          f"violation {worst['violation']:.3g}, max KKT residual {worst['kkt']:.3g}; cvxopt: "
          + ", ".join(f"{key} {n} times" for key, n in COUNTS.items())
          + f"; qp_solve {solved - start:.2f} s, total {time.monotonic() - start:.1f} s")
    if args.xunit:
        write_xunit(args.xunit, "compare_qp", results)
    return 1 if total_failed else 0


if __name__ == "__main__":
    sys.exit(main())
