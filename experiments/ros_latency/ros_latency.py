#!/usr/bin/python3
"""Latency of the follower pipeline (run by experiments/ros_latency/run.sh, which sets up ROS).

`run` launches experiments/probes/latency.launch RUNS times per setting, each on its own master
(roslaunch -p PORT), and keeps the probe's JSON of each run; the settings are the machine as it
is ("as is") and with one nice-19 busy loop per core ("keep-awake": on this Firecracker VM an
idle core halts and wakes late, which delays timers and message deliveries), with --realtime
also every node under SCHED_FIFO with the cores kept awake ("keep-awake, SCHED_FIFO": probe,
relay and both followers alike, through the launch's launch_prefix), and with --follower-thread
the followers' control tick on their real-time thread with the cores kept awake
("keep-awake, control thread": ~control_loop thread, ~control_priority 80, ~lock_memory true;
probe and relay as in keep-awake). Then it writes the raw per-run figures to CSV and prints a
Markdown table of medians over the runs of each setting.

Usage: ros_latency.py --runs N --duration S --rate HZ --keep-awake none|both|all [--realtime]
                      [--follower-thread] [--only SETTING[,SETTING...]]
                      --csv doc/ros_latency.csv --port 11421 --work DIR
  --keep-awake none: as is only; all: keep-awake only; both: as is, then keep-awake.
  --only: exactly these settings (of as-is, keep-awake, realtime, follower-thread), in the
          order given, whatever --keep-awake, --realtime and --follower-thread say.
"""

import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "experiments", "common"))
from process_control import start_spinners, stop  # noqa: E402 (from experiments/common/)
LAUNCH = os.path.join(ROOT, "test", "performance", "latency.launch")
STREAMS = ("relay", "follower_measurement", "follower_timer")
FOLLOWERS = ("follower_measurement", "follower_timer")
TARGET_PERIODS_PERCENT = 0.1  # missed or late periods, at most
TARGET_ADDED_PERCENT = 20.0  # latency the measurement-triggered follower adds to the relay's


REALTIME_PRIORITY = 50  # SCHED_FIFO priority of every node in the realtime setting
FOLLOWER_THREAD_PRIORITY = 80  # ~control_priority of the followers in the follower-thread setting

# The settings: (key for --only, name in the table and CSV, cores kept awake, every node under
# chrt -f REALTIME_PRIORITY, followers on ~control_loop thread).
SETTINGS = (
    ("as-is", "as is", False, False, False),
    ("keep-awake", "keep-awake", True, False, False),
    ("realtime", "keep-awake, SCHED_FIFO", True, True, False),
    ("follower-thread", "keep-awake, control thread", True, False, True),
)


def log(*words):
    print("[ros_latency]", *words, file=sys.stderr, flush=True)


def cpu_times():
    """(total, steal) jiffies of all cores, from /proc/stat."""
    with open("/proc/stat") as f:
        fields = [int(x) for x in f.readline().split()[1:]]
    return sum(fields[:8]), fields[7] if len(fields) > 7 else 0


def loadavg():
    with open("/proc/loadavg") as f:
        return float(f.read().split()[0])


def run_one(args, setting, index, realtime=False, follower_thread=False):
    """One launch; returns the CSV row (ok False when the probe wrote nothing usable)."""
    tag = "%s_%d" % (setting.replace(", ", "_").replace(" ", "_").replace("-", "_"), index)
    output = os.path.join(args.work, tag + ".json")
    launch_log = os.path.join(args.work, tag + ".log")
    if os.path.exists(output):
        os.remove(output)
    env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % args.port,
               ROS_LOG_DIR=os.path.join(args.work, "ros_logs"))
    command = ["roslaunch", "-p", str(args.port), LAUNCH, "duration:=%g" % args.duration,
               "rate:=%g" % args.rate, "control_rate:=%g" % args.rate, "output:=%s" % output]
    if realtime:
        command.append("launch_prefix:=chrt -f %d" % REALTIME_PRIORITY)
    if follower_thread:
        command += ["control_loop:=thread", "control_priority:=%d" % FOLLOWER_THREAD_PRIORITY,
                    "lock_memory:=true"]
    row = {"setting": setting, "run": index, "duration_s": args.duration, "rate_hz": args.rate,
           "load1_before": loadavg(), "ok": False}
    total0, steal0 = cpu_times()
    started = time.time()
    with open(launch_log, "w") as out:
        launch = subprocess.Popen(command, stdout=out, stderr=subprocess.STDOUT, env=env,
                                  start_new_session=True)
        try:
            launch.wait(timeout=args.duration + 180.0)
        except subprocess.TimeoutExpired:
            log("%s run %d: launch still running after %.0f s; stopping it"
                % (setting, index, args.duration + 180.0))
        finally:
            stop(launch)
    total1, steal1 = cpu_times()
    row["wall_s"] = round(time.time() - started, 1)
    row["steal_percent"] = round(100.0 * (steal1 - steal0) / max(1, total1 - total0), 2)
    if not os.path.exists(output):
        log("%s run %d: the probe wrote no %s (launch log %s)" % (setting, index, output,
                                                                 launch_log))
        return row
    with open(output) as f:
        result = json.load(f)
    row["probe_published"] = result["probe"]["published"]
    row["probe_skipped_periods"] = result["probe"]["skipped_periods"]
    row["probe_skipped_percent"] = round(
        100.0 * result["probe"]["skipped_periods"] / result["expected_periods"], 3)
    row["probe_publish_delay_p99_us"] = result["probe"]["publish_delay_us"]["p99"]
    # The order in which the probe's publish() writes to the relay and the followers.
    row["send_order"] = " > ".join(result["probe"].get("send_order", []))
    ok = True
    for name in STREAMS:
        s = result["streams"][name]
        row[name + "_received"] = s["received"]
        for q in ("p50", "p90", "p99", "max"):
            row["%s_%s_us" % (name, q)] = s["latency_us"][q]
        ok = ok and s["received"] > 0
    for name in FOLLOWERS:
        f = result["followers"][name]
        for key in ("ticks", "missed_periods", "late_periods", "ticks_percent", "missed_percent",
                    "late_percent"):
            row["%s_%s" % (name, key)] = f[key]
        row[name + "_tick_delay_p50_us"] = f["tick_delay_us"]["p50"]
        row[name + "_tick_delay_p99_us"] = f["tick_delay_us"]["p99"]
        ok = ok and f["statuses"] > 0
    if ok:
        for q in ("p50", "p99"):
            row["added_%s_percent" % q] = round(
                100.0 * (row["follower_measurement_%s_us" % q] / row["relay_%s_us" % q] - 1.0), 2)
    row["ok"] = ok
    return row


def chosen_settings(args):
    """The SETTINGS entries to run, in order."""
    if args.only:
        return [next(s for s in SETTINGS if s[0] == key) for key in args.only]
    keys = {"none": ["as-is"], "all": ["keep-awake"], "both": ["as-is", "keep-awake"]}[
        args.keep_awake]
    keys += ["realtime"] * args.realtime + ["follower-thread"] * args.follower_thread
    return [s for key in keys for s in SETTINGS if s[0] == key]


def run(args):
    os.makedirs(args.work, exist_ok=True)
    rows = []
    for _, setting, awake, realtime, follower_thread in chosen_settings(args):
        spinners = start_spinners() if awake else []
        try:
            for index in range(1, args.runs + 1):
                log("%s, run %d of %d: %g s at %g Hz (load average %.2f)"
                    % (setting, index, args.runs, args.duration, args.rate, loadavg()))
                row = run_one(args, setting, index, realtime, follower_thread)
                rows.append(row)
                if row["ok"]:
                    log("  relay p50 %.0f / p99 %.0f us; measurement-triggered p50 %.0f / p99 %.0f "
                        "us (+%.1f %% / +%.1f %%); timer-triggered p50 %.0f / p99 %.0f us; "
                        "missed/late %% measurement %.3f/%.3f, timer %.3f/%.3f; steal %.1f %%; "
                        "sent to %s"
                        % (row["relay_p50_us"], row["relay_p99_us"],
                           row["follower_measurement_p50_us"], row["follower_measurement_p99_us"],
                           row["added_p50_percent"], row["added_p99_percent"],
                           row["follower_timer_p50_us"], row["follower_timer_p99_us"],
                           row["follower_measurement_missed_percent"],
                           row["follower_measurement_late_percent"],
                           row["follower_timer_missed_percent"],
                           row["follower_timer_late_percent"], row["steal_percent"],
                           row["send_order"]))
                else:
                    log("  run failed; see", args.work)
        finally:
            for spinner in spinners:
                stop(spinner, timeout=5.0)
    write_csv(rows, args.csv)
    print(table(rows, args))
    return 0 if rows and all(r["ok"] for r in rows) else 1


def write_csv(rows, path):
    os.makedirs(os.path.dirname(os.path.abspath(path)) or ".", exist_ok=True)
    keys = []
    for row in rows:
        keys += [k for k in row if k not in keys]
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=keys)
        writer.writeheader()
        writer.writerows(rows)
    log("raw per-run figures in", path)


def median(rows, key):
    values = [r[key] for r in rows if r.get(key) is not None]
    return statistics.median(values) if values else float("nan")


def table(rows, args):
    lines = [
        "ROS pipeline latency, `experiments/ros_latency/run.sh --runs %d --duration %g` (%g Hz, "
        "paper_run2, real time): medians over the runs of each setting." % (
            args.runs, args.duration, args.rate),
        "",
        "| setting | runs ok | relay p50 / p99 (µs) | measurement-triggered follower p50 / p99 "
        "(µs) | added over relay p50 / p99 (%) | timer follower p50 / p99 (µs) | "
        "missed / late periods, measurement-triggered (%) | missed / late periods, timer (%) | "
        "probe: skipped periods (%) | load average, steal (%) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    verdicts = []
    for setting in dict.fromkeys(r["setting"] for r in rows):
        ok = [r for r in rows if r["setting"] == setting and r["ok"]]
        n = len([r for r in rows if r["setting"] == setting])
        if not ok:
            lines.append("| %s | 0 of %d | | | | | | | | |" % (setting, n))
            continue
        m = {k: median(ok, k) for k in ok[0]
             if isinstance(ok[0][k], (int, float)) and not isinstance(ok[0][k], bool)}
        lines.append(
            "| %s | %d of %d | %.0f / %.0f | %.0f / %.0f | %+.1f / %+.1f | %.0f / %.0f | "
            "%.3f / %.3f | %.3f / %.3f | %.3f | %.2f, %.1f |" % (
                setting, len(ok), n, m["relay_p50_us"], m["relay_p99_us"],
                m["follower_measurement_p50_us"], m["follower_measurement_p99_us"],
                m["added_p50_percent"], m["added_p99_percent"],
                m["follower_timer_p50_us"], m["follower_timer_p99_us"],
                m["follower_measurement_missed_percent"], m["follower_measurement_late_percent"],
                m["follower_timer_missed_percent"], m["follower_timer_late_percent"],
                m["probe_skipped_percent"], m["load1_before"], m["steal_percent"]))
        periods = max(m["follower_%s_%s_percent" % (f, k)]
                      for f in ("measurement", "timer") for k in ("missed", "late"))
        verdicts.append(
            "%s: added latency p50 %+.1f %% (target < %g %%: %s); worst missed/late periods "
            "%.3f %% (target <= %g %%: %s)" % (
                setting, m["added_p50_percent"], TARGET_ADDED_PERCENT,
                "met" if m["added_p50_percent"] < TARGET_ADDED_PERCENT else "not met", periods,
                TARGET_PERIODS_PERCENT, "met" if periods <= TARGET_PERIODS_PERCENT else "not met"))
    lines += [
        "",
        "Latency: from a measurement's stamp (ros::Time::now() just before publish) to the "
        "probe's receipt of the relay's copy or of the command answering it (the timer follower: "
        "every command of a tick in the window, against the measurement the tick used). Missed: "
        "periods without a step (measurement-triggered: without a measurement, so the probe's "
        "own skipped periods count too); late: steps started more than half a period after they "
        "were due (measurement-triggered: after the measurement's stamp). Percentages of "
        "duration x rate. The probe writes each measurement to the relay and the followers one "
        "after the other, in the order they connected (CSV column send_order), and the three "
        "share two cores: the order alone moves a receiver's latency by tens of µs. The load "
        "average is the 1-minute one before each run (with keep-awake it includes the busy "
        "loops, one per core).",
        ""]
    lines += ["- " + v for v in verdicts]
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--duration", type=float, default=60.0)
    parser.add_argument("--rate", type=float, default=1000.0)
    parser.add_argument("--keep-awake", choices=("none", "both", "all"), default="both")
    parser.add_argument("--realtime", action="store_true",
                        help="also run every node under SCHED_FIFO (chrt -f %d), cores kept awake"
                        % REALTIME_PRIORITY)
    parser.add_argument("--follower-thread", action="store_true",
                        help="also run the followers on their real-time control thread "
                        "(~control_loop thread, ~control_priority %d, ~lock_memory true), cores "
                        "kept awake" % FOLLOWER_THREAD_PRIORITY)
    parser.add_argument("--only", type=lambda text: text.split(","), default=None,
                        metavar="SETTING[,SETTING...]",
                        help="exactly these settings: " + ", ".join(s[0] for s in SETTINGS))
    parser.add_argument("--csv", default=os.path.join(ROOT, "doc", "ros_latency.csv"))
    parser.add_argument("--port", type=int, default=11421)
    parser.add_argument("--work", required=True)
    args = parser.parse_args()
    if args.runs < 1 or args.duration <= 0 or args.rate <= 0:
        parser.error("--runs >= 1, --duration > 0 and --rate > 0")
    unknown = [key for key in args.only or [] if key not in [s[0] for s in SETTINGS]]
    if unknown or args.only == [""]:
        parser.error("--only: unknown setting(s) %s; choose from %s"
                     % (", ".join(unknown) or "''", ", ".join(s[0] for s in SETTINGS)))
    return run(args)


if __name__ == "__main__":
    sys.exit(main())
