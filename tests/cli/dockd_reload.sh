#!/usr/bin/env bash
# dockd SIGHUP config reload (docs/dockd.md "Config reload"), as a process with the development-only
# fake CAN: a valid file (watchdog threshold, host allowlist) is applied (event config_reload applied, status
# config_reloads 1); a file with a bad value is rejected with file:line:column in the event log and on stderr and the running
# config stays (dockd keeps answering on its port, chassis_stale_ms unchanged); a restart-only change (host.port) is
# rejected as a whole; SIGTERM still ends dockd with exit 0.
set -u
DOCKD=$1 DOCKCTL=$2 WORK=$3
rm -rf "$WORK" && mkdir -p "$WORK"
PORT=$(( 20000 + (($$ + 7919) % 20000) ))
pid=
fail() { echo "FAIL: $*" >&2; [ -n "$pid" ] && kill -TERM "$pid" 2>/dev/null; exit 1; }
cfg="$WORK/dockd.toml"
write_cfg() {  # $1: extra [watchdog] line, $2: extra [host] line, $3: port
  cat > "$cfg" <<CFG
[lidar]
device = "$WORK/no-lidar"
[can]
interface = "fake"
[host]
port = $3
$2
[record]
dir = "$WORK/rec"
[state]
file = "$WORK/dockd.state"
[watchdog]
$1
CFG
}
status() { "$DOCKCTL" --port $PORT --timeout 0.5 status; }
wait_event() {  # $1: grep pattern in events.jsonl, $2: count wanted
  for _ in $(seq 1 50); do
    [ "$(grep -c "$1" "$WORK/rec/events.jsonl" 2>/dev/null)" -ge "$2" ] && return 0
    sleep 0.1
  done
  return 1
}

write_cfg "chassis_stale_ms = 200" "" $PORT
"$DOCKD" --config "$cfg" --allow-fake-can --log-level warn 2>"$WORK/dockd.err" &
pid=$!
ok=0
for _ in $(seq 1 50); do
  if status >"$WORK/s0.json" 2>/dev/null; then ok=1; break; fi
done
[ $ok -eq 1 ] || fail "dockctl status never answered"
grep -q '"config_reloads":0,' "$WORK/s0.json" || fail "status lacks config_reloads: $(cat "$WORK/s0.json")"

# 1. Valid: runtime keys (a watchdog threshold, the host allowlist).
write_cfg "chassis_stale_ms = 300" 'allowlist = ["127.0.0.2"]' $PORT
kill -HUP $pid
wait_event '"event":"config_reload","result":"applied"' 1 || fail "good reload not applied: $(tail -3 "$WORK/rec/events.jsonl")"
status >"$WORK/s1.json" || fail "no status after the good reload"
grep -qE '"config_reloads":1,"config_reloads_rejected":0[,}]' "$WORK/s1.json" &&
  grep -q '"config_reload_pending":false' "$WORK/s1.json" ||
  fail "status after good reload: $(cat "$WORK/s1.json")"

# 2. Invalid value on line 13, column 20: rejected with its position; dockd keeps running on the old config.
write_cfg "chassis_stale_ms = 5" "" $PORT
kill -HUP $pid
wait_event '"result":"rejected"' 1 || fail "bad reload not rejected"
grep '"result":"rejected"' "$WORK/rec/events.jsonl" | grep -q "dockd.toml:13:20: watchdog.chassis_stale_ms = 5 is out of range" ||
  fail "rejection message: $(grep rejected "$WORK/rec/events.jsonl")"
grep -q "dockd.toml:13:20: watchdog.chassis_stale_ms = 5 is out of range" "$WORK/dockd.err" || fail "rejection not on stderr"
status >"$WORK/s2.json" || fail "dockd stopped answering after a bad reload"
grep -qE '"config_reloads":1,"config_reloads_rejected":1[,}]' "$WORK/s2.json" || fail "status after bad reload: $(cat "$WORK/s2.json")"

# 3. A restart-only key (host.port) changed: the whole file is rejected, the old port keeps serving.
write_cfg "chassis_stale_ms = 250" "" $((PORT + 1))
kill -HUP $pid
wait_event '"result":"rejected"' 2 || fail "restart-only reload not rejected"
grep '"result":"rejected"' "$WORK/rec/events.jsonl" | tail -1 | grep -q "restart-only keys changed (host.port)" ||
  fail "restart-only message: $(grep rejected "$WORK/rec/events.jsonl" | tail -1)"
status >"$WORK/s3.json" || fail "old port no longer answers"
grep -qE '"config_reloads":1,"config_reloads_rejected":2[,}]' "$WORK/s3.json" || fail "status after restart-only: $(cat "$WORK/s3.json")"

kill -TERM $pid
wait $pid; rc=$?
pid=
[ $rc -eq 0 ] || fail "SIGTERM: dockd exit $rc"
echo "dockd_reload: OK"
