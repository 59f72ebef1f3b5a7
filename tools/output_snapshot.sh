#!/usr/bin/env bash
# Stores what the binary prints (stdout, stderr, exit status) for a fixed set of commands over the shipped
# fixtures, so that a refactor that promises "every output byte the same" can be checked with `diff -r`:
#   tools/output_snapshot.sh path/to/glossmeter OUTDIR
# Run it on the binary before a change and after, then `diff -r BEFORE AFTER`. Timing is left out
# (--no-timing); everything else is reproducible bit for bit. Run by hand, not by the tests.
set -u
BIN="$(realpath "$1")"; OUT="$2"
cd "$(dirname "$0")/.."
mkdir -p "$OUT"
n=0
run() { # run NAME ARGS...
  local name="$1"; shift
  n=$((n + 1))
  local f="$OUT/$(printf '%03d' $n)-$name"
  "$BIN" "$@" > "$f.out" 2> "$f.err"; echo $? > "$f.rc"
}
# Tables to fit the minutes: the 32-cell RGL table's default panel meets the wall-clock budget, so it is read
# at a loose tolerance (see docs/instrument.md).
for r in fixtures/recipes/*.json fixtures/materials/guenther-2005/*.json; do
  b=$(basename "$r" .json)
  for fmt in table json csv; do run "measure-$b-$fmt" measure "$r" --format $fmt --no-timing; done
  run "explain-$b" measure "$r" --explain --no-timing
done
run measure-rgl-32 measure fixtures/materials/rgl/beckmann-iso-32.json --rtol 1e-3 --no-timing --format json
run measure-dir measure fixtures/recipes --no-timing -g astm-d523-60
run measure-colour measure fixtures/recipes/blue-metallic-spectral.json -g d8-sci -g d8-sce --no-timing --format json
for r in fixtures/bad/*.json; do run "bad-$(basename "$r" .json)" measure "$r"; done
for g in fixtures/geometry/*.json; do run "geofile-$(basename "$g" .json)" measure fixtures/recipes/black-glass.json --geometry-file "$g" --no-timing; done
run standards standards
for id in $("$BIN" standards | awk '{print $1}'); do run "standards-$id" standards "$id"; done
run schema schema
for s in measure compare sweep fit; do run "schema-$s" schema --output-format $s; done
for s in fixtures/sheets/*.csv; do run "compare-$(basename "$s" .csv)" compare "$s" --recipe-dir fixtures/recipes --format json; done
run compare-glass compare fixtures/recipes/glass-n1.5.json fixtures/sheets/byk-semicolon-decimal-comma.csv
run compare-qc-junit compare fixtures/sheets/qc-many-samples.csv --recipe-dir fixtures/recipes --format junit
run compare-qc-csv compare fixtures/sheets/qc-many-samples.csv --recipe-dir fixtures/recipes --format csv
run sweep-grid sweep fixtures/recipes/cook-torrance-lobes.json --vary /lobes/0/m=0.05..0.4:4 -g astm-d523-60 --no-timing
run sweep-lhs sweep fixtures/recipes/bench-b4-ggx-0.3.json --vary /roughness=0.1..0.5 --lhs 5 --seed 3 --format jsonl --no-timing
run sweep-shard sweep fixtures/recipes/bench-b4-ggx-0.3.json --vary /roughness=0.1..0.5:6 --shard 2/3 --no-timing
run fit-json fit fixtures/recipes/bench-b4-ggx-0.3.json --free /roughness=log:1e-3..0.5 --target 'astm-d523-60/gloss=3±0.2' --format json
run fit-table fit fixtures/recipes/bench-b4-ggx-0.3.json --free /roughness=log:1e-3..0.5 --target 'astm-d523-60/gloss=3±0.2'
run profile-csv profile fixtures/recipes/glass-n1.5.json
run profile-json profile fixtures/recipes/semigloss-white.json --format json
run usage-1 measure
run usage-2 measure fixtures/recipes/black-glass.json --rtol 0
run usage-3 measure fixtures/recipes/black-glass.json -g nope
run usage-4 sweep fixtures/recipes/black-glass.json --vary /nope=1..2:3
run usage-5 sweep fixtures/recipes/bench-b4-ggx-0.3.json --vary /roughness=0.1..0.5 --lhs 0 --seed 1
run usage-6 compare fixtures/sheets/qc-many-samples.csv --tolerance -1
run usage-7 fit fixtures/recipes/bench-b4-ggx-0.3.json --free /roughness=0.1..0.5

# fit's JSON states its wall time; the one number that is not reproducible is masked.
sed -i -E 's/"seconds": [0-9.e+-]+/"seconds": "(masked)"/; s/forward runs (.*), [0-9.]+ s$/forward runs (\1), (masked) s/' "$OUT"/*.out
echo "$n commands into $OUT"
