#!/bin/bash
# ctest: lidar-dump on the checked-in captures gives the expected scans and counters; lidar-emu -> pty -> lidar-dump
# end to end for ld06 and rplidar: with 5 % corrupted bytes the counters show it and scans still arrive; with 5 %
# corrupted packets dock-sim detect finds the dock in most scans; the intensity verdict is printed (LD06: usable).
# Usage: lidar_tools.sh LIDAR_DUMP LIDAR_EMU DOCK_SIM SOURCE_DIR WORK_DIR
set -u
DUMP=$1 EMU=$2 DOCKSIM=$3 SRC=$4 WORK=$5
mkdir -p "$WORK"
fail() { echo "FAIL: $*"; exit 1; }
jget() { /usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))[sys.argv[2]])" "$1" "$2"; }

# 1. Captures: exact counters (tests/data/lidar/make_captures.py explains each number).
check_capture() {  # protocol file key=value...
  local proto=$1 file=$2; shift 2
  "$DUMP" --protocol "$proto" --file "$SRC/tests/data/lidar/$file" --json-counters "$WORK/$proto.counters.json" \
    > "$WORK/$proto.capture.jsonl" 2> "$WORK/$proto.capture.err" || fail "lidar-dump $proto exited $?"
  for kv in "$@"; do
    local k=${kv%%=*} v=${kv#*=} got
    got=$(jget "$WORK/$proto.counters.json" "$k")
    [ "$got" = "$v" ] || fail "$proto capture: $k = $got, expected $v"
  done
  local lines; lines=$(wc -l < "$WORK/$proto.capture.jsonl")
  local scans; scans=$(jget "$WORK/$proto.counters.json" scans)
  [ "$lines" = "$scans" ] || fail "$proto capture: $lines JSON lines for $scans scans"
  "$DOCKSIM" detect --scans "$WORK/$proto.capture.jsonl" --detector estimator > /dev/null 2> "$WORK/$proto.detect.err" \
    || grep -q "0 malformed" "$WORK/$proto.detect.err" || fail "dock-sim detect cannot read lidar-dump's $proto output"
  echo "ok: $proto capture $(cat "$WORK/$proto.counters.json")"
}
check_capture ld06 ld06_capture.bin scans=3 crc_errors=2 resyncs=2 dropped_bytes=70 packets=111 health_packets=1 info_packets=1
check_capture rplidar rplidar_capture.bin scans=2 resyncs=1 dropped_bytes=7 packets=830 descriptors=1 health_packets=1
check_capture lakibeam lakibeam_capture.bin scans=2 bad_packets=1 packets=19 dropped_bytes=1206

# CSV: header + one row per sample.
"$DUMP" --protocol ld06 --file "$SRC/tests/data/lidar/ld06_capture.bin" --csv --count 1 > "$WORK/ld06.csv" 2>/dev/null
[ "$(wc -l < "$WORK/ld06.csv")" = 451 ] || fail "CSV: expected 1 header + 450 rows"

# 2. End to end over a pty.
e2e() {  # protocol corrupt-option min_found
  local proto=$1 opt=$2 min_found=$3
  local link="$WORK/lidar-$proto.pty"
  "$EMU" --protocol "$proto" --pty "$link" --scenario "$SRC/tools/scenarios/default.toml" $opt --duration 4 \
    2> "$WORK/$proto.emu.err" &
  local emu=$!
  for _ in $(seq 50); do [ -L "$link" ] && break; sleep 0.05; done
  "$DUMP" --protocol "$proto" --device "$link" --duration 2.5 --json-counters "$WORK/$proto.e2e.json" \
    > "$WORK/$proto.e2e.jsonl" 2> "$WORK/$proto.dump.err"
  wait $emu
  local scans crc resyncs
  scans=$(jget "$WORK/$proto.e2e.json" scans)
  crc=$(jget "$WORK/$proto.e2e.json" crc_errors)
  resyncs=$(jget "$WORK/$proto.e2e.json" resyncs)
  [ "$scans" -ge 5 ] || fail "$proto $opt: only $scans scans ($(cat "$WORK/$proto.dump.err"))"
  [ $((crc + resyncs)) -gt 0 ] || fail "$proto $opt: corruption not visible in the counters"
  "$DOCKSIM" detect --scans "$WORK/$proto.e2e.jsonl" --profile plate-v --detector estimator > "$WORK/$proto.detect" \
    2> "$WORK/$proto.detect.err"
  local found; found=$(grep -c '"found":true' "$WORK/$proto.detect")
  [ "$found" -ge "$min_found" ] || fail "$proto $opt: dock found in $found of $scans scans (< $min_found)"
  # The simulated LD06's intensities follow the surfaces: the intensity check calls them usable once it has judged a
  # window of scans (16).
  if [ "$proto" = ld06 ] && [ "$(jget "$WORK/$proto.e2e.json" intensity_scans_judged)" -ge 16 ]; then
    [ "$(jget "$WORK/$proto.e2e.json" intensity)" = usable ] \
      || fail "$proto $opt: intensity $(jget "$WORK/$proto.e2e.json" intensity), expected usable"
  fi
  grep -q '^intensity: ' "$WORK/$proto.dump.err" || fail "$proto $opt: no intensity verdict after the counters"
  echo "ok: $proto $opt: scans=$scans crc_errors=$crc resyncs=$resyncs dock found in $found, intensity $(jget "$WORK/$proto.e2e.json" intensity)"
}
e2e ld06 "--corrupt 0.05" 0
e2e rplidar "--corrupt 0.05" 0
e2e ld06 "--corrupt-packets 0.05" 10
e2e rplidar "--corrupt-packets 0.05" 5
echo "lidar tools: all ok"
