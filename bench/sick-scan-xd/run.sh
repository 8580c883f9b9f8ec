#!/usr/bin/env bash
# Runs SICK's own driver, sick_scan_xd (built without ROS), against `sailshape emulate` for the LMS111 and the
# LMS511 in both CoLa dialects, and prints what the driver logged and received. Outside CI: the driver is
# fetched and built by the developer.
#
#   bench/sick-scan-xd/run.sh SICK_SCAN_XD_SOURCE SICK_SCAN_XD_BUILD [SECONDS]
#
# SICK_SCAN_XD_BUILD is a build of the source with
#   cmake -DROS_VERSION=0 -DLDMRS=0 -DSCANSEGMENT_XD=0 -DCMAKE_BUILD_TYPE=Release SOURCE && ninja sick_scan_xd_shared_lib
# SECONDS (default 10) is how long each run listens. The sailshape binary is build/cli/sailshape.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
src="$(cd "${1:?sick_scan_xd source folder}" && pwd)"
bld="$(cd "${2:?sick_scan_xd build folder}" && pwd)"
seconds="${3:-10}"
sailshape="$root/build/cli/sailshape"
[ -x "$sailshape" ] || { echo "run.sh: $sailshape is missing; run scripts/build first" >&2; exit 1; }
[ -f "$bld/libsick_scan_xd_shared_lib.so" ] || { echo "run.sh: $bld/libsick_scan_xd_shared_lib.so is missing" >&2; exit 1; }

work="$(mktemp -d /tmp/sick-scan-xd-bench.XXXXXX)"
trap 'pkill -P $$ 2>/dev/null || true; [ -n "${KEEP:-}" ] || rm -rf "$work"' EXIT
g++ -O2 -std=c++17 -I"$src/include" "$here/client.cpp" -L"$bld" -lsick_scan_xd_shared_lib \
    -Wl,-rpath,"$bld" -lpthread -o "$work/client"

echo "sick_scan_xd $(grep -m1 -o '<version>[^<]*' "$src/package.xml" | cut -d'>' -f2), sailshape $(git -C "$root" rev-parse --short HEAD), $(date -u +%Y-%m-%d)"
echo
echo "| model | dialect | driver's errors | driver's warnings | point clouds received |"
echo "|---|---|---|---|---|"
for model in lms111 lms511; do
  launch="$src/launch/sick_lms_1xx.launch"
  [ "$model" = lms511 ] && launch="$src/launch/sick_lms_5xx.launch"
  for binary in true false; do
    dialect="CoLa-B"; [ "$binary" = false ] && dialect="CoLa-A"
    "$sailshape" emulate --model "$model" --port 0 --serial-link "$work/tt" --duration $((seconds + 20)) \
      >"$work/emulator.txt" 2>&1 &
    emu=$!
    port=""
    for _ in $(seq 100); do
      port="$(grep -o '127\.0\.0\.1:[0-9]*' "$work/emulator.txt" | head -1 | cut -d: -f2 || true)"
      [ -n "$port" ] && break
      sleep 0.1
    done
    [ -n "$port" ] || { echo "run.sh: the emulator did not start: $(cat "$work/emulator.txt")" >&2; exit 1; }
    log="$work/$model-$dialect.log"
    # The driver does not always end its threads; the client prints its counts and exits hard.
    (cd "$src" && timeout -s KILL $((seconds + 30)) "$work/client" \
      "$launch hostname:=127.0.0.1 port:=$port use_binary_protocol:=$binary" "$seconds" >"$log" 2>&1 || true)
    summary="$(grep -a -o 'summary: .*' "$log" | cut -c10- || true)"
    kill "$emu" 2>/dev/null || true
    wait "$emu" 2>/dev/null || true
    errors="$(grep -a -c '\[Error\]' "$log" || true)"
    warnings="$(grep -a -c '\[Warn' "$log" || true)"
    echo "| $model | $dialect | $errors | $warnings | ${summary:-none (the client died: see below)} |"
    grep -a -E '\[Error\]|\[Warn' "$log" | sed "s/^/    $model $dialect: /" | cut -c1-220 | sort | uniq -c | head -20 >>"$work/problems.txt" || true
  done
done
echo
if [ -s "$work/problems.txt" ]; then
  echo "What the driver logged as errors or warnings (count, line):"
  cat "$work/problems.txt"
else
  echo "The driver logged no error and no warning."
fi
