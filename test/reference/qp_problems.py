"""The QP problems of compare_qp.py (doc/math.md (B3)), seeded: random ones in 1 to 3
dimensions and the degenerate families, some with their exact solution."""

import math
from dataclasses import dataclass
from typing import Optional, Tuple

import numpy as np


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
