#!/usr/bin/python3
"""Tables and figure of formation runs of cf_sim: does the error grow along a chain?

Usage::

    plot_string_stability.py --run LABEL CF_SIM_OUTPUT [--run ...] --scenario SCENARIO.yaml
                             --md OUT.md --png OUT.png [--info TEXT]

Each CF_SIM_OUTPUT is the stdout of one ``cf_sim SCENARIO --set formation.followers=N ...``
run (the scenario's controller.alpha unchanged): a line ``follower_<i> target=<..>
max_xi=.. max_xi_hat=.. xi_max=.. min_separation=.. time_outside=.. wall_s=..`` per
follower and a closing ``formation ... min_pair_separation=..``.

Writes
  OUT.md   peak ||xi_i|| per follower i and configuration (bold when above xi_i's bound),
           the mean over i >= 2 of peak_{i+1} / peak_i (follower 1 is the only one that sees
           the leader's disturbance directly; > 1 means the error grows along the chain, i.e.
           string instability), then the min separation of each follower to its target
           (bold when inside the perimeter) and the formation's min pair separation;
  OUT.png  the same two quantities against i, one line per configuration, with the bounds.

Rerun everything with scripts/string_stability.sh.
"""

from __future__ import annotations

import argparse
import re
import sys

import numpy as np
import yaml
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)

ZERO = 1e-9   # m (1 nm): a peak below this is numerically zero, a ratio of two such is meaningless


def parse(path):
    """{"followers": [{index, target, max_xi, xi_max, min_separation, ...}], "pair": float}."""
    followers, pair = [], None
    with open(path, encoding="utf-8") as fh:
        for line in fh:
            m = re.match(r"follower_(\d+) target=(\S+) (.*)", line.strip())
            if m:
                values = dict(tok.split("=", 1) for tok in m.group(3).split())
                entry = {k: float(v) for k, v in values.items()}
                entry.update(index=int(m.group(1)), target=m.group(2))
                followers.append(entry)
            elif line.startswith("formation "):
                values = dict(tok.split("=", 1) for tok in line.split()[1:])
                pair = float(values["min_pair_separation"])
    if not followers or pair is None:
        raise ValueError(f"{path}: not the output of a cf_sim formation run")
    followers.sort(key=lambda f: f["index"])
    return {"followers": followers, "pair": pair}


def fmt(value, bold=False):
    text = f"{value:.1e}" if abs(value) < 1e-3 and value != 0 else f"{value:.3f}"
    return f"**{text}**" if bold else text


def ratio_text(peaks):
    """Mean (min-max) of peak_{i+1}/peak_i over i >= 2 (1-based), or why there is none."""
    tail = np.asarray(peaks[1:])
    if tail.size < 2:
        return "n/a (fewer than 3 followers)", None
    if np.any(tail < ZERO):
        return "n/a (peaks < 1 nm: numerically zero)", None
    ratios = tail[1:] / tail[:-1]
    return f"{ratios.mean():.3f} ({ratios.min():.3f}–{ratios.max():.3f})", ratios.mean()


def markdown(runs, info, alpha):
    labels = list(runs)
    n = max(len(r["followers"]) for r in runs.values())
    lines = ["# String stability", ""]
    if info:
        lines += [info, ""]
    lines += [
        "Peak ‖ξ_i‖ over the run, ξ_i = x_target − x_i − d_i, for each follower i (chain: the "
        "target of follower i is follower i−1, of follower 1 the leader; star: every target is "
        "the leader and d_i = i d). Bold: above the follower's bound ξ_max,i. "
        "\"shared\": every follower is fed the acceleration command of its target (follower 1: "
        "the leader's a_1, including the velocity-rate part of the disturbance) in its "
        "command. The ratio row is the mean (min–max) of peak_{i+1}/peak_i over i ≥ 2 "
        "(follower 1 alone sees the disturbance itself): above 1 the error grows along the "
        "chain (string instability).", ""]
    xi_max_col = []
    for i in range(n):
        bounds = sorted({r["followers"][i]["xi_max"] for r in runs.values()
                         if i < len(r["followers"])})
        xi_max_col.append(" / ".join(f"{b:g}" for b in bounds))
    lines.append("| follower i | ξ_max,i | " + " | ".join(labels) + " |")
    lines.append("|---:|---:|" + "---:|" * len(labels))
    for i in range(n):
        cells = []
        for r in runs.values():
            if i >= len(r["followers"]):
                cells.append("")
                continue
            f = r["followers"][i]
            cells.append(fmt(f["max_xi"], f["max_xi"] > f["xi_max"]))
        lines.append(f"| {i + 1} | {xi_max_col[i]} | " + " | ".join(cells) + " |")
    lines.append("| **peak_{i+1}/peak_i, i ≥ 2** | | " + " | ".join(
        ratio_text([f["max_xi"] for f in r["followers"]])[0] for r in runs.values()) + " |")
    lines.append("| time outside ξ_max (s), all followers | | " + " | ".join(
        f"{sum(f['time_outside'] for f in r['followers']):g}" for r in runs.values()) + " |")
    exact = [label for label, r in runs.items()
             if len(r["followers"]) > 1 and all(f["max_xi"] < ZERO for f in r["followers"][1:])]
    if exact:
        names = " and ".join(f"“{x}”" for x in exact)
        lines += ["", f"In {names} the followers i ≥ 2 keep ξ_i = 0 to rounding: each "
                  "is fed its target's acceleration command of the same tick, without delay or "
                  "noise, and starts on its slot, so it copies its target's motion exactly. "
                  "That is the ideal of the model, not a margin to count on."]
    lines += ["", f"Min separation of follower i to its target (m). Bold: inside the perimeter "
              f"α |d_i| (α = {alpha:g}).", ""]
    lines.append("| follower i | perimeter | " + " | ".join(labels) + " |")
    lines.append("|---:|---:|" + "---:|" * len(labels))
    for i in range(n):
        cells, bounds = [], set()
        for r in runs.values():
            if i >= len(r["followers"]):
                cells.append("")
                continue
            f = r["followers"][i]
            per = f["xi_max"] * alpha / (1.0 - alpha)
            bounds.add(per)
            cells.append(fmt(f["min_separation"], f["min_separation"] < per))
        lines.append(f"| {i + 1} | {' / '.join(f'{b:g}' for b in sorted(bounds))} | "
                     + " | ".join(cells) + " |")
    lines.append("| formation min pair separation | | " + " | ".join(
        fmt(r["pair"]) for r in runs.values()) + " |")
    lines.append("")
    return "\n".join(lines)


def style(label):
    color = {("chain", "off"): "tab:blue", ("chain", "on"): "tab:red",
             ("star", "off"): "tab:cyan", ("star", "on"): "tab:orange"}
    topology = "star" if label.startswith("star") else "chain"
    tracker = "on" if "tracker on" in label else "off"
    shared = "shared" in label
    return dict(color=color[(topology, tracker)], ls=":" if shared else "-",
                marker="s" if topology == "star" else ("^" if shared else "o"),
                lw=2.6 if shared else 2.0, ms=7)


def plot(runs, alpha, path):
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(14, 6.4))
    for label, r in runs.items():
        fs = r["followers"]
        i = np.array([f["index"] for f in fs])
        ax1.plot(i, [f["max_xi"] for f in fs], label=label, **style(label))
        ax2.plot(i, [f["min_separation"] for f in fs], label=label, **style(label))
    chains = [r for label, r in runs.items() if not label.startswith("star")]
    stars = [r for label, r in runs.items() if label.startswith("star")]
    peak_max = max(f["max_xi"] for r in runs.values() for f in r["followers"])
    top = peak_max * 1.15
    for r, kind, ls in ((chains[0] if chains else None, "chain", "--"),
                        (stars[0] if stars else None, "star", "-.")):
        if r is None:
            continue
        i = np.array([f["index"] for f in r["followers"]])
        xi_max = np.array([f["xi_max"] for f in r["followers"]])
        values = ", ".join(f"{x:g}" for x in xi_max[:3])
        if kind == "chain" or xi_max.max() <= top:
            ax1.step(i, xi_max, where="mid", color="black", lw=1.3, ls=ls,
                     label=f"ξ_max,i ({kind}: {values}, ...)")
            top = max(top, xi_max.max() * 1.15)
        else:   # a star's bounds grow with i: say so rather than squash the plot
            ax1.plot([], [], color="black", lw=1.3, ls=ls,
                     label=f"ξ_max,i ({kind}: {values}, ..., not drawn)")
        ax2.step(i, xi_max * alpha / (1 - alpha), where="mid", color="black", lw=1.3, ls=ls,
                 label=f"perimeter α|d_i| ({kind})")
    ax1.set_ylim(0, top)
    ax1.set_title("peak ‖ξ_i‖ along the formation")
    ax1.set_ylabel("peak ‖ξ_i‖ (m)")
    ax2.set_title("min separation of follower i to its target (log scale)")
    ax2.set_ylabel("separation (m)")
    ax2.set_yscale("log")
    for ax in (ax1, ax2):
        ax.set_xlabel("follower i (1 looks at the leader)")
        ax.set_xticks(sorted({f["index"] for r in runs.values() for f in r["followers"]}))
        ax.grid(True, alpha=0.4)
        handles, labels = ax.get_legend_handles_labels()
        bounds = [(h, t) for h, t in zip(handles, labels) if t.startswith(("ξ_max", "perim"))]
        ax.legend(*zip(*bounds), fontsize=9, loc="upper left", framealpha=0.9)
    handles, labels = ax1.get_legend_handles_labels()
    configs = [(h, t) for h, t in zip(handles, labels) if t in runs]
    fig.legend(*zip(*configs), loc="lower center", ncol=3, fontsize=10, frameon=False)
    fig.suptitle("String stability, paper Run 2 (leader disturbed 20–23 s); "
                 "chain: i looks at i−1, star: all look at the leader", fontsize=12)
    fig.tight_layout(rect=(0, 0.1, 1, 0.95))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="plot_string_stability.py",
                                 description=__doc__.split("\n")[0])
    ap.add_argument("--run", nargs=2, action="append", required=True,
                    metavar=("LABEL", "FILE"), help="a configuration and its cf_sim output")
    ap.add_argument("--md", required=True, help="Markdown tables to write")
    ap.add_argument("--png", required=True, help="figure to write")
    ap.add_argument("--scenario", required=True,
                    help="the base scenario; its controller.alpha gives the perimeters")
    ap.add_argument("--info", default="", help="a line of text put under the Markdown title")
    args = ap.parse_args(argv)
    try:
        runs = {label: parse(path) for label, path in args.run}
        with open(args.scenario, encoding="utf-8") as fh:
            alpha = float(yaml.safe_load(fh)["controller"]["alpha"])
    except (OSError, ValueError, KeyError, TypeError) as exc:
        print(f"plot_string_stability: error: {exc}", file=sys.stderr)
        return 1
    with open(args.md, "w", encoding="utf-8") as fh:
        fh.write(markdown(runs, args.info, alpha) + "\n")
    plot(runs, alpha, args.png)
    return 0


if __name__ == "__main__":
    sys.exit(main())
