#!/usr/bin/env bash
# One run: generate a sail (gen.py), its truth (`sailshape design show` on the exact
# surface) and its analysis (`sailshape analyze` on the samples), into DIR.
#   run.sh KIND SEED POINTS NOISE_MM DIR [gen.py options]     (points/lines runs)
#   LINES="LINE_M ALONG_M" run.sh KIND SEED 0 NOISE_MM DIR    (scan-line samples, genlines.py)
# SAILSHAPE picks the binary (default build/cli/sailshape); PARAMS, a `--params` file for the analysis. Sweeps: xargs -P2 over runs,
# then compare.py DIR. Runs of one DIR must differ in KIND, SEED or NOISE_MM.
set -uo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
sailshape="${SAILSHAPE:-$here/../../build/cli/sailshape}"
kind=$1 seed=$2 points=$3 noise=$4 dir=$5
shift 5
mkdir -p "$dir"
p="$dir/${kind}_${seed}_${noise}"
if [ -n "${LINES:-}" ]; then
  python3 "$here/gen.py" "$kind" "$seed" 1000 "$noise" "$p" >/dev/null
  python3 "$here/genlines.py" "$kind" "$seed" "$noise" "$p" $LINES >/dev/null
else
  python3 "$here/gen.py" "$kind" "$seed" "$points" "$noise" "$p" "$@" >/dev/null
fi
"$sailshape" design show "${p}_design.ply" --axes boat --unit m --json "${p}_d.json" >/dev/null 2>&1 || echo "DESIGN FAIL $p"
"$sailshape" analyze "$p.xyz" ${PARAMS:+--params "$PARAMS"} --json "${p}_a.json" -q >"${p}_a.log" 2>&1 || echo "ANALYZE FAIL $p: $(tail -1 "${p}_a.log")"
rm -f "$p.xyz"
