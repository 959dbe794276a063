"""CPU per follower and per plant agent against the platoon's size, everything in one manager.

For each N, launches formation.launch with N followers (star, line, paper_run2.yaml, real time,
no rviz) as nodelets of one manager, the plant and the leader in it too (world_nodelets:=true),
waits until every follower ticks, then over a window of wall seconds reads
  - the CPU time of each thread of the manager (/proc/<pid>/task/<tid>/schedstat): the followers'
    tick threads ("tick <i>"), the plant's ("plant tick") and the rest (roscpp's network and timer
    threads, the nodelet workers), and the manager's utime + stime (/proc/<pid>/stat);
  - each follower's diagnostics (ticks, missed_periods, late_periods, mode), which the followers
    publish anyway at 1 Hz: its rate (ticks / s) and its late ticks (late / ticks);
  - the plant's log lines saying it dropped ticks it could not keep up with.
Holds: every follower at >= 99 % of the rate with <= 1 % late ticks, tracking at the end, and the
plant dropped no tick.

  platoon_cpu.py run --sizes 1 8 32 64 128 --json OUT.jsonl [--window 20] [--rate 100]
  platoon_cpu.py report --json OUT.jsonl --csv OUT.csv --png OUT.png
"""

import argparse
import json
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "common"))
sys.path.insert(0, HERE)
from node_cpu import cpu_jiffies, launch_children, start_launch, thread_ns  # noqa: E402
from process_control import stop as stop_process  # noqa: E402

SCENARIO = os.path.join(HERE, "..", "..", "config", "scenarios", "paper_run2.yaml")

# Prints one JSON line per follower diagnostics status, and one per plant line about dropped
# ticks, until killed.
READER = r"""
import json, sys, rospy
from diagnostic_msgs.msg import DiagnosticArray
from rosgraph_msgs.msg import Log
KEYS = ("ticks", "missed_periods", "late_periods", "mode")
def diagnostics(msg):
    for s in msg.status:
        values = {kv.key: kv.value for kv in s.values}
        if all(k in values for k in KEYS):
            # In one manager every follower's status has the manager's name: its hardware_id
            # (the follower's frame) tells them apart.
            print(json.dumps({"t": msg.header.stamp.to_sec(), "name": s.name + "/" + s.hardware_id,
                              **{k: values[k] for k in KEYS}}), flush=True)
def log(msg):
    if msg.name == "/plant" and "behind the wall clock" in msg.msg:
        print(json.dumps({"t": msg.header.stamp.to_sec(), "plant_dropped": msg.msg}), flush=True)
rospy.init_node("platoon_cpu_reader", anonymous=True, disable_signals=True)
rospy.Subscriber("/diagnostics", DiagnosticArray, diagnostics, queue_size=1000)
rospy.Subscriber("/rosout_agg", Log, log, queue_size=1000)
rospy.spin()
"""


def manager_pid(launch_pid):
    """The nodelet manager among roslaunch's children (None before it runs)."""
    for pid in launch_children(launch_pid):
        try:
            with open("/proc/%d/cmdline" % pid, "rb") as f:
                args = f.read().split(b"\0")
        except OSError:
            continue
        if b"manager" in args and any(a == b"__name:=formation_manager" for a in args):
            return pid
    return None


def total_jiffies(pids):
    total = 0
    for pid in pids:
        try:
            total += cpu_jiffies(pid)
        except OSError:
            pass
    return total


def machine_jiffies():
    """(busy, all, steal) clock ticks of every core, from /proc/stat. Steal: time the hypervisor
    kept this VM's cores from running (counted in busy)."""
    with open("/proc/stat") as f:
        fields = [int(x) for x in f.readline().split()[1:]]
    idle = fields[3] + fields[4]
    return sum(fields) - idle, sum(fields), fields[7]


def read_lines(path):
    out = []
    with open(path) as f:
        for line in f:
            try:
                out.append(json.loads(line))
            except ValueError:
                pass  # a line being written
    return out


def measure(args, n):
    env = dict(os.environ)
    env["ROS_MASTER_URI"] = "http://localhost:%d" % args.port
    command = ["roslaunch", "--port", str(args.port), "projection_collision_avoidance",
               "formation.launch", "followers:=%d" % n, "nodelets:=true", "world_nodelets:=true",
               "scenario:=" + os.path.abspath(SCENARIO), "control_rate:=%g" % args.rate,
               "topology:=star", "shape:=line", "sim_time:=false", "rviz:=false"]
    lines_path = os.path.join(args.work, "platoon_reader_%d.jsonl" % n)
    launch, reader = start_launch(command, env,
                                  os.path.join(args.work, "platoon_launch_%d.log" % n), READER,
                                  lines_path)
    result = {"n": n, "rate": args.rate, "window_s": args.window}
    try:
        deadline = time.time() + 60.0 + 1.0 * n
        pid = None
        while time.time() < deadline:  # every follower ticking
            pid = pid or manager_pid(launch.pid)
            ticking = {d["name"] for d in read_lines(lines_path)
                       if "name" in d and int(d["ticks"]) > 0}
            if pid and len(ticking) >= n:
                break
            time.sleep(0.5)
        else:
            raise RuntimeError("N=%d: %d followers ticking within the deadline" % (n, len(ticking)))
        time.sleep(args.settle)
        others = [p for p in launch_children(launch.pid) if p != pid]  # the nodelet loaders
        jiffies0, threads0 = cpu_jiffies(pid), thread_ns(pid)
        others0, busy0 = total_jiffies(others), machine_jiffies()
        t0 = time.time()
        time.sleep(args.window)
        t1 = time.time()
        jiffies1, threads1 = cpu_jiffies(pid), thread_ns(pid)
        others1, busy1 = total_jiffies(others), machine_jiffies()
        time.sleep(3.5)  # the diagnostics after t1 (1 Hz each)
    finally:
        stop_process(reader, 5.0)
        stop_process(launch, 60.0)
    window = t1 - t0
    groups = {"followers' ticks": 0.0, "plant tick": 0.0, "other threads": 0.0}
    for tid, (name, ns) in threads1.items():
        seconds = (ns - threads0.get(tid, (name, 0))[1]) * 1e-9
        key = ("followers' ticks" if name.startswith(("tick ", "follower ticks")) else
               "plant tick" if name == "plant tick" else "other threads")
        groups[key] += seconds
    lines = read_lines(lines_path)
    per = {}
    for d in lines:
        if "name" in d:
            per.setdefault(d["name"], []).append(d)
    rates, late, missed, tracking, worst = [], [], [], 0, []
    for name, seen in per.items():
        before = [d for d in seen if d["t"] <= t0]
        after = [d for d in seen if d["t"] >= t1]
        if not before or not after:
            continue
        a, b = before[-1], after[0]
        ticks = int(b["ticks"]) - int(a["ticks"])
        rates.append(ticks / (b["t"] - a["t"]))
        late.append((int(b["late_periods"]) - int(a["late_periods"])) / max(1, ticks))
        missed.append(int(b["missed_periods"]) - int(a["missed_periods"]))
        tracking += 1 if b["mode"] == "tracking" else 0
        worst.append((missed[-1], name))
    dropped = [d["plant_dropped"] for d in lines if "plant_dropped" in d and t0 <= d["t"] <= t1]
    manager_cpu = (jiffies1 - jiffies0) / os.sysconf("SC_CLK_TCK")
    ticks_per_s = n * args.rate
    result.update({
        "followers_measured": len(rates), "tracking": tracking,
        "min_rate": min(rates) if rates else 0.0, "max_late": max(late) if late else 1.0,
        "max_missed": max(missed) if missed else None, "plant_drops": len(dropped),
        "manager_percent_stat": 100.0 * manager_cpu / window,
        "manager_percent_sched": 100.0 * sum(groups.values()) / window,
        "groups_percent": {k: 100.0 * v / window for k, v in groups.items()},
        "follower_tick_us": 1e6 * groups["followers' ticks"] / (ticks_per_s * window),
        "follower_percent": 100.0 * groups["followers' ticks"] / window / n,
        "plant_agent_us": 1e6 * groups["plant tick"] / (args.rate * window * (n + 1)),
        "other_us_per_follower_tick": 1e6 * groups["other threads"] / (ticks_per_s * window),
        "load": os.getloadavg()[0],
        "loaders_percent": 100.0 * (others1 - others0) / os.sysconf("SC_CLK_TCK") / window,
        "loaders": len(others),
        "machine_busy_percent": 100.0 * (busy1[0] - busy0[0]) / max(1, busy1[1] - busy0[1]),
        "steal_percent": 100.0 * (busy1[2] - busy0[2]) / max(1, busy1[1] - busy0[1]),
        "most_missed": sorted(worst, reverse=True)[:5],
    })
    result["holds"] = (len(rates) == n and result["min_rate"] >= 0.99 * args.rate and
                       result["max_late"] <= 0.01 and tracking == n and not dropped)
    return result


def command_run(args):
    with open(args.json, "a") as out:
        for n in args.sizes:
            r = measure(args, n)
            out.write(json.dumps(r) + "\n")
            out.flush()
            print("N=%3d  manager %6.1f %% (stat %6.1f %%)  follower tick %6.1f us (%.3f %% each)"
                  "  plant %5.1f us per agent  other %5.1f us per follower tick  min rate %.2f Hz"
                  "  max late %.2f %%  tracking %d/%d  plant drops %d  loaders %.1f %%"
                  "  machine busy %.0f %% (steal %.1f %%)  most missed %s  holds %s" % (
                      n, r["manager_percent_sched"], r["manager_percent_stat"],
                      r["follower_tick_us"], r["follower_percent"], r["plant_agent_us"],
                      r["other_us_per_follower_tick"], r["min_rate"], 100 * r["max_late"],
                      r["tracking"], n, r["plant_drops"], r["loaders_percent"],
                      r["machine_busy_percent"], r["steal_percent"], r["most_missed"][:3],
                      r["holds"]), flush=True)


def command_report(args):
    rows = [json.loads(line) for line in open(args.json)]
    header = ["N", "manager (% of a core)", "followers' ticks (%)", "plant tick (%)",
              "other threads (%)", "us per follower tick", "us per plant agent and tick",
              "other threads per follower tick (us)", "min follower rate (Hz)",
              "max late ticks (%)", "most missed periods", "tracking", "plant drops",
              "nodelet loaders (% of a core)", "machine busy (%)", "steal (%)", "holds"]
    with open(args.csv, "w") as out:
        out.write(",".join(header) + "\n")
        for r in rows:
            g = r["groups_percent"]
            out.write(",".join(str(x) for x in [
                r["n"], "%.1f" % r["manager_percent_sched"], "%.1f" % g["followers' ticks"],
                "%.1f" % g["plant tick"], "%.1f" % g["other threads"],
                "%.1f" % r["follower_tick_us"], "%.2f" % r["plant_agent_us"],
                "%.1f" % r["other_us_per_follower_tick"], "%.2f" % r["min_rate"],
                "%.2f" % (100 * r["max_late"]), r["max_missed"],
                "%d/%d" % (r["tracking"], r["n"]), r["plant_drops"],
                "%.1f" % r["loaders_percent"] if "loaders_percent" in r else "",
                "%.0f" % r["machine_busy_percent"] if "machine_busy_percent" in r else "",
                "%.1f" % r["steal_percent"] if "steal_percent" in r else "",
                "yes" if r["holds"] else "no"]) + "\n")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows.sort(key=lambda r: r["n"])
    n = [r["n"] for r in rows]
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4))
    left.plot(n, [r["follower_tick_us"] for r in rows], "o-", label="follower tick thread")
    left.plot(n, [r["other_us_per_follower_tick"] for r in rows], "s-",
              label="manager's other threads, per follower tick")
    left.plot(n, [r["plant_agent_us"] for r in rows], "^-", label="plant, per agent and tick")
    left.set_xscale("log", base=2)
    left.set_xlabel("followers N")
    left.set_ylabel("CPU per tick (us)")
    left.legend()
    left.grid(True, alpha=0.3)
    right.plot(n, [r["manager_percent_sched"] for r in rows], "o-", label="manager, all threads")
    right.axhline(100.0 * os.cpu_count(), color="k", linestyle="--", label="all cores")
    right.set_xscale("log", base=2)
    right.set_xlabel("followers N")
    right.set_ylabel("% of a core")
    right2 = right.twinx()  # the criterion that fails first: late ticks
    right2.plot(n, [100.0 * r["max_late"] for r in rows], "r.-", label="max late ticks")
    right2.axhline(1.0, color="r", linestyle=":", label="1 % (holds below)")
    right2.set_ylim(0.0, max(5.0, max(100.0 * r["max_late"] for r in rows) * 1.1))
    right2.set_ylabel("max late ticks of a follower (%)", color="r")
    right2.legend(loc="upper right")
    right.legend(loc="center left")
    right.grid(True, alpha=0.3)
    fig.tight_layout()
    fig.savefig(args.png, dpi=110)
    print("platoon_cpu: %s, %s" % (args.csv, args.png))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run")
    run.add_argument("--sizes", type=int, nargs="+", default=[1, 8, 32, 64, 128])
    run.add_argument("--window", type=float, default=20.0)
    run.add_argument("--settle", type=float, default=5.0)
    run.add_argument("--rate", type=float, default=100.0)
    run.add_argument("--port", type=int, default=11432)
    run.add_argument("--json", required=True, help="results, one JSON line per N (appended)")
    run.add_argument("--work", default="/tmp")
    report = sub.add_parser("report")
    report.add_argument("--json", required=True)
    report.add_argument("--csv", required=True)
    report.add_argument("--png", required=True)
    args = parser.parse_args()
    command_run(args) if args.command == "run" else command_report(args)


if __name__ == "__main__":
    main()
