#!/usr/bin/python3
"""Plot one or more leader-follower runs in the style of the paper's Figs. 4-7.

Usage::

    plot_run.py RUN.csv|RUN.bag [RUN2 ...] -o OUT.png [--title T ...] [--xlim T0 T1]

Each run becomes one column of stacked subplots sharing the time axis:

  (a) leader and follower positions (one line per axis)          -- Fig. 4
  (b) the leader disturbance components ud_*                      -- Fig. 5
  (c) one panel per relative-error component xi_i: true xi_i, the
      CF estimate xi_hat_i, the hard bounds +-xi_max (solid) and the
      soft bounds +-xi_soft (dashed)                              -- Figs. 6, 7
  (d) ||xi|| and ||xi_hat|| against xi_max
  (e) the position separation against the safety perimeter

Several runs are drawn side by side, with a common y range per row when the
runs have the same layout, so e.g. Run 1 and Run 2 compare at a glance.

The input is the CSV of ``cf_sim --csv`` / ``reference_sim.py --csv``
(doc/cf_sim.md, section 'Scenario files') or a rosbag recorded by the demo
(``roslaunch projection_collision_avoidance demo.launch record:=true``; see load_bag()).
Loading is done by load_run(), which dispatches on the file name to a loader
returning a dict of column name -> numpy array, the same columns for every loader,
so a bag and a CSV of the same run plot alike.
"""

from __future__ import annotations

import argparse
import csv
import os
import re
import sys

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)

PROG = "plot_run"


# --------------------------------------------------------------------------
# Loading
# --------------------------------------------------------------------------

def load_csv(path):
    """Read a run CSV into {column name: 1-D float array} (header row first)."""
    with open(path, newline="", encoding="utf-8") as fh:
        reader = csv.reader(fh)
        try:
            header = [h.strip() for h in next(reader)]
        except StopIteration:
            raise ValueError(f"{path}: empty file") from None
        rows = [r for r in reader if r]
    if not rows:
        raise ValueError(f"{path}: no data rows")
    try:
        data = np.array(rows, dtype=float)
    except ValueError as exc:
        raise ValueError(f"{path}: non-numeric data ({exc})") from None
    if data.ndim != 2 or data.shape[1] != len(header):
        raise ValueError(f"{path}: rows do not match the {len(header)} header columns")
    return {name: data[:, i] for i, name in enumerate(header)}


# --------------------------------------------------------------------------
# rosbag recordings (roslaunch projection_collision_avoidance demo.launch record:=true)
# --------------------------------------------------------------------------

# Topics of the demo's recording, by role. A role whose topic is not in the bag
# is looked up by message type when exactly one topic has that type.
BAG_TOPICS = {
    "status": ("/follower/status", "projection_collision_avoidance/FollowerStatus"),
    "leader_odom": ("/leader/odom", None),
    "follower_odom": ("/follower/odom", None),
    "broadcast": ("/leader/broadcast", "projection_collision_avoidance/LeaderBroadcast"),
    "leader_command": ("/leader/command", None),
}


def _stamp(msg, record_time):
    """A message's header stamp in s; its record time when the stamp is unset."""
    stamp = msg.header.stamp
    if stamp.secs == 0 and stamp.nsecs == 0:
        return record_time.to_sec()
    return stamp.to_sec()


def _bag_topic_map(bag, path):
    """{role: topic in this bag, or None}."""
    info = bag.get_type_and_topic_info().topics
    roles = {}
    for role, (name, msg_type) in BAG_TOPICS.items():
        topic = name if name in info else None
        if topic is None and msg_type is not None:
            same = [t for t, i in info.items() if i.msg_type == msg_type]
            topic = same[0] if len(same) == 1 else None
        roles[role] = topic
    if roles["status"] is None:
        raise ValueError(f"{path}: no {BAG_TOPICS['status'][0]} "
                         f"({BAG_TOPICS['status'][1]}) messages")
    return roles


def _fixed_width(rows, width, what, path):
    """rows (lists, possibly empty) as a (len, width) array; empty rows become zeros."""
    out = np.zeros((len(rows), width))
    for i, row in enumerate(rows):
        if len(row) == width:
            out[i] = row
        elif len(row):
            raise ValueError(f"{path}: {what} has {len(row)} entries, expected {width}")
    return out


def _hold(t_samples, values, t, width):
    """Zero-order hold of values (one row per sample time) onto t; zeros before the first."""
    out = np.zeros((t.size, width))
    if not len(t_samples):
        return out
    order = np.argsort(t_samples, kind="stable")
    ts, vs = np.asarray(t_samples)[order], np.asarray(values).reshape(-1, width)[order]
    idx = np.searchsorted(ts, t, side="right") - 1
    held = idx >= 0
    out[held] = vs[idx[held]]
    return out


def _warn_gaps(path, topic, stamps, origin, how):
    """Warn on stderr when a topic has a hole much longer than its usual interval.

    rosbag record drops messages when it (or the machine) cannot keep up, e.g. at a high
    real_time_factor; the columns taken from that topic are then filled in by `how`.
    """
    stamps = np.sort(np.asarray(stamps, dtype=float))
    if stamps.size < 3:
        return
    gaps = np.diff(stamps)
    limit = max(0.1, 20.0 * float(np.median(gaps)))
    holes = np.flatnonzero(gaps > limit)
    if holes.size:
        worst = holes[np.argmax(gaps[holes])]
        print(f"{PROG}: warning: {path}: {topic} has {holes.size} gap(s) longer than "
              f"{limit:.3g} s, the longest {gaps[worst]:.3g} s from t = "
              f"{stamps[worst] - origin:.3f} s (not published, or dropped by rosbag record); "
              f"{how} across them", file=sys.stderr)


def load_bag(path):
    """Read a rosbag of the demo into the columns of the cf_sim CSV.

    One row per /follower/status message (ordered by header stamp): t is the stamp, xi_*,
    xi_hat_*, norms, bounds, f, projection_active, separation, perimeter and the commands
    come from the status; leader/follower positions and velocities are /leader/odom and
    /follower/odom linearly interpolated onto the status stamps; ud_* (leader disturbance)
    and leader_u_* (leader input) are /leader/broadcast held from one broadcast to the next
    (zeros before the first one, and ud_* zeros when the broadcast does not carry it);
    leader_u_* falls back to /leader/command without broadcasts.

    Messages are deserialised from the definitions stored in the bag, so the package's
    generated Python messages need not be importable. Under simulated time (/clock in the
    bag) t is the simulated time; otherwise t counts from the first odometry stamp (the
    plant's tick 0), or the first status stamp without odometry.
    """
    try:
        import rosbag  # Debian python3-rosbag; imported here so that CSVs need no ROS
    except ImportError as exc:
        raise ValueError(f"{path}: reading a bag needs the rosbag Python module "
                         f"(python3-rosbag; run with /usr/bin/python3): {exc}") from None
    try:
        bag = rosbag.Bag(path)
    except rosbag.ROSBagException as exc:
        raise ValueError(f"{path}: not a readable bag ({exc})") from None
    with bag:
        roles = _bag_topic_map(bag, path)
        sim_time = "/clock" in bag.get_type_and_topic_info().topics
        by_topic = {}
        for role, topic in roles.items():
            if topic is not None:
                by_topic.setdefault(topic, []).append(role)
        data = {role: [] for role in roles}
        for topic, msg, rec in bag.read_messages(topics=list(by_topic), raw=False):
            for role in by_topic[topic]:
                data[role].append((msg, rec))

    status = sorted(data["status"], key=lambda mr: _stamp(*mr))
    if not status:
        raise ValueError(f"{path}: {roles['status']} has no messages")
    msgs = [m for m, _ in status]
    n = len(msgs[0].xi)
    m = len(msgs[0].command)
    if n == 0 or n % 2:
        raise ValueError(f"{path}: status xi has {n} entries; expected 2 per axis "
                         f"(double integrator)")
    k = n // 2

    def odometry(role):
        samples = data[role]
        if not samples:
            raise ValueError(f"{path}: no {BAG_TOPICS[role][0]} messages")
        samples = sorted(samples, key=lambda mr: _stamp(*mr))
        ts = np.array([_stamp(mm, rr) for mm, rr in samples])
        pos = np.array([[o.pose.pose.position.x, o.pose.pose.position.y,
                         o.pose.pose.position.z][:k] for o, _ in samples])
        vel = np.array([[o.twist.twist.linear.x, o.twist.twist.linear.y,
                         o.twist.twist.linear.z][:k] for o, _ in samples])
        return ts, pos, vel

    leader_odom = odometry("leader_odom")
    follower_odom = odometry("follower_odom")

    t_abs = np.array([_stamp(mm, rr) for mm, rr in status])
    if sim_time:
        origin = 0.0
    else:
        origin = min(leader_odom[0][0], follower_odom[0][0])
    t = t_abs - origin
    _warn_gaps(path, roles["status"], t_abs, origin, "the plot draws straight lines")
    for role, (ts, _, _) in (("leader_odom", leader_odom), ("follower_odom", follower_odom)):
        _warn_gaps(path, roles[role], ts, origin, "positions and velocities are interpolated")

    def status_array(field, width):
        return _fixed_width([getattr(s, field) for s in msgs], width,
                            f"{roles['status']} {field}", path)

    cols = {"t": t}
    xi = status_array("xi", n)
    xi_hat = status_array("xi_hat", n)
    for i in range(n):
        cols[f"xi_{i}"] = xi[:, i]
    for i in range(n):
        cols[f"xi_hat_{i}"] = xi_hat[:, i]
    for name, field in (("norm_xi", "xi_norm"), ("norm_xi_hat", "xi_hat_norm"),
                        ("xi_max", "xi_max"), ("xi_soft", "xi_soft"), ("f", "constraint")):
        cols[name] = np.array([getattr(s, field) for s in msgs], dtype=float)
    cols["projection_active"] = np.array([1.0 if s.projection_active else 0.0 for s in msgs])

    for who, (ts, pos, vel) in (("leader", leader_odom), ("follower", follower_odom)):
        for i in range(k):
            cols[f"{who}_p_{i}"] = np.interp(t_abs, ts, pos[:, i])
    for who, (ts, pos, vel) in (("leader", leader_odom), ("follower", follower_odom)):
        for i in range(k):
            cols[f"{who}_v_{i}"] = np.interp(t_abs, ts, vel[:, i])

    cols["separation"] = np.array([s.distance for s in msgs], dtype=float)
    cols["perimeter"] = np.array([s.perimeter for s in msgs], dtype=float)
    for prefix, field in (("u", "command"), ("u_baseline", "baseline_command"),
                          ("u_tracker", "tracker_command")):
        values = status_array(field, m)
        for i in range(m):
            cols[f"{prefix}_{i}"] = values[:, i]

    broadcast = data["broadcast"]
    if broadcast:
        tb = [_stamp(mm, rr) for mm, rr in broadcast]
        _warn_gaps(path, roles["broadcast"], tb, origin, "ud_* and leader_u_* are held")
        leader_u = _hold(tb, _fixed_width([b.input for b, _ in broadcast], m,
                                          f"{roles['broadcast']} input", path), t_abs, m)
        ud = _hold(tb, _fixed_width([b.disturbance for b, _ in broadcast], n,
                                    f"{roles['broadcast']} disturbance", path), t_abs, n)
    else:
        command = data["leader_command"]
        tc = [_stamp(mm, rr) for mm, rr in command]
        leader_u = _hold(tc, np.array([[c.accel.linear.x, c.accel.linear.y,
                                        c.accel.linear.z][:m] for c, _ in command]),
                         t_abs, m)
        ud = np.zeros((t.size, n))
    for i in range(m):
        cols[f"leader_u_{i}"] = leader_u[:, i]
    for i in range(n):
        cols[f"ud_{i}"] = ud[:, i]
    return cols


# File-name suffix -> loader. Each loader returns {column: np.ndarray}
# with the column names of doc/cf_sim.md, section 'Scenario files'.
LOADERS = {".csv": load_csv, ".bag": load_bag}

REQUIRED = ("t", "xi_0", "xi_hat_0", "norm_xi", "norm_xi_hat", "xi_max", "xi_soft",
            "leader_p_0", "follower_p_0", "separation", "perimeter")


def load_run(path):
    """Load a run with the loader registered for its file suffix and check the columns."""
    suffix = os.path.splitext(path)[1].lower()
    loader = LOADERS.get(suffix)
    if loader is None:
        raise ValueError(f"{path}: no loader for '{suffix}' files "
                         f"(known: {', '.join(sorted(LOADERS))})")
    cols = loader(path)
    missing = [c for c in REQUIRED if c not in cols]
    if missing:
        raise ValueError(f"{path}: missing columns {', '.join(missing)}")
    return cols


def indexed(cols, prefix):
    """Sorted indices i of the columns named prefix + str(i)."""
    pat = re.compile(re.escape(prefix) + r"(\d+)$")
    return sorted(int(m.group(1)) for m in map(pat.match, cols) if m)


# --------------------------------------------------------------------------
# Layout
# --------------------------------------------------------------------------

class RunLayout:
    """What one run provides: sizes and the units of its state components."""

    def __init__(self, cols):
        self.n = len(indexed(cols, "xi_"))
        self.k = len(indexed(cols, "leader_p_"))
        self.double_integrator = bool(indexed(cols, "leader_v_"))
        self.has_ud = bool(indexed(cols, "ud_"))
        self.axis_names = "xyz" if self.k <= 3 else [str(i) for i in range(self.k)]

    def rows(self):
        """Row kinds, top to bottom."""
        kinds = ["positions"]
        if self.has_ud:
            kinds.append("disturbance")
        kinds += [("xi", i) for i in range(self.n)]
        kinds += ["norms", "separation"]
        return kinds

    def component(self, i):
        """(description, unit) of state component i."""
        if not self.double_integrator:
            kind = "position" if i < self.k else "state"
            return f"{kind} {i}", ("m" if i < self.k else "state units")
        axis = self.axis_names[i % self.k]
        return (f"p_{axis}", "m") if i < self.k else (f"v_{axis}", "m/s")

    def disturbance_unit(self, i):
        if not self.double_integrator:
            return "state units/s"
        return "m/s" if i < self.k else "m/s²"


# --------------------------------------------------------------------------
# Drawing
# --------------------------------------------------------------------------

TRUE_STYLE = dict(color="tab:blue", lw=1.3)
EST_STYLE = dict(color="tab:orange", lw=1.3, ls="--")
HARD_STYLE = dict(color="tab:red", lw=1.0)
SOFT_STYLE = dict(color="tab:red", lw=0.9, ls=(0, (5, 4)), alpha=0.7)


def draw_positions(ax, c, lay):
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for i in range(lay.k):
        name = lay.axis_names[i] if lay.double_integrator else str(i)
        ax.plot(c["t"], c[f"leader_p_{i}"], color=colors[2 * i % len(colors)], lw=1.3,
                label=f"leader p_{name}")
        ax.plot(c["t"], c[f"follower_p_{i}"], color=colors[(2 * i + 1) % len(colors)], lw=1.3,
                ls="--", label=f"follower p_{name}")
    ax.set_ylabel("position (m)")
    ax.set_title("(a) leader and follower positions", loc="left", fontsize=9)


def draw_disturbance(ax, c, lay):
    # Components are often equal (the paper's pulse is [-2, -2]): vary the
    # dash pattern and width so that coinciding lines stay distinguishable.
    dashes = ["-", "--", "-.", ":"]
    for j, i in enumerate(indexed(c, "ud_")):
        if lay.double_integrator:
            label = f"u_d,{i}: {lay.component(i)[0]} rate ({lay.disturbance_unit(i)})"
        else:
            label = f"u_d,{i} ({lay.disturbance_unit(i)})"
        ax.plot(c["t"], c[f"ud_{i}"], lw=2.2 if j == 0 else 1.3, ls=dashes[j % len(dashes)],
                label=label)
    ax.set_ylabel("disturbance\n(m/s, m/s²)" if lay.double_integrator else "disturbance")
    ax.set_title("(b) leader disturbance u_d", loc="left", fontsize=9)


def draw_bounds(ax, c, hard_label, soft_label, both_signs=True):
    t = c["t"]
    ax.plot(t, c["xi_max"], label=hard_label, **HARD_STYLE)
    ax.plot(t, c["xi_soft"], label=soft_label, **SOFT_STYLE)
    if both_signs:
        ax.plot(t, -c["xi_max"], **HARD_STYLE)
        ax.plot(t, -c["xi_soft"], **SOFT_STYLE)


def draw_xi(ax, c, lay, i, letter):
    desc, unit = lay.component(i)
    ax.plot(c["t"], c[f"xi_{i}"], label=fr"$\xi_{{{i}}}$ true", **TRUE_STYLE)
    ax.plot(c["t"], c[f"xi_hat_{i}"], label=fr"$\hat{{\xi}}_{{{i}}}$ CF estimate", **EST_STYLE)
    # The bounds are on the norm of the whole vector; they are drawn in every
    # component panel as in the paper (in m; the same number for velocities).
    draw_bounds(ax, c, r"$\pm\xi_{max}$ (hard)", r"$\pm\xi_{max}/\sqrt{1+\varepsilon}$ (soft)")
    ax.set_ylabel(fr"$\xi_{{{i}}}$: {desc} ({unit})")
    ax.set_title(f"({letter}) relative error component {i} ({desc})", loc="left", fontsize=9)


def draw_norms(ax, c, lay, letter):
    ax.plot(c["t"], c["norm_xi"], label=r"$\Vert\xi\Vert$ true", **TRUE_STYLE)
    ax.plot(c["t"], c["norm_xi_hat"], label=r"$\Vert\hat{\xi}\Vert$ CF estimate", **EST_STYLE)
    draw_bounds(ax, c, r"$\xi_{max}$ (hard)", r"$\xi_{max}/\sqrt{1+\varepsilon}$ (soft)",
                both_signs=False)
    if "projection_active" in c:
        on = c["projection_active"] > 0.5
        if np.any(on):
            ax.fill_between(c["t"], 0, 1, where=on, transform=ax.get_xaxis_transform(),
                            color="tab:purple", alpha=0.12, lw=0, label="projection active")
    ax.set_ylabel("norm (m, m/s)" if lay.double_integrator else "norm")
    ax.set_title(f"({letter}) relative error norms", loc="left", fontsize=9)


def draw_separation(ax, c, letter):
    ax.plot(c["t"], c["separation"], color="tab:green", lw=1.3,
            label=r"separation $\Vert p_1 - p_2\Vert$")
    ax.plot(c["t"], c["perimeter"], label=r"safety perimeter $\alpha\Vert d\Vert$", **HARD_STYLE)
    below = c["separation"] < c["perimeter"]
    if np.any(below):
        ax.fill_between(c["t"], 0, 1, where=below, transform=ax.get_xaxis_transform(),
                        color="tab:red", alpha=0.15, lw=0, label="perimeter violated")
    ax.set_ylabel("separation (m)")
    ax.set_title(f"({letter}) position separation", loc="left", fontsize=9)


def crop(cols, t0, t1):
    """The rows of a run with t0 <= t <= t1 (all of it if none fall inside)."""
    keep = (cols["t"] >= t0) & (cols["t"] <= t1)
    if np.count_nonzero(keep) < 2:
        return cols
    return {name: values[keep] for name, values in cols.items()}


def _row_legend(axes_row, outside):
    """One legend for a row: handles of all its panels, each label once."""
    seen = {}
    for ax in axes_row:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            seen.setdefault(label, handle)
    if outside:
        axes_row[-1].legend(seen.values(), seen.keys(), loc="upper left",
                            bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0,
                            fontsize=7.5, frameon=False)
    else:
        for ax in axes_row:
            ax.legend(loc="upper right", fontsize=7, framealpha=0.85)


def plot_runs(runs, titles, out, dpi=110, column_width=7.0, xlim=None):
    """Draw the runs (list of column dicts) side by side and save the figure to out.

    xlim: optional (t0, t1) time window, s; default the whole run. The runs
    are cut to it, so that every y range fits the part shown.
    """
    if xlim:
        runs = [crop(c, *xlim) for c in runs]
    layouts = [RunLayout(c) for c in runs]
    row_lists = [lay.rows() for lay in layouts]
    nrows = max(len(r) for r in row_lists)
    # Runs with the same rows share one y range per row and one legend per
    # row (right of the last column); otherwise every panel has its own.
    same_layout = all(r == row_lists[0] for r in row_lists)
    legend_width = 2.4 if same_layout else 0.0
    fig, axes = plt.subplots(nrows, len(runs), squeeze=False, layout="constrained",
                             figsize=(column_width * len(runs) + legend_width, 1.9 * nrows + 0.8),
                             sharex="col", sharey="row" if same_layout else False)

    for col, (c, lay, rows, title) in enumerate(zip(runs, layouts, row_lists, titles)):
        for row, kind in enumerate(rows):
            ax = axes[row, col]
            if kind == "positions":
                draw_positions(ax, c, lay)
            elif kind == "disturbance":
                draw_disturbance(ax, c, lay)
            elif kind == "norms":
                draw_norms(ax, c, lay, "d")
            elif kind == "separation":
                draw_separation(ax, c, "e")
            else:
                draw_xi(ax, c, lay, kind[1], f"c{kind[1] + 1}")
            ax.grid(True, lw=0.4, alpha=0.5)
            ax.tick_params(labelsize=8, labelleft=True)
            ax.yaxis.label.set_size(8)
        for row in range(len(rows), nrows):
            axes[row, col].set_visible(False)
        last = axes[len(rows) - 1, col]
        last.set_xlabel("time (s)")
        last.tick_params(labelbottom=True)
        t = c["t"]
        # The rows are one per control period: the last period ends one step after t[-1].
        t_end = t[-1] + (t[-1] - t[-2] if t.size > 1 else 0.0)
        last.set_xlim(xlim if xlim else (t[0], t_end if t_end > t[0] else t[0] + 1.0))
        # The run title goes on its own line above the panel title of (a).
        axes[0, col].annotate(title, xy=(0.5, 1.0), xycoords="axes fraction",
                              xytext=(0, 20), textcoords="offset points",
                              ha="center", va="bottom", fontsize=11, fontweight="bold")

    # Norm and separation panels start at 0; their top covers every run of the row.
    for col, (c, rows) in enumerate(zip(runs, row_lists)):
        for row, kind in enumerate(rows):
            if kind in ("norms", "separation"):
                keys = (("norm_xi", "norm_xi_hat", "xi_max") if kind == "norms"
                        else ("separation", "perimeter"))
                cols_of_row = runs if same_layout else [c]
                top = max(float(np.max(r[key])) for r in cols_of_row for key in keys)
                axes[row, col].set_ylim(0.0, 1.08 * top if top > 0 else 1.0)

    for row in range(nrows):
        _row_legend([ax for ax in axes[row] if ax.get_visible()], outside=same_layout)

    fig.savefig(out, dpi=dpi)
    plt.close(fig)


def parse_args(argv):
    ap = argparse.ArgumentParser(
        prog="plot_run.py",
        description="Plot leader-follower runs (CSV of cf_sim / reference_sim, or a rosbag "
                    "of the demo) like the paper's Figs. 4-7, one column per run.")
    ap.add_argument("runs", nargs="+", metavar="RUN.csv|RUN.bag", help="run recordings")
    ap.add_argument("-o", "--output", required=True, metavar="OUT.png", help="image to write")
    ap.add_argument("--title", action="append", default=[], metavar="T",
                    help="column title, once per run in order (default: file name)")
    ap.add_argument("--xlim", type=float, nargs=2, metavar=("T0", "T1"),
                    help="time window to show, s (default: the whole run)")
    ap.add_argument("--dpi", type=int, default=110, help="resolution (default 110)")
    return ap.parse_args(argv)


def main(argv=None):
    args = parse_args(argv)
    if len(args.title) > len(args.runs):
        print(f"{PROG}: error: more --title than runs", file=sys.stderr)
        return 2
    titles = args.title + [os.path.basename(p) for p in args.runs[len(args.title):]]
    try:
        runs = [load_run(p) for p in args.runs]
    except (OSError, ValueError) as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return 1
    plot_runs(runs, titles, args.output, dpi=args.dpi, xlim=args.xlim)
    return 0


if __name__ == "__main__":
    sys.exit(main())
