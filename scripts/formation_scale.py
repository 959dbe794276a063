#!/usr/bin/python3
"""How many followers formation.launch holds at its control rate, as processes and as nodelets.

For each mode (processes: one follower_node each; nodelets: FollowerNodelets in one manager) and
each N, starts

  roslaunch --port PORT projection_collision_avoidance formation.launch followers:=N
    nodelets:=false|true scenario:=config/scenarios/paper_run2.yaml control_rate:=RATE
    topology:=star shape:=line sim_time:=false rviz:=false

(real ROS time = wall time), waits until every follower publishes its status, records
/follower_*/status with `rosbag record` (C++) for a window of W wall seconds while reading the
CPU time (utime + stime of all threads, /proc/<pid>/stat) of every node at its start and end,
stops the launch (SIGINT) and checks that none of its processes remain, then reads the bag:

  rate   per follower: status messages stamped in the window / W
  late   per follower: fraction of consecutive status stamps more than 1.5 periods apart
  holds  every follower's rate >= 99 % of RATE and every late fraction <= 1 %

Larger sizes of a mode are skipped once a size fails badly (a follower below 90 % of RATE, or
not every follower publishing). Writes one JSON line per run to RESULTS (appends), then the
table OUT.md and the figure OUT.png from all of RESULTS.

Usage (scripts/formation_scale.sh sets up the environment):
  formation_scale.py run --results R.jsonl [--sizes 1 2 4 ...] [--modes processes nodelets]
                         [--window 20] [--rate 100] [--port 11411]
  formation_scale.py report --results R.jsonl --md doc/formation_scale.md --png doc/...png
                            [--command "..."]
"""

import argparse
import json
import os
import re
import signal
import struct
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENARIO = os.path.join(ROOT, "config", "scenarios", "paper_run2.yaml")
CLK_TCK = os.sysconf("SC_CLK_TCK")
HOLD_RATE = 0.99  # of the control rate
HOLD_LATE = 0.01  # late-tick fraction
BAD_RATE = 0.90  # below this fraction of the control rate a size fails badly
LEFTOVER_PATTERN = "follower_node|nodelet|plant_node|leader_node|rosmaster|roslaunch"

# A status message that the waiter needs from each follower before the window starts.
WAITER = r"""
import sys, time, rospy
n, timeout = int(sys.argv[1]), float(sys.argv[2])
rospy.init_node("formation_scale_wait", anonymous=True, disable_signals=True)
seen, subs = set(), {}
def heard(i):
    def cb(_):
        seen.add(i)
    return cb
for i in range(1, n + 1):
    subs[i] = rospy.Subscriber("/follower_%d/status" % i, rospy.AnyMsg, heard(i), queue_size=1)
deadline = time.time() + timeout
while time.time() < deadline and len(seen) < n:
    for i in list(subs):
        if i in seen:
            subs.pop(i).unregister()
    time.sleep(0.1)
print(len(seen))
sys.exit(0 if len(seen) == n else 1)
"""


def log(*args):
    print("[formation_scale]", *args, flush=True)


def cpu_seconds(pid):
    """utime + stime of the whole process (all threads), or None once it is gone."""
    try:
        with open("/proc/%d/stat" % pid) as f:
            fields = f.read().rsplit(")", 1)[1].split()
    except OSError:
        return None
    return (int(fields[11]) + int(fields[12])) / CLK_TCK  # fields 14 and 15 of stat


def machine_busy():
    """(busy, total) jiffies of all cores, from /proc/stat."""
    with open("/proc/stat") as f:
        values = [int(v) for v in f.readline().split()[1:]]
    idle = values[3] + values[4]  # idle + iowait
    total = sum(values[:8])
    return total - idle, total


def loadavg():
    with open("/proc/loadavg") as f:
        return [float(v) for v in f.read().split()[:3]]


def cmdline(pid):
    try:
        with open("/proc/%d/cmdline" % pid, "rb") as f:
            return f.read().replace(b"\0", b" ").decode(errors="replace").strip()
    except OSError:
        return ""


def children(pid):
    try:
        with open("/proc/%d/task/%d/children" % (pid, pid)) as f:
            return [int(p) for p in f.read().split()]
    except OSError:
        return []


def group_members(pgid):
    out = subprocess.run(["pgrep", "-g", str(pgid)], capture_output=True, text=True).stdout
    return [int(p) for p in out.split()]


def classify(pid):
    """The role of one of roslaunch's children: plant, leader, follower, manager, loader, master."""
    cmd = cmdline(pid)
    if "plant_node" in cmd:
        return "plant"
    if "leader_node" in cmd:
        return "leader"
    if "follower_node" in cmd:
        return "follower"
    if "nodelet" in cmd and " manager" in cmd:
        return "manager"
    if "nodelet" in cmd and " load " in cmd:
        return "loader"
    if "rosmaster" in cmd:
        return "master"
    if "rosout" in cmd:
        return "rosout"
    return "other"


def stop(proc, name, timeout=40.0):
    """SIGINT, then SIGTERM, then SIGKILL to one process that this script started."""
    for sig, wait in ((signal.SIGINT, timeout), (signal.SIGTERM, 10.0), (signal.SIGKILL, 5.0)):
        if proc.poll() is not None:
            return
        proc.send_signal(sig)
        try:
            proc.wait(wait)
            return
        except subprocess.TimeoutExpired:
            log("%s did not end after %s" % (name, signal.Signals(sig).name))


def read_bag(path, n, t0, t1, period):
    """Per follower: status stamps in [t0, t1) from the raw messages' headers."""
    import rosbag  # noqa: E402 (only needed here)

    stamps = {i: [] for i in range(1, n + 1)}
    topic_index = {"/follower_%d/status" % i: i for i in range(1, n + 1)}
    with rosbag.Bag(path) as bag:
        for topic, raw, _ in bag.read_messages(raw=True):
            data = raw[1]
            _, secs, nsecs = struct.unpack_from("<III", data, 0)  # std_msgs/Header first
            stamps[topic_index[topic]].append(secs + nsecs * 1e-9)
    window = t1 - t0
    rates, late, max_gap = {}, {}, {}
    for i, s in stamps.items():
        s = sorted(x for x in s if t0 <= x < t1)
        gaps = [b - a for a, b in zip(s, s[1:])]
        rates[i] = len(s) / window
        late[i] = (sum(g > 1.5 * period for g in gaps) / len(gaps)) if gaps else 1.0
        max_gap[i] = max(gaps) if gaps else window
    return rates, late, max_gap


def run_one(args, mode, n, work):
    """One launch of N followers in MODE: returns the result dict."""
    env = dict(os.environ)
    env["ROS_MASTER_URI"] = "http://localhost:%d" % args.port
    env["ROS_LOG_DIR"] = os.path.join(work, "log")
    launch_log = os.path.join(work, "launch_%s_%d.log" % (mode, n))
    command = ["roslaunch", "--port", str(args.port), "projection_collision_avoidance",
               "formation.launch", "followers:=%d" % n,
               "nodelets:=%s" % ("true" if mode == "nodelets" else "false"),
               "scenario:=%s" % SCENARIO, "control_rate:=%g" % args.rate, "topology:=star",
               "shape:=line", "sim_time:=false", "rviz:=false"]
    result = {"mode": mode, "n": n, "rate": args.rate, "window": args.window, "ok": False}
    started = time.time()
    with open(launch_log, "w") as out:
        launch = subprocess.Popen(command, stdout=out, stderr=subprocess.STDOUT, env=env,
                                  start_new_session=True)
    recorder = None
    try:
        # Every follower publishing its status (bounded).
        timeout = 60.0 + 2.0 * n
        waiter = subprocess.run([sys.executable, "-c", WAITER, str(n), str(timeout)], env=env,
                                capture_output=True, text=True)
        heard = int((waiter.stdout.strip().splitlines() or ["0"])[-1])
        result["startup_s"] = time.time() - started
        result["publishing"] = heard
        if heard < n or launch.poll() is not None:
            log("%s N=%d: only %d of %d followers publish (launch %s)"
                % (mode, n, heard, n, "ended" if launch.poll() is not None else "running"))
            return result
        # The nodes, from roslaunch's children.
        roles = {}
        for pid in children(launch.pid):
            roles.setdefault(classify(pid), []).append(pid)
        result["processes"] = {k: len(v) for k, v in roles.items()}
        # The recorder (C++), then the window once it has subscribed.
        bag = os.path.join(work, "status_%s_%d.bag" % (mode, n))
        topics = ["/follower_%d/status" % i for i in range(1, n + 1)]
        # rosrun execs the C++ recorder itself (`rosbag record` would be a Python parent of it).
        recorder = subprocess.Popen(["rosrun", "rosbag", "record", "-b", "512",
                                     "-O", bag, "__name:=formation_scale_record"] + topics,
                                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env,
                                    start_new_session=True)
        time.sleep(max(3.0, 1.0 + 0.1 * n))  # its subscriptions connected
        watched = {pid: role for role, pids in roles.items() for pid in pids}
        watched[recorder.pid] = "recorder"
        cpu0 = {pid: cpu_seconds(pid) for pid in watched}
        busy0 = machine_busy()
        load0 = loadavg()
        t0 = time.time()
        time.sleep(args.window)
        t1 = time.time()
        cpu1 = {pid: cpu_seconds(pid) for pid in watched}
        busy1 = machine_busy()
        load1 = loadavg()
        window = t1 - t0
        time.sleep(1.0)  # the window's last messages into the bag
        stop(recorder, "rosbag record")
        died = [pid for pid in watched if cpu1[pid] is None or cpu0[pid] is None]
        if died:
            log("%s N=%d: processes ended during the window: %s"
                % (mode, n, ", ".join("%d (%s)" % (p, watched[p]) for p in died)))
        cpu = {}
        for pid, role in watched.items():
            if cpu0[pid] is not None and cpu1[pid] is not None:
                cpu[role] = cpu.get(role, 0.0) + (cpu1[pid] - cpu0[pid]) / window * 100.0
        result.update({
            "window_s": window,
            "cpu_percent": cpu,
            "machine_busy_percent": 100.0 * (busy1[0] - busy0[0]) / max(1, busy1[1] - busy0[1]),
            "cores": os.cpu_count(),
            "loadavg_start": load0,
            "loadavg_end": load1,
            "died": len(died),
        })
        stop(launch, "roslaunch")
        rates, late, max_gap = read_bag(bag, n, t0, t1, 1.0 / args.rate)
        result.update({
            "rates": [rates[i] for i in range(1, n + 1)],
            "late": [late[i] for i in range(1, n + 1)],
            "max_gap_s": [max_gap[i] for i in range(1, n + 1)],
            "ok": True,
        })
        os.remove(bag)
        return result
    finally:
        if recorder is not None:
            stop(recorder, "rosbag record")
        stop(launch, "roslaunch")
        # Nothing of this launch may remain: its process group, then the usual names.
        time.sleep(0.5)
        rest = [p for p in group_members(launch.pid) if p != os.getpid()]
        if rest:
            log("%s N=%d: left over after roslaunch ended: %s"
                % (mode, n, "; ".join("%d %s" % (p, cmdline(p)[:80]) for p in rest)))
            for p in rest:
                try:
                    os.kill(p, signal.SIGKILL)
                except OSError:
                    pass
        result["leftover"] = len(rest)
        others = subprocess.run(["pgrep", "-af", LEFTOVER_PATTERN], capture_output=True,
                                text=True).stdout.strip()
        others = [line for line in others.splitlines()
                  if "pgrep" not in line and int(line.split()[0]) != os.getpid()]
        if others:
            log("%s N=%d: still running (not this launch's process group):\n  %s"
                % (mode, n, "\n  ".join(others)))
        result["foreign_processes"] = others
        # What the launch said: deaths, errors, warnings.
        with open(launch_log, errors="replace") as f:
            text = f.read()
        result["log_died"] = len(re.findall(r"process has died", text))
        result["log_errors"] = len(re.findall(r"\[ERROR\]|\[FATAL\]", text))
        result["log_warnings"] = len(re.findall(r"\[ WARN\]", text))
        result["log_error_lines"] = [line for line in text.splitlines()
                                     if re.search(r"process has died|\[ERROR\]|\[FATAL\]",
                                                  line)][:5]
        result["wall_s"] = time.time() - started


def summarise(r):
    """Derived numbers of one result."""
    if not r.get("ok"):
        return None
    cpu = r["cpu_percent"]
    follower = cpu.get("follower", 0.0) + cpu.get("manager", 0.0) + cpu.get("loader", 0.0)
    min_rate = min(r["rates"])
    worst_late = max(r["late"])
    return {
        "min_rate": min_rate,
        "worst_late": worst_late,
        "max_gap_ms": 1000.0 * max(r["max_gap_s"]),
        "follower_cpu": follower,
        "loader_cpu": cpu.get("loader", 0.0),
        "per_follower": follower / r["n"],
        "plant_cpu": cpu.get("plant", 0.0),
        "leader_cpu": cpu.get("leader", 0.0),
        "recorder_cpu": cpu.get("recorder", 0.0),
        "holds": min_rate >= HOLD_RATE * r["rate"] and worst_late <= HOLD_LATE,
        "bad": min_rate < BAD_RATE * r["rate"],
    }


def command_run(args):
    os.makedirs(os.path.dirname(os.path.abspath(args.results)) or ".", exist_ok=True)
    work = tempfile.mkdtemp(prefix="formation_scale_")
    log("work directory (launch logs, ROS logs):", work)
    for mode in args.modes:
        for n in args.sizes:
            log("%s N=%d: starting (load average %s)" % (mode, n, loadavg()))
            r = run_one(args, mode, n, work)
            with open(args.results, "a") as f:
                f.write(json.dumps(r) + "\n")
            s = summarise(r)
            if s is None:
                log("%s N=%d: failed (%d of %d publishing); larger sizes skipped"
                    % (mode, n, r.get("publishing", 0), n))
                break
            log("%s N=%d: min rate %.2f Hz, worst late %.2f %%, follower CPU %.1f %% "
                "(%.2f %% each), plant %.1f %%, machine busy %.0f %%, holds %s, %.0f s"
                % (mode, n, s["min_rate"], 100 * s["worst_late"], s["follower_cpu"],
                   s["per_follower"], s["plant_cpu"], r["machine_busy_percent"],
                   "yes" if s["holds"] else "no", r["wall_s"]))
            if s["bad"]:
                log("%s: N=%d fails badly; larger sizes skipped" % (mode, n))
                break
    log("ROS and launch logs kept in", work)


def load_results(path):
    results = []
    with open(path) as f:
        for line in f:
            if line.strip():
                results.append(json.loads(line))
    return results


def command_report(args):
    results = load_results(args.results)
    modes = [m for m in ("processes", "nodelets") if any(r["mode"] == m for r in results)]
    lines = [
        "# Formation scale: followers holding their control rate",
        "",
        "Generated by `scripts/formation_scale.sh` (with `scripts/formation_scale.py`). "
        "Each row is one launch of",
        "",
        "```",
        "roslaunch --port %d projection_collision_avoidance formation.launch followers:=N "
        "nodelets:=false|true \\" % args.port,
        "  scenario:=config/scenarios/paper_run2.yaml control_rate:=%g topology:=star "
        "shape:=line sim_time:=false rviz:=false" % results[0]["rate"],
        "```",
        "",
        "measured, once every follower published its status, over a window of %g wall s: "
        "the status messages of every follower recorded with `rosbag record` (rate = messages "
        "stamped in the window / window; late = consecutive stamps more than 1.5 periods "
        "apart), and the CPU time (utime + stime of all threads from `/proc/<pid>/stat`) of "
        "every node, in percent of one core. Follower CPU is that of the follower_node "
        "processes, or with nodelets that of the manager plus its `nodelet load` processes "
        "(column loaders). *Holds* = every follower at >= %g %% of %g Hz and at most %g %% "
        "late ticks." % (results[0]["window"], 100 * HOLD_RATE, results[0]["rate"],
                         100 * HOLD_LATE),
        "",
        "| mode | N | min follower rate (Hz) | worst late ticks (%) | longest gap (ms) "
        "| follower CPU (% of a core) | CPU per follower (%) | of which loaders (%) "
        "| plant CPU (%) | leader CPU (%) | machine busy (% of all cores) | load average "
        "| holds |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | --- "
        "| --- |",
    ]
    largest = {}
    for mode in modes:
        for r in sorted((r for r in results if r["mode"] == mode), key=lambda r: r["n"]):
            s = summarise(r)
            if s is None:
                lines.append("| %s | %d | (%d of %d followers published within %.0f s) "
                             "| | | | | | | | | | no |"
                             % (mode, r["n"], r.get("publishing", 0), r["n"],
                                r.get("startup_s", 0)))
                continue
            if s["holds"]:
                largest[mode] = max(largest.get(mode, 0), r["n"])
            lines.append(
                "| %s | %d | %.2f | %.2f | %.1f | %.1f | %.2f | %s | %.1f | %.1f | %.0f "
                "| %.2f | %s |"
                % (mode, r["n"], s["min_rate"], 100 * s["worst_late"], s["max_gap_ms"],
                   s["follower_cpu"], s["per_follower"],
                   "%.1f" % s["loader_cpu"] if mode == "nodelets" else "",
                   s["plant_cpu"], s["leader_cpu"], r["machine_busy_percent"],
                   r["loadavg_start"][0], "yes" if s["holds"] else "**no**"))
    lines.append("")
    for mode in modes:
        tried = sorted(r["n"] for r in results if r["mode"] == mode)
        lines.append("- Largest N that holds %g Hz with %s: **%s** (sizes run: %s)."
                     % (results[0]["rate"], mode, largest.get(mode, "none"),
                        ", ".join(str(n) for n in tried)))
    loads = [r["loadavg_start"][0] for r in results if "loadavg_start" in r]
    busy = [r["machine_busy_percent"] for r in results if "machine_busy_percent" in r]
    if loads:
        lines.append("- Machine: %d cores; 1-min load average at the windows' starts %.2f to "
                     "%.2f; all cores busy %.0f %% to %.0f %% during the windows (this "
                     "formation included)." % (results[0].get("cores", 0), min(loads),
                                                max(loads), min(busy), max(busy)))
    rec = [summarise(r)["recorder_cpu"] for r in results if summarise(r)]
    if rec:
        lines.append("- `rosbag record` itself took %.1f %% to %.1f %% of a core." %
                     (min(rec), max(rec)))
    problems = []
    for r in results:
        for key, what in (("log_died", "process deaths"), ("log_errors", "ERROR lines"),
                          ("leftover", "processes left over")):
            if r.get(key):
                problems.append("%s N=%d: %d %s" % (r["mode"], r["n"], r[key], what))
    lines.append("- Launch logs: " + ("; ".join(problems) if problems else
                                      "no process deaths, no ERROR lines, nothing left over."))
    if args.command:
        lines.append("")
        lines.append("Command: `%s`%s." % (args.command, " (%s)" % args.wall if args.wall
                                           else ""))
    lines.append("")
    lines.append("![CPU and rate vs N](formation_scale.png)")
    with open(args.md, "w") as f:
        f.write("\n".join(lines) + "\n")

    import matplotlib  # noqa: E402

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: E402

    fig, (ax_cpu, ax_rate) = plt.subplots(1, 2, figsize=(10, 4))
    styles = {"processes": ("tab:blue", "o"), "nodelets": ("tab:orange", "s")}
    for mode in modes:
        rows = sorted((r for r in results if r["mode"] == mode and summarise(r)),
                      key=lambda r: r["n"])
        if not rows:
            continue
        color, marker = styles[mode]
        ns = [r["n"] for r in rows]
        sums = [summarise(r) for r in rows]
        ax_cpu.plot(ns, [s["follower_cpu"] for s in sums], marker=marker, color=color,
                    label="%s: followers, total" % mode)
        ax_cpu.plot(ns, [s["per_follower"] for s in sums], marker=marker, color=color,
                    linestyle="--", label="%s: per follower" % mode)
        ax_cpu.plot(ns, [s["plant_cpu"] for s in sums], marker=marker, color=color,
                    linestyle=":", label="%s: plant" % mode)
        ax_rate.plot(ns, [s["min_rate"] for s in sums], marker=marker, color=color,
                     label="%s: slowest follower" % mode)
    rate = results[0]["rate"]
    ax_cpu.set_xscale("log", base=2)
    ax_cpu.set_yscale("log")
    ax_cpu.set_xlabel("followers N")
    ax_cpu.set_ylabel("CPU (% of one core)")
    ax_cpu.axhline(100.0 * results[0].get("cores", 2), color="grey", linewidth=0.8)
    ax_cpu.set_title("CPU over the window")
    ax_cpu.grid(True, which="both", alpha=0.3)
    ax_cpu.legend(fontsize=7)
    ax_rate.axhline(HOLD_RATE * rate, color="grey", linestyle="--", linewidth=0.8,
                    label="%g %% of %g Hz" % (100 * HOLD_RATE, rate))
    ax_rate.set_xscale("log", base=2)
    ax_rate.set_xlabel("followers N")
    ax_rate.set_ylabel("status rate of the slowest follower (Hz)")
    ax_rate.set_title("Achieved control rate (%g Hz asked)" % rate)
    ax_rate.grid(True, which="both", alpha=0.3)
    ax_rate.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(args.png, dpi=90)
    print("wrote %s and %s" % (args.md, args.png))


def interrupted(signum, frame):
    raise KeyboardInterrupt()


def main():
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = parser.add_subparsers(dest="command_name", required=True)
    run = sub.add_parser("run")
    run.add_argument("--results", required=True)
    run.add_argument("--sizes", type=int, nargs="+", default=[1, 2, 4, 8, 16, 32, 64])
    run.add_argument("--modes", nargs="+", default=["processes", "nodelets"],
                     choices=["processes", "nodelets"])
    run.add_argument("--window", type=float, default=20.0)
    run.add_argument("--rate", type=float, default=100.0)
    run.add_argument("--port", type=int, default=11411)
    report = sub.add_parser("report")
    report.add_argument("--results", required=True)
    report.add_argument("--md", required=True)
    report.add_argument("--png", required=True)
    report.add_argument("--port", type=int, default=11411)
    report.add_argument("--command", default="")
    report.add_argument("--wall", default="")
    args = parser.parse_args()
    # SIGTERM as SIGINT: the launches' clean-up (finally) runs.
    signal.signal(signal.SIGTERM, interrupted)
    if args.command_name == "run":
        command_run(args)
    else:
        command_report(args)


if __name__ == "__main__":
    main()
