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

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from compare_common import tool_command, write_xunit  # noqa: E402  (beside this file)
from qp_problems import FAMILIES, degenerate_problems, random_problems, vnorm  # noqa: E402
from qp_reference import (COUNTS, FEASIBILITY, ROUNDING, depth, ours_kkt,  # noqa: E402
                          reference, scaled)

TOLERANCE = 1e-6        # ||u*_ours - u*_ref|| / s
BAND = 1e-7             # |depth| / s below which feasibility is not decided by cvxopt
TIMEOUT_S = 300


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
