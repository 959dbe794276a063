#!/usr/bin/python3
"""The follower and the unicycle command adapter on a third-party simulator (Enki), case by case.

Each case launches test/enki/enki_sweep.launch (the Enki bridge, the pushed leader robot_0, the
follower robot_1 through follower_node + command_adapter, rosbag) on its own ROS master, on wall
time, one case after the other, and computes from the bag:

  * max ||xi|| of the follower's statuses against its xi_max = (1 - alpha) ||d||;
  * the smallest distance of the controlled points (the follower's look-ahead point, the leader's
    centre) and of the robots' centres, from Enki's ground truth, against the perimeter alpha ||d||
    (the centres are guaranteed alpha ||d|| - l only);
  * the realised against the commanded acceleration of the follower's controlled point: the
    least-squares ratio sum(a_real . a_cmd) / sum(a_cmd . a_cmd), a_real the look-ahead point's
    ground-truth velocity differenced over consecutive windows of at least --window s, a_cmd the
    mean of the follower's `command` over the same window one physics step earlier (a wheel speed
    set before a step acts during it); 1 = the vehicle does what the follower assumes;
  * the fraction of the adapter's cmd_vel at a wheel limit (speed or yaw rate).

Writes a CSV and a markdown table. Usage (run.sh beside it sources the workspace first):
  enki_sweep.py [--cases quick|full] [--vehicles thymio2 epuck] [--inputs odometry tf position]
                [--steps 0.01 0.05 0.1] [--headings 0 90 180] [--pushes 1 2] [--duration S]
                [--csv FILE] [--md FILE] [--port P] [--keep DIR]
  enki_sweep.py --from-csv FILE [--md FILE]   (the tables again from a CSV, running nothing)
The markdown file has a summary per vehicle x input x step, then every case.
"""

import argparse
import csv
import itertools
import math
import os
import pathlib
import subprocess
import sys
import tempfile
import time

import rosbag

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(HERE.parent / "common"))
from process_control import stop  # noqa: E402

LAUNCH = ROOT / "test" / "enki" / "enki_sweep.launch"
MODE_TRACKING = 1
# A handful of cases across every axis: what --cases quick runs.
QUICK = [
    ("thymio2", "odometry", 0.1, 0, 1),
    ("thymio2", "tf", 0.01, 90, 2),
    ("thymio2", "position", 0.05, 180, 1),
    ("thymio2", "position", 0.01, 0, 2),
    ("epuck", "odometry", 0.01, 0, 2),
]
FIELDS = ["vehicle", "input", "physics_step", "heading_deg", "push_scale", "statuses", "tracking",
          "fallback_steps", "rejected", "max_xi", "xi_max", "min_controlled", "min_centres",
          "perimeter", "accel_ratio", "accel_windows", "limited_fraction", "adapter_update",
          "adapter_delay", "adapter_realised", "recorded_from", "wall_s", "result"]
MAX_SPEED = {"thymio2": 0.166, "epuck": 0.128}
MAX_YAW_RATE = {"thymio2": 3.5, "epuck": 5.0}


def yaw_of(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def read_bag(path):
    """Ground truth per robot {stamp ns: (x, y, yaw, vx, vy, wz)}, statuses, commands, cmd_vel
    and the command adapter's last diagnostics values."""
    truth = {"robot_0": {}, "robot_1": {}}
    statuses, commands, cmd_vel, response = [], [], [], {}
    with rosbag.Bag(str(path)) as bag:
        for topic, msg, t in bag.read_messages():
            if topic.endswith("/ground_truth"):
                p, q, v = msg.pose.pose.position, msg.pose.pose.orientation, msg.twist.twist
                truth[topic.split("/")[1]][msg.header.stamp.to_nsec()] = (
                    p.x, p.y, yaw_of(q), v.linear.x, v.linear.y, v.angular.z)
            elif topic == "/follower/status":
                statuses.append(msg)
            elif topic == "/follower/command":
                commands.append((msg.header.stamp.to_sec(), msg.accel.linear.x, msg.accel.linear.y))
            elif topic == "/robot_1/cmd_vel":
                cmd_vel.append((t.to_sec(), msg.linear.x, msg.angular.z))
            elif topic == "/diagnostics":
                for status in msg.status:  # the command adapter's estimate of its vehicle
                    values = {kv.key: kv.value for kv in status.values}
                    if "vehicle_realised_fraction" in values:
                        response.update(values)
    return truth, statuses, commands, cmd_vel, response


def look_ahead_state(s, l):
    """(x, y, vx, vy) of the point l ahead of the axle of ground-truth state s."""
    x, y, yaw, vx, vy, wz = s
    c, n = math.cos(yaw), math.sin(yaw)
    return x + l * c, y + l * n, vx - l * wz * n, vy + l * wz * c


def accel_ratio(follower, commands, l, step, window):
    """Least-squares ratio of realised to commanded acceleration and the number of windows."""
    samples, last = [], None
    for stamp in sorted(follower):  # the states Enki stepped to (repeats carry fresh stamps)
        s = follower[stamp]
        if s != last:
            samples.append((stamp * 1e-9, look_ahead_state(s, l)))
            last = s
    commands = sorted(commands)
    num = den = 0.0
    windows = 0
    i = 0
    while i < len(samples):
        j = i + 1
        while j < len(samples) and samples[j][0] - samples[i][0] < window - 1e-6:
            j += 1
        if j >= len(samples):
            break
        (ta, sa), (tb, sb) = samples[i], samples[j]
        inside = [(ax, ay) for tc, ax, ay in commands if ta - step <= tc < tb - step]
        if inside:
            cx = sum(a[0] for a in inside) / len(inside)
            cy = sum(a[1] for a in inside) / len(inside)
            rx, ry = (sb[2] - sa[2]) / (tb - ta), (sb[3] - sa[3]) / (tb - ta)
            num += rx * cx + ry * cy
            den += cx * cx + cy * cy
            windows += 1
        i = j
    return (num / den if den > 0.0 else float("nan")), windows


def analyse(bag, case, look_ahead, window):
    vehicle, _, step, _, _ = case
    truth, statuses, commands, cmd_vel, response = read_bag(bag)
    both = sorted(set(truth["robot_0"]) & set(truth["robot_1"]))
    if not both or not statuses:
        raise RuntimeError("no ground truth or no status recorded")
    min_centres = min_controlled = math.inf
    for stamp in both:
        s0, s1 = truth["robot_0"][stamp], truth["robot_1"][stamp]
        min_centres = min(min_centres, math.hypot(s0[0] - s1[0], s0[1] - s1[1]))
        x, y, _, _ = look_ahead_state(s1, look_ahead)
        min_controlled = min(min_controlled, math.hypot(s0[0] - x, s0[1] - y))
    ratio, windows = accel_ratio(truth["robot_1"], commands, look_ahead, step, window)
    limited = sum(1 for _, v, w in cmd_vel
                  if abs(v) >= MAX_SPEED[vehicle] - 1e-6 or abs(w) >= MAX_YAW_RATE[vehicle] - 1e-6)
    first_leader = truth["robot_0"][both[0]]
    return {
        "statuses": len(statuses),
        "tracking": sum(1 for s in statuses if s.mode == MODE_TRACKING),
        "fallback_steps": sum(1 for s in statuses if s.fallback),
        "rejected": max(s.rejected_measurements for s in statuses),
        "max_xi": max(s.xi_norm for s in statuses),
        "xi_max": statuses[-1].xi_max,
        "perimeter": statuses[-1].perimeter,
        "min_controlled": min_controlled,
        "min_centres": min_centres,
        "accel_ratio": ratio,
        "accel_windows": windows,
        "limited_fraction": limited / len(cmd_vel) if cmd_vel else float("nan"),
        # What the command adapter estimated of its vehicle (doc/vehicles.md).
        "adapter_update": float(response.get("vehicle_update_interval (s)", "nan")),
        "adapter_delay": float(response.get("vehicle_response_delay (s)", "nan")),
        "adapter_realised": float(response.get("vehicle_realised_fraction", "nan")),
        # Whether the bag saw the leader at rest (recorded before it started) or already moving.
        "recorded_from": "start" if math.hypot(first_leader[3], first_leader[4]) < 1e-3 else "late",
    }


def verdict(row, look_ahead):
    """'ok', or what the case broke: the bound, the perimeter, the centres' guarantee."""
    broken = []
    if row["max_xi"] > row["xi_max"]:
        broken.append("xi>xi_max")
    if row["min_controlled"] < row["perimeter"]:
        broken.append("controlled<perimeter")
    if row["min_centres"] < row["perimeter"] - look_ahead:
        broken.append("centres<perimeter-l")
    if row["tracking"] == 0:
        broken.append("never tracked")
    return " ".join(broken) or "ok"


def run_case(case, args, work):
    vehicle, input_, step, heading, push = case
    name = f"{vehicle}_{input_}_{int(round(step * 1000))}ms_{heading}deg_x{push}"
    bag = work / f"{name}.bag"
    env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{args.port}",
               ROS_LOG_DIR=str(work / "log"))
    cmd = ["roslaunch", "--port", str(args.port), str(LAUNCH), f"vehicle:={vehicle}",
           f"input:={input_}", f"physics_step:={step}", f"heading_deg:={heading}",
           f"push_scale:={push}", f"duration:={args.duration}", f"look_ahead:={args.look_ahead}",
           f"adapter_world_frame:={args.adapter_world_frame}", f"bag:={bag}"]
    start = time.monotonic()
    with open(work / f"{name}.log", "w") as log:
        proc = subprocess.Popen(cmd, stdout=log, stderr=subprocess.STDOUT, env=env)
        try:
            proc.wait(args.duration + 90.0)
        except subprocess.TimeoutExpired:
            stop(proc)
    wall = time.monotonic() - start
    row = dict(zip(FIELDS[:5], case), wall_s=round(wall, 1))
    if not bag.exists():
        row["result"] = f"no bag (see {work / name}.log)"
        return row
    try:
        row.update(analyse(bag, case, args.look_ahead, args.window))
        row["result"] = verdict(row, args.look_ahead)
    except (RuntimeError, ValueError) as error:
        row["result"] = f"failed: {error}"
    return row


def fmt(value, digits=3):
    if isinstance(value, float):
        return "nan" if math.isnan(value) else f"{value:.{digits}f}"
    return "" if value is None else str(value)


def markdown(rows):
    head = ("| vehicle | input | step (s) | heading (°) | push | tracking statuses | max ‖ξ‖ (m) "
            "| ξ_max (m) | min controlled points (m) | min centres (m) | perimeter α‖d‖ (m) "
            "| a_real/a_cmd | at a wheel limit | adapter: update (s) | delay (s) "
            "| realised | result |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    for r in rows:
        lines.append("| " + " | ".join([
            r["vehicle"], r["input"], fmt(r["physics_step"], 2), str(r["heading_deg"]),
            f"×{r['push_scale']}", fmt(r.get("tracking")), fmt(r.get("max_xi")),
            fmt(r.get("xi_max")), fmt(r.get("min_controlled")), fmt(r.get("min_centres")),
            fmt(r.get("perimeter")), fmt(r.get("accel_ratio"), 2),
            fmt(100.0 * r["limited_fraction"], 0) + " %" if "limited_fraction" in r else "",
            fmt(r.get("adapter_update"), 3), fmt(r.get("adapter_delay"), 2),
            fmt(r.get("adapter_realised"), 2), r["result"]]) + " |")
    return "\n".join(lines) + "\n"


def summary(rows):
    """Per vehicle x input x physics step, over headings and pushes: the worst case of each."""
    head = ("| vehicle | input | step (s) | cases ok | max ‖ξ‖ (m) | ξ_max (m) "
            "| min controlled points (m) | min centres (m) | perimeter (m) "
            "| a_real/a_cmd median (min–max) | adapter delay (s) |")
    lines = [head, "|" + "---|" * (head.count("|") - 1)]
    groups = {}
    for r in rows:
        groups.setdefault((r["vehicle"], r["input"], float(r["physics_step"])), []).append(r)

    def values(group, key):
        out = [float(r[key]) for r in group if r.get(key) not in (None, "")]
        return [v for v in out if not math.isnan(v)]

    for (vehicle, input_, step), group in sorted(groups.items()):
        ratios = sorted(values(group, "accel_ratio"))
        delays = values(group, "adapter_delay")
        median = ratios[len(ratios) // 2] if len(ratios) % 2 else \
            0.5 * (ratios[len(ratios) // 2 - 1] + ratios[len(ratios) // 2]) if ratios else math.nan
        lines.append("| " + " | ".join([
            vehicle, input_, fmt(step, 2),
            f"{sum(1 for r in group if r['result'] == 'ok')}/{len(group)}",
            fmt(max(values(group, "max_xi"), default=math.nan)),
            fmt(max(values(group, "xi_max"), default=math.nan)),
            fmt(min(values(group, "min_controlled"), default=math.nan)),
            fmt(min(values(group, "min_centres"), default=math.nan)),
            fmt(max(values(group, "perimeter"), default=math.nan)),
            f"{fmt(median, 2)} ({fmt(ratios[0], 2)}–{fmt(ratios[-1], 2)})" if ratios else "",
            f"{fmt(min(delays), 2)}–{fmt(max(delays), 2)}" if delays else ""]) + " |")
    return "\n".join(lines) + "\n"


def write_markdown(path, rows, note):
    with open(path, "w") as out:
        out.write(f"<!-- {note} -->\n" + summary(rows) + "\n" + markdown(rows))


COUNTS = ("statuses", "tracking", "fallback_steps", "rejected", "accel_windows")


def from_csv(path):
    """The rows of a CSV this script wrote, numbers as floats."""
    rows = []
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            for key in FIELDS[5:-1]:
                if row.get(key) not in (None, "") and key != "recorded_from":
                    number = float(row[key])
                    row[key] = int(number) if key in COUNTS else number
            row["physics_step"] = float(row["physics_step"])
            rows.append(row)
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--cases", choices=("quick", "full"), default="quick")
    parser.add_argument("--vehicles", nargs="+", default=["thymio2", "epuck"])
    parser.add_argument("--inputs", nargs="+", default=["odometry", "tf", "position"])
    parser.add_argument("--steps", nargs="+", type=float, default=[0.01, 0.05, 0.1])
    parser.add_argument("--headings", nargs="+", type=int, default=[0, 90, 180])
    parser.add_argument("--pushes", nargs="+", type=int, default=[1, 2])
    parser.add_argument("--duration", type=float, default=25.0, help="s of each run [25]")
    parser.add_argument("--look-ahead", type=float, default=0.05, help="m [0.05]")
    parser.add_argument("--window", type=float, default=0.2, help="s of each a_real [0.2]")
    parser.add_argument("--csv", default=str(ROOT / "doc" / "vehicles_enki.csv"))
    parser.add_argument("--md", default=str(ROOT / "doc" / "vehicles_enki.md"))
    parser.add_argument("--adapter-world-frame", default="world",
                        help="the adapter's ~world_frame; none leaves it to the odometry's frame "
                             "(commands turned by tf) [world]")
    parser.add_argument("--port", type=int, default=11431)
    parser.add_argument("--keep", help="directory for the bags and logs (default: a temporary one)")
    parser.add_argument("--from-csv", metavar="CSV",
                        help="run nothing: write --md again from a CSV this script wrote")
    args = parser.parse_args()

    if args.from_csv:
        rows = from_csv(args.from_csv)
        write_markdown(args.md, rows, f"experiments/enki_sweep/run.sh: {len(rows)} cases "
                                      f"(from {pathlib.Path(args.from_csv).name})")
        return 0
    if args.cases == "quick":
        cases = QUICK
    else:
        cases = list(itertools.product(args.vehicles, args.inputs, args.steps, args.headings,
                                       args.pushes))
    with tempfile.TemporaryDirectory() as tmp:
        work = pathlib.Path(args.keep or tmp)
        work.mkdir(parents=True, exist_ok=True)
        rows = []
        for n, case in enumerate(cases, 1):
            row = run_case(case, args, work)
            rows.append(row)
            print(f"[{n}/{len(cases)}] " + " ".join(f"{k}={fmt(row.get(k))}" for k in FIELDS
                                                    if k in row), flush=True)
        pathlib.Path(args.csv).parent.mkdir(parents=True, exist_ok=True)
        with open(args.csv, "w", newline="") as out:
            writer = csv.DictWriter(out, FIELDS, extrasaction="ignore")
            writer.writeheader()
            for row in rows:
                writer.writerow({k: fmt(row.get(k), 4) if isinstance(row.get(k), float)
                                 else row.get(k, "") for k in FIELDS})
        write_markdown(args.md, rows, f"experiments/enki_sweep/run.sh --cases {args.cases}: "
                                      f"{len(rows)} cases, {args.duration:g} s each")
        print(summary(rows), end="")
    return 0 if all(r["result"] == "ok" for r in rows) else 1


if __name__ == "__main__":
    sys.exit(main())
