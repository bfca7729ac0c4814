#!/usr/bin/python3
"""Side by side: `piezocontact fclib ... --out DIR` (DIR/summary.json) against
`bench/siconos/solve.py ... --json FILE`, per file: our time and outcome, Siconos' best solver
(the fastest that solved it) and its time, the ratio, and the counts.

    python3 bench/siconos/compare.py DIR/summary.json siconos.json [DIR2/summary.json ...]

With more runs of ours (further summaries after Siconos'), our time per file is their median.
"""
import json, math, statistics, sys

ours = {r["file"]: r for r in json.load(open(sys.argv[1]))}
for extra in sys.argv[3:]:
    for r in json.load(open(extra)):
        ours[r["file"]].setdefault("times", [ours[r["file"]]["time_s"]]).append(r["time_s"])
for r in ours.values():
    r["time_s"] = statistics.median(r.get("times", [r["time_s"]]))
theirs = {}
for r in json.load(open(sys.argv[2])):
    theirs.setdefault(r["file"], []).append(r)

print(f"| file | contacts | ours (s) | ours | Siconos best | Siconos (s) | ratio | Siconos solvers that solved |")
print("|---|---|---|---|---|---|---|---|")
ratios, n_ours, n_theirs, n_both = [], 0, 0, 0
for f in sorted(ours):
    o = ours[f]
    solved = [r for r in theirs.get(f, []) if r["converged"]]
    best = min(solved, key=lambda r: r["time_s"]) if solved else None
    n_ours += o["converged"]
    n_theirs += bool(best)
    ratio = ""
    if o["converged"] and best:
        n_both += 1
        # times below 0.1 ms are clock noise for both
        q = max(o["time_s"], 1e-4) / max(best["time_s"], 1e-4)
        ratios.append(q)
        ratio = f"{q:.2f}"
    print(f"| {f} | {o['contacts']} | {o['time_s']:.4f} | {'solved' if o['converged'] else 'failed'} | "
          f"{best['solver'] if best else '-'} | {best['time_s'] if best else float('nan'):.4f} | {ratio} | "
          f"{', '.join(r['solver'] for r in solved) or 'none'} |")
gm = math.exp(sum(map(math.log, ratios)) / len(ratios)) if ratios else float("nan")
print(f"\nsolved: ours {n_ours} of {len(ours)}, Siconos (any solver) {n_theirs}; "
      f"where both solve ({n_both}), time ratio ours / Siconos' best: geometric mean {gm:.2f}, "
      f"median {sorted(ratios)[len(ratios)//2] if ratios else float('nan'):.2f}")

# against each Siconos solver on its own: the files both solve, the geometric mean of the ratio
by_solver = {}
for f, o in ours.items():
    for r in theirs.get(f, []):
        if r["converged"] and o["converged"]:
            q = max(o["time_s"], 1e-4) / max(r["time_s"], 1e-4)
            by_solver.setdefault(r["solver"], []).append(q)
for s, qs in sorted(by_solver.items()):
    solved = sum(1 for f in ours for r in theirs.get(f, []) if r["solver"] == s and r["converged"])
    gm = math.exp(sum(map(math.log, qs)) / len(qs))
    print(f"against {s}: it solves {solved} of {len(ours)}; where both solve ({len(qs)}), ours / its time: geometric mean {gm:.2f}")
