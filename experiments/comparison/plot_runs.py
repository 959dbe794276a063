#!/usr/bin/python3
"""Two pushes on the paper's pair, each method against time: the separation against the
perimeter, ||xi|| against xi_max, and the command (doc/comparison.md).
Usage: plot_runs.py CF_SIM OUT_PNG
"""

import subprocess
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from comparison_table import SCENARIOS, SHARED, TRACKER_OFF, VELOCITY_PUSH, cbf  # noqa: E402

PUSHES = [("Run 2's push, u_d = [-2 m/s, -2 m/s²]", []),
          ("a velocity-rate push of 8 m/s², a_1 shared", [VELOCITY_PUSH, SHARED])]
METHODS = [("baseline", [TRACKER_OFF], "0.6"), ("CF", [], "C0"),
           ("CBF λ=2", [TRACKER_OFF, cbf(2)], "C3"), ("CBF λ=4", [TRACKER_OFF, cbf(4)], "C1")]


def trace(cf_sim, overrides, path):
    args = [cf_sim, str(SCENARIOS / "paper_run2.yaml"), "--csv", path]
    for s in overrides:
        args += ["--set", s]
    subprocess.run(args, check=True, capture_output=True)
    return np.genfromtxt(path, delimiter=",", names=True)


def main(cf_sim, out_png):
    fig, axes = plt.subplots(3, 2, figsize=(11, 8), sharex=True)
    with tempfile.TemporaryDirectory() as tmp:
        for column, (title, push) in enumerate(PUSHES):
            for name, overrides, colour in METHODS:
                d = trace(cf_sim, push + overrides, f"{tmp}/run.csv")
                keep = (d["t"] >= 15.0) & (d["t"] <= 35.0)
                t = d["t"][keep]
                axes[0, column].plot(t, d["separation"][keep], color=colour, label=name)
                axes[1, column].plot(t, d["norm_xi"][keep], color=colour, label=name)
                axes[2, column].plot(t, d["u_0"][keep], color=colour, label=name)
            axes[0, column].axhline(d["perimeter"][0], color="k", ls="--", lw=0.8,
                                    label="perimeter")
            axes[1, column].axhline(d["xi_max"][0], color="k", ls="--", lw=0.8, label="ξ_max")
            axes[0, column].set_title(title)
    axes[0, 0].set_ylabel("separation (m)")
    axes[1, 0].set_ylabel("‖ξ‖ (m)")
    axes[2, 0].set_ylabel("u (m/s²)")
    for ax in axes[2]:
        ax.set_xlabel("t (s)")
    for ax in axes.flat:
        ax.grid(alpha=0.3)
    axes[0, 1].legend(loc="upper right", fontsize=8)
    axes[1, 1].legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(out_png, dpi=90)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
