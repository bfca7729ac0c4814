#!/usr/bin/env bash
# Open (floating, uncharged) conducting tips against the half-space's closed form at four
# sizes: the table of docs/theory.md ("A floating conducting indenter"). Run from the
# repository's root after `cargo build --release`; prints a Markdown table.
set -euo pipefail
P=${PIEZOCONTACT:-target/release/piezocontact}
OUT=${OUT:-out/floating-tips}
mkdir -p "$OUT"
for scene in indent-sphere indent-cone indent-punch; do
  for n in 160 240 320 640; do
    out="$OUT/$scene-$n"
    if "$P" run "$scene" --set mesh.n="$n" --set contact.electric=conducting --set contact.charge=0.0 \
        --out "$out" > "$out.log" 2>&1; then
      python3 - "$out/run.json" "$scene" "$n" <<'PY'
import json, sys
r = json.load(open(sys.argv[1])); i = r["indenter"]; h = i["half_space"]
e = lambda a, b: 100 * (a - b) / b
print(f"| {sys.argv[2]} | {sys.argv[3]} | {i['force']:.5g} | {h['force']:.5g} | {e(i['force'], h['force']):+.2f} % "
      f"| {i['potential']:.5g} | {h['potential']:.5g} | {e(i['potential'], h['potential']):+.2f} % | {i['contact_radius']:.4g} |")
PY
    else
      echo "| $scene | $n | error: $(tail -1 "$out.log" | cut -c1-150) |"
    fi
  done
done
