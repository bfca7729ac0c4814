"""The direct solvers side by side on one matrix (issue 25, item 3): the scene's `K` without
contact (the linear floor: analysis, numeric factorisation, one solve), factored by

- faer, as the default backend does it (`bench_direct`), on 1 and 2 threads of rayon's pool
  (`RAYON_NUM_THREADS`: on 2, the factor's elimination tree on both cores),
- PARDISO (Intel MKL, through `pypardiso` from PyPI) on 1 and 2 threads,
- MUMPS through PETSc on 1 and 2 MPI ranks (the optional backend's build,
  `target/petsc/release/piezocontact`, with `-ksp_type preonly -pc_type lu
  -pc_factor_mat_solver_type mumps`; its run.json's factorisation and solve), where that build
  exists,

in interleaved rounds (faer 1, faer 2, PARDISO 1, PARDISO 2, MUMPS 1, MUMPS 2, then again), so that the
machine's drift falls on all alike; prints each one's median over the rounds and its ratio to
faer's.

    cargo build --release -p driver --example bench_direct
    pip install scipy pypardiso
    python3 bench/direct/compare.py [n] [scene] [rounds]
"""

import json
import os
import pathlib
import statistics
import subprocess
import sys

REPO = pathlib.Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "target" / "release" / "examples" / "bench_direct"
PETSC = REPO / "target" / "petsc" / "release" / "piezocontact"

CHILD = r"""
import os, sys, time
import numpy as np, scipy.io, scipy.sparse as sp
import pypardiso
d = sys.argv[1]
cache = os.path.join(d, "K.npz")
if os.path.exists(cache):
    k = sp.load_npz(cache)
else:
    k = sp.csr_matrix(scipy.io.mmread(os.path.join(d, "K.mtx")))
    sp.save_npz(cache, k)
b = np.loadtxt(os.path.join(d, "b.txt"))
a = sp.triu(k, format="csr")  # PARDISO's real symmetric indefinite (mtype -2): the upper triangle
a.sort_indices()
s = pypardiso.PyPardisoSolver(mtype=-2)
t = time.perf_counter(); s.set_phase(11); s._call_pardiso(a, b); analysis = time.perf_counter() - t
t = time.perf_counter(); s.set_phase(22); s._call_pardiso(a, b); factor = time.perf_counter() - t
t = time.perf_counter(); s.set_phase(33); x = s._call_pardiso(a, b); solve = time.perf_counter() - t
r = np.linalg.norm(k @ x - b) / np.linalg.norm(b)
print(f"pardiso analysis {analysis:.4f} factor {factor:.4f} solve {solve:.4f} residual {r:.2e}")
"""


def parse(line):
    """`name analysis A factor F solve S residual R` -> the four numbers."""
    w = line.split()
    return {w[i]: float(w[i + 1]) for i in range(1, len(w) - 1, 2)}


def faer(n, scene, d, threads=1):
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    out = subprocess.run([str(EXAMPLE), str(n), scene, d, "1"], check=True, capture_output=True, text=True,
                         env=env).stdout
    return parse([l for l in out.splitlines() if l.startswith("faer")][-1])


def pardiso(threads, d):
    env = dict(os.environ, MKL_NUM_THREADS=str(threads), OMP_NUM_THREADS=str(threads))
    out = subprocess.run([sys.executable, "-c", CHILD, d], check=True, capture_output=True, text=True, env=env).stdout
    return parse(out.strip().splitlines()[-1])


def mumps(ranks, n, scene, d):
    opts = '"-ksp_type preonly -pc_type lu -pc_factor_mat_solver_type mumps"'
    where = pathlib.Path(d) / f"mumps-{ranks}"
    env = dict(os.environ, OMPI_MCA_btl_vader_single_copy_mechanism="none")
    cmd = ["mpirun", "-np", str(ranks), "--allow-run-as-root", "--oversubscribe", str(PETSC), "run", scene,
           "--set", f"mesh.n={n}", "--set", "contact.law=\"none\"", "--set", "solver.backend=\"petsc\"",
           "--set", f"solver.petsc_options={opts}", "--out", str(where)]
    subprocess.run(cmd, check=True, capture_output=True, env=env)
    t = json.loads((where / "run.json").read_text())["timings_s"]
    # PETSc's set-up of the preconditioner is MUMPS' analysis and factorisation together
    return {"analysis": 0.0, "factor": t["factorization"], "solve": t["solve"], "residual": float("nan")}


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 256
    scene = sys.argv[2] if len(sys.argv) > 2 else "paper"
    rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    d = str(REPO / "out" / "bench-direct" / f"{scene}-{n}")
    runs = {"faer 1 thread": lambda: faer(n, scene, d, 1),
            "faer 2 threads": lambda: faer(n, scene, d, 2),
            "PARDISO 1 thread": lambda: pardiso(1, d),
            "PARDISO 2 threads": lambda: pardiso(2, d)}
    if PETSC.exists():
        runs["MUMPS 1 rank"] = lambda: mumps(1, n, scene, d)
        runs["MUMPS 2 ranks"] = lambda: mumps(2, n, scene, d)
    else:
        print(f"no {PETSC}: MUMPS left out (cargo build --release --features petsc --target-dir target/petsc)")
    faer(n, scene, d)  # writes the matrix
    pardiso(1, d)  # caches it for PARDISO
    got = {k: [] for k in runs}
    for _ in range(rounds):
        for name, run in runs.items():
            got[name].append(run())
    base = None
    print(f"{scene} n = {n}, medians of {rounds} interleaved rounds (s):")
    print(f"{'solver':20} {'analysis':>9} {'factor':>9} {'solve':>9} {'total':>9} {'faer / it':>10}  residual")
    for name, rs in got.items():
        med = {k: statistics.median(r[k] for r in rs) for k in ("analysis", "factor", "solve")}
        total = sum(med.values())
        base = base or total
        res = statistics.median(r["residual"] for r in rs)
        print(f"{name:20} {med['analysis']:9.3f} {med['factor']:9.3f} {med['solve']:9.3f} {total:9.3f} {base / total:10.2f}  {res:.1e}")


if __name__ == "__main__":
    main()
