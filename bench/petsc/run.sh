#!/usr/bin/env bash
# The PETSc backend's measurements for docs/performance.md: agreement with the default backend,
# and paper-3d with Coulomb friction F = 0.1 from n = 16 to 64 on 2 ranks (1 rank beside it
# where it fits), each run's run.json summarised by summary.py.
#   bench/petsc/run.sh agreement | scale | memory | faer
# Needs: cargo build --release --features petsc --target-dir target/petsc
set -euo pipefail
cd "$(dirname "$0")/../.."
P=target/petsc/release/piezocontact
OUT=${OUT:-out/bench-petsc}
mkdir -p "$OUT"
mpi() { mpirun -np "$1" --allow-run-as-root --oversubscribe "${@:2}"; }
case "${1:-scale}" in
agreement)
  for spec in "paper-frictionless 128" "paper-tresca 128" "paper 128" "paper-slip 128" \
              "paper-3d 16 contact.law=\"signorini\" ~contact.friction" \
              "paper-3d 16 contact.law=\"tresca\" ~contact.friction contact.slip_bound=0.05" \
              "paper-3d 16" "paper-3d 16 contact.friction=0.1"; do
    read -r scene n rest <<<"$spec"
    sets=(--set "mesh.n=$n")
    for kv in ${rest:-}; do sets+=(--set "$kv"); done
    tag="$scene-$n-$(echo "${rest:-}" | tr -c 'a-z0-9.' '_')"
    $P run "$scene" "${sets[@]}" --out "$OUT/agree/$tag/faer" >/dev/null 2>&1
    for np in 1 2; do
      mpi "$np" $P run "$scene" "${sets[@]}" --set 'solver.backend="petsc"' --out "$OUT/agree/$tag/petsc-$np" >/dev/null 2>&1
    done
  done
  python3 bench/petsc/summary.py agreement "$OUT/agree"
  ;;
scale)
  for n in 16 32 48 64; do
    mpi 2 $P run paper-3d --set "mesh.n=$n" --set contact.friction=0.1 --set 'solver.backend="petsc"' \
      --out "$OUT/scale/2-$n" >"$OUT/scale-2-$n.log" 2>&1 || echo "n = $n on 2 ranks failed: $OUT/scale-2-$n.log"
  done
  python3 bench/petsc/summary.py scale "$OUT/scale"
  ;;
memory)
  for np in 1 2; do
    mpi "$np" $P run paper-3d --set mesh.n=32 --set contact.friction=0.1 --set 'solver.backend="petsc"' \
      --out "$OUT/memory/$np-32" >/dev/null 2>&1
  done
  python3 bench/petsc/summary.py scale "$OUT/memory"
  ;;
faer)
  for n in 16 32; do
    $P run paper-3d --set "mesh.n=$n" --set contact.friction=0.1 --out "$OUT/faer/1-$n" >/dev/null 2>&1
  done
  python3 bench/petsc/summary.py scale "$OUT/faer"
  ;;
esac
