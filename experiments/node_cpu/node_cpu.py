"""CPU time per control tick of the follower and the plant, from /proc.

Launches pair.launch (Run 2, real time, no rviz) on its own master at each control rate, waits
until the follower ticks, then reads every node's CPU time at the start and the end of a window of
wall seconds, two ways:
  - /proc/<pid>/stat, utime + stime (clock ticks of 10 ms: the coarse, independent reading);
  - /proc/<pid>/task/<tid>/schedstat, the run time of each thread in ns (per thread, by its name).
The follower's ticks over the window come from its diagnostics ("ticks"), which it publishes
anyway (1 Hz), so that the measurement adds no subscriber to the topics it times.

  node_cpu.py --rates 100 1000 --window 30 --json OUT.jsonl [--label L] [--launch-arg k:=v ...]
  node_cpu.py --floor ...   the same with floor.launch: in the follower's place a bare roscpp relay
                            (measurement_relay), one message in and one out per tick; its messages
                            are counted by a subscriber on its output, at 1 Hz
  node_cpu.py --report --json OUT.jsonl --csv OUT.csv     (the table of every measurement)

Prints one line per rate and node; writes one JSON line per rate to OUT.jsonl.
"""

import argparse
import json
import os
import signal
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "common"))
from process_control import stop as stop_process  # noqa: E402

NODES = ("follower_node", "plant_node", "leader_node")
FLOOR_NODES = ("measurement_relay", "plant_node", "leader_node")
SCENARIO = os.path.join(HERE, "..", "..", "config", "scenarios", "paper_run2.yaml")

# Runs in its own interpreter with the launch's ROS_MASTER_URI: prints "stamp ticks" of each
# /diagnostics status of the follower until killed.
TICKS = r"""
import sys, rospy
from diagnostic_msgs.msg import DiagnosticArray
def seen(msg):
    for s in msg.status:
        for kv in s.values:
            if kv.key == "ticks":
                print("%.6f %s" % (msg.header.stamp.to_sec(), kv.value), flush=True)
rospy.init_node("node_cpu_ticks", anonymous=True, disable_signals=True)
rospy.Subscriber("/diagnostics", DiagnosticArray, seen, queue_size=100)
rospy.spin()
"""

# The same output for floor.launch: "stamp count" of the relay's messages, once a second.
RELAYED = r"""
import sys, threading, rospy
from projection_collision_avoidance.msg import RelativeMeasurement
count = [0]
lock = threading.Lock()
def seen(msg):
    with lock:
        count[0] += 1
rospy.init_node("node_cpu_relayed", anonymous=True, disable_signals=True)
rospy.Subscriber("/follower/relay_output", RelativeMeasurement, seen, queue_size=1000,
                 tcp_nodelay=True)
while True:
    rospy.sleep(1.0)
    with lock:
        print("%.6f %d" % (rospy.get_time(), count[0]), flush=True)
"""


def cpu_jiffies(pid):
    """utime + stime of the whole process (all threads), in clock ticks."""
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return int(fields[11]) + int(fields[12])


def thread_ns(pid):
    """{tid: (name, run time in ns)} of every thread of @p pid."""
    out = {}
    for tid in os.listdir("/proc/%d/task" % pid):
        try:
            with open("/proc/%d/task/%s/comm" % (pid, tid)) as f:
                name = f.read().strip()
            with open("/proc/%d/task/%s/schedstat" % (pid, tid)) as f:
                out[int(tid)] = (name, int(f.read().split()[0]))
        except OSError:  # the thread ended
            pass
    return out


def launch_children(launch_pid):
    """The pids of roslaunch's child processes (none once it has ended)."""
    try:
        with open("/proc/%d/task/%d/children" % (launch_pid, launch_pid)) as f:
            return [int(p) for p in f.read().split()]
    except OSError:
        return []


def node_pids(launch_pid, nodes):
    """{node executable: pid} of @p nodes among roslaunch's children (each node has a session of
    its own)."""
    pids = {}
    for pid in launch_children(launch_pid):
        try:
            with open("/proc/%d/cmdline" % pid, "rb") as f:
                exe = os.path.basename(f.read().split(b"\0")[0].decode())
        except OSError:
            continue
        if exe in nodes:
            pids[exe] = pid
    return pids


def start_launch(command, env, log_path, reader_code, reader_path):
    """roslaunch @p command (its output to @p log_path) and a rospy reader running
    @p reader_code (its output to @p reader_path), each in a session of its own."""
    with open(log_path, "w") as out:
        launch = subprocess.Popen(command, stdout=out, stderr=subprocess.STDOUT, env=env,
                                  start_new_session=True)
    with open(reader_path, "w") as out:
        reader = subprocess.Popen([sys.executable, "-c", reader_code], stdout=out,
                                  stderr=subprocess.DEVNULL, env=env, start_new_session=True)
    return launch, reader


def read_ticks(lines):
    """[(stamp, ticks)] from the ticks reader's output lines."""
    out = []
    for line in lines:
        parts = line.split()
        if len(parts) == 2:
            out.append((float(parts[0]), int(parts[1])))
    return out


def measure(args, rate):
    """One launch at @p rate Hz: the result dict."""
    env = dict(os.environ)
    env["ROS_MASTER_URI"] = "http://localhost:%d" % args.port
    launch_file = (["projection_collision_avoidance", "pair.launch"] if not args.floor
                   else [os.path.join(HERE, "floor.launch")])
    nodes = FLOOR_NODES if args.floor else NODES
    command = (["roslaunch", "--port", str(args.port)] + launch_file +
               ["scenario:=" + os.path.abspath(SCENARIO), "sim_time:=false",
                "control_rate:=%g" % rate] + args.launch_arg)
    ticks_log = os.path.join(args.work, "ticks_%g.txt" % rate)
    launch, reader = start_launch(command, env, os.path.join(args.work, "launch_%g.log" % rate),
                                  RELAYED if args.floor else TICKS, ticks_log)
    try:
        deadline = time.time() + 60.0
        pids = {}
        while time.time() < deadline:  # every node running, the follower ticking
            pids = node_pids(launch.pid, nodes)
            with open(ticks_log) as f:
                ticking = [t for t in read_ticks(f) if t[1] > 0]
            if len(pids) == len(nodes) and len(ticking) >= 2:
                break
            time.sleep(0.2)
        else:
            raise RuntimeError("rate %g: nodes %s, follower not ticking within 60 s" % (rate, pids))
        time.sleep(args.settle)
        jiffies0 = {n: cpu_jiffies(p) for n, p in pids.items()}
        threads0 = {n: thread_ns(p) for n, p in pids.items()}
        t0 = time.time()
        time.sleep(args.window)
        t1 = time.time()
        jiffies1 = {n: cpu_jiffies(p) for n, p in pids.items()}
        threads1 = {n: thread_ns(p) for n, p in pids.items()}
        time.sleep(1.5)  # the diagnostics after t1
    finally:
        stop_process(reader, 5.0)
        stop_process(launch, 30.0)
    with open(ticks_log) as f:
        ticks = read_ticks(f)
    before = [t for t in ticks if t[0] <= t0]
    after = [t for t in ticks if t[0] >= t1]
    if not before or not after:
        raise RuntimeError("rate %g: no diagnostics around the window" % rate)
    (s0, k0), (s1, k1) = before[-1], after[0]
    tick_rate = (k1 - k0) / (s1 - s0)
    window = t1 - t0
    result = {"label": args.label, "rate": rate, "window_s": window, "tick_rate": tick_rate, "nodes": {},
              "launch_args": args.launch_arg}
    hz = os.sysconf("SC_CLK_TCK")
    for node in pids:
        cpu_stat = (jiffies1[node] - jiffies0[node]) / hz
        per_thread = {}
        for tid, (name, ns) in threads1[node].items():
            start = threads0[node].get(tid, (name, 0))[1]
            key = "%s/%d" % (name, tid)
            per_thread[key] = (ns - start) * 1e-9
        cpu_sched = sum(per_thread.values())
        result["nodes"][node] = {
            "cpu_s_stat": cpu_stat, "cpu_s_sched": cpu_sched,
            "percent_core_stat": 100.0 * cpu_stat / window,
            "percent_core_sched": 100.0 * cpu_sched / window,
            "us_per_tick_stat": 1e6 * cpu_stat / (tick_rate * window),
            "us_per_tick_sched": 1e6 * cpu_sched / (tick_rate * window),
            "threads_s": {k: v for k, v in sorted(per_thread.items(), key=lambda kv: -kv[1])
                          if v > 0.0},
        }
    return result


def report(args):
    """The CSV of every measurement in --json, and the same as a Markdown table on stdout."""
    rows = []
    with open(args.json) as f:
        for line in f:
            r = json.loads(line)
            for node, n in sorted(r["nodes"].items()):
                rows.append([r.get("label", ""), "%g" % r["rate"], node,
                             "%.2f" % n["percent_core_sched"], "%.2f" % n["percent_core_stat"],
                             "%.1f" % n["us_per_tick_sched"], "%.1f" % n["us_per_tick_stat"],
                             "%.2f" % r["tick_rate"], "%.1f" % r["window_s"]])
    header = ["build", "control rate (Hz)", "node", "% of a core (schedstat)", "% of a core (stat)",
              "us per tick (schedstat)", "us per tick (stat)", "follower ticks (Hz)", "window (s)"]
    with open(args.csv, "w") as out:
        out.write(",".join(header) + "\n")
        for row in rows:
            out.write(",".join(row) + "\n")
    print("| " + " | ".join(header) + " |")
    print("|" + "---|" * len(header))
    for row in rows:
        print("| " + " | ".join(row) + " |")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rates", type=float, nargs="+", default=[100.0, 1000.0])
    parser.add_argument("--window", type=float, default=30.0, help="wall seconds measured")
    parser.add_argument("--settle", type=float, default=3.0, help="s after the first ticks")
    parser.add_argument("--port", type=int, default=11431)
    parser.add_argument("--json", required=True, help="results, one JSON line per rate (appended)")
    parser.add_argument("--label", default="", help="name of the build measured")
    parser.add_argument("--report", action="store_true", help="only write --csv from --json")
    parser.add_argument("--csv", help="with --report: the table as CSV")
    parser.add_argument("--work", default="/tmp", help="directory of the ticks logs")
    parser.add_argument("--floor", action="store_true",
                        help="floor.launch: a bare roscpp relay in the follower's place")
    parser.add_argument("--launch-arg", action="append", default=[],
                        help="extra pair.launch argument k:=v (repeatable)")
    args = parser.parse_args()
    if args.report:
        report(args)
        return
    signal.signal(signal.SIGTERM, signal.default_int_handler)
    with open(args.json, "a") as out:
        for rate in args.rates:
            result = measure(args, rate)
            out.write(json.dumps(result) + "\n")
            out.flush()
            for node, r in sorted(result["nodes"].items()):
                print("rate %5g Hz  %-14s %6.2f %% of a core (stat %6.2f %%)  %7.1f us/tick "
                      "(stat %7.1f)  ticks at %.2f Hz" % (
                          rate, node, r["percent_core_sched"], r["percent_core_stat"],
                          r["us_per_tick_sched"], r["us_per_tick_stat"], result["tick_rate"]))
            threads = result["nodes"][(FLOOR_NODES if args.floor else NODES)[0]]["threads_s"]
            print("   follower threads (s of CPU over %.1f s): %s" % (
                result["window_s"], ", ".join("%s %.3f" % kv for kv in threads.items())))


if __name__ == "__main__":
    main()
