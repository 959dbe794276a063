#!/usr/bin/python3
"""Tables and figure of the string stability report (experiments/string_stability/run.sh).

Usage::

    plot_string_stability.py MANIFEST.tsv --followers N --wall SECONDS --gamma GAMMA.md
                             --md OUT.md --csv OUT.csv --png OUT.png

MANIFEST has one row per cf_sim run (tab separated, with a header): group, rate, topology,
tracker, sharing, delay ("T" one period, else s, "-" none), dropout, scenario, arguments, file.
Each file is the stdout of ``cf_sim SCENARIO --set formation.followers=N ...``: a line
``follower_<i> target=.. max_xi=.. xi_max=.. min_separation=.. ...`` per follower, then
``formation ... min_pair_separation=..`` and ``string_stability first_outside_bound=..
first_inside_perimeter=.. peak_ratio_max=.. peak_growth=..`` (StringStability.hpp; 0: none).
GAMMA.md is the table of experiments/string_stability/string_stability_analysis.py.
"""

from __future__ import annotations

import argparse
import csv
import math
import re
import sys

import numpy as np
import yaml

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402  (after the backend is chosen)

MILLIMETRE = 1e-3
SHOWN = (1, 2, 3, 5, 10, 12, 15, 17, 20, 25, 30, 50, 75, 100)


def alpha_of(row):
    """controller.alpha of the run: the scenario's, or its --set override."""
    m = re.search(r"--set controller\.alpha=(\S+)", row["arguments"])
    if m:
        return float(m.group(1))
    with open(row["scenario"], encoding="utf-8") as fh:
        return float(yaml.safe_load(fh)["controller"]["alpha"])


def parse(path, alpha):
    """{"followers": [{index, max_xi, xi_max, min_separation, perimeter}], "pair", "figures"},
    with the perimeter alpha ||d_i|| = xi_max,i alpha / (1 - alpha)."""
    followers, pair, figures = [], None, None
    with open(path, encoding="utf-8") as fh:
        for line in fh:
            words = line.split()
            m = re.match(r"follower_(\d+)$", words[0]) if words else None
            values = dict(w.split("=", 1) for w in words[1:] if "=" in w)
            if m:
                entry = {k: float(v) for k, v in values.items() if k != "target"}
                entry["index"] = int(m.group(1))
                entry["perimeter"] = entry["xi_max"] * alpha / (1.0 - alpha)
                followers.append(entry)
            elif words and words[0] == "formation":
                pair = float(values["min_pair_separation"])
            elif words and words[0] == "string_stability":
                figures = {k: float(v) for k, v in values.items()}
    if not followers or pair is None or figures is None:
        raise ValueError(f"{path}: not the output of a cf_sim formation run")
    followers.sort(key=lambda f: f["index"])
    return {"followers": followers, "pair": pair, "figures": figures}


def delay_text(row):
    if row["sharing"] != "link":
        return row["sharing"]
    delay = "1 period" if row["delay"] == "T" else f"{float(row['delay']) * 1e3:g} ms"
    loss = float(row["dropout"])
    return f"link {delay}" + (f", {loss * 100:g} % lost" if loss > 0 else "")


def label(row):
    tracker = "tracker on" if row["tracker"] == "true" else "tracker off"
    rate = "1 kHz" if row["rate"] == "1000" else f"{row['rate']} Hz"
    return f"{row['group']}: {row['topology']}, {tracker}, {delay_text(row)}, {rate}"


def first(index):
    return "—" if index == 0 else f"{index:d}"


def verdict(run, n):
    fig = run["figures"]
    bad = [int(x) for x in (fig["first_outside_bound"], fig["first_inside_perimeter"]) if x]
    if bad:
        return f"**unsafe from N = {min(bad)}**"
    ratio = fig["peak_ratio_max"]
    if run["topology"] == "star":
        return f"safe to N = {n} (a star passes nothing on)"
    if math.isnan(ratio):
        return f"safe to N = {n}, peaks ≈ 0 behind follower 1"
    if ratio <= 1.0:
        return f"safe and string stable to N = {n}"
    return f"safe to N = {n}, peaks grow"


def first_within(run, distance):
    for f in run["followers"]:
        if f["min_separation"] < distance:
            return f["index"]
    return 0


def number(x):
    if math.isnan(x):
        return "n/a"
    return f"{x:.1e}" if abs(x) < 1e-3 and x != 0 else f"{x:.4g}"


def ratio(x):
    """A peak ratio: 4 digits, or 9 where it lies within 1e-3 of 1."""
    if math.isnan(x):
        return "n/a"
    return f"{x:.9g}" if abs(x - 1.0) < 1e-3 else f"{x:.4g}"


def summary_table(rows, runs, n):
    lines = ["| # | configuration | peak ‖ξ_1‖ | peak ‖ξ_N‖ | growth per follower "
             "| max peak_i / peak_target | first out of ξ_max | first inside perimeter "
             "| first within 1 mm | min pair separation (m) | verdict |",
             "|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---|"]
    for k, (row, run) in enumerate(zip(rows, runs), 1):
        fs, fig = run["followers"], run["figures"]
        lines.append(
            f"| {k} | {label(row)} | {number(fs[0]['max_xi'])} | {number(fs[-1]['max_xi'])} | "
            f"{number(fig['peak_growth'])} | {ratio(fig['peak_ratio_max'])} | "
            f"{first(int(fig['first_outside_bound']))} | "
            f"{first(int(fig['first_inside_perimeter']))} | "
            f"{first(first_within(run, MILLIMETRE))} | {number(run['pair'])} | "
            f"{verdict(run, n)} |")
    return lines


def follower_table(rows, runs, picks, key, bound, what):
    shown = [i for i in SHOWN if i <= len(runs[picks[0]]["followers"])]
    lines = [f"{what}. Bold: {'above ξ_max,i' if key == 'max_xi' else 'inside the perimeter'}.",
             "", "| follower i | " + " | ".join(f"#{k + 1}" for k in picks) + " |",
             "|---:|" + "---:|" * len(picks)]
    for i in shown:
        cells = []
        for k in picks:
            f = runs[k]["followers"][i - 1]
            bad = f[key] > f[bound] if key == "max_xi" else f[key] < f[bound]
            text = number(f[key])
            cells.append(f"**{text}**" if bad else text)
        lines.append(f"| {i} | " + " | ".join(cells) + " |")
    return lines


def plot(rows, runs, path):
    """Left: the paper's laws and the headway alone (log scale); right: the chosen
    configuration's chains (linear scale)."""
    fig, axes = plt.subplots(2, 2, figsize=(15, 11))
    right = [k for k, r in enumerate(rows)
             if r["group"].startswith("chosen") and r["topology"] == "chain"]
    left = [k for k in range(len(rows)) if k not in right and rows[k]["topology"] == "chain"]
    titles = ("chains, the paper's laws and the headway alone", "chains, the string-stable configuration")
    for col, (picks, title) in enumerate(zip((left, right), titles)):
        colors = plt.cm.tab20(np.linspace(0.0, 1.0, max(len(picks), 2)))
        for n, k in enumerate(picks):
            fs = runs[k]["followers"]
            i = np.array([f["index"] for f in fs])
            style = dict(lw=1.4, color=colors[n],
                         ls="--" if rows[k]["topology"] == "star" else ("-" if n % 2 == 0 else "-."))
            axes[0, col].plot(i, [f["max_xi"] for f in fs], label=f"#{k + 1} {label(rows[k])}",
                              **style)
            axes[1, col].plot(i, [max(f["min_separation"], 1e-7) for f in fs], **style)
        first = runs[picks[0]]["followers"][0]
        axes[0, col].axhline(first["xi_max"], color="black", ls=":", lw=1.5,
                             label=f"ξ_max = {first['xi_max']:g} m (chain; star: i ξ_max)")
        axes[1, col].axhline(first["perimeter"], color="black", ls=":", lw=1.5,
                             label=f"perimeter {first['perimeter']:g} m (chain; star: i times)")
        axes[0, col].set_title(f"peak ‖ξ_i‖, {title}")
        axes[1, col].set_title(f"min separation to the target, {title}")
        axes[0, col].legend(fontsize=6.5 if col == 0 else 5.8,
                            loc="upper left" if col == 0 else "upper right")
        axes[1, col].legend(fontsize=7, loc="lower right")
        for row in range(2):
            axes[row, col].set_xlabel("follower i")
            axes[row, col].grid(True, which="both", alpha=0.3)
    for row in range(2):
        axes[row, 0].set_yscale("log")
    axes[0, 0].set_ylim(1e-2, 1e16)
    axes[0, 1].set_ylim(0.0, 1.6 * runs[right[0]]["followers"][0]["xi_max"])
    axes[1, 1].set_ylim(0.0, 5.5)
    axes[0, 0].set_ylabel("m")
    axes[1, 0].set_ylabel("m (below 1e-7 drawn at 1e-7)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("manifest")
    ap.add_argument("--followers", type=int, required=True)
    ap.add_argument("--wall", required=True)
    ap.add_argument("--gamma", required=True)
    for name in ("md", "csv", "png"):
        ap.add_argument(f"--{name}", required=True)
    args = ap.parse_args(argv)
    try:
        with open(args.manifest, encoding="utf-8") as fh:
            rows = list(csv.DictReader(fh, delimiter="\t"))
        runs = [parse(r["file"], alpha_of(r)) for r in rows]
        for row, run in zip(rows, runs):
            run["topology"] = row["topology"]
        with open(args.gamma, encoding="utf-8") as fh:
            gamma = fh.read().rstrip("\n").split("\n")
    except (OSError, ValueError, KeyError, TypeError, yaml.YAMLError) as exc:
        print(f"plot_string_stability: error: {exc}", file=sys.stderr)
        return 1
    n = args.followers
    with open(args.csv, "w", encoding="utf-8", newline="") as fh:
        out = csv.writer(fh)
        out.writerow(["configuration", "label", "follower", "max_xi", "xi_max", "min_separation",
                      "perimeter"])
        for k, (row, run) in enumerate(zip(rows, runs), 1):
            for f in run["followers"]:
                out.writerow([k, label(row), f["index"], repr(f["max_xi"]), repr(f["xi_max"]),
                              repr(f["min_separation"]), repr(f["perimeter"])])
    # Per follower: the runs whose tables say something (not the same-tick zeros, not the
    # repeats at another delay); every run is in the CSV.
    paper = [k for k, r in enumerate(rows) if r["group"].startswith("paper")
             and r["sharing"] != "same tick" and not (r["topology"] == "star" and r["sharing"] == "link")]
    chosen = [k for k, r in enumerate(rows) if not r["group"].startswith("paper") and (
        r["sharing"] != "link" or r["tracker"] == "false" or r["topology"] == "star"
        or (r["dropout"] != "0" and r["delay"] in ("0.1", "0.2")))]
    text = ["# String stability", "",
            f"Generated by `bash experiments/string_stability/run.sh` ({len(rows)} cf_sim runs of "
            f"N = {n} followers in {args.wall} s, then the analysis): the paper's push on the "
            "leader (Run 2, `config/scenarios/paper_run2.yaml`) with the paper's laws, and the "
            "string-stable configuration of [math.md, Platoons](math.md#platoons-string-stability) "
            "(`config/scenarios/platoon_run2.yaml`). The cf_sim arguments of every run are listed "
            "at the end; every follower's figures are in `string_stability.csv`. A follower of "
            "a chain does not depend on those behind it, so one run of N followers gives every "
            "shorter chain: a chain of N is unsafe exactly when N reaches the first failing "
            "follower.", "",
            "Peak ‖ξ_i‖ = max_t ‖x_target − x_i − d_i‖ at the ticks; ξ_max,i = (1 − α)‖d_i‖ and "
            "the perimeter α‖d_i‖ (4 m and 1 m in a chain, i times that in a star). Peak *ratios* "
            "go from a follower's target to the follower: peak_i / peak_{i−1} in a line chain, "
            "along each arm in a V chain; a star has none. *Growth*: their geometric mean "
            "behind the followers that see the push itself, (peak_N / peak_2)^(1/(N−2)) in a "
            "line chain. *Link*: the target's acceleration delayed "
            "and lost as [math.md (L1)–(L3)](math.md#the-link-of-shared-information) describe "
            "(seed 1), the last value held; *same tick*: without delay or loss. *Leader stops*: "
            "after the push the leader brakes back to rest (u_1 = 1 m/s² for 23 s ≤ t < 29 s); "
            "otherwise it keeps reversing at 6 m/s, and with the time headway h every slot sits "
            "h · 6 m/s closer for good (1.8 m at h = 0.3 s), which is then the peak of most "
            "followers of the chosen configuration.", ""]
    text += summary_table(rows, runs, n) + [""]
    text += ["## Per follower", ""]
    text += follower_table(rows, runs, paper, "max_xi", "xi_max",
                           "Peak ‖ξ_i‖ (m), the paper's laws") + [""]
    text += follower_table(rows, runs, paper, "min_separation", "perimeter",
                           "Min separation to the target (m), the paper's laws") + [""]
    text += follower_table(rows, runs, chosen, "max_xi", "xi_max",
                           "Peak ‖ξ_i‖ (m), the string-stable configuration") + [""]
    text += follower_table(rows, runs, chosen, "min_separation", "perimeter",
                           "Min separation to the target (m), the string-stable "
                           "configuration") + [""]
    text += ["![Peak error and separation against the follower's index](string_stability.png)",
             "", "## Error propagation |Γ|", "",
             "From `experiments/string_stability/string_stability_analysis.py "
             "config/scenarios/platoon_run2.yaml` (the sampled linear loop, projection at rest; [math.md](math.md#platoons-string-"
             "stability)). sup_ω |Γ| ≤ 1 is string stability in energy (ℓ2); ‖g‖₁, the sum of "
             "the impulse response's magnitudes, bounds the growth of a peak from one follower to "
             "the next for any input (ℓ∞). Where sup_ω |Γ| − 1 is −2e-6 at ω = 0.003 rad/s, the "
             "supremum is the limit |Γ| → 1 at ω → 0 (a constant error is passed on).", ""]
    text += gamma + ["", "![|Gamma| against frequency](string_stability_gamma.png)", "",
                     "## Commands", ""]
    for k, row in enumerate(rows, 1):
        text.append(f"{k}. `cf_sim {row['scenario']} {row['arguments'].strip()}`")
    with open(args.md, "w", encoding="utf-8") as fh:
        fh.write("\n".join(text) + "\n")
    plot(rows, runs, args.png)
    return 0


if __name__ == "__main__":
    sys.exit(main())
