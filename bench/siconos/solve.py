#!/usr/bin/python3
"""Siconos' own solvers on Siconos-format frictional contact problems, for a side-by-side
comparison with `piezocontact fclib` on the same machine (see docs/fclib.md).

Needs Debian's python3-siconos (4.4) and python3-scipy; run with the system python:
    /usr/bin/python3 bench/siconos/solve.py FILE... [--tol 1e-8] [--timeout 60] [--json OUT]

Each (file, solver) runs in its own process under the time limit. 3D problems: NSN-AC
(Alart-Curnier Newton), NSGS, PROX (proximal point around NSN-AC). 2D problems: Siconos' 2D
NSGS and Lemke, and the three 3D solvers on the problem lifted to 3D (a second tangential
direction, uncoupled, with unit compliance and no load: its reaction is zero). Every answer is
judged by the same error, computed here from (r, u): De Saxce's natural map divided by
max(|q|, |r|, |u|), as in the README of the problem set.
"""
import argparse, json, multiprocessing as mp, os, sys, time
import numpy as np
import scipy.sparse
import siconos.numerics as sn


def dense_w(p):
    """W as a dense array (sparse block storage) or a scipy sparse matrix (sparse storage)."""
    m = p.dimension * p.numberOfContacts
    a = sn.NM_convert(p.M)
    if isinstance(a, np.ndarray):
        return a.reshape(m, m)
    if scipy.sparse.issparse(a):
        return a.tocsr()
    return np.array([[sn.SBM_get_value(a, i, j) for j in range(m)] for i in range(m)])


def project_cone(x, mu):
    xn, xt = x[0], x[1:]
    nt = np.linalg.norm(xt)
    if nt <= mu * xn:
        return x.copy()
    if mu * nt <= -xn:
        return np.zeros_like(x)
    t = (xn + mu * nt) / (1 + mu * mu)
    return np.concatenate(([t], mu * t * xt / nt))


def error(dim, w, q, mu, r):
    u = w @ r + q
    e = 0.0
    for i, m in enumerate(mu):
        s = slice(i * dim, (i + 1) * dim)
        ut = u[s].copy()
        ut[0] += m * np.linalg.norm(u[s][1:])
        e += np.sum((r[s] - project_cone(r[s] - ut, m)) ** 2)
    den = max(np.linalg.norm(q), np.linalg.norm(r), np.linalg.norm(u))
    return np.sqrt(e) / den if den > 0 else np.sqrt(e)


def lifted(dim, w, q, mu):
    """A 2D problem as a 3D one with an uncoupled second tangential direction."""
    nc = len(mu)
    q3 = np.zeros(3 * nc)
    idx = np.array([3 * i + k for i in range(nc) for k in range(2)])
    q3[idx] = q
    if scipy.sparse.issparse(w):
        c = w.tocoo()
        rows = np.concatenate([idx[c.row], 3 * np.arange(nc) + 2])
        cols = np.concatenate([idx[c.col], 3 * np.arange(nc) + 2])
        vals = np.concatenate([c.data, np.ones(nc)])
        return scipy.sparse.csc_matrix((vals, (rows, cols)), shape=(3 * nc, 3 * nc)), q3
    w3 = np.zeros((3 * nc, 3 * nc))
    w3[np.ix_(idx, idx)] = w
    for i in range(nc):
        w3[3 * i + 2, 3 * i + 2] = 1.0
    return w3, q3


SOLVERS_3D = {"nsn-ac": "SICONOS_FRICTION_3D_NSN_AC", "nsgs": "SICONOS_FRICTION_3D_NSGS", "prox": "SICONOS_FRICTION_3D_PROX"}
SOLVERS_2D = {"2d-nsgs": "SICONOS_FRICTION_2D_NSGS", "2d-lemke": "SICONOS_FRICTION_2D_LEMKE"}


def solve(path, solver, tol, queue):
    p = sn.frictionContact_new_from_filename(path)
    dim, nc = p.dimension, p.numberOfContacts
    w, q, mu = dense_w(p), np.array(p.q), np.array(p.mu)
    if solver in SOLVERS_2D:
        options = sn.SolverOptions(getattr(sn, SOLVERS_2D[solver]))
        prob, m = p, dim * nc
        drive = sn.fc2d_driver
    else:
        options = sn.SolverOptions(getattr(sn, SOLVERS_3D[solver]))
        if dim == 2:
            w3, q3 = lifted(dim, w, q, mu)
            prob = sn.FrictionContactProblem(3, w3, q3, mu)
        else:
            prob = p
        m = 3 * nc
        drive = sn.fc3d_driver
    options.dparam[sn.SICONOS_DPARAM_TOL] = tol
    options.iparam[sn.SICONOS_IPARAM_MAX_ITER] = 100000
    r, u = np.zeros(m), np.zeros(m)
    start = time.perf_counter()
    info = drive(prob, r, u, options)
    elapsed = time.perf_counter() - start
    if dim == 2 and solver not in SOLVERS_2D:
        r = np.array([r[3 * i + k] for i in range(nc) for k in range(2)])
    queue.put(dict(info=int(info), iterations=int(options.iparam[sn.SICONOS_IPARAM_ITER_DONE]),
                   time_s=elapsed, own_error=float(options.dparam[sn.SICONOS_DPARAM_RESIDU]),
                   siconos_error=float(error(dim, w, q, mu, r))))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("files", nargs="+")
    ap.add_argument("--tol", type=float, default=1e-8)
    ap.add_argument("--timeout", type=float, default=60)
    ap.add_argument("--json")
    a = ap.parse_args()
    rows = []
    print(f"{'file':40} {'solver':9} {'iters':>7} {'time (s)':>9} {'error':>9}  outcome", flush=True)
    for f in a.files:
        dim = int(open(f).read().split()[0])
        solvers = list(SOLVERS_3D) + (list(SOLVERS_2D) if dim == 2 else [])
        for s in solvers:
            queue = mp.Queue()
            proc = mp.Process(target=solve, args=(f, s, a.tol, queue))
            proc.start()
            proc.join(a.timeout)
            if proc.is_alive():
                proc.kill()
                row = dict(file=os.path.basename(f), solver=s, converged=False, outcome=f"timeout {a.timeout:g} s")
            elif queue.empty():
                row = dict(file=os.path.basename(f), solver=s, converged=False, outcome=f"crashed ({proc.exitcode})")
            else:
                res = queue.get()
                ok = res["info"] == 0 and res["siconos_error"] <= a.tol
                row = dict(file=os.path.basename(f), solver=s, converged=ok,
                           outcome="solved" if ok else f"info {res['info']}", **res)
            rows.append(row)
            print(f"{row['file']:40} {s:9} {row.get('iterations', '-'):>7} {row.get('time_s', float('nan')):9.3f} "
                  f"{row.get('siconos_error', float('nan')):9.2e}  {row['outcome']}", flush=True)
    if a.json:
        json.dump(rows, open(a.json, "w"), indent=1)


if __name__ == "__main__":
    main()
