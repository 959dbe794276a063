#!/usr/bin/python3
"""The paper's CF estimator and tracker against a control barrier function (CBF-QP) safety filter
(controller.safety_filter, doc/math.md (B1)-(B3)) on the same scenarios, through cf_sim.

Methods (the same baseline law, the same plant, the same pushes):
  baseline  the baseline formation law alone (controller.tracker.enabled: false): the paper's Run 1
  CF        the scenario's CF estimator and tracker (tracker on): the paper's method
  CBF l=L   the baseline law filtered by the exponential barrier of rate L (tracker off), one
            barrier per sensed agent where formation.neighbours is set
  CF+N      in formations with formation.neighbours: the CF tracker with the neighbours' (N3)
Per run, over every follower: min separation to the target against the perimeter alpha ||d||
(and over every pair in formations), max ||xi_i|| / xi_max,i and the time any follower spends
outside its bound, the command effort (the mean over followers of the integral of ||u_i||^2 dt),
peak ||u_i||, peak jerk (max ||u_i(k) - u_i(k-1)|| / T), the time to settle (after the push
starts, the last time a follower's ||xi_i|| exceeds 5 % of xi_max,i; 'no' when it still does at
the end), and the ticks at which the filter moved the command and could not meet its barriers.
The disturbance sweep: for each of 16 directions phi of u_d = s [cos phi, sin phi] (Run 2's pair,
cf. doc/formations.md "Disturbance sweep"), the largest s up to 20 (0.25 steps, then bisection to
1e-3) whose run keeps the separation outside the perimeter, and the largest that keeps ||xi||
within xi_max, per method.

Writes OUT_DIR/comparison.csv (one row per run), comparison_sweep.csv, comparison_tables.md (the tables,
also placed in doc/comparison.md between its markers).
Usage: comparison_table.py CF_SIM OUT_DIR [--quick]
"""

import csv
import math
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "common"))
from doc_block import replace_block  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = ROOT / "config" / "scenarios"
TRACKER_OFF = "controller.tracker.enabled=false"
SHARED = "controller.leader_information={estimator: true, disturbance: true}"
VELOCITY_PUSH = "leader.disturbance=[{start: 20.0, end: 23.0, vector: [0.0, -8.0]}]"
NEIGHBOURS_V4 = "formation.neighbours={braking_acceleration: 1, neighbour_acceleration: 2, rate: 1}"


def cbf(rate):
    return f"controller.safety_filter={{rate: {rate}}}"


def methods(cbf_rates=(2, 4), neighbours=None):
    """(name, overrides) of the methods on one scenario."""
    rows = [("baseline", [TRACKER_OFF]), ("CF", [])]
    if neighbours:
        rows.append(("CF+N", [neighbours]))
    for rate in cbf_rates:
        rows.append((f"CBF l={rate}", [TRACKER_OFF, cbf(rate)] + ([neighbours] if neighbours else [])))
    return rows


# (case, scenario, common overrides, push start s, methods)
CASES = [
    ("Run 2's push (position and velocity rate)", "paper_run2.yaml", [], 20.0, methods()),
    ("a velocity-rate push of 8 m/s^2, a_1 shared", "paper_run2.yaml", [VELOCITY_PUSH, SHARED], 20.0,
     methods()),
    ("Run 2's push, a_max = 4 m/s^2", "paper_run2.yaml", ["controller.acceleration_limit=4"], 20.0,
     methods()),
    ("2-D figure eight, V star of 4", "figure_eight_2d.yaml", [], 20.0, methods()),
    ("turning formation (U-turn)", "turning_u_turn.yaml", [], 0.0, methods()),
    ("chain of 100 (platoon_run2.yaml, link)", "platoon_run2.yaml", [], 20.0, methods(cbf_rates=(2,))),
    ("V star of 4, gust on follower 2", "crowd_v4_gust.yaml", [], 20.0,
     methods(neighbours=NEIGHBOURS_V4)),
]


def summary_lines(out):
    """The per-follower fields and the formation's (None for a pair) of cf_sim's output."""
    followers, formation = [], None
    for line in out.splitlines():
        fields = dict(f.split("=", 1) for f in line.split() if "=" in f)
        if line.startswith("formation "):
            formation = fields
        elif "max_xi" in fields:
            followers.append(fields)
    return followers, formation


def run(cf_sim, scenario, overrides, csv_prefix=None):
    args = [cf_sim, str(SCENARIOS / scenario)]
    if csv_prefix:
        args += ["--csv", f"{csv_prefix}.csv"]
    for s in overrides:
        args += ["--set", s]
    out = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    return summary_lines(out)


def csv_paths(prefix, followers, formation):
    if formation is None:
        return [f"{prefix}.csv"]
    return [f"{prefix}_follower_{i}.csv" for i in range(1, followers + 1)]


def command_figures(paths, push_start):
    """Effort, peak ||u||, peak jerk and settle time over the followers' CSVs."""
    efforts, peak_u, peak_jerk, settle, perimeter = [], 0.0, 0.0, 0.0, math.inf
    for path in paths:
        data = np.genfromtxt(path, delimiter=",", names=True)
        perimeter = min(perimeter, float(data["perimeter"][0]))
        t = data["t"]
        dt = t[1] - t[0]
        u = np.c_[[data[n] for n in data.dtype.names if n.startswith("u_") and n[2:].isdigit()]].T
        norms = np.linalg.norm(u, axis=1)
        efforts.append(float(np.sum(norms ** 2) * dt))
        peak_u = max(peak_u, float(norms.max()))
        peak_jerk = max(peak_jerk, float(np.linalg.norm(np.diff(u, axis=0), axis=1).max() / dt))
        outside = np.nonzero((data["norm_xi"] > 0.05 * data["xi_max"]) & (t >= push_start))[0]
        if outside.size:
            last = outside[-1]
            settle = math.inf if last == len(t) - 1 else max(settle, t[last + 1] - push_start)
    return float(np.mean(efforts)), peak_u, peak_jerk, settle, perimeter


def measure(cf_sim, tmp, index, case, scenario, common, push_start, method, overrides):
    prefix = f"{tmp}/run{index}"
    followers, formation = run(cf_sim, scenario, common + overrides, prefix)
    effort, peak_u, peak_jerk, settle, perimeter = command_figures(
        csv_paths(prefix, len(followers), formation), push_start)
    f = lambda key: [float(x[key]) for x in followers]  # noqa: E731
    row = {
        "case": case, "method": method, "followers": len(followers),
        "min_separation": min(f("min_separation")),
        "perimeter": perimeter,
        "min_pair_separation": float(formation["min_pair_separation"]) if formation else math.nan,
        "max_xi_ratio": max(a / b for a, b in zip(f("max_xi"), f("xi_max"))),
        "time_outside": max(f("time_outside")),
        "effort": effort, "peak_u": peak_u, "peak_jerk": peak_jerk, "settle": settle,
        "barrier_ticks": sum(int(x.get("barrier_ticks", 0)) for x in followers),
        "barrier_infeasible_ticks": sum(int(x.get("barrier_infeasible_ticks", 0)) for x in followers),
    }
    return row


def sweep_limit(cf_sim, overrides, direction, criterion, max_size=20.0, step=0.25, tol=1e-3):
    """The largest push s along @p direction whose run meets @p criterion (scan, then bisect)."""
    def holds(size):
        vector = f"[{size * math.cos(direction):.12g}, {size * math.sin(direction):.12g}]"
        push = f"leader.disturbance=[{{start: 20.0, end: 23.0, vector: {vector}}}]"
        followers, _ = run(cf_sim, "paper_run2.yaml",
                           ["controller.control_rate=100", push] + overrides)
        return criterion(followers[0])
    safe, size = 0.0, step
    while size <= max_size + 1e-9:
        if not holds(size):
            low, high = safe, size
            while high - low > tol:
                mid = 0.5 * (low + high)
                low, high = (mid, high) if holds(mid) else (low, mid)
            return low, False
        safe, size = size, size + step
    return max_size, True


def outside_perimeter(fields):
    return float(fields["min_separation"]) >= 1.0  # alpha ||d|| of paper_run2.yaml


def inside_bound(fields):
    return float(fields["max_xi"]) <= float(fields["xi_max"])


SWEEP_METHODS = [("baseline", [TRACKER_OFF]), ("CF", []), ("CBF l=2", [TRACKER_OFF, cbf(2)]),
                 ("CBF l=2, a_1 shared", [TRACKER_OFF, cbf(2), SHARED]),
                 ("CF, a_1 shared", [SHARED])]


def fmt(x, digits=2):
    if isinstance(x, str):
        return x
    if math.isinf(x):
        return "no"
    if math.isnan(x):
        return "—"
    return f"{x:.{digits}f}"


def table(rows):
    head = ("| case | method | min separation / perimeter (m) | min pair distance (m) | "
            "max ‖ξ_i‖/ξ_max,i | time outside (s) | ∫‖u‖² dt (m²/s³) | peak ‖u‖ (m/s²) | "
            "peak jerk (m/s³) | settle (s) | filter ticks | infeasible ticks |")
    lines = [head, "|" + "---|" * 12]
    for r in rows:
        inside = " **inside**" if r["min_separation"] < r["perimeter"] else ""
        lines.append(
            f"| {r['case']} | {r['method']} | {fmt(r['min_separation'])} / {fmt(r['perimeter'])}"
            f"{inside} | {fmt(r['min_pair_separation'])} | {fmt(r['max_xi_ratio'])} | "
            f"{fmt(r['time_outside'])} | {fmt(r['effort'], 1)} | {fmt(r['peak_u'])} | "
            f"{fmt(r['peak_jerk'], 0)} | {fmt(r['settle'], 1)} | {r['barrier_ticks']} | "
            f"{r['barrier_infeasible_ticks']} |")
    return "\n".join(lines) + "\n"


def sweep_table(points, directions):
    names = [name for name, _ in SWEEP_METHODS]
    lines = ["| φ (°) | " + " | ".join(f"{n}: perimeter / bound" for n in names) + " |",
             "|---|" + "---|" * len(names)]
    for k in range(directions):
        cells = []
        for name in names:
            p = points[(name, k)]
            cells.append(f"{p[0]:.2f}{'+' if p[1] else ''} / {p[2]:.2f}{'+' if p[3] else ''}")
        lines.append(f"| {360.0 * k / directions:.1f} | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def main(argv):
    cf_sim, out = argv[1], Path(argv[2])
    quick = "--quick" in argv
    directions = 4 if quick else 16
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        index = 0
        for case, scenario, common, start, rows_of_case in CASES[:2] if quick else CASES:
            for method, overrides in rows_of_case:
                index += 1
                rows.append(measure(cf_sim, tmp, index, case, scenario, common, start, method,
                                    overrides))
                print(f"comparison: {case}, {method}", file=sys.stderr)
    points = {}
    for name, overrides in SWEEP_METHODS:
        for k in range(directions):
            phi = 2.0 * math.pi * k / directions
            points[(name, k)] = (sweep_limit(cf_sim, overrides, phi, outside_perimeter)
                                 + sweep_limit(cf_sim, overrides, phi, inside_bound))
        print(f"comparison: sweep {name}", file=sys.stderr)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "comparison.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        writer.writeheader()
        writer.writerows(rows)
    with open(out / "comparison_sweep.csv", "w", newline="") as f:
        writer = csv.writer(f)
        writer.writerow(["method", "direction_deg", "perimeter_limit", "perimeter_capped",
                         "bound_limit", "bound_capped"])
        for (name, k), p in points.items():
            writer.writerow([name, 360.0 * k / directions, *p])
    text = table(rows) + "\n" + sweep_table(points, directions)
    (out / "comparison_tables.md").write_text(text)
    if not quick:
        replace_block(ROOT / "doc" / "comparison.md", "<!-- comparison table begin -->",
                      "<!-- comparison table end -->", text)


if __name__ == "__main__":
    main(sys.argv)
