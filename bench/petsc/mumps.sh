#!/usr/bin/env bash
# The PETSc backend's condensed route (MUMPS with the contact dofs' Schur complement) against the
# default backend, for docs/performance.md:
#   bench/petsc/mumps.sh paper3d   paper-3d (Coulomb) at n = 16, 24, 32: the default backend on
#                                  2 threads, PETSc on 2 ranks 3 times each (n >= 24), and on 1
#                                  and 4 ranks once; rows.csv: wall, Newton steps, factorisation,
#                                  condensation, contact solve
#   bench/petsc/mumps.sh path      a 100-instant path (paper-cycle, n = 128, fields at the last
#                                  instant) against one static solve (paper, n = 128), 3 times
# Needs: cargo build --release --features petsc, and an optimised BLAS (Debian:
# libopenblas0-pthread; MUMPS runs on the system's BLAS). One BLAS thread per rank.
set -euo pipefail
cd "$(dirname "$0")/../.."
P=target/release/piezocontact
OUT=${OUT:-out/bench-mumps}
mkdir -p "$OUT"
export OMPI_MCA_btl_vader_single_copy_mechanism=${OMPI_MCA_btl_vader_single_copy_mechanism:-none}
mpi() { mpirun --allow-run-as-root --oversubscribe -x OPENBLAS_NUM_THREADS=1 -np "$1" "${@:2}"; }
row() { # file tag wall dir
  python3 - "$@" <<'PY'
import json, sys
f, tag, wall, d = sys.argv[1:]
j = json.load(open(d + "/run.json"))
t, it = j["timings_s"], j["iterations"]
open(f, "a").write(f"{tag},{float(wall):.2f},{t['total']:.2f},{it.get('newton')},{t.get('factorization', 0):.2f},"
                   f"{t.get('condense', 0):.2f},{t.get('contact', 0):.2f}\n")
PY
}
timed() { local t0; t0=$(date +%s.%N); "$@" >/dev/null 2>&1; echo "$(date +%s.%N) - $t0" | bc; }
case "${1:-paper3d}" in
paper3d)
  f="$OUT/paper3d.csv"
  echo "n,backend,ranks,rep,wall_s,total_s,newton,factor_s,condense_s,contact_s" >"$f"
  for n in 16 24 32; do
    reps=3; [ "$n" = 16 ] && reps=1
    for k in $(seq "$reps"); do
      d="$OUT/p3d-$n-faer-$k"; w=$(timed $P run paper-3d --set "mesh.n=$n" --out "$d"); row "$f" "$n,faer,0,$k" "$w" "$d"
      d="$OUT/p3d-$n-petsc2-$k"; w=$(timed mpi 2 $P run paper-3d --set "mesh.n=$n" --set 'solver.backend="petsc"' --out "$d"); row "$f" "$n,petsc,2,$k" "$w" "$d"
    done
    for np in 1 4; do
      d="$OUT/p3d-$n-petsc$np"; w=$(timed mpi "$np" $P run paper-3d --set "mesh.n=$n" --set 'solver.backend="petsc"' --out "$d"); row "$f" "$n,petsc,$np,1" "$w" "$d"
    done
  done
  cat "$f"
  ;;
path)
  f="$OUT/path.csv"
  echo "what,backend,wall_s,total_s,newton,factor_s,condense_s,contact_s" >"$f"
  for k in 1 2 3; do
    for b in faer petsc; do
      run() { if [ "$b" = faer ]; then $P run "$@"; else mpi 2 $P run "$@" --set 'solver.backend="petsc"'; fi; }
      d="$OUT/static-$b-$k"; w=$(timed run paper --set mesh.n=128 --out "$d"); row "$f" "static,$b" "$w" "$d"
      d="$OUT/path-$b-$k"; w=$(timed run paper-cycle --set mesh.n=128 --set path.steps=100 --set path.output_every=0 --out "$d"); row "$f" "path100,$b" "$w" "$d"
    done
  done
  cat "$f"
  ;;
*) echo "usage: bench/petsc/mumps.sh paper3d | path" >&2; exit 2 ;;
esac
