#!/usr/bin/env python3
"""Plots a recorded run of launch/vehicles.launch (record:=true) from its bag.

(a) the x-y paths of the leader (/leader/odom) and the followers (/follower_<i>/odom), with
    heading arrows, and at the instant of the smallest separation the safety perimeter (status
    perimeter) around each follower's controlled point;
(b) each follower's ||xi|| (status xi_norm) against its xi_max;
(c) the distance between each follower's controlled point and its target's (from the odometry)
    against the perimeter.
The controlled point is look_ahead m ahead of the origin along the body x axis (unicycles); the
leader's is its origin. Prints, per follower: max ||xi||, xi_max, min controlled-point distance,
perimeter, final ||xi||.

Usage: plot_vehicles.py BAG [-o PNG] [--look-ahead M] [--title TEXT] [--push T0 T1]
"""
import argparse
import math
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import rosbag  # noqa: E402


def yaw_of(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def read_bag(path):
    """Odometry per agent as {stamp_ns: (x, y, yaw, vx, vy)} (velocity in the world frame), and
    the statuses per follower index as arrays."""
    odom, status = {}, {}
    odom_re = re.compile(r"^/(leader|follower_\d+)/odom$")
    status_re = re.compile(r"^/follower_(\d+)/status$")
    with rosbag.Bag(path) as bag:
        for topic, m, _ in bag.read_messages():
            match = odom_re.match(topic)
            if match:
                p, t = m.pose.pose.position, m.twist.twist.linear
                yaw = yaw_of(m.pose.pose.orientation)
                # REP 105: the twist in the body frame (child_frame_id).
                vx = math.cos(yaw) * t.x - math.sin(yaw) * t.y
                vy = math.sin(yaw) * t.x + math.cos(yaw) * t.y
                odom.setdefault(match.group(1), {})[m.header.stamp.to_nsec()] = (p.x, p.y, yaw, vx, vy)
                continue
            match = status_re.match(topic)
            if match and m.mode != m.MODE_WAITING:
                s = status.setdefault(int(match.group(1)), {"t": [], "xi": [], "xi_max": [],
                                                            "perimeter": [], "target": m.target})
                s["t"].append(m.header.stamp.to_sec())
                s["xi"].append(m.xi_norm)
                s["xi_max"].append(m.xi_max)
                s["perimeter"].append(m.perimeter)
    for s in status.values():
        for key in ("t", "xi", "xi_max", "perimeter"):
            s[key] = np.asarray(s[key])
    return odom, status


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("bag")
    parser.add_argument("-o", "--out", default="vehicles_run.png")
    parser.add_argument("--look-ahead", type=float, default=0.4,
                        help="m, the followers' controlled point ahead of the origin (0 for kind velocity)")
    parser.add_argument("--title", default="vehicles.launch")
    parser.add_argument("--push", type=float, nargs=2, default=(20.0, 23.0), metavar=("T0", "T1"),
                        help="s, the leader's push (shaded)")
    args = parser.parse_args()

    odom, status = read_bag(args.bag)
    followers = sorted(status)
    if "leader" not in odom or not followers:
        raise SystemExit("plot_vehicles: no /leader/odom or no /follower_<i>/status in " + args.bag)
    # The instants at which every agent has an odometry message.
    stamps = sorted(set.intersection(*(set(v) for v in odom.values())))
    t = np.array(stamps) * 1e-9
    agents = {name: np.array([odom[name][s] for s in stamps]) for name in odom}

    def controlled_point(name):
        a = agents[name]
        look = 0.0 if name == "leader" else args.look_ahead
        return a[:, 0:2] + look * np.column_stack((np.cos(a[:, 2]), np.sin(a[:, 2])))

    points = {name: controlled_point(name) for name in agents}
    distance = {i: np.linalg.norm(points[status[i]["target"]] - points["follower_%d" % i], axis=1)
                for i in followers}
    # The instant of the smallest separation of a follower from its target.
    closest = min(followers, key=lambda i: distance[i].min())
    k_min = int(np.argmin(distance[closest]))
    t_min = t[k_min]

    names = ["leader"] + ["follower_%d" % i for i in followers]
    colours = {"leader": "black"}
    cycle = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for n, i in enumerate(followers):
        colours["follower_%d" % i] = cycle[n % len(cycle)]

    fig = plt.figure(figsize=(12, 10), constrained_layout=True)
    grid = fig.add_gridspec(2, 2, height_ratios=(1.35, 1))
    ax_xy = fig.add_subplot(grid[0, :])
    ax_xi = fig.add_subplot(grid[1, 0])
    ax_d = fig.add_subplot(grid[1, 1], sharex=ax_xi)
    fig.suptitle(args.title)

    # (a) paths, heading arrows every 8 s, and the perimeters at t_min.
    period = float(np.median(np.diff(t)))
    arrow_every = max(1, int(round(8.0 / period)))
    span = max(np.ptp(np.concatenate([a[:, 0] for a in agents.values()])),
               np.ptp(np.concatenate([a[:, 1] for a in agents.values()])))
    arrow = 0.04 * span
    for name in names:
        a = agents[name]
        ax_xy.plot(a[:, 0], a[:, 1], color=colours[name], lw=1.2, label=name.replace("_", " "))
        k = np.arange(arrow_every // 2, len(a), arrow_every)
        if name == "leader":  # a double integrator: its arrows along its velocity
            heading = np.arctan2(a[k, 4], a[k, 3])
        else:
            heading = a[k, 2]
        ax_xy.quiver(a[k, 0], a[k, 1], arrow * np.cos(heading), arrow * np.sin(heading),
                     color=colours[name], angles="xy", scale_units="xy", scale=1, width=0.003)
        ax_xy.plot(*a[0, 0:2], marker="o", color=colours[name], ms=6, mfc="white")
    ax_xy.plot(*points["leader"][k_min], marker="*", color="black", ms=13, ls="none")
    for i in followers:
        name = "follower_%d" % i
        centre = points[name][k_min]
        perimeter = np.interp(t_min, status[i]["t"], status[i]["perimeter"])
        ax_xy.add_patch(plt.Circle(centre, perimeter, fill=False, color=colours[name], lw=1.5))
        ax_xy.plot(*centre, marker="+", color=colours[name], ms=9, mew=2)
    ax_xy.plot([], [], "o", color="grey", mfc="white", ms=6, label="start (t = %.1f s)" % t[0])
    ax_xy.plot([], [], "*", color="black", ms=13, label="leader at t = %.2f s (closest)" % t_min)
    ax_xy.plot([], [], "+", color="grey", ms=9, mew=2,
               label="controlled points at t = %.2f s, perimeter circles" % t_min)
    ax_xy.set_aspect("equal", adjustable="datalim")
    ax_xy.set_xlabel("x (m)")
    ax_xy.set_ylabel("y (m)")
    ax_xy.set_title("(a) paths, arrows: heading every %.0f s" % (arrow_every * period))
    ax_xy.grid(alpha=0.3)
    ax_xy.legend(loc="lower left", fontsize=9)

    # (b) ||xi|| against xi_max; (c) controlled-point distance against the perimeter.
    # Follower 1 widest, so that curves that coincide stay visible.
    for n, i in enumerate(followers):
        c, s, lw = colours["follower_%d" % i], status[i], 1.0 + 1.2 * (len(followers) - 1 - n)
        ax_xi.plot(s["t"], s["xi"], color=c, lw=lw)
        ax_xi.plot(s["t"], s["xi_max"], color=c, lw=1.0, ls="--")
        ax_d.plot(t, distance[i], color=c, lw=lw)
        ax_d.plot(s["t"], s["perimeter"], color=c, lw=1.0, ls="--")
    targets = sorted({status[i]["target"].replace("_", " ") for i in followers})
    for ax, solid, dashed in ((ax_xi, "‖ξ‖", "ξ_max"),
                              (ax_d, "distance to " + ", ".join(targets), "perimeter")):
        ax.axvspan(*args.push, color="orange", alpha=0.2, lw=0)
        ax.axvline(t_min, color="grey", lw=0.8, ls=":")
        ax.set_ylim(0, 1.15 * ax.get_ylim()[1])
        ax.grid(alpha=0.3)
        ax.plot([], [], color="grey", lw=1.2, label=solid)
        ax.plot([], [], color="grey", lw=1.0, ls="--", label=dashed)
        ax.fill_between([], [], color="orange", alpha=0.2, lw=0,
                        label="push, %g-%g s" % tuple(args.push))
        ax.plot([], [], color="grey", lw=0.8, ls=":", label="t = %.2f s (closest)" % t_min)
        ax.legend(loc="best", fontsize=9, ncol=2)
        ax.set_xlabel("t (s)")
    ax_xi.set_ylabel("‖ξ‖, ξ_max (m)")
    ax_xi.set_title("(b) ‖ξ‖ of each follower against its ξ_max")
    ax_d.set_ylabel("distance, perimeter (m)")
    ax_d.set_title("(c) controlled points: distance to the target's")
    ax_d.set_xlim(0, t[-1])
    fig.savefig(args.out, dpi=110)

    print("wrote %s: %.1f s of %d followers; smallest separation at t = %.2f s (follower %d)"
          % (args.out, t[-1], len(followers), t_min, closest))
    print("| follower | target | max ‖ξ‖ (m) | ξ_max (m) | min distance of the controlled points (m) "
          "| perimeter (m) | ‖ξ‖ at %.0f s (m) |" % status[followers[0]]["t"][-1])
    print("|---|---|---|---|---|---|---|")
    for i in followers:
        s = status[i]
        print("| %d | %s | %.3f | %.1f | %.3f | %.1f | %.3f |" % (
            i, s["target"], s["xi"].max(), s["xi_max"].max(), distance[i].min(),
            s["perimeter"].min(), s["xi"][-1]))


if __name__ == "__main__":
    main()
