#!/usr/bin/python3
"""Tables and figure of a disturbance sweep (``cf_sim SCENARIO --sweep OUT.csv``).

Usage::

    plot_sweep.py SWEEP.csv --md OUT.md --png OUT.png [--scenario SCENARIO.yaml] [--info TEXT]

SWEEP.csv has the rows ``tracker,sharing,direction_deg,bound_limit,bound_capped,
perimeter_limit,perimeter_capped`` of cf_sim's sweep mode: for each of the 8
configurations (tracker off/on x leader-acceleration sharing none/command/
estimator/both) and each direction phi of the disturbance vector
u_d = s (cos phi [r; 0] + sin phi [0; r]), r = d/|d|, the largest pulse size s
that keeps max ||xi|| <= xi_max (bound) or min separation >= perimeter.
A capped limit (no size up to the sweep's maximum failed) is written "≥ max".

Writes
  OUT.md   one table per criterion: rows = directions, columns = configurations,
           last column the best configuration(s) (largest limit; equal at the
           table's 2 decimals counts as a tie); a last row with the worst
           direction of each configuration;
  OUT.png  limit vs direction, one panel per criterion, one line per configuration,
           with the scenario's own pulse (--scenario: its first disturbance
           vector, e.g. s = 2.83 at 225 deg for the paper's [-2, -2]) marked.

Rerun everything with experiments/disturbance_sweep/run.sh.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
from collections import OrderedDict

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)

TRACKERS = ("off", "on")
SHARINGS = ("none", "command", "estimator", "both")
CRITERIA = (("bound", "max ‖ξ‖ ≤ ξ_max"), ("perimeter", "separation ≥ perimeter α‖d‖"))
COLORS = {"none": "tab:blue", "command": "tab:red", "estimator": "tab:green", "both": "tab:purple"}
TIE = 0.005          # limits equal at 2 decimals are ties


def load(path):
    """{(tracker, sharing): {"dirs": array, "<crit>_limit": array, "<crit>_capped": bool array}}."""
    with open(path, newline="", encoding="utf-8") as fh:
        rows = list(csv.DictReader(fh))
    if not rows:
        raise ValueError(f"{path}: no rows")
    configs = OrderedDict()
    for tracker in TRACKERS:
        for sharing in SHARINGS:
            sel = sorted((r for r in rows if r["tracker"] == tracker and r["sharing"] == sharing),
                         key=lambda r: float(r["direction_deg"]))
            if not sel:
                continue
            data = {"dirs": np.array([float(r["direction_deg"]) for r in sel])}
            for crit, _ in CRITERIA:
                data[f"{crit}_limit"] = np.array([float(r[f"{crit}_limit"]) for r in sel])
                data[f"{crit}_capped"] = np.array([r[f"{crit}_capped"] == "1" for r in sel])
            configs[(tracker, sharing)] = data
    dirs = [tuple(c["dirs"]) for c in configs.values()]
    if len(set(dirs)) != 1:
        raise ValueError(f"{path}: the configurations have different directions")
    return configs


def label(config):
    return f"tracker {config[0]} / {config[1]}"


def short(config):
    return f"{config[0]}/{config[1]}"


def describe(phi_deg):
    """Words for u_d's direction: position-rate part cos(phi), acceleration part sin(phi)."""
    c, s = math.cos(math.radians(phi_deg)), math.sin(math.radians(phi_deg))
    parts = []
    for weight, what in ((c, "pos-rate"), (s, "accel")):
        if abs(weight) > 1e-9:
            parts.append((weight, what))
    if len(parts) == 1:
        weight, what = parts[0]
        full = "position-rate" if what == "pos-rate" else "acceleration"
        return f"pure {full} {'away from' if weight > 0 else 'toward'} follower"
    return " + ".join(f"{abs(w):.2f} {what} {'away' if w > 0 else 'toward'}" for w, what in parts)


def scenario_pulse(path):
    """(phi_deg, s) of the scenario's first disturbance vector in the sweep's coordinates."""
    import yaml
    with open(path, encoding="utf-8") as fh:
        raw = yaml.safe_load(fh)
    model = raw.get("model", {})
    if model.get("type") != "double_integrator":
        return None
    k = int(model.get("dimension", 1))
    d = np.array(raw["controller"]["separation"], dtype=float)[:k]
    pulses = raw.get("leader", {}).get("disturbance") or []
    if not pulses:
        return None
    v = np.array(pulses[0]["vector"], dtype=float)
    r = d / np.linalg.norm(d)
    c, s = float(v[:k] @ r), float(v[k:] @ r)
    if np.linalg.norm(v - np.concatenate([c * r, s * r])) > 1e-9 * max(1.0, np.linalg.norm(v)):
        return None                      # not in the plane the sweep covers
    return math.degrees(math.atan2(s, c)) % 360.0, math.hypot(c, s)


def same_as(configs):
    """{config: earlier config with identical limits in both criteria}."""
    out = {}
    keys = list(configs)
    for i, a in enumerate(keys):
        for b in keys[:i]:
            if b in out:
                continue
            if all(np.array_equal(configs[a][f"{c}_limit"], configs[b][f"{c}_limit"])
                   for c, _ in CRITERIA):
                out[a] = b
                break
    return out


def cell(limit, capped):
    return f"≥ {limit:g}" if capped else f"{limit:.2f}"


def markdown(configs, info, pulse):
    keys = list(configs)
    dirs = next(iter(configs.values()))["dirs"]
    lines = ["# Disturbance sweep", ""]
    if info:
        lines += [info, ""]
    lines += [
        "Pulse u_d = s (cos φ [r; 0] + sin φ [0; r]) with r = d/|d|, applied over the base "
        "scenario's pulse interval: φ = 0° pushes the leader's position away from the follower, "
        "90° accelerates it away, 180° pushes its position toward the follower, 270° accelerates "
        "it toward the follower. Each cell is the largest size s (m/s for the position-rate "
        "part, m/s² for the acceleration part) such that every size up to it keeps the "
        "criterion; \"≥ X\" means no size up to the sweep's maximum X failed. "
        "Columns: tracker off/on / leader acceleration a_1 shared with nobody (none), fed "
        "forward in the command, given to the CF estimator, or both. Best: the configuration(s) "
        "with the largest limit (equal at 2 decimals counts as a tie).",
        ""]
    if pulse:
        lines += [f"The scenario's own pulse is s = {pulse[1]:.2f} at φ = {pulse[0]:g}° "
                  "(marked ◀ below).", ""]
    dup = same_as(configs)
    if dup:
        lines += ["Identical columns (every direction, both criteria): " + "; ".join(
            f"{short(a)} = {short(b)}" for a, b in dup.items()) + ".", ""]
    for crit, title in CRITERIA:
        lines += [f"## Criterion: {title}", ""]
        lines.append("| φ (deg) | direction | " + " | ".join(short(k) for k in keys) + " | best |")
        lines.append("|---:|---|" + "---:|" * len(keys) + "---|")
        for j, phi in enumerate(dirs):
            vals = [configs[k][f"{crit}_limit"][j] for k in keys]
            caps = [configs[k][f"{crit}_capped"][j] for k in keys]
            top = max(vals)
            best = [short(k) for k, v in zip(keys, vals) if v >= top - TIE]
            best_text = "all" if len(best) == len(keys) else ", ".join(best)
            mark = " ◀" if pulse and abs(phi - pulse[0]) < 1e-6 else ""
            lines.append(f"| {phi:g}{mark} | {describe(phi)} | "
                         + " | ".join(cell(v, c) for v, c in zip(vals, caps))
                         + f" | {best_text} |")
        worst = [(configs[k][f"{crit}_limit"].min(), configs[k][f"{crit}_capped"].all())
                 for k in keys]
        top = max(w for w, _ in worst)
        best = [short(k) for k, (w, _) in zip(keys, worst) if w >= top - TIE]
        lines.append("| **worst φ** | smallest limit over all directions | "
                     + " | ".join(f"**{cell(w, c)}**" for w, c in worst)
                     + f" | {', '.join(best)} |")
        lines.append("")
    return "\n".join(lines)


def plot(configs, pulse, path):
    dup = same_as(configs)
    groups = OrderedDict()              # one curve per set of identical configurations
    for key in configs:
        groups.setdefault(dup.get(key, key), []).append(key)
    dirs = next(iter(configs.values()))["dirs"]
    cap = max(max(c[f"{crit}_limit"].max() for c in configs.values()) for crit, _ in CRITERIA)
    fig, axes = plt.subplots(1, 2, figsize=(15, 6.2), sharey=True)
    for ax, (crit, title) in zip(axes, CRITERIA):
        for first, members in groups.items():
            tracker, sharing = first
            lim = configs[first][f"{crit}_limit"]
            x = np.append(dirs, dirs[0] + 360.0)          # close the curve over 360 deg
            y = np.append(lim, lim[0])
            text = f"tracker {tracker} / " + " = ".join(m[1] for m in members)
            ax.plot(x, y, color=COLORS[sharing], ls="-" if tracker == "on" else "--",
                    lw=2.2, marker="o" if tracker == "on" else "s", ms=5, label=text)
        ax.axhspan(cap * 0.97, cap * 1.6, color="0.9", zorder=0)
        ax.text(180, cap * 1.3, f"capped: no size up to {cap:g} failed", fontsize=9,
                color="0.3", ha="center", va="center")
        if pulse:
            ax.plot([pulse[0]], [pulse[1]], marker="*", ms=18, color="gold", mec="black",
                    zorder=10, ls="none", label=f"scenario's pulse (s = {pulse[1]:.2f}, "
                                               f"φ = {pulse[0]:g}°)")
        ax.set_yscale("log")
        ax.set_ylim(1.5, cap * 1.6)
        ticks = [t for t in (2, 3, 4, 5, 6, 8, 10, 15, 20, 30, 50) if t <= cap]
        ax.set_yticks(ticks)
        ax.set_yticklabels([f"{t:g}" for t in ticks])
        ax.yaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.set_xlim(0, 360)
        ax.set_xticks(range(0, 361, 45))
        ax.set_xticklabels(["0°\npos-rate\naway", "45°", "90°\naccel\naway", "135°",
                            "180°\npos-rate\ntoward", "225°", "270°\naccel\ntoward", "315°",
                            "360°"])
        ax.grid(True, which="major", alpha=0.4)
        ax.set_title(f"Criterion: {title}", fontsize=12)
        ax.set_xlabel("direction φ of u_d (leader relative to follower)")
    axes[0].set_ylabel("largest safe pulse size s (log scale)")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=10, frameon=False)
    fig.suptitle("Disturbance sweep: largest safe pulse size per direction "
                 "(solid = tracker on, dashed = tracker off; colour = who gets a_1)",
                 fontsize=12.5)
    fig.tight_layout(rect=(0, 0.11, 1, 0.96))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(prog="plot_sweep.py", description=__doc__.split("\n")[0])
    ap.add_argument("csv", help="cf_sim --sweep output")
    ap.add_argument("--md", required=True, help="Markdown tables to write")
    ap.add_argument("--png", required=True, help="figure to write")
    ap.add_argument("--scenario", help="base scenario, to mark its own pulse")
    ap.add_argument("--info", default="", help="a line of text put under the Markdown title")
    args = ap.parse_args(argv)
    try:
        configs = load(args.csv)
        pulse = scenario_pulse(args.scenario) if args.scenario else None
    except (OSError, ValueError, KeyError) as exc:
        print(f"plot_sweep: error: {exc}", file=sys.stderr)
        return 1
    with open(args.md, "w", encoding="utf-8") as fh:
        fh.write(markdown(configs, args.info, pulse) + "\n")
    plot(configs, pulse, args.png)
    return 0


if __name__ == "__main__":
    sys.exit(main())
