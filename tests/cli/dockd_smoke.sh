#!/usr/bin/env bash
# dockd / dockctl process tests: config errors exit 2 with file:line:column; a CAN interface that cannot open
# (this kernel has no CAN) exits 3 with a clear message; with the development-only fake CAN, dockd answers dockctl,
# rejects an unknown dock id (dockctl exit 1), dockctl without a daemon exits 3, and SIGTERM ends dockd with exit 0
# after zero-velocity wheel frames (checked in the session record's candump log). dockctl: argument errors exit 2
# (an unknown subcommand is named with the valid ones), --help exits 0; `dockctl test --dock 3` puts dockd into
# TEST_MODE on dock 3 and the status reports dock 3 until `stop`.
set -u
DOCKD=$1 DOCKCTL=$2 WORK=$3
rm -rf "$WORK" && mkdir -p "$WORK"
fail() { echo "FAIL: $*" >&2; exit 1; }
PORT=$(( 20000 + ($$ % 20000) ))

printf '[can]\ninterface = "can0"\nbogus = 1\n' > "$WORK/badkey.toml"
out=$("$DOCKD" --config "$WORK/badkey.toml" --check-config 2>&1); rc=$?
[ $rc -eq 2 ] || fail "bad key: exit $rc"; grep -q "badkey.toml:3:1: unknown key 'can.bogus'" <<<"$out" || fail "bad key message: $out"
printf '[watchdog]\nlidar_stale_ms = 5\n' > "$WORK/badval.toml"
out=$("$DOCKD" --config "$WORK/badval.toml" --check-config 2>&1); rc=$?
[ $rc -eq 2 ] || fail "bad value: exit $rc"; grep -q "badval.toml:2:18: watchdog.lidar_stale_ms = 5 is out of range" <<<"$out" || fail "bad value message: $out"
printf '[host]\nport = "x"\n' > "$WORK/badtype.toml"
out=$("$DOCKD" --config "$WORK/badtype.toml" 2>&1); rc=$?
[ $rc -eq 2 ] || fail "wrong type: exit $rc"; grep -q "badtype.toml:2:8: host.port must be an integer, not a string" <<<"$out" || fail "wrong type message: $out"
"$DOCKD" --help >/dev/null || fail "--help"
out=$("$DOCKD" --bogus 2>&1); rc=$?
[ $rc -eq 2 ] || fail "dockd --bogus: exit $rc (want 2)"

"$DOCKCTL" --help >/dev/null; rc=$?
[ $rc -eq 0 ] || fail "dockctl --help: exit $rc"
"$DOCKCTL" test --help | grep -q -- "--dock" || fail "dockctl test --help lists no --dock"
out=$("$DOCKCTL" fly 2>&1); rc=$?
[ $rc -eq 2 ] || fail "dockctl fly: exit $rc (want 2)"
grep -q "unknown subcommand 'fly' (valid: dock, undock, stop, status, test, teach)" <<<"$out" || fail "dockctl fly: $out"
out=$("$DOCKCTL" --bogus 2>&1); rc=$?
[ $rc -eq 2 ] || fail "dockctl --bogus: exit $rc (want 2)"
grep -q "unknown option '--bogus'" <<<"$out" || fail "dockctl --bogus: $out"
out=$("$DOCKCTL" 2>&1); rc=$?
[ $rc -eq 2 ] || fail "dockctl without a subcommand: exit $rc (want 2)"
out=$("$DOCKCTL" dock --dock x 2>&1); rc=$?
[ $rc -eq 2 ] || fail "dockctl dock --dock x: exit $rc (want 2)"
out=$("$DOCKCTL" test --dock 70000 2>&1); rc=$?
[ $rc -eq 2 ] || fail "dockctl test --dock 70000: exit $rc (want 2)"

cat > "$WORK/base.toml" <<CFG
[lidar]
device = "$WORK/no-lidar"
[can]
interface = "IFACE"
[host]
port = $PORT
[record]
dir = "$WORK/rec"
[state]
file = "$WORK/dockd.state"
[[docks]]
id = 0
[[docks]]
id = 3
profile = "breakpoint"
CFG
sed 's/IFACE/can0/' "$WORK/base.toml" > "$WORK/can0.toml"
out=$("$DOCKD" --config "$WORK/can0.toml" 2>&1); rc=$?
if [ $rc -ne 3 ] || ! grep -q "cannot open CAN interface 'can0'" <<<"$out"; then
  fail "CAN open failure: exit $rc: $out"
fi
sed 's/IFACE/fake/' "$WORK/base.toml" > "$WORK/fake.toml"
out=$("$DOCKD" --config "$WORK/fake.toml" 2>&1); rc=$?
[ $rc -eq 2 ] || fail "fake CAN without --allow-fake-can: exit $rc"

"$DOCKCTL" --port $PORT --timeout 0.3 status >/dev/null 2>&1; rc=$?
[ $rc -eq 3 ] || fail "dockctl without dockd: exit $rc (want 3)"

"$DOCKD" --config "$WORK/fake.toml" --allow-fake-can --log-level warn 2>"$WORK/dockd.err" &
pid=$!
ok=0
for i in $(seq 1 50); do
  if "$DOCKCTL" --port $PORT --timeout 0.2 status >"$WORK/status.json" 2>/dev/null; then ok=1; break; fi
done
[ $ok -eq 1 ] || { kill $pid; fail "dockctl status never answered"; }
grep -q '"state":"NOT_TASKING"' "$WORK/status.json" || { kill $pid; fail "status: $(cat "$WORK/status.json")"; }
grep -q '"chassis_stale":true' "$WORK/status.json" || { kill $pid; fail "fake CAN must be chassis-stale"; }
"$DOCKCTL" --port $PORT dock --dock 7 >"$WORK/dock7.json"; rc=$?
[ $rc -eq 1 ] || { kill $pid; fail "unknown dock: dockctl exit $rc"; }
grep -q '"error":"unknown_dock_id"' "$WORK/dock7.json" || { kill $pid; fail "unknown dock reply: $(cat "$WORK/dock7.json")"; }
"$DOCKCTL" --port $PORT test --dock 3 >"$WORK/test3.json"; rc=$?
[ $rc -eq 0 ] || { kill $pid; fail "test --dock 3: dockctl exit $rc: $(cat "$WORK/test3.json")"; }
grep -q '"dock_id":3,"state":"TEST_MODE"' "$WORK/test3.json" || { kill $pid; fail "test reply: $(cat "$WORK/test3.json")"; }
"$DOCKCTL" --port $PORT status >"$WORK/status3.json" || { kill $pid; fail "status in test mode"; }
grep -q '"state":"TEST_MODE"' "$WORK/status3.json" || { kill $pid; fail "test mode status: $(cat "$WORK/status3.json")"; }
grep -q '"dock_id":3,' "$WORK/status3.json" || { kill $pid; fail "a test on dock 3 must report dock 3: $(cat "$WORK/status3.json")"; }
# status --field: the named values, one per line, strings bare; a missing key exits 1 naming it.
out=$("$DOCKCTL" --port $PORT status --field state --field dock_id); rc=$?
[ $rc -eq 0 ] && [ "$out" = "$(printf 'TEST_MODE\n3')" ] || { kill $pid; fail "status --field: exit $rc: $out"; }
out=$("$DOCKCTL" --port $PORT status --field no_such_key 2>&1); rc=$?
[ $rc -eq 1 ] && grep -q 'no field "no_such_key"' <<<"$out" || { kill $pid; fail "status --field no_such_key: exit $rc: $out"; }
out=$("$DOCKCTL" --port $PORT status --follow --field state 2>&1); rc=$?
[ $rc -eq 2 ] || { kill $pid; fail "status --follow --field: exit $rc (want 2): $out"; }
# The camera part: named, and empty without a camera (no status fields in it).
out=$("$DOCKCTL" --port $PORT status --part camera); rc=$?
[ $rc -eq 0 ] && grep -q '"part":"camera"}$' <<<"$out" || { kill $pid; fail "status --part camera: exit $rc: $out"; }
out=$("$DOCKCTL" --port $PORT status --part lidar 2>&1); rc=$?
[ $rc -eq 2 ] || { kill $pid; fail "status --part lidar: exit $rc (want 2): $out"; }
"$DOCKCTL" --port $PORT stop >/dev/null || { kill $pid; fail "stop after test"; }
"$DOCKCTL" --port $PORT status >"$WORK/status4.json" || { kill $pid; fail "status after stop"; }
grep -q '"state":"NOT_TASKING"' "$WORK/status4.json" || { kill $pid; fail "stop must end the test: $(cat "$WORK/status4.json")"; }
before=$(wc -l < "$WORK/rec/can.log")
kill -TERM $pid
wait $pid; rc=$?
[ $rc -eq 0 ] || fail "SIGTERM: dockd exit $rc"
grep -q '"event":"shutdown","reason":"SIGTERM"' "$WORK/rec/events.jsonl" || fail "no shutdown event"
# The last five frames are the stop frames: wheel command id 0x100 with both speeds zero.
tail -n 5 "$WORK/rec/can.log" | grep -c ' 100#00000000' | grep -q '^5$' || fail "no zero wheel frames after SIGTERM: $(tail -n 5 "$WORK/rec/can.log")"
[ "$(wc -l < "$WORK/rec/can.log")" -gt "$before" ] || fail "can.log did not grow"
# While running, every wheel frame was zero (no chassis: the watchdog holds).
grep ' 100#' "$WORK/rec/can.log" | grep -vq ' 100#00000000' && fail "non-zero wheel frame without a chassis"
echo "dockd_smoke: OK"
