#!/usr/bin/python3
"""CPU per follower step against the number of sensed neighbours, from benchmark_neighbours'
JSON (Google Benchmark, every repetition; test/benchmark/benchmark_neighbours.cpp).

Checks that every case of both dimensions ran every repetition without an error and with no heap
allocation in its timed loop (exits 1 otherwise), and writes to OUT_DIR:
  neighbours_cpu.csv  one row per case: axes, crowd, max_neighbours, sensed agents N, the median,
                      smallest and largest wall time per step over the repetitions (ns), the
                      median CPU time (ns; the table's and the plot's figure: a busy machine
                      inflates it less), the most allocations per step of a repetition, and
                      of the last step the half-spaces kept, active and dropped, whether the
                      command was projected and its norm
  neighbours_cpu.md   the table (µs per step), also placed in formations.md between its markers
  neighbours_cpu.png  µs per step against N, 2-D and 3-D panels, one line per crowd and
                      max_neighbours, the step without neighbours as a reference line
With OUT_DIR = doc/ a summary line goes into performance_summary.md between its markers.
Usage: neighbours_cpu.py BENCHMARK.json OUT_DIR [--date YYYY-MM-DD]
"""

import argparse
import csv
import json
import statistics
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "common"))
from doc_block import replace_block  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
AXES = (2, 3)
CROWDS = ("far", "arc", "ring")
MAX_KEPT = (8, 32)
SENSED = (1, 2, 4, 8, 16, 32, 64)
CROWD_TEXT = {"far": "far (at rest, 10 m: none binds)",
              "arc": "arc (closing from ahead: binding)",
              "ring": "ring (closing from every side: squeezed)"}
COLORS = {"far": "tab:green", "arc": "tab:orange", "ring": "tab:red"}
BEGIN, END = "<!-- neighbours cpu begin -->", "<!-- neighbours cpu end -->"


def cases():
    """Every (axes, crowd, max_neighbours, N) the benchmark registers."""
    result = [(k, "none", 0, 0) for k in AXES]
    result += [(k, c, m, n) for k in AXES for c in CROWDS for m in MAX_KEPT for n in SENSED]
    return result


def case_name(axes, crowd, max_kept, sensed):
    return f"neighbours_{axes}d/{crowd}/max_{max_kept}/agents_{sensed}"


def load(path):
    """{case: row} of the benchmark's repetitions; exits naming what failed."""
    data = json.loads(Path(path).read_text())
    runs, failures = {}, []
    for b in data["benchmarks"]:
        if b.get("error_occurred"):
            failures.append(f"{b['name']}: {b.get('error_message', 'error')}")
        elif b.get("run_type", "iteration") == "iteration":
            runs.setdefault(b.get("run_name", b["name"]), []).append(b)
    rows = {}
    for case in cases():
        reps = runs.get(case_name(*case), [])
        if not reps:
            failures.append(f"{case_name(*case)}: did not run")
            continue
        scale = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}[reps[0]["time_unit"]]
        real = [r["real_time"] * scale for r in reps]
        allocations = max(r["allocations"] for r in reps)
        if allocations != 0:
            failures.append(f"{case_name(*case)}: {allocations:g} heap allocations per step")
        last = reps[-1]
        rows[case] = {"axes": case[0], "crowd": case[1], "max_neighbours": case[2],
                      "sensed": case[3], "repetitions": len(reps),
                      "real_ns_median": statistics.median(real), "real_ns_min": min(real),
                      "real_ns_max": max(real),
                      "cpu_ns_median": statistics.median(r["cpu_time"] * scale for r in reps),
                      "allocations_max": allocations, "kept": int(last["kept"]),
                      "active": int(last["active"]), "dropped": int(last["dropped"]),
                      "projected": int(last["projected"]), "command": last["command"]}
    if failures:
        sys.exit("neighbours cpu: FAILED\n  " + "\n  ".join(failures))
    return rows, data["context"]


def us(ns):
    """µs with three significant digits."""
    value = ns / 1e3
    return f"{value:.0f}" if value >= 100 else f"{value:#.3g}"


def table(rows, context, reps, min_time, date):
    """The markdown block: a caption, the table and one sentence of the extremes."""
    load_avg = ", ".join(f"{x:.1f}" for x in context.get("load_avg", []))
    lines = [f"Made by `bash experiments/neighbours/cpu.sh` on {date}: µs per follower step, "
             f"median CPU time of {reps} repetitions of at least {min_time} s each, "
             f"{context['num_cpus']} CPUs at {context['mhz_per_cpu']} MHz, load average "
             f"{load_avg or 'unknown'}. Heap allocations per step: 0 in every case and "
             "repetition.", "",
             "| axes | crowd | max_neighbours | N = 0 | 1 | 2 | 4 | 8 | 16 | 32 | 64 |",
             "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for k in AXES:
        none = rows[(k, "none", 0, 0)]["cpu_ns_median"]
        lines.append(f"| {k}-D | none (no neighbours) | — | {us(none)} |" + " — |" * len(SENSED))
        for crowd in CROWDS:
            for m in MAX_KEPT:
                cells = " | ".join(us(rows[(k, crowd, m, n)]["cpu_ns_median"]) for n in SENSED)
                lines.append(f"| {k}-D | {CROWD_TEXT[crowd]} | {m} | — | {cells} |")
    lines += ["", summary_sentence(rows)]
    return "\n".join(lines) + "\n"


def worst(rows, k, m, n):
    """The slowest crowd at (axes k, max_neighbours m, N = n): (µs text, crowd)."""
    crowd = max(CROWDS, key=lambda c: rows[(k, c, m, n)]["cpu_ns_median"])
    return us(rows[(k, crowd, m, n)]["cpu_ns_median"]), crowd


def summary_sentence(rows):
    n = SENSED[-1]
    parts = []
    for m in MAX_KEPT:
        (t2, c2), (t3, c3) = worst(rows, 2, m, n), worst(rows, 3, m, n)
        parts.append(f"at most {m} kept, up to {t2} µs in 2-D ({c2}) and {t3} µs in 3-D ({c3})")
    return (f"Without neighbours a step takes {us(rows[(2, 'none', 0, 0)]['cpu_ns_median'])} µs "
            f"(2-D) and {us(rows[(3, 'none', 0, 0)]['cpu_ns_median'])} µs (3-D); with N = {n} "
            f"sensed agents (a follower of a V of {n}), {parts[0]}; {parts[1]}.")


def plot(rows, path):
    fig, panels = plt.subplots(1, len(AXES), figsize=(12, 5), sharey=True)
    for panel, k in zip(panels, AXES):
        none = rows[(k, "none", 0, 0)]["cpu_ns_median"] / 1e3
        panel.axhline(none, color="black", linestyle=":")
        panel.annotate(f"no neighbours (N = 0): {us(none * 1e3)} µs", (SENSED[-1], none),
                       xytext=(0, 4), textcoords="offset points", ha="right", fontsize=9)
        for crowd in CROWDS:
            for m, style, marker in zip(MAX_KEPT, ("-", "--"), ("o", "s")):
                y = [rows[(k, crowd, m, n)]["cpu_ns_median"] / 1e3 for n in SENSED]
                panel.plot(SENSED, y, linestyle=style, marker=marker, color=COLORS[crowd],
                           label=f"{crowd}, max_neighbours {m}")
        panel.set_xscale("log", base=2)
        panel.set_yscale("log")
        panel.set_xticks(SENSED, [str(n) for n in SENSED])
        panel.set_xlabel("sensed agents N")
        panel.set_title(f"{k}-D: one follower step with formation.neighbours")
        panel.grid(True, which="both", alpha=0.3)
    panels[0].set_ylabel("µs per step (median CPU time)")
    panels[0].legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def performance_line(rows, date, reps):
    n = SENSED[-1]
    (t2, _), (t3, _) = worst(rows, 2, 8, n), worst(rows, 3, 8, n)
    return (f"Neighbour protection (made by `bash experiments/neighbours/cpu.sh` on {date}, median "
            f"CPU times of {reps} repetitions): one control step with N = {n} sensed agents and the default "
            f"max_neighbours 8 takes up to {t2} µs in 2-D and {t3} µs in 3-D over the benchmark's "
            f"crowds ({us(rows[(2, 'none', 0, 0)]['cpu_ns_median'])} / "
            f"{us(rows[(3, 'none', 0, 0)]['cpu_ns_median'])} µs without neighbours), 0 heap "
            "allocations per step; every case in "
            "[formations.md](formations.md#cpu-per-follower-step).")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("json")
    parser.add_argument("out_dir", type=Path)
    parser.add_argument("--date", default="")
    parser.add_argument("--min-time", default="0.1")
    args = parser.parse_args()
    rows, context = load(args.json)
    reps = rows[(2, "none", 0, 0)]["repetitions"]
    args.out_dir.mkdir(parents=True, exist_ok=True)
    ordered = [rows[c] for c in cases()]
    with open(args.out_dir / "neighbours_cpu.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(ordered[0]))
        writer.writeheader()
        writer.writerows(ordered)
    block = table(rows, context, reps, args.min_time, args.date)
    (args.out_dir / "neighbours_cpu.md").write_text(
        "<!-- made by experiments/neighbours/cpu.sh; do not edit -->\n" + block)
    plot(rows, args.out_dir / "neighbours_cpu.png")
    if args.out_dir.resolve() == (ROOT / "doc").resolve():
        replace_block(ROOT / "doc" / "formations.md", BEGIN, END, block)
        replace_block(ROOT / "doc" / "performance_summary.md", BEGIN, END,
                      performance_line(rows, args.date, reps))
    print(block)


if __name__ == "__main__":
    main()
