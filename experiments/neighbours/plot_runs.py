#!/usr/bin/python3
"""The gusty V stars of 4, 16 and 64 (config/scenarios/crowd_16_gusts.yaml, one seed) without and
with formation.neighbours (the protection of neighbours_table.py), against time: the smallest
distance over every pair of agents (the leader included) against the perimeter rho, and the
largest ||xi_i|| / xi_max,i over the followers.

Runs cf_sim six times with --csv and reads each follower's file (t, follower_p_*, leader_p_*,
norm_xi, xi_max); checks that the series' extremes are cf_sim's own summary figures
(min_pair_separation, max_xi / xi_max; exits 1 otherwise) and writes OUT_PNG.
Usage: plot_runs.py CF_SIM OUT_PNG [--seed S]
"""

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)

sys.path.insert(0, str(Path(__file__).resolve().parent))
from neighbours_table import PROTECTION, run  # noqa: E402

SCENARIO = "crowd_16_gusts.yaml"
SIZES = (4, 16, 64)
STYLE = {False: ("tab:red", "none"), True: ("tab:blue", "formation.neighbours")}


def columns(path, names):
    """The columns @p names of a cf_sim CSV, as arrays."""
    header = path.open().readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, usecols=[header.index(n) for n in names],
                      ndmin=2)
    return {n: data[:, j] for j, n in enumerate(names)}


def series(prefix, followers, dims=2):
    """t, the smallest pair distance at each tick, the largest ||xi_i|| / xi_max,i at each tick."""
    positions, ratio, t, leader = [], None, None, None
    for i, summary in enumerate(followers, start=1):
        names = ["t", "norm_xi", "xi_max"] + [f"follower_p_{e}" for e in range(dims)] + [
            f"leader_p_{e}" for e in range(dims)]
        c = columns(Path(f"{prefix}_follower_{i}.csv"), names)
        t = c["t"]
        positions.append(np.c_[[c[f"follower_p_{e}"] for e in range(dims)]].T)
        if leader is None and summary["target"] == "leader":
            leader = np.c_[[c[f"leader_p_{e}"] for e in range(dims)]].T
        r = c["norm_xi"] / c["xi_max"]
        ratio = r if ratio is None else np.maximum(ratio, r)
    agents = np.stack([leader] + positions, axis=1)  # (ticks, agents, dims)
    closest = np.full(len(t), np.inf)
    for a in range(agents.shape[1] - 1):
        gaps = np.linalg.norm(agents[:, a + 1:, :] - agents[:, a:a + 1, :], axis=2)
        closest = np.minimum(closest, gaps.min(axis=1))
    return t, closest, ratio


def check(name, value, expected):
    if abs(value - expected) > 1e-6 * max(1.0, abs(expected)):
        sys.exit(f"plot_runs: {name} from the CSV is {value:.9g}, cf_sim says {expected:.9g}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cf_sim")
    parser.add_argument("out_png", type=Path)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    fig, axes = plt.subplots(2, len(SIZES), figsize=(15, 7.5), sharex=True)
    with tempfile.TemporaryDirectory() as work:
        for col, size in enumerate(SIZES):
            top, bottom = axes[0][col], axes[1][col]
            for protected in (False, True):
                sets = [f"formation.followers={size}", f"world.seed={args.seed}"]
                sets += [PROTECTION[SCENARIO]] if protected else []
                prefix = f"{work}/run"
                formation, followers = run(args.cf_sim, SCENARIO, sets, prefix)
                t, closest, ratio = series(prefix, followers)
                check("min_pair_separation", closest.min(), float(formation["min_pair_separation"]))
                check("max ||xi_i|| / xi_max,i", ratio.max(),
                      max(float(f["max_xi"]) / float(f["xi_max"]) for f in followers))
                color, label = STYLE[protected]
                top.plot(t, closest, color=color, lw=0.9,
                         label=f"{label}: min {closest.min():.2f} m")
                bottom.plot(t, ratio, color=color, lw=0.9, label=f"{label}: max {ratio.max():.2f}")
                print(f"V of {size}, seed {args.seed}, {label}: min pair {closest.min():.3f} m, "
                      f"max ||xi_i||/xi_max,i {ratio.max():.3f}")
            rho = float(formation["perimeter"])
            top.axhline(rho, color="black", ls="--", lw=1, label=f"perimeter ρ = {rho:g} m")
            top.axhspan(0, rho, color="tab:red", alpha=0.08)
            top.set_title(f"V star of {size}, random gusts, seed {args.seed}")
            bottom.axhline(1.0, color="black", ls="--", lw=1, label="‖ξ_i‖ = ξ_max,i")
            bottom.set_xlabel("t (s)")
            for ax in (top, bottom):
                ax.set_ylim(0, 1.5 * ax.get_ylim()[1])  # room for the legend above the runs
                ax.grid(True, alpha=0.3)
                ax.legend(fontsize=9, loc="upper left")
    axes[0][0].set_ylabel("min distance over every pair (m)")
    axes[1][0].set_ylabel("max over followers of ‖ξ_i‖ / ξ_max,i")
    fig.tight_layout()
    args.out_png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(args.out_png, dpi=100)
    plt.close(fig)


if __name__ == "__main__":
    main()
