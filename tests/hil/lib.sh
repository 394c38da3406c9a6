# Helpers for HIL cases; sourced inside the VM (bash, vcan0 up, host tree read-only, $OUT writable, /tmp tmpfs).
# A case prints PASS/FAIL lines through check(); hil_end exits non-zero when any check failed.
HIL_FAILS=0
HIL_PIDS=()

hil_begin() {
  HIL_T0=$(date +%s.%N)
  trap hil_cleanup EXIT
  echo "INFO case $CASE on $(uname -r), $(nproc) cpus"
}

hil_cleanup() {
  local p
  for p in "${HIL_PIDS[@]}"; do kill -TERM "$p" 2>/dev/null; done
  sleep 0.3
  for p in "${HIL_PIDS[@]}"; do kill -KILL "$p" 2>/dev/null; done
}

hil_end() {
  hil_cleanup
  HIL_PIDS=()
  trap - EXIT
  if [ "$HIL_FAILS" -eq 0 ]; then echo "INFO case $CASE passed"; exit 0; fi
  echo "INFO case $CASE: $HIL_FAILS check(s) failed"; exit 1
}

# Seconds since the case began (float).
hil_now() { awk -v a="$HIL_T0" -v b="$(date +%s.%N)" 'BEGIN{printf "%.2f", b-a}'; }

# check NAME COMMAND...: runs the command, prints PASS/FAIL NAME.
check() {
  local name="$1"; shift
  if "$@"; then echo "PASS $name"; else echo "FAIL $name"; HIL_FAILS=$((HIL_FAILS + 1)); fi
}

# bg NAME COMMAND...: starts a background process with its output in $OUT/NAME.log; remembers its pid in
# the variable PID_<NAME>.
bg() {
  local name="$1"; shift
  "$@" > "$OUT/$name.log" 2>&1 &
  local pid=$!
  HIL_PIDS+=("$pid")
  printf -v "PID_${name//-/_}" '%s' "$pid"
}

# wait_for TIMEOUT_S COMMAND...: polls the command every 0.2 s until it succeeds; false on timeout.
wait_for() {
  local timeout="$1"; shift
  local end=$(( $(date +%s) + ${timeout%.*} ))
  while [ "$(date +%s)" -lt "$end" ]; do
    "$@" && return 0
    sleep 0.2
  done
  return 1
}

# stop_bg PID [SIGNAL]: stops a process started with bg (default TERM), waits for it and leaves its exit status in
# STOP_STATUS. Not in $(...): a subshell cannot wait for this shell's children.
stop_bg() {
  local pid="$1" sig="${2:-TERM}"
  kill "-$sig" "$pid" 2>/dev/null
  STOP_STATUS=0
  wait "$pid" 2>/dev/null || STOP_STATUS=$?
}

# Starts candump on vcan0 into $OUT/candump.log (candump -L format, what dock-decode reads).
start_candump() { bg candump candump -L vcan0; }

# Writes the HIL dockd config (tests/hil/dockd-hil.toml with this case's paths) to $OUT/dockd.toml, applying
# extra `sed` expressions given as arguments.
make_dockd_config() {
  sed -e "s|@OUT@|$OUT|g" "$@" "$SRC/tests/hil/dockd-hil.toml" > "$OUT/dockd.toml"
}

# DOCKCTL_TIMEOUT_S: how long dockctl waits for the reply (dockd under memcheck answers slowly).
DOCKCTL() { "$BUILD/app/dockctl" --port 7300 --timeout "${DOCKCTL_TIMEOUT_S:-2}" "$@"; }

# json_jq FILE JQ-ARGS...: jq over FILE's lines read raw ("-": standard input), its errors silenced.
json_jq() {
  local f=$1
  shift
  if [ "$f" = - ]; then jq -R "$@" 2>/dev/null; else jq -R "$@" "$f" 2>/dev/null; fi
}
# json_values FILE KEY [EVENT]: KEY of every JSON object in FILE (one object, or JSON lines; "-": standard input)
# that has it — only those whose "event" is EVENT when given —, one per line, strings bare. A torn or non-JSON line
# (a log still being written) is skipped.
json_values() {
  json_jq "$1" -r --arg k "$2" --arg ev "${3:-}" \
    'fromjson? | objects | select(has($k) and ($ev == "" or .event == $ev)) | .[$k] | tostring'
}
# json_field FILE KEY [EVENT]: the last of those values ("" when there is none).
json_field() { json_values "$@" | tail -n 1; }
# json_select FILE CONDITION: the JSON objects of FILE (as above) for which the jq CONDITION holds, one per line.
# json_has: at least one does. json_count: how many do.
json_select() { json_jq "$1" -c "fromjson? | objects | select($2)"; }
json_has() { [ -n "$(json_select "$@")" ]; }
json_count() { json_select "$@" | wc -l; }

# Current task state name from dockd over UDP ("" when dockd does not answer).
# The polled helpers ask dockctl for the fields (status --field): one process per poll, no JSON tool started in the
# loaded VM.
dock_state() { DOCKCTL status --field state 2>/dev/null; }
state_is() { [ "$(dock_state)" = "$1" ]; }
# dockd idle with fresh lidar and chassis data: a docking commanded now starts without a watchdog hold. (A host that
# docks before that sees the 184/185 watchdog code in the status until the data comes, which a no-fault check counts.)
dockd_ready() {
  [ "$(DOCKCTL status --field state --field lidar_stale --field chassis_stale 2>/dev/null | paste -sd ' ')" = \
    "NOT_TASKING false false" ]
}

# chassis-sim from this build.
chassis-sim-run() { "$BUILD/tools/chassis-sim/chassis-sim" "$@"; }
