#!/bin/sh
# Ours (three runs, the median taken) and Siconos' solvers (one run each, 30 s per solver) on
# the same files in one session, then the table of bench/siconos/compare.py.
#     sh bench/siconos/side_by_side.sh DIR      (DIR: the files, e.g. from fetch.sh)
set -eu
dir=$1
out=${OUT:-target/side_by_side}
mkdir -p "$out"
cargo build --release -q
for k in 1 2 3; do
    ./target/release/piezocontact fclib "$dir"/*.dat --out "$out/ours$k" > "$out/ours$k.log" 2>&1 || true
done
/usr/bin/python3 bench/siconos/solve.py "$dir"/*.dat --timeout 30 --json "$out/siconos.json" > "$out/siconos.log" 2>&1
python3 bench/siconos/compare.py "$out/ours1/summary.json" "$out/siconos.json" \
    "$out/ours2/summary.json" "$out/ours3/summary.json"
