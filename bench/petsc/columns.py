"""Every shipped scene's outputs from two runs (the default backend's and the PETSc backend's)
column by column: contact.csv's numeric columns, each relative to its own largest value, the
worst one named; run.json's normal force; both equilibrium residuals. One markdown row each.

  python3 bench/petsc/columns.py DEFAULT_DIR PETSC_DIR   (one sub-directory per scene in each)
"""
import csv, sys, os, json
base, other = sys.argv[1], sys.argv[2]
rows = []
for s in sorted(os.listdir(other)):
    a, b = os.path.join(base, s, 'contact.csv'), os.path.join(other, s, 'contact.csv')
    worst = (0.0, '-')
    if os.path.exists(a) and os.path.exists(b):
        A = list(csv.DictReader(open(a))); B = list(csv.DictReader(open(b)))
        assert len(A) == len(B), s
        for col in A[0].keys():
            try:
                x = [float(r[col]) for r in A]; y = [float(r[col]) for r in B]
            except ValueError:
                continue
            sc = max(abs(v) for v in x)
            d = max(abs(p - q) for p, q in zip(x, y))
            if sc > 0:
                r = d / sc
                if r > worst[0]:
                    worst = (r, col)
    ja = json.load(open(os.path.join(base, s, 'run.json'))); jb = json.load(open(os.path.join(other, s, 'run.json')))
    fa = ja.get('contact', {}).get('normal_force'); fb = jb.get('contact', {}).get('normal_force')
    df = abs(fa - fb) / abs(fa) if fa else 0.0
    rows.append((s, worst, df, ja['residuals']['equilibrium'], jb['residuals']['equilibrium']))
for s, w, df, ea, eb in rows:
    print(f"| {s} | {w[0]:.1e} ({w[1]}) | {df:.1e} | {ea:.1e} / {eb:.1e} |")
