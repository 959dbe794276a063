#!/usr/bin/python3
"""Safety from every neighbour: formations in a world that can hurt, without and with
formation.neighbours ((N1)-(N3) of doc/math.md), every pair's separation.

Runs cf_sim on config/scenarios/crowd_v4_gust.yaml (a V star of 4, a gust on follower 2 that its
3 m/s^2 vehicle cannot answer) and crowd_16_gusts.yaml (V stars in seeded random gusts up to 6 m/s^2,
vehicles limited to 4 m/s^2 with a 0.2 s lag, measurement noise), the latter with 4, 16 and 64 followers
and seeds 1 to 5, each without and with neighbour protection (PROTECTION below), and writes to
OUT_DIR:
  neighbour_safety.csv  one row per run: min distance over every pair and over the neighbours
                        (pairs of which neither looks at the other) against the perimeter
                        alpha ||d||, the pairs that came inside it, the largest
                        max ||xi_i|| / xi_max,i of its followers, the command effort (the mean
                        over followers of the integral of ||u_i||^2 dt), the ticks at which a
                        follower's command was projected, and cf_sim's wall time per follower
                        step (the whole loop: plant, sensing, controller)
  neighbour_safety.md   the table, also placed in formations.md between its markers
Usage: neighbours_table.py CF_SIM OUT_DIR
"""

import csv
import subprocess
import sys
import tempfile

import numpy as np
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "common"))
from doc_block import replace_block  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SEEDS = (1, 2, 3, 4, 5)
# formation.neighbours per scenario: a_b + A_n = the vehicle's limit; A_n covers the push a
# follower cannot answer (the gust less the vehicle's limit: V4 5 - 3 m/s^2, the gusts up to
# 6 - 4 m/s^2, with 0.5 m/s^2 more for the lag); omega h >= A_n at rest at the slots' 5 m.
PROTECTION = {
    "crowd_v4_gust.yaml":
        "formation.neighbours={braking_acceleration: 1, neighbour_acceleration: 2, rate: 1}",
    "crowd_16_gusts.yaml":
        "formation.neighbours={braking_acceleration: 1.5, neighbour_acceleration: 2.5, rate: 1}",
}
CASES = [("V star of 4, gust on follower 2", "crowd_v4_gust.yaml", [], None),
         ("V star of 4, calm", "crowd_v4_gust.yaml", ["world.followers=[]"], None)]
for count in (4, 16, 64):
    for seed in SEEDS:
        CASES.append((f"V star of {count}, random gusts", "crowd_16_gusts.yaml",
                      [f"formation.followers={count}", f"world.seed={seed}"], seed))


def effort_and_projected(csv_prefix, followers):
    """Mean over followers of the integral of ||u_i||^2 dt, and the ticks with a projection."""
    efforts, projected = [], 0
    for i in range(1, followers + 1):
        data = np.genfromtxt(f"{csv_prefix}_follower_{i}.csv", delimiter=",", names=True)
        dt = data["t"][1] - data["t"][0]
        u = np.c_[[data[name] for name in data.dtype.names if name.startswith("u_")
                   and name[2:].isdigit()]].T
        efforts.append(float(np.sum(np.sum(u * u, axis=1)) * dt))
        if "command_projected" in data.dtype.names:
            projected += int(np.sum(data["command_projected"]))
    return float(np.mean(efforts)), projected


def run(cf_sim, scenario, sets, csv_prefix):
    """The formation line's fields and each follower's, from cf_sim's summary."""
    args = [cf_sim, str(ROOT / "config" / "scenarios" / scenario), "--csv", f"{csv_prefix}.csv"]
    for s in sets:
        args += ["--set", s]
    out = subprocess.run(args, check=True, capture_output=True, text=True).stdout
    followers, formation = [], None
    for line in out.splitlines():
        fields = dict(f.split("=", 1) for f in line.split()[1:] if "=" in f)
        if line.startswith("follower"):
            followers.append(fields)
        elif line.startswith("formation "):
            formation = fields
    return formation, followers


def steps(scenario, sets):
    """Control ticks of a run: duration times rate, plus the tick at 0."""
    text = (ROOT / "config" / "scenarios" / scenario).read_text()
    duration = float(text.split("duration:")[1].split()[0])
    rate = float(text.split("control_rate:")[1].split()[0])
    return round(duration * rate) + 1


def main():
    cf_sim, out_dir = sys.argv[1], Path(sys.argv[2])
    rows = []
    work = tempfile.TemporaryDirectory()
    for (name, scenario, sets, seed), protected in [(c, p) for c in CASES for p in (False, True)]:
        prefix = f"{work.name}/run"
        run_sets = sets + ([PROTECTION[scenario]] if protected else [])
        formation, followers = run(cf_sim, scenario, run_sets, prefix)
        ratio = max(float(f["max_xi"]) / float(f["xi_max"]) for f in followers)
        effort, projected = effort_and_projected(prefix, len(followers))
        rows.append({"case": name, "seed": "" if seed is None else seed,
                     "protection": "neighbours" if protected else "none",
                     "followers": len(followers),
                     "perimeter": float(formation["perimeter"]),
                     "min_pair": float(formation["min_pair_separation"]),
                     "min_neighbour": float(formation["min_neighbour_separation"]),
                     "pairs_inside": int(formation["pairs_inside_perimeter"]),
                     "neighbour_pairs_inside": int(formation["neighbour_pairs_inside_perimeter"]),
                     "worst_xi_ratio": ratio, "effort": effort, "projected_ticks": projected,
                     "wall_us_per_step": float(formation["wall_s"]) * 1e6 / (
                         len(followers) * steps(scenario, sets))})
    out_dir.mkdir(parents=True, exist_ok=True)
    with open(out_dir / "neighbour_safety.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    lines = ["| formation | seed | protection | min distance, every pair (m) | "
             "min distance, neighbours (m) | pairs inside ρ (neighbours) | "
             "worst max ‖ξ_i‖ / ξ_max,i | effort ∫‖u‖² dt (m²/s³) | projected ticks | "
             "wall µs / follower step |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        mark = " **inside**" if r["min_pair"] < r["perimeter"] else ""
        lines.append(f"| {r['case']} | {r['seed'] or '—'} | {r['protection']} | "
                     f"{r['min_pair']:.2f}{mark} | {r['min_neighbour']:.2f} | "
                     f"{r['pairs_inside']} ({r['neighbour_pairs_inside']}) | "
                     f"{r['worst_xi_ratio']:.2f} | {r['effort']:.1f} | {r['projected_ticks']} | "
                     f"{r['wall_us_per_step']:.2f} |")
    table = "\n".join(lines) + "\n"
    (out_dir / "neighbour_safety.md").write_text(
        "<!-- made by experiments/neighbours/run.sh; do not edit -->\n" + table)
    formations = ROOT / "doc" / "formations.md"
    if out_dir.resolve() == (ROOT / "doc").resolve():
        replace_block(formations, "<!-- neighbour table begin -->", "<!-- neighbour table end -->",
                      table)
    print(table)


if __name__ == "__main__":
    main()
