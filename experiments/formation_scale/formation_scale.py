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

A size that fails badly (a follower below 90 % of RATE, or not every follower publishing) is run
a second time; larger sizes of that mode are skipped once it fails badly twice. With
--keep-awake yes (or both: a pass without, then one with) a nice-19 busy loop runs on every core,
so that the VM's cores never halt while idle: on a VM, resuming a halted core can delay a timer
by tens of milliseconds (the hypervisor counts it as steal time). Writes one JSON line per run to RESULTS (appends), then the
table OUT.md and the figure OUT.png from all of RESULTS.

Usage (experiments/formation_scale/run.sh sets up the environment):
  formation_scale.py run --results R.jsonl [--sizes 1 2 4 ...] [--modes processes nodelets]
                         [--window 20] [--rate 100] [--port 11411] [--keep-awake no|yes|both]
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

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "experiments", "common"))
from process_control import start_spinners  # noqa: E402 (from experiments/common/)
from process_control import stop as stop_process  # noqa: E402
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
    """(busy, steal, total) jiffies of all cores, from /proc/stat; busy excludes steal."""
    with open("/proc/stat") as f:
        values = [int(v) for v in f.readline().split()[1:]]
    idle = values[3] + values[4]  # idle + iowait
    steal = values[7]  # time the hypervisor ran something else while this VM wanted a core
    total = sum(values[:8])
    return total - idle - steal, steal, total


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
    """process_control.stop(), logging each signal @p name outlives."""
    stop_process(proc, timeout,
                 lambda signal_name: log("%s did not end after %s" % (name, signal_name)))


def cpu_share(cpu0, cpu1, watched, role, window):
    """Percent of one core used by the processes of ROLE over the window."""
    return sum((cpu1[p] - cpu0[p]) / window * 100.0 for p, r in watched.items()
               if r == role and cpu0[p] is not None and cpu1[p] is not None)


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


def run_one(args, mode, n, work, attempt, spinners):
    """One launch of N followers in MODE: returns the result dict."""
    env = dict(os.environ)
    env["ROS_MASTER_URI"] = "http://localhost:%d" % args.port
    env["ROS_LOG_DIR"] = os.path.join(work, "log")
    tag = "%s_%d_%s%d" % (mode, n, "awake_" if spinners else "", attempt)
    launch_log = os.path.join(work, "launch_%s.log" % tag)
    command = ["roslaunch", "--port", str(args.port), "projection_collision_avoidance",
               "formation.launch", "followers:=%d" % n,
               "nodelets:=%s" % ("true" if mode == "nodelets" else "false"),
               "scenario:=%s" % SCENARIO, "control_rate:=%g" % args.rate, "topology:=star",
               "shape:=line", "sim_time:=false", "rviz:=false"]
    result = {"mode": mode, "n": n, "rate": args.rate, "window": args.window, "ok": False,
              "attempt": attempt, "keep_awake": bool(spinners)}
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
        bag = os.path.join(work, "status_%s.bag" % tag)
        topics = ["/follower_%d/status" % i for i in range(1, n + 1)]
        # rosrun execs the C++ recorder itself (`rosbag record` would be a Python parent of it).
        recorder = subprocess.Popen(["rosrun", "rosbag", "record", "-b", "512",
                                     "-O", bag, "__name:=formation_scale_record"] + topics,
                                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env,
                                    start_new_session=True)
        time.sleep(max(3.0, 1.0 + 0.1 * n))  # its subscriptions connected
        watched = {pid: role for role, pids in roles.items() for pid in pids}
        watched[recorder.pid] = "recorder"
        for spinner in spinners:
            watched[spinner.pid] = "spinner"
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
            # All cores' busy share, less the spinners' (which only fill idle time).
            "machine_busy_percent": 100.0 * (busy1[0] - busy0[0]) / max(1, busy1[2] - busy0[2])
            - cpu_share(cpu0, cpu1, watched, "spinner", window) / os.cpu_count(),
            "steal_percent": 100.0 * (busy1[1] - busy0[1]) / max(1, busy1[2] - busy0[2]),
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
        if args.keep_bags:
            os.makedirs(args.keep_bags, exist_ok=True)
            os.replace(bag, os.path.join(args.keep_bags, os.path.basename(bag)))
            result["t0"], result["t1"] = t0, t1
        else:
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
        # A nodelet loader whose bond to the manager timed out exits, and the manager unloads
        # its follower.
        result["log_bond_broken"] = len(re.findall(r"Bond broken", text))
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
    passes = {"no": [False], "yes": [True], "both": [False, True]}[args.keep_awake]
    for awake in passes:
        spinners = start_spinners() if awake else []
        try:
            run_pass(args, work, spinners)
        finally:
            for spinner in spinners:
                stop(spinner, "spinner", timeout=5.0)
    log("ROS and launch logs kept in", work)


def run_pass(args, work, spinners):
    """Every mode and size, with the cores kept awake by SPINNERS or (none) left to idle."""
    what = "cores kept awake" if spinners else "cores left to idle"
    probe = timer_probe(args.rate, 5.0)
    probe["keep_awake"] = bool(spinners)
    log("%s: timer probe: %.2f ms median, %.1f ms p99, %.1f ms max late; steal %.0f %%"
        % (what, probe["p50_ms"], probe["p99_ms"], probe["max_ms"], probe["steal_percent"]))
    with open(args.results, "a") as f:
        f.write(json.dumps(probe) + "\n")
    for mode in args.modes:
        for n in args.sizes:
            bad = False
            # A size that fails badly gets a second try (unless no larger size would follow).
            for attempt in ((1, 2) if n != args.sizes[-1] else (1,)):
                log("%s, %s N=%d: starting (load average %s)" % (what, mode, n, loadavg()))
                r = run_one(args, mode, n, work, attempt, spinners)
                with open(args.results, "a") as f:
                    f.write(json.dumps(r) + "\n")
                s = summarise(r)
                if s is None:
                    log("%s N=%d: failed (%d of %d publishing)"
                        % (mode, n, r.get("publishing", 0), n))
                    bad = True
                    continue
                log("%s N=%d: min rate %.2f Hz, worst late %.2f %%, follower CPU %.1f %% "
                    "(%.2f %% each), plant %.1f %%, machine busy %.0f %% + steal %.0f %%, "
                    "holds %s, %.0f s"
                    % (mode, n, s["min_rate"], 100 * s["worst_late"], s["follower_cpu"],
                       s["per_follower"], s["plant_cpu"], r["machine_busy_percent"],
                       r["steal_percent"], "yes" if s["holds"] else "no", r["wall_s"]))
                bad = s["bad"]
                if not bad:
                    break
            if bad:
                log("%s: N=%d fails badly; larger sizes skipped" % (mode, n))
                break


def timer_probe(rate, seconds):
    """The machine's own timer jitter: a bare loop sleeping to RATE Hz deadlines (no ROS)."""
    period = 1.0 / rate
    busy0 = machine_busy()
    late = []
    deadline = time.monotonic()
    for _ in range(int(seconds * rate)):
        deadline += period
        delay = deadline - time.monotonic()
        if delay > 0:
            time.sleep(delay)
        late.append(time.monotonic() - deadline)
    busy1 = machine_busy()
    late.sort()
    pick = lambda q: 1000.0 * late[min(len(late) - 1, int(q * len(late)))]  # noqa: E731
    return {"probe": True, "rate": rate, "seconds": seconds, "p50_ms": pick(0.5),
            "p99_ms": pick(0.99), "max_ms": 1000.0 * late[-1],
            "over_half_period": sum(x > 0.5 * period for x in late) / len(late),
            "steal_percent": 100.0 * (busy1[1] - busy0[1]) / max(1, busy1[2] - busy0[2]),
            "loadavg": loadavg()}


def load_results(path):
    results, probes = [], []
    with open(path) as f:
        for line in f:
            if line.strip():
                r = json.loads(line)
                (probes if r.get("probe") else results).append(r)
    return results, probes


TABLE_HEAD = [
    "| mode | N | min follower rate (Hz) | worst late ticks (%) | longest gap (ms) "
    "| follower CPU (% of a core) | CPU per follower (%) | of which loaders (%) "
    "| plant CPU (%) | leader CPU (%) | recorder CPU (%) | machine busy (%) | steal (%) "
    "| load average at start | holds |",
    "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: "
    "| ---: | ---: | --- |",
]


def table(results, modes, rate):
    """The table rows and the summary lines of one pass."""
    lines = list(TABLE_HEAD)
    largest, largest_rate = {}, {}
    for mode in modes:
        for r in sorted((r for r in results if r["mode"] == mode),
                        key=lambda r: (r["n"], r.get("attempt", 1))):
            s = summarise(r)
            label = "%d%s" % (r["n"], " (2nd try)" if r.get("attempt", 1) > 1 else "")
            if s is None:
                lines.append("| %s | %s | only %d of %d followers published within %.0f s "
                             "| | | | | | | | | | | | no |"
                             % (mode, label, r.get("publishing", 0), r["n"],
                                r.get("startup_s", 0)))
                continue
            if s["holds"]:
                largest[mode] = max(largest.get(mode, 0), r["n"])
            if s["min_rate"] >= HOLD_RATE * rate:
                largest_rate[mode] = max(largest_rate.get(mode, 0), r["n"])
            lines.append(
                "| %s | %s | %.2f | %.2f | %.0f | %.1f | %.2f | %s | %.1f | %.1f | %.1f | %.0f "
                "| %.0f | %.2f | %s |"
                % (mode, label, s["min_rate"], 100 * s["worst_late"], s["max_gap_ms"],
                   s["follower_cpu"], s["per_follower"],
                   "%.1f" % s["loader_cpu"] if mode == "nodelets" else "",
                   s["plant_cpu"], s["leader_cpu"], s["recorder_cpu"],
                   r["machine_busy_percent"], r.get("steal_percent", float("nan")),
                   r["loadavg_start"][0], "yes" if s["holds"] else "**no**"))
    lines.append("")
    for mode in modes:
        tried = sorted({r["n"] for r in results if r["mode"] == mode})
        lines.append("- %s: largest N that holds %g Hz: **%s**; largest N at which every "
                     "follower keeps >= %g Hz (late ticks aside): **%s** (sizes run: %s)."
                     % (mode, rate, largest.get(mode, "none"), HOLD_RATE * rate,
                        largest_rate.get(mode, "none"), ", ".join(str(n) for n in tried)))
    loads = [r["loadavg_start"][0] for r in results if "loadavg_start" in r]
    busy = [r["machine_busy_percent"] for r in results if "machine_busy_percent" in r]
    steal = [r["steal_percent"] for r in results if "steal_percent" in r]
    if loads:
        lines.append("- Machine: %d cores; 1-min load average at the windows' starts %.2f to "
                     "%.2f (it includes the previous size's launch, still decaying); cores busy "
                     "%.0f %% to %.0f %% and stolen %.0f %% to %.0f %% during the windows (this "
                     "formation and the recorder included)."
                     % (results[0].get("cores", 0), min(loads), max(loads), min(busy),
                        max(busy), min(steal or [0]), max(steal or [0])))
    problems = []
    for r in results:
        for key, what in (("log_died", "process deaths"), ("log_errors", "ERROR lines"),
                          ("leftover", "processes left over"),
                          ("died", "node process(es) ended in the window"),
                          ("log_bond_broken", "nodelet loaders exited on 'Bond broken' (their "
                                              "followers unloaded)")):
            if r.get(key):
                problems.append("%s N=%d%s: %d %s" % (r["mode"], r["n"],
                                                      " (2nd try)" if r.get("attempt", 1) > 1
                                                      else "", r[key], what))
    lines.append("- Launch logs (whole launch, start-up and shut-down included): " +
                 ("; ".join(problems) if problems else
                  "no process deaths, no ERROR lines, nothing left over") + ".")
    return lines, largest


def probe_line(p):
    return ("- Timer jitter of the machine itself, before this pass's launches: a bare Python "
            "loop sleeping to %g Hz deadlines for %g s woke %.2f ms late at the median, "
            "%.1f ms at the 99th percentile, %.1f ms at worst (%.1f %% of wake-ups more than "
            "half a period late; steal %.0f %%, load average %.2f)."
            % (p["rate"], p["seconds"], p["p50_ms"], p["p99_ms"], p["max_ms"],
               100 * p["over_half_period"], p["steal_percent"], p["loadavg"][0]))


def command_report(args):
    results, probes = load_results(args.results)
    rate = results[0]["rate"]
    modes = [m for m in ("processes", "nodelets") if any(r["mode"] == m for r in results)]
    passes = [a for a in (False, True) if any(r.get("keep_awake", False) == a for r in results)]
    lines = [
        "# Formation scale: followers holding their control rate",
        "",
        "Generated by `experiments/formation_scale/run.sh` (with "
        "`experiments/formation_scale/formation_scale.py`). Each row is one launch of",
        "",
        "```",
        "roslaunch --port %d projection_collision_avoidance formation.launch followers:=N "
        "nodelets:=false|true \\" % args.port,
        "  scenario:=config/scenarios/paper_run2.yaml control_rate:=%g topology:=star "
        "shape:=line sim_time:=false rviz:=false" % rate,
        "```",
        "",
        "measured, once every follower published its status, over a window of %g wall s: "
        "the status messages of every follower recorded with `rosbag record` (rate = messages "
        "stamped in the window / window; late = consecutive stamps more than 1.5 periods "
        "apart), and the CPU time (utime + stime of all threads from `/proc/<pid>/stat`) of "
        "every node, in percent of one core. Follower CPU is that of the follower_node "
        "processes, or with nodelets that of the manager plus its `nodelet load` processes "
        "(column loaders). *Holds* = every follower at >= %g %% of %g Hz and at most %g %% "
        "late ticks. Machine busy and steal are shares of all cores over the window, from "
        "`/proc/stat` (steal: time the hypervisor kept this VM's cores waiting, which includes "
        "resuming a core that had halted while idle). A size that failed badly (a follower "
        "below %g %% of the rate) was run a second time before larger sizes were given up. "
        "The recorder itself costs CPU too (column recorder), which counts against the "
        "formation at the larger sizes."
        % (results[0]["window"], 100 * HOLD_RATE, rate, 100 * HOLD_LATE, 100 * BAD_RATE),
    ]
    for awake in passes:
        subset = [r for r in results if r.get("keep_awake", False) == awake]
        lines.append("")
        if awake:
            lines.append("## Cores kept awake")
            lines.append("")
            lines.append("The same launches with one lowest-priority busy loop per core "
                         "(`nice -n 19`; excluded from machine busy, but each adds 1 to the "
                         "load average), which keeps the VM's cores from halting when idle, so "
                         "that a timer's wake-up does not wait for the hypervisor to resume a "
                         "core.")
        else:
            lines.append("## Cores left to idle (the machine as it is)")
        lines.append("")
        for p in probes:
            if p.get("keep_awake", False) == awake:
                lines.append(probe_line(p))
                lines.append("")
        rows, _ = table(subset, modes, rate)
        lines.extend(rows)
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

    fig, (ax_cpu, ax_rate) = plt.subplots(1, 2, figsize=(11, 5.6))
    floor = 70.0  # Hz: rates below are drawn on the axis' floor, with their value
    low = []
    styles = {"processes": ("tab:blue", "o"), "nodelets": ("tab:orange", "s")}
    for awake in passes:
        suffix = ", cores kept awake" if awake else ""
        fill = "none" if awake else None
        for mode in modes:
            last = {}  # the last try of each size
            for r in results:
                if (r["mode"] == mode and r.get("keep_awake", False) == awake and summarise(r)
                        and (r["n"] not in last
                             or r.get("attempt", 1) >= last[r["n"]].get("attempt", 1))):
                    last[r["n"]] = r
            rows = [last[n] for n in sorted(last)]
            if not rows:
                continue
            color, marker = styles[mode]
            ns = [r["n"] for r in rows]
            sums = [summarise(r) for r in rows]
            kw = dict(marker=marker, color=color, markerfacecolor=fill,
                      alpha=0.55 if awake else 1.0)
            ax_cpu.plot(ns, [s["follower_cpu"] for s in sums], label="%s: followers%s"
                        % (mode, suffix), **kw)
            ax_cpu.plot(ns, [s["per_follower"] for s in sums], linestyle="--",
                        label="%s: per follower%s" % (mode, suffix), **kw)
            if not awake:
                ax_cpu.plot(ns, [s["plant_cpu"] for s in sums], linestyle=":",
                            label="%s: plant" % mode, **kw)
            ax_rate.plot(ns, [max(floor, s["min_rate"]) for s in sums],
                         label="%s: slowest follower%s" % (mode, suffix), **kw)
            low += [(n, s["min_rate"], color) for n, s in zip(ns, sums) if s["min_rate"] < floor]
    ax_cpu.set_xscale("log", base=2)
    ax_cpu.set_yscale("log")
    ax_cpu.set_xlabel("followers N")
    ax_cpu.set_ylabel("CPU (% of one core)")
    ax_cpu.axhline(100.0 * results[0].get("cores", 2), color="grey", linewidth=0.8,
                   label="all cores")
    ax_cpu.set_title("CPU over the window")
    ax_cpu.grid(True, which="both", alpha=0.3)
    ax_cpu.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.15), ncol=2)
    ax_rate.axhline(HOLD_RATE * rate, color="grey", linestyle="--", linewidth=0.8,
                    label="%g %% of %g Hz" % (100 * HOLD_RATE, rate))
    ax_rate.set_xscale("log", base=2)
    ax_rate.set_xlabel("followers N")
    ax_rate.set_ylabel("status rate of the slowest follower (Hz)")
    ax_rate.set_title("Achieved control rate (%g Hz asked)" % rate)
    ax_rate.grid(True, which="both", alpha=0.3)
    for n, value, color in low:
        ax_rate.annotate("%.0f Hz" % value, (n, floor), xytext=(-30, 8),
                         textcoords="offset points", color=color, fontsize=8)
    ax_rate.set_ylim(floor - 1.0, 101.0)
    ax_rate.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.15), ncol=2)
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
    run.add_argument("--keep-bags", default="", help="directory to keep the status bags in")
    run.add_argument("--keep-awake", choices=["no", "yes", "both"], default="no",
                     help="run a nice-19 busy loop per core (yes), or a pass without and one "
                          "with (both)")
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
