#!/usr/bin/env bash
# test_cli.sh - the grainpack command line as a user runs it: outputs, exit statuses and
# error messages. Usage: test_cli.sh PATH/TO/grainpack EXAMPLES_DIR
set -u
bin=$1 examples=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
failures=0
fail() { echo "FAIL: $*" >&2; failures=$((failures + 1)); }

# run: CSV to a file, header and one line per disk
"$bin" run "$examples/iron.json" --format csv -o "$tmp/iron.csv" || fail "run csv exited $?"
[ "$(head -1 "$tmp/iron.csv")" = "x,y,r,R" ] || fail "csv header is '$(head -1 "$tmp/iron.csv")'"
lines=$(($(wc -l < "$tmp/iron.csv") - 1))
[ "$lines" -gt 900 ] || fail "csv has $lines disks"

# JSON on stdout by default, with the same count
count=$("$bin" run "$examples/iron.json" | sed -n 's/.*"count":\([0-9]*\),"domain_area".*/\1/p')
[ "$count" = "$lines" ] || fail "json count '$count' differs from csv's $lines"

# SVG
"$bin" run "$examples/fixed.json" -f svg -o "$tmp/fixed.svg" || fail "run svg exited $?"
grep -q '</svg>' "$tmp/fixed.svg" || fail "svg is not closed"

# balance and Laguerre cells from the spec; VTK polydata with one polygon per grain
python3 - "$examples/variable.json" > "$tmp/staged.json" <<'PY' 2>/dev/null || sed 's/"seed": 1/"seed": 1, "balance": {"method": "relocation"}, "laguerre": {"shrink": "offset"}/' "$examples/variable.json" > "$tmp/staged.json"
import json, sys
spec = json.load(open(sys.argv[1]))
spec["inputs"]["balance"] = {"method": "relocation"}
spec["inputs"]["laguerre"] = {"shrink": "offset"}
print(json.dumps(spec))
PY
"$bin" run "$tmp/staged.json" -f vtk -o "$tmp/cells.vtk" || fail "run vtk exited $?"
head -1 "$tmp/cells.vtk" | grep -q "# vtk DataFile Version 3.0" || fail "vtk header is '$(head -1 "$tmp/cells.vtk")'"
polygons=$(sed -n 's/^POLYGONS \([0-9]*\) .*/\1/p' "$tmp/cells.vtk")
"$bin" run "$tmp/staged.json" -f csv -o "$tmp/staged.csv" || fail "run staged csv exited $?"
[ "$polygons" = "$(($(wc -l < "$tmp/staged.csv") - 1))" ] || fail "vtk has '$polygons' polygons for $(($(wc -l < "$tmp/staged.csv") - 1)) grains"
"$bin" run "$tmp/staged.json" | grep -q '"balance":{"method":"relocation"' || fail "json lacks the balance statistics"

# the periodic RVE example balances on the torus: every grain has F, F_max does not rise
"$bin" run "$examples/iron_periodic.json" -o "$tmp/rve.json" || fail "run iron_periodic exited $?"
python3 - "$tmp/rve.json" <<'PY' || fail "iron_periodic: F not on every grain, or F_max rose"
import json, sys
out = json.load(open(sys.argv[1]))
b, n = out["statistics"]["balance"], out["statistics"]["count"]
print("  iron_periodic:", n, "grains, F_max", b["before"]["max"], "->", b["after"]["max"], file=sys.stderr)
ok = b["method"] == "relocation" and b["before"]["interior"] == n == b["after"]["interior"]
sys.exit(0 if ok and b["after"]["max"] <= b["before"]["max"] and all(d["F"] is not None for d in out["disks"]) else 1)
PY

# the bare inputs object on stdin works as well as the whole request
python3 - "$examples/iron.json" > "$tmp/bare.json" <<'PY' 2>/dev/null || jq '.inputs' "$examples/iron.json" > "$tmp/bare.json"
import json, sys
print(json.dumps(json.load(open(sys.argv[1]))["inputs"]))
PY
"$bin" run - -f csv < "$tmp/bare.json" | cmp -s - "$tmp/iron.csv" || fail "bare inputs on stdin give other disks"

# validate
"$bin" validate "$examples/bagi.json" | grep -q "valid, about" || fail "validate says nothing useful"

# a bad spec: exit 3, file and JSON pointer and expectation on stderr, nothing written
cat > "$tmp/bad.json" <<'JSON'
{"inputs": {"domain": {"width": 10, "height": 10},
  "distribution": {"kind": "histogram", "bins": [{"min": 1, "max": 2, "p": 1.1}, {"min": 2, "max": 3, "p": -0.1}]}}}
JSON
"$bin" run "$tmp/bad.json" -o "$tmp/out.csv" 2> "$tmp/err"
status=$?
[ $status -eq 3 ] || fail "bad spec exited $status, expected 3"
grep -q "bad.json: /inputs/distribution/bins/0/p: must be <= 1, got 1.1" "$tmp/err" || fail "bad spec message: $(cat "$tmp/err")"
[ ! -e "$tmp/out.csv" ] || fail "output written for a bad spec"

# malformed JSON: exit 3 with line and column
echo '{"inputs": {"domain": ' > "$tmp/broken.json"
"$bin" run "$tmp/broken.json" 2> "$tmp/err"
[ $? -eq 3 ] || fail "broken json exit status"
grep -q "line 2" "$tmp/err" || fail "broken json message: $(cat "$tmp/err")"

# over the disk cap: exit 3, says how many
"$bin" run "$examples/bagi.json" --max-disks 1000 2> "$tmp/err"
[ $? -eq 3 ] || fail "capped spec exit status"
grep -q "more than the limit of 1000" "$tmp/err" || fail "cap message: $(cat "$tmp/err")"

# usage errors: exit 2
"$bin" run "$examples/iron.json" --format xml 2> "$tmp/err"; [ $? -eq 2 ] || fail "unknown format"
grep -q "expected json, csv, svg, vtk, vtu, msh or inp" "$tmp/err" || fail "unknown format message: $(cat "$tmp/err")"
"$bin" frobnicate 2> /dev/null; [ $? -eq 2 ] || fail "unknown command"
"$bin" run 2> /dev/null; [ $? -eq 2 ] || fail "missing spec"
"$bin" run "$examples/iron.json" --max-disks -5 2> /dev/null; [ $? -eq 2 ] || fail "negative cap"
"$bin" --help | grep -q "Usage: grainpack run" || fail "--help"

# a missing file: exit 1 with the reason
"$bin" run "$tmp/nope.json" 2> "$tmp/err"
[ $? -eq 1 ] || fail "missing file exit status"
grep -q "No such file" "$tmp/err" || fail "missing file message: $(cat "$tmp/err")"

[ $failures -eq 0 ] && echo "ok   test_cli ($bin)"
exit $((failures > 0))
