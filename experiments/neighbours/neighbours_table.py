#!/usr/bin/python3
"""Safety from every neighbour: formations in a world that can hurt, every pair's separation.

Runs cf_sim on config/scenarios/crowd_v4_gust.yaml (a V star of 4, a gust on follower 2 that its
3 m/s^2 vehicle cannot answer) and crowd_16_gusts.yaml (a V star of 16 in seeded random gusts,
vehicles limited to 4 m/s^2 with a 0.2 s lag, measurement noise), the latter with 4, 16 and 64
followers and seeds 1 to 5, and writes to OUT_DIR:
  neighbour_safety.csv  one row per run: min distance over every pair and over the neighbours
                        (pairs of which neither looks at the other) against the perimeter
                        alpha ||d||, the pairs that came inside it, and the largest
                        max ||xi_i|| / xi_max,i of its followers
  neighbour_safety.md   the table, also placed in formations.md between its markers
Usage: neighbours_table.py CF_SIM OUT_DIR
"""

import csv
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "common"))
from doc_block import replace_block  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
SEEDS = (1, 2, 3, 4, 5)
CASES = [("V star of 4, gust on follower 2", "crowd_v4_gust.yaml", [], None),
         ("V star of 4, calm", "crowd_v4_gust.yaml", ["world.followers=[]"], None)]
for count in (4, 16, 64):
    for seed in SEEDS:
        CASES.append((f"V star of {count}, random gusts", "crowd_16_gusts.yaml",
                      [f"formation.followers={count}", f"world.seed={seed}"], seed))


def run(cf_sim, scenario, sets):
    """The formation line's fields and each follower's, from cf_sim's summary."""
    args = [cf_sim, str(ROOT / "config" / "scenarios" / scenario)]
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


def main():
    cf_sim, out_dir = sys.argv[1], Path(sys.argv[2])
    rows = []
    for name, scenario, sets, seed in CASES:
        formation, followers = run(cf_sim, scenario, sets)
        ratio = max(float(f["max_xi"]) / float(f["xi_max"]) for f in followers)
        rows.append({"case": name, "seed": "" if seed is None else seed,
                     "followers": len(followers),
                     "perimeter": float(formation["perimeter"]),
                     "min_pair": float(formation["min_pair_separation"]),
                     "min_neighbour": float(formation["min_neighbour_separation"]),
                     "pairs_inside": int(formation["pairs_inside_perimeter"]),
                     "neighbour_pairs_inside": int(formation["neighbour_pairs_inside_perimeter"]),
                     "worst_xi_ratio": ratio})
    out_dir.mkdir(parents=True, exist_ok=True)
    with open(out_dir / "neighbour_safety.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    lines = ["| formation | seed | min distance, every pair (m) | min distance, neighbours (m) | "
             "perimeter (m) | pairs inside (neighbours) | worst max ‖ξ_i‖ / ξ_max,i |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        mark = " **inside**" if r["min_pair"] < r["perimeter"] else ""
        lines.append(f"| {r['case']} | {r['seed'] or '—'} | {r['min_pair']:.2f}{mark} | "
                     f"{r['min_neighbour']:.2f} | {r['perimeter']:.2f} | "
                     f"{r['pairs_inside']} ({r['neighbour_pairs_inside']}) | "
                     f"{r['worst_xi_ratio']:.2f} |")
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
