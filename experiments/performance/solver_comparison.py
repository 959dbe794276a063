#!/usr/bin/python3
"""cf_sim against the SciPy reference (solve_ivp, LSODA) on the paper's scenario.

Both programs are timed as whole processes (start, scenario file, simulation, summary line,
exit), side by side: every repetition runs every configuration once, in turn, and the table
gives the median over the repetitions. Accuracy is measured once per configuration, from its
CSV, against a tight-tolerance solution of the same continuous-time model (reference_sim.py,
LSODA at rtol 1e-12, atol 1e-14), itself checked against DOP853 at the same tolerances.

The error of a run is the largest of ||xi(t) - xi*(t)|| and ||xi_hat(t) - xi_hat*(t)|| over the
10 Hz grid, which every configuration samples.

Configurations:
  cf_sim --continuous h   the same continuous-time model, classical RK4 at the fixed step h
  cf_sim --continuous h --method rk6
                          the same, Butcher's 7-stage 6th-order method at the fixed step h
  cf_sim (sampled)        the deployed sampled-data controller at the scenario's control rate;
                          its distance to the continuous model is the zero-order hold, not a
                          solver error (first order in the period)
  reference_sim LSODA     solve_ivp(method="LSODA") at the given rtol / atol

Usage: solver_comparison.py --cf-sim PATH [--scenario FILE] [--reps N] [--json FILE]
Prints a Markdown table and the equal-accuracy ratios.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
REFERENCE = os.path.join(ROOT, "test", "reference", "reference_sim.py")
PYTHON = "/usr/bin/python3"
TRUTH_TOLERANCES = ("1e-12", "1e-14")
# Steps that land on the 10 Hz grid: 0.1 s / k.
RK4_STEPS = tuple(f"{0.1 / k:.10g}" for k in (1, 2, 4, 5, 8, 10, 16, 20, 25, 32, 40, 50))
RK6_STEPS = tuple(f"{0.1 / k:.10g}" for k in (1, 2, 4, 5, 8, 10))
LSODA_TOLERANCES = (("1e-3", "1e-6"), ("1e-6", "1e-9"), ("1e-8", "1e-11"), ("1e-10", "1e-13"))


def configurations(cf_sim, scenario):
    """(label, kind, argv) of every timed configuration."""
    result = []
    for step in RK4_STEPS:
        result.append((f"cf_sim --continuous {step}", "cf_sim continuous",
                       [cf_sim, scenario, "--continuous", step]))
    for step in RK6_STEPS:
        result.append((f"cf_sim --continuous {step} --method rk6", "cf_sim continuous",
                       [cf_sim, scenario, "--continuous", step, "--method", "rk6"]))
    result.append(("cf_sim (sampled)", "cf_sim sampled", [cf_sim, scenario]))
    for rtol, atol in LSODA_TOLERANCES:
        result.append((f"LSODA rtol {rtol} atol {atol}", "LSODA",
                       [PYTHON, REFERENCE, scenario, "--rtol", rtol, "--atol", atol]))
    return result


def run(argv):
    completed = subprocess.run(argv, check=True, stdout=subprocess.PIPE, text=True)
    return completed.stdout


def load(path):
    data = np.genfromtxt(path, delimiter=",", names=True)
    return data


def columns(data, prefix):
    names = [n for n in data.dtype.names if n.startswith(prefix) and n[len(prefix):].isdigit()]
    return np.column_stack([data[n] for n in names])


def on_grid(data, grid):
    """Rows of data at the times of grid (each must be a sample time, within 1e-9 s)."""
    index = np.searchsorted(data["t"], grid - 1e-9)
    index = np.minimum(index, data["t"].size - 1)
    if np.max(np.abs(data["t"][index] - grid)) > 1e-9:
        raise RuntimeError("a run does not sample the 10 Hz grid")
    return index


def error(data, truth, grid):
    i = on_grid(data, grid)
    j = on_grid(truth, grid)
    xi = np.linalg.norm(columns(data, "xi_")[i] - columns(truth, "xi_")[j], axis=1)
    xi_hat = np.linalg.norm(columns(data, "xi_hat_")[i] - columns(truth, "xi_hat_")[j], axis=1)
    return float(max(np.max(xi), np.max(xi_hat)))


def duration_of(scenario):
    import yaml  # Debian's python3-yaml
    with open(scenario) as handle:
        return float(yaml.safe_load(handle)["simulation"]["duration"])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cf-sim", required=True)
    parser.add_argument("--scenario", default=os.path.join(ROOT, "config", "scenarios",
                                                           "paper_run2.yaml"))
    parser.add_argument("--reps", type=int, default=5)
    parser.add_argument("--json", help="write the figures to this file")
    args = parser.parse_args(argv)
    duration = duration_of(args.scenario)
    configs = configurations(args.cf_sim, args.scenario)

    with tempfile.TemporaryDirectory() as tmp:
        truth_csv = os.path.join(tmp, "truth.csv")
        dop_csv = os.path.join(tmp, "dop853.csv")
        run([PYTHON, REFERENCE, args.scenario, "--rtol", TRUTH_TOLERANCES[0], "--atol",
             TRUTH_TOLERANCES[1], "--csv", truth_csv])
        run([PYTHON, REFERENCE, args.scenario, "--method", "DOP853", "--rtol",
             TRUTH_TOLERANCES[0], "--atol", TRUTH_TOLERANCES[1], "--csv", dop_csv])
        truth = load(truth_csv)
        grid = np.round(np.arange(0.0, duration + 1e-9, 0.1), 9)
        truth_check = error(load(dop_csv), truth, grid)
        errors = {}
        for label, _, cmd in configs:
            csv = os.path.join(tmp, "run.csv")
            run(cmd + ["--csv", csv])
            errors[label] = error(load(csv), truth, grid)

    times = {label: [] for label, _, _ in configs}
    for _ in range(args.reps):
        for label, _, cmd in configs:
            start = time.perf_counter()
            run(cmd)
            times[label].append(time.perf_counter() - start)

    rows = []
    for label, kind, _ in configs:
        median = statistics.median(times[label])
        rows.append({"configuration": label, "kind": kind, "error": errors[label],
                     "median_s": median, "min_s": min(times[label]),
                     "real_time_factor": duration / median})
    comparisons = []
    for lsoda in (r for r in rows if r["kind"] == "LSODA"):
        candidates = [r for r in rows
                      if r["kind"] == "cf_sim continuous" and r["error"] <= lsoda["error"]]
        if not candidates:
            continue
        best = min(candidates, key=lambda r: r["median_s"])
        comparisons.append({"lsoda": lsoda["configuration"], "cf_sim": best["configuration"],
                            "lsoda_error": lsoda["error"], "cf_sim_error": best["error"],
                            "speedup": lsoda["median_s"] / best["median_s"],
                            "cf_sim_real_time_factor": best["real_time_factor"]})

    print(f"Scenario {os.path.basename(args.scenario)}, {duration:g} s; whole processes, "
          f"median of {args.reps} side-by-side repetitions; error = max over the 10 Hz grid "
          f"of ||xi - xi*|| and ||xi_hat - xi_hat*|| (10 Hz grid) against LSODA at rtol "
          f"{TRUTH_TOLERANCES[0]} (DOP853 at the same tolerances differs from it by "
          f"{truth_check:.1e}).")
    print()
    print("| configuration | error (m) | median time (s) | faster than real time |")
    print("|---|---|---|---|")
    for r in rows:
        print(f"| {r['configuration']} | {r['error']:.1e} | {r['median_s']:.4f} | "
              f"{r['real_time_factor']:,.0f}x |")
    print()
    print("| LSODA | its error | cheapest cf_sim at equal or better accuracy | its error | "
          "cf_sim faster by |")
    print("|---|---|---|---|---|")
    for c in comparisons:
        print(f"| {c['lsoda']} | {c['lsoda_error']:.1e} | {c['cf_sim']} | "
              f"{c['cf_sim_error']:.1e} | {c['speedup']:,.0f}x |")
    if args.json:
        with open(args.json, "w") as handle:
            json.dump({"duration_s": duration, "reps": args.reps, "truth_check": truth_check,
                       "rows": rows, "comparisons": comparisons, "times": times}, handle,
                      indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
