#!/usr/bin/python3
"""Turning formations: every turning scenario, each formation, world-fixed and turning slots.

Runs cf_sim on config/scenarios/{figure_eight_2d,turning_circle,turning_u_turn,
turning_stop_and_go}.yaml (each with the paper's push) for a pair, a V star of 4 and a line
chain of 10, with formation.slots world, turning, turning with formation.turning.reversing, and path (a
convoy: the star of 4 then a line, each follower on the leader's path), and writes to OUT_DIR:
  turning_formations.csv   one row per run and follower: max ||xi_i||, xi_max,i, min distance to
                           its target, perimeter alpha ||d_i||, max and mean distance from the
                           leader's path
  turning_formations.md    the table per run (worst follower), between markers in formations.md
  turning_paths.png        paths with headings (arrows along the leader's path, grey dots: every
                           agent's place every 5 s), world-fixed beside turning
The distance from the leader's path is that of each follower position (every tick) to the
nearest point of the leader's path: its positions over the whole run (2 cm apart at 2 m/s and
100 Hz), and the road it came on, 80 m straight behind its first position against its initial
velocity, on which the followers start (with path slots the convoy's virtual road, behind the
leader along its slot direction).
Usage: turning_table.py CF_SIM OUT_DIR
"""

import csv
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "common"))
from doc_block import replace_block  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SCENARIOS = (("figure eight", "figure_eight_2d.yaml", 60.0), ("circle", "turning_circle.yaml", None),
             ("U-turn", "turning_u_turn.yaml", None), ("stop and go", "turning_stop_and_go.yaml", None))
FORMATIONS = (("pair", ["formation.followers=1"]),
              ("V star of 4", ["formation.followers=4", "formation.shape=v"]),
              ("chain of 10", ["formation.followers=10", "formation.topology=chain"]))
FRAMES = ("world", "turning", "turning, reversing", "path")
FRAME_SETS = {"world": ["formation.slots=world"], "turning": ["formation.slots=turning"],
              "turning, reversing": ["formation.slots=turning", "formation.turning.reversing=true"],
              "path": ["formation.slots=path"]}
# Path slots put every follower on its target's path: the star of 4 is a line (d_i = i d), each
# follower an arc gap 1.5 ||d_i|| behind the leader.
PATH_STAR = "star of 4 (line)"


def formation_sets(formation, fsets, frame):
    """The formation's name and overrides for FRAME (a V has no place on one path)."""
    if frame == "path" and "formation.shape=v" in fsets:
        return PATH_STAR, [s for s in fsets if s != "formation.shape=v"]
    return formation, fsets


def run(cf_sim, scenario, sets, csv_path):
    args = [cf_sim, str(ROOT / "config" / "scenarios" / scenario), "--csv", str(csv_path)]
    for s in sets:
        args += ["--set", s]
    out = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    followers = {}
    pair_min = None
    for line in out.splitlines():
        fields = dict(f.split("=", 1) for f in line.split()[1:] if "=" in f)
        if line.startswith("follower_"):
            followers[line.split()[0]] = fields
        elif line.startswith("formation "):
            pair_min = float(fields["min_pair_separation"])
    return followers, pair_min


def columns(path, prefix, k=2):
    data = np.genfromtxt(path, delimiter=",", names=True)
    return np.column_stack([data[f"{prefix}{i}"] for i in range(k)]), data


def road_behind(start, data, frame, length=80.0, spacing=0.02):
    """The road the leader came on: LENGTH m straight behind its first position, against its
    initial velocity (its followers start on it); with path slots the convoy's virtual road (C1),
    from follower 1's first position to the leader's."""
    if frame == "path":
        direction = start - np.array([data["follower_p_0"][0], data["follower_p_1"][0]])
    else:
        direction = np.array([data["leader_v_0"][0], data["leader_v_1"][0]])
    direction = direction / np.linalg.norm(direction)
    s = np.arange(spacing, length, spacing)
    return start[None, :] - s[:, None] * direction[None, :]


def main():
    cf_sim, out = sys.argv[1], Path(sys.argv[2])
    rows = []
    paths = {}  # (scenario, formation, frame) -> (leader path, [follower paths])
    with tempfile.TemporaryDirectory() as tmp:
        for name, scenario, duration in SCENARIOS:
            for formation, fsets in FORMATIONS:
                for frame in FRAMES:
                    label, sets = formation_sets(formation, fsets, frame)
                    sets = sets + FRAME_SETS[frame]
                    if duration:
                        sets.append(f"simulation.duration={duration}")
                    base = Path(tmp) / f"{scenario}_{formation}_{frame}.csv".replace(" ", "_").replace(",", "")
                    followers, pair_min = run(cf_sim, scenario, sets, base)
                    leader = None
                    fpaths = []
                    for i in range(1, len(followers) + 1):
                        f = base.with_name(f"{base.stem}_follower_{i}{base.suffix}")
                        own, data = columns(f, "follower_p_")
                        if i == 1:
                            leader, data = columns(f, "leader_p_")
                            tree = cKDTree(np.vstack([road_behind(leader[0], data, frame), leader]))
                        stray, _ = tree.query(own)
                        s = followers[f"follower_{i}"]
                        xi_max = float(s["xi_max"])
                        rows.append({
                            "scenario": name, "formation": label, "slots": frame, "follower": i,
                            "target": s["target"], "max_xi": float(s["max_xi"]), "xi_max": xi_max,
                            "min_separation": float(s["min_separation"]),
                            "perimeter": xi_max / 4.0,  # alpha ||d_i|| = xi_max alpha / (1 - alpha), alpha 0.2
                            "min_pair_separation": pair_min,
                            "max_path_distance": float(stray.max()),
                            "mean_path_distance": float(stray.mean())})
                        fpaths.append(own[::10])
                    paths[(name, formation, frame)] = (leader[::10], fpaths)
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "turning_formations.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        for r in rows:
            writer.writerow({k: (f"{v:.4f}" if isinstance(v, float) else v) for k, v in r.items()})
    write_table(rows, out)
    plot(paths, out / "turning_paths.png")


def write_table(rows, out):
    lines = ["| scenario | formation | slots | max ‖ξ_i‖ / ξ_max,i (worst) | min distance to target "
             "− perimeter | min distance, any two agents | distance from the leader's path: max / mean |",
             "|---|---|---|---:|---:|---:|---:|"]
    keys = []
    for r in rows:
        key = (r["scenario"], r["formation"], r["slots"])
        if key not in keys:
            keys.append(key)
    for key in keys:
        group = [r for r in rows if (r["scenario"], r["formation"], r["slots"]) == key]
        worst = max(group, key=lambda r: r["max_xi"] / r["xi_max"])
        margin = min(group, key=lambda r: r["min_separation"] - r["perimeter"])
        stray = max(r["max_path_distance"] for r in group)
        mean = np.mean([r["mean_path_distance"] for r in group])
        lines.append(
            f"| {key[0]} | {key[1]} | {key[2]} | {worst['max_xi']:.2f} / {worst['xi_max']:.0f} m "
            f"(follower {worst['follower']}) | {margin['min_separation'] - margin['perimeter']:.2f} m "
            f"(follower {margin['follower']}) | {group[0]['min_pair_separation']:.2f} m | "
            f"{stray:.2f} / {mean:.2f} m |")
    text = "\n".join(lines)
    (out / "turning_formations.md").write_text(text + "\n")
    doc = out / "formations.md"
    if doc.exists():
        replace_block(doc, "<!-- turning table begin -->", "<!-- turning table end -->", text)


def plot(paths, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    cases = (("figure eight", "V star of 4"), ("U-turn", "chain of 10"), ("stop and go", "V star of 4"))
    fig, axes = plt.subplots(len(cases), len(FRAMES), figsize=(6 * len(FRAMES), 5 * len(cases)))
    for row, (scenario, formation) in enumerate(cases):
        for col, frame in enumerate(FRAMES):
            ax = axes[row][col]
            leader, followers = paths[(scenario, formation, frame)]
            title = formation_sets(formation, ["formation.shape=v"] if "V" in formation else [],
                                   frame)[0]
            ax.plot(leader[:, 0], leader[:, 1], "k-", lw=2.5, label="leader")
            for i, p in enumerate(followers, start=1):
                ax.plot(p[:, 0], p[:, 1], lw=1, label=f"follower {i}" if len(followers) <= 4 else None)
            # headings: arrows along the leader's path every 5 s, and each follower's position then
            for j in range(0, len(leader) - 1, 50):
                d = leader[min(j + 1, len(leader) - 1)] - leader[j]
                if np.linalg.norm(d) > 1e-6:
                    ax.annotate("", leader[j] + 2 * d / np.linalg.norm(d), leader[j],
                                arrowprops={"arrowstyle": "->", "color": "k"})
                ax.plot([leader[j, 0]] + [p[j, 0] for p in followers],
                        [leader[j, 1]] + [p[j, 1] for p in followers], "o", ms=3, color="grey")
            ax.set_title(f"{scenario}, {title}: {frame} slots")
            ax.set_aspect("equal", adjustable="datalim")
            ax.grid(True, alpha=0.3)
            ax.set_xlabel("x (m)")
            ax.set_ylabel("y (m)")
            if len(followers) <= 4:
                ax.legend(fontsize=7, loc="best")
    fig.tight_layout()
    fig.savefig(path, dpi=80)


if __name__ == "__main__":
    main()
