#!/usr/bin/python3
"""Renders the figures of experiments/performance/run.sh as doc/performance.md and the table of
doc/performance_summary.md.

Inputs (all written by experiments/performance/run.sh and the scripts it runs):
  --benchmark FILE     Google Benchmark JSON (aggregates of repeated runs)
  --instructions FILE  CSV axes,regime,instructions at 1000 steps,instructions at 11000 steps
  --solvers FILE       JSON of experiments/performance/solver_comparison.py
  --ros-csv FILE       CSV of experiments/ros_latency/run.sh (optional)
  --scale FILE         doc/formation_scale.md of experiments/formation_scale/run.sh (optional)
doc/performance_summary.md's table is replaced between the lines <!-- performance:begin --> and
<!-- performance:end -->.
"""

from __future__ import annotations

import argparse
import csv
import datetime
import json
import os
import re
import statistics
import sys

BEGIN = "<!-- performance:begin -->"
END = "<!-- performance:end -->"
AXES = {"DoubleIntegrator1D": 1, "DoubleIntegrator2D": 2, "DoubleIntegrator3D": 3}
STEP_TARGET_NS = {1: 250.0, 3: 1000.0}


def load_benchmarks(path):
    """{(name, axes or None): median aggregate} of the benchmark JSON, and its context."""
    data = json.load(open(path))
    medians = {}
    for b in data["benchmarks"]:
        if b.get("aggregate_name") != "median":
            continue
        match = re.match(r"(\w+)<(\w+)>", b["run_name"])
        key = (match.group(1), AXES[match.group(2)]) if match else (b["run_name"], None)
        medians[key] = b
    return medians, data["context"]


def nanoseconds(b):
    scale = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}[b["time_unit"]]
    return b["real_time"] * scale


def load_instructions(path):
    per_step = {}
    with open(path) as handle:
        for axes, regime, first, second in csv.reader(handle):
            per_step[(int(axes), regime)] = (int(second) - int(first)) / 10000.0
    return per_step


def load_ros(path):
    if not path or not os.path.exists(path):
        return None
    with open(path) as handle:
        return list(csv.DictReader(handle))


def median_of(rows, column):
    values = [float(r[column]) for r in rows if r.get(column, "") not in ("", "nan")]
    return statistics.median(values) if values else float("nan")


def load_scale(path):
    """Largest N holding 100 Hz as processes and as nodelets, and CPU per follower (median over
    the sizes that held), from the kept-awake section of doc/formation_scale.md."""
    if not path or not os.path.exists(path):
        return None
    text = open(path).read()
    sections = re.split(r"\n## ", text)
    awake = [s for s in sections if "awake" in s.splitlines()[0].lower()]
    if not awake:
        return None
    result = {}
    for mode in ("processes", "nodelets"):
        held, cpu = [], []
        for line in awake[0].splitlines():
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if len(cells) < 6 or cells[0] != mode or not cells[1].isdigit():
                continue
            if cells[-1] == "yes":
                held.append(int(cells[1]))
                cpu.append(float(cells[6]))
        result[mode] = (max(held) if held else 0, statistics.median(cpu) if cpu else float("nan"))
    return result


def fmt_ns(ns):
    return f"{ns:.0f} ns" if ns < 1e4 else f"{ns / 1e6:.2f} ms"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--benchmark", required=True)
    parser.add_argument("--instructions", required=True)
    parser.add_argument("--solvers", required=True)
    parser.add_argument("--ros-csv")
    parser.add_argument("--scale")
    parser.add_argument("--reps", type=int, required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--summary")
    parser.add_argument("--date", help="the day the figures were measured (default: today)")
    args = parser.parse_args(argv)

    bench, context = load_benchmarks(args.benchmark)
    instructions = load_instructions(args.instructions)
    solvers = json.load(open(args.solvers))
    ros = load_ros(args.ros_csv)
    scale = load_scale(args.scale)
    mhz = float(context["mhz_per_cpu"])
    today = args.date or datetime.date.today().isoformat()

    # --- one control step
    step_rows = []
    for axes in (1, 2, 3):
        row = {"axes": axes}
        for regime, name in (("inside", "BM_FollowerStep"), ("outside", "BM_FollowerStepProjected")):
            b = bench[(name, axes)]
            ns = nanoseconds(b)
            flops = b["flops"]
            row[regime] = {"ns": ns, "flops": flops, "allocations": b["allocations"],
                           "instructions": instructions[(axes, regime)],
                           "cycles_per_flop": ns * mhz * 1e-3 / flops,
                           "instructions_per_flop": instructions[(axes, regime)] / flops}
        step_rows.append(row)

    lines = ["# Performance", "",
             f"Generated by `bash experiments/performance/run.sh` on {today}: "
             f"{context['num_cpus']} CPUs at {mhz:.0f} MHz (nominal, from Google Benchmark); medians of {args.reps} "
             "repetitions. The machine is a shared 2-core VM: compare figures of one run, and "
             "prefer the ratios and the instruction counts (which do not depend on load).", "",
             "## One control step", "",
             "`FollowerController::step()`: baseline law, CF estimator over one period (RK4 at the "
             "scenario's substeps), CF tracker and saturation test; the paper's Run 2 parameters "
             "(1 kHz, 1 substep), embedded along the diagonal in 2-D and 3-D. *Inside*: a "
             "constant measurement inside the bound, the projection idle. *On the bound*: a "
             "measurement outside, the estimate held on the sphere, the projection acting at "
             "every derivative evaluation. Heap allocations: counted in the timed loop, divided by its "
             "steps (the benchmark harness itself allocates about once per run; "
             "`test_no_allocation` asserts exactly zero for the steps). Flops are counted from the code "
             "(test/benchmark/StepFlops.hpp: +, -, *, /, sqrt each one; dense products); "
             "cycles per flop use the nominal clock; instructions per step come from callgrind "
             "(difference of 11000 and 1000 steps, /10000).", "",
             "| axes | regime | time | heap allocations | flops | cycles per flop | "
             "instructions (callgrind) | instructions per flop | target |",
             "|---:|---|---:|---:|---:|---:|---:|---:|---|"]
    for row in step_rows:
        for regime, label in (("inside", "inside"), ("outside", "on the bound")):
            r = row[regime]
            target = STEP_TARGET_NS.get(row["axes"])
            target_text = f"≤ {target / 1000:g} µs, 0 allocations" if target else ""
            lines.append(f"| {row['axes']} | {label} | {r['ns']:.0f} ns | {r['allocations']:.6f} | "
                         f"{r['flops']:.0f} | {r['cycles_per_flop']:.2f} | "
                         f"{r['instructions']:.0f} | {r['instructions_per_flop']:.2f} | "
                         f"{target_text} |")
    run_sampled = bench[("BM_PaperRun2Sampled", None)]
    run_continuous = bench[("BM_PaperRun2Continuous", None)]
    lines += ["", "In process (no start-up, no file): the whole 60 s Run 2 takes "
              f"{fmt_ns(nanoseconds(run_sampled))} with the sampled controller at 1 kHz "
              f"(60 001 ticks, {60e9 / nanoseconds(run_sampled):,.0f}x real time) and "
              f"{fmt_ns(nanoseconds(run_continuous))} in continuous time with RK4 at 5 ms "
              f"({60e9 / nanoseconds(run_continuous):,.0f}x real time).", ""]

    # --- cf_sim against LSODA
    lines += ["## cf_sim against SciPy's LSODA", "",
              "`experiments/performance/solver_comparison.py`: whole processes (start, YAML, "
              "simulation, summary line), every configuration once per repetition in turn, median over "
              f"{solvers['reps']} repetitions. Error: the largest of ‖ξ − ξ*‖ and ‖ξ̂ − ξ̂*‖ "
              "over the 10 Hz grid against LSODA at rtol 1e-12, atol 1e-14 (DOP853 at the same "
              f"tolerances differs from that by {solvers['truth_check']:.1e}). "
              "`cf_sim --continuous h` integrates the same continuous-time model as the "
              "reference (classical RK4 at the fixed step h; with `--method rk6`, Butcher's "
              "7-stage 6th-order method); plain `cf_sim` runs the sampled controller "
              "at the scenario's 1 kHz, whose distance to the continuous model is the zero-order "
              "hold (first order in the period), not a solver error.", "",
              "| configuration | error | median process time | faster than real time |",
              "|---|---:|---:|---:|"]
    for r in solvers["rows"]:
        lines.append(f"| {r['configuration']} | {r['error']:.1e} | {r['median_s'] * 1e3:.1f} ms | "
                     f"{r['real_time_factor']:,.0f}x |")
    lines += ["", "| LSODA | its error | cheapest cf_sim at equal or better accuracy | its error "
              "| cf_sim faster by |", "|---|---:|---|---:|---:|"]
    for c in solvers["comparisons"]:
        lines.append(f"| {c['lsoda']} | {c['lsoda_error']:.1e} | {c['cf_sim']} | "
                     f"{c['cf_sim_error']:.1e} | {c['speedup']:,.0f}x |")
    lines.append("")

    # --- ROS
    if ros:
        lines += ros_section(ros)
    else:
        lines += ["## ROS pipeline at 1 kHz", "", "Not measured in this run (--skip-ros).", ""]

    # --- scale
    lines += ["## Platoon scale", ""]
    if scale:
        lines.append(
            "From the kept-awake pass of `doc/formation_scale.md` (`bash "
            "experiments/formation_scale/run.sh`, stars at 100 Hz on real time): the largest N "
            f"holding 100 Hz is {scale['processes'][0]} as processes and {scale['nodelets'][0]} as "
            f"nodelets; CPU per follower {scale['processes'][1]:.1f} % and "
            f"{scale['nodelets'][1]:.1f} % of a core (median over the sizes that held).")
    else:
        lines.append("No doc/formation_scale.md.")
    lines.append("")
    lines += ["## The nodes' CPU time", "",
              "CPU per tick of the ROS nodes, its parts, and platoons in one nodelet manager: "
              "[node_cpu.md](node_cpu.md) (`experiments/node_cpu/`).", ""]
    with open(args.out, "w") as handle:
        handle.write("\n".join(lines))

    if args.summary:
        table = summary_table(step_rows, run_sampled, solvers, ros, scale, args.reps, today)
        text = open(args.summary).read()
        if BEGIN not in text or END not in text:
            print(f"{args.summary} has no {BEGIN} ... {END} block", file=sys.stderr)
            return 1
        head, rest = text.split(BEGIN, 1)
        _, tail = rest.split(END, 1)
        with open(args.summary, "w") as handle:
            handle.write(head + BEGIN + "\n" + table + END + tail)
    return 0


def ros_rows(ros):
    """Per-setting medians of the runs that completed: {setting: {short name: median}}."""
    names = {"relay_p50_us": "relay_p50_us", "relay_p99_us": "relay_p99_us",
             "measurement_p50_us": "follower_measurement_p50_us",
             "measurement_p99_us": "follower_measurement_p99_us",
             "timer_p50_us": "follower_timer_p50_us", "timer_p99_us": "follower_timer_p99_us",
             "added_p50_percent": "added_p50_percent", "added_p99_percent": "added_p99_percent",
             "measurement_missed_percent": "follower_measurement_missed_percent",
             "measurement_late_percent": "follower_measurement_late_percent",
             "timer_missed_percent": "follower_timer_missed_percent",
             "timer_late_percent": "follower_timer_late_percent",
             "probe_skipped_percent": "probe_skipped_percent", "load": "load1_before",
             "steal_percent": "steal_percent"}
    settings = {}
    for r in ros:
        if r.get("ok", "True") == "True":
            settings.setdefault(r["setting"], []).append(r)
    result = {}
    for setting, rows in settings.items():
        result[setting] = {short: median_of(rows, column) for short, column in names.items()}
        result[setting]["runs"] = len(rows)
    return result


def ros_section(ros):
    medians = ros_rows(ros)
    lines = ["## ROS pipeline at 1 kHz", "",
             "`bash experiments/ros_latency/run.sh` (`experiments/probes/latency.launch`): a probe "
             "publishes relative measurements at 1 kHz on real time; a bare roscpp relay "
             "(`experiments/probes/measurement_relay.cpp`), a follower triggered by each "
             "measurement (`~trigger: measurement`) and a follower on its 1 kHz timer "
             "(`~trigger: timer`) all subscribe to it in the same run; in the SCHED_FIFO setting all "
             "four run under `chrt -f 50`; in the control-thread setting both followers run their "
             "control tick on their real-time thread (`~control_loop: thread`, "
             "`~control_priority: 80`, `~lock_memory: true`), probe and relay as when kept "
             "awake. Latency: from the "
             "measurement's publication to the probe's receipt of the relayed measurement or of "
             "the command computed from it. Missed periods: scheduled periods that never ran; "
             "late: ran more than half a period after their due time. Medians over the runs; "
             "*as is*: the machine untouched; *kept awake*: one `nice -n 19` busy loop per core "
             "(this VM wakes idle cores late). The probe's own 1 kHz thread skips periods too "
             "(column probe): the machine, not the follower, sets the floor.", "",
             "| setting | runs | relay p50 / p99 (µs) | follower (measurement) p50 / p99 (µs) | "
             "added to the relay (p50) | follower (timer) p50 / p99 (µs) | missed / late "
             "periods, measurement | missed / late periods, timer | probe skipped | load | steal |",
             "|---|---:|---|---|---:|---|---|---|---:|---:|---:|"]
    for setting, m in sorted(medians.items()):
        lines.append(
            f"| {setting} | {m['runs']} | {m['relay_p50_us']:.0f} / {m['relay_p99_us']:.0f} | "
            f"{m['measurement_p50_us']:.0f} / {m['measurement_p99_us']:.0f} | "
            f"{m['added_p50_percent']:+.0f} % | {m['timer_p50_us']:.0f} / {m['timer_p99_us']:.0f} | "
            f"{m['measurement_missed_percent']:.3f} % / {m['measurement_late_percent']:.3f} % | "
            f"{m['timer_missed_percent']:.3f} % / {m['timer_late_percent']:.3f} % | "
            f"{m['probe_skipped_percent']:.3f} % | {m['load']:.2f} | {m['steal_percent']:.1f} % |")
    lines += ["", "Every run (steal: the share of CPU time the hypervisor gave to other guests during "
              "the run, from /proc/stat; a run with much steal measures the host):", "",
              "| setting | run | steal | relay p50 / p99 (µs) | follower (measurement) p50 / p99 "
              "(µs) | added (p50) | missed / late, measurement | missed / late, timer | "
              "probe skipped |", "|---|---:|---:|---|---|---:|---|---|---:|"]
    for r in ros:
        if r.get("ok", "True") != "True":
            lines.append(f"| {r['setting']} | {r['run']} | | failed | | | | | |")
            continue
        f = {k: float(v) for k, v in r.items() if k not in ("setting", "send_order", "ok")
             and v not in ("", "nan") and re.match(r"^-?[0-9.e+-]+$", v)}
        lines.append(
            f"| {r['setting']} | {r['run']} | {f['steal_percent']:.1f} % | "
            f"{f['relay_p50_us']:.0f} / {f['relay_p99_us']:.0f} | "
            f"{f['follower_measurement_p50_us']:.0f} / {f['follower_measurement_p99_us']:.0f} | "
            f"{f['added_p50_percent']:+.0f} % | {f['follower_measurement_missed_percent']:.3f} / "
            f"{f['follower_measurement_late_percent']:.3f} % | "
            f"{f['follower_timer_missed_percent']:.3f} / {f['follower_timer_late_percent']:.3f} % | "
            f"{f['probe_skipped_percent']:.3f} % |")
    lines.append("")
    return lines


def summary_table(step_rows, run_sampled, solvers, ros, scale, reps, today):
    one = step_rows[0]
    three = step_rows[2]
    rows = ["| what | measured | target |", "|---|---|---|"]
    for row, target in ((one, "≤ 0.25 µs"), (step_rows[1], ""), (three, "≤ 1 µs")):
        i, o = row["inside"], row["outside"]
        rows.append(
            f"| one control step, {row['axes']}-D (inside / on the bound) | {i['ns']:.0f} / "
            f"{o['ns']:.0f} ns; {i['allocations']:.6f} / {o['allocations']:.6f} heap allocations per step; "
            f"{i['flops']:.0f} / {o['flops']:.0f} flops = {i['cycles_per_flop']:.2f} / "
            f"{o['cycles_per_flop']:.2f} cycles per flop; {i['instructions']:.0f} / "
            f"{o['instructions']:.0f} instructions (callgrind) | {target}"
            f"{', 0 allocations' if target else ''} |")
    for c in solvers["comparisons"]:
        rows.append(f"| cf_sim vs {c['lsoda']} (error {c['lsoda_error']:.0e} m), whole processes "
                    f"| {c['speedup']:,.0f}x faster with {c['cf_sim']} (error "
                    f"{c['cf_sim_error']:.0e} m) | ≥ 300x at equal or better accuracy |")
    sampled = [r for r in solvers["rows"] if r["kind"] == "cf_sim sampled"]
    if solvers["comparisons"]:
        slowest = min(solvers["comparisons"], key=lambda c: c["cf_sim_real_time_factor"])
        fastest = max(solvers["comparisons"], key=lambda c: c["cf_sim_real_time_factor"])
        rows.append(f"| cf_sim, 60 s of Run 2 as a whole process, in the configurations that "
                    f"match LSODA above | {slowest['cf_sim_real_time_factor']:,.0f}x "
                    f"({slowest['cf_sim']}) to {fastest['cf_sim_real_time_factor']:,.0f}x "
                    f"({fastest['cf_sim']}) real time; the sampled controller at 1 kHz: "
                    f"{sampled[0]['real_time_factor']:,.0f}x "
                    f"({60e9 / nanoseconds(run_sampled):,.0f}x in process) | ≥ 10,000x |")
    if ros:
        for setting, m in sorted(ros_rows(ros).items()):
            rows.append(
                f"| ROS follower at 1 kHz, 60 s ({setting}; median steal "
                f"{m['steal_percent']:.1f} %): missed / late periods | timer: "
                f"{m['timer_missed_percent']:.3f} / {m['timer_late_percent']:.3f} %; "
                f"measurement-triggered: {m['measurement_missed_percent']:.3f} / "
                f"{m['measurement_late_percent']:.3f} % | ≤ 0.1 % |")
            rows.append(
                f"| latency measurement → command, p50 / p99 ({setting}) | relay "
                f"{m['relay_p50_us']:.0f} / {m['relay_p99_us']:.0f} µs; follower "
                f"(measurement-triggered) {m['measurement_p50_us']:.0f} / "
                f"{m['measurement_p99_us']:.0f} µs ({m['added_p50_percent']:+.0f} % at p50); "
                f"follower (timer) {m['timer_p50_us']:.0f} / {m['timer_p99_us']:.0f} µs | "
                "< 20 % added to the relay |")
    if scale:
        rows.append(f"| platoon at 100 Hz on real time | largest N: {scale['processes'][0]} "
                    f"processes, {scale['nodelets'][0]} nodelets; CPU per follower "
                    f"{scale['processes'][1]:.1f} % / {scale['nodelets'][1]:.1f} % of a core | — |")
    return (f"Generated by `bash experiments/performance/run.sh` on {today} (medians of {reps} "
            "repetitions; every figure and its method in `doc/performance.md`):\n\n"
            + "\n".join(rows) + "\n")


if __name__ == "__main__":
    sys.exit(main())
