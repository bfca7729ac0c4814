"""Summaries of bench/petsc/run.sh's runs (standard library only).

  summary.py agreement DIR   one line per case: multipliers and displacements of the PETSc runs
                             against the default backend's (contact.csv), relative 2-norms
  summary.py scale DIR       one line per run: unknowns, ranks, Newton (active-set) steps, Krylov
                             iterations in all and per step, times, peak memory per rank
"""
import csv
import json
import math
import os
import sys


def contact(path):
    with open(os.path.join(path, "contact.csv")) as f:
        rows = list(csv.DictReader(f))
    lam = [float(r[k]) for r in rows for k in r if k.startswith("lambda")]
    u = [float(r[k]) for r in rows for k in r if k.startswith("u_")]
    return lam, u


def rel(a, b):
    num = math.sqrt(sum((x - y) ** 2 for x, y in zip(a, b)))
    den = math.sqrt(sum(x * x for x in a))
    return num / den if den > 0 else num


def agreement(root):
    print("| case | ranks | steps | Krylov | multipliers | contact displacements |")
    print("|---|---|---|---|---|---|")
    for case in sorted(os.listdir(root)):
        ref = os.path.join(root, case, "faer")
        lam0, u0 = contact(ref)
        for run in sorted(d for d in os.listdir(os.path.join(root, case)) if d.startswith("petsc")):
            path = os.path.join(root, case, run)
            r = json.load(open(os.path.join(path, "run.json")))
            lam, u = contact(path)
            print(f"| {case} | {r['petsc']['ranks']} | {r['iterations']['newton']} | "
                  f"{r['petsc']['krylov_iterations']} | {rel(lam0, lam):.1e} | {rel(u0, u):.1e} |")


def scale(root):
    print("| run | unknowns | ranks | steps | Krylov (per step) | assembly s | solve s | total s | peak MiB per rank |")
    print("|---|---|---|---|---|---|---|---|---|")
    for run in sorted(os.listdir(root), key=lambda s: [int(x) if x.isdigit() else x for x in s.split("-")]):
        path = os.path.join(root, run, "run.json")
        if not os.path.exists(path):
            continue
        r = json.load(open(path))
        p = r.get("petsc")
        t = r["timings_s"]
        steps = r["iterations"]["newton"]
        if p:
            krylov = p["krylov_iterations"]
            per = krylov / (steps + 1)
            mem = ", ".join(str(round(b / 2**20)) for b in p["peak_bytes_per_rank"])
            print(f"| {run} | {p['unknowns']} | {p['ranks']} | {steps} | {krylov} ({per:.0f}) | "
                  f"{t['assembly']:.1f} | {t['solve']:.1f} | {t['total']:.1f} | {mem} |")
        else:
            dofs = r["dofs"]["u"] + r["dofs"]["phi"]
            mem = round(r["memory"]["peak_bytes"] / 2**20)
            print(f"| {run} (faer) | {dofs} | 1 | {steps} | - | {t['assembly']:.1f} | "
                  f"{t['factorization'] + t['condense'] + t['solve']:.1f} | {t['total']:.1f} | {mem} |")


if __name__ == "__main__":
    {"agreement": agreement, "scale": scale}[sys.argv[1]](sys.argv[2])
