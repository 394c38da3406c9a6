# Fault-injection matrix helpers, sourced by tests/hil/cases/matrix_*.sh after lib.sh. Each row gets a
# fresh chassis-sim + dockd + candump with its logs in $OUT/<row>/ (candump.log, truth.jsonl, inject.log, record/,
# dockd.log, chassis.log, status.json) and is judged from the candump stamps by tests/hil/matrix.py.
#
# Two phases: in the VM the case runs the rows (live checks with check(): dockd answers, states reached); every
# judgement from the logs is deferred with `judge ...` / `post ...` into $OUT/post.sh, which run-case executes on the
# host afterwards with MATRIX_POST=1 (the case file returns before its rows then) — Python in the loaded TCG VM took
# ~100 s per start. Case files define their host-side check functions (post_<row>) before that early return.
MATRIX_PY="/usr/bin/python3 $SRC/tests/hil/matrix.py"
DEFAULT_SCENARIO="$SRC/tools/scenarios/default.toml"

# post COMMAND ARGS...: run this on the host after the VM, with RD and ROW of the current row.
post() {
  { printf 'RD=%q; ROW=%q; ' "$RD" "$ROW"; printf '%q ' "$@"; echo; } >> "$OUT/post.sh"
}

# judge ARGS...: tests/hil/matrix.py row on this row (host side); its PASS/FAIL lines count like check()'s.
judge() { post judge_now "$@"; }
judge_now() {
  [ -f "$RD/decode.json" ] || "$BUILD/tools/dock-decode/dock-decode" --json "$RD/candump.log" > "$RD/decode.json" \
    2> "$RD/decode.stderr"
  local out
  out=$($MATRIX_PY row "$RD" --row "$ROW" "$@" 2>&1)
  echo "$out" | tee "$RD/judge.txt"
  HIL_FAILS=$((HIL_FAILS + $(grep -c '^FAIL ' <<< "$out")))
  grep -q '^Traceback' <<< "$out" && HIL_FAILS=$((HIL_FAILS + 1))
  return 0
}

# check_no_fault NAME: no fault in the row's status frames (host side). Watchdog faults that followed a stall of
# dockd's own loop (matrix.py faults-split) are reported as STARVED instead, unless HIL_STRICT_TIMING=1. Leaves the
# split in FAULTS_SPLIT.
check_no_fault() {
  local unexc exc
  FAULTS_SPLIT=$($MATRIX_PY faults-split "$RD")  # kept for the caller (e.g. the flood rows' state check)
  unexc=${FAULTS_SPLIT%%;*}; exc=${FAULTS_SPLIT#*;}
  echo "INFO $1 faults: '$unexc' starvation-excused: '$exc'"
  if [ -z "$unexc" ] && [ -n "$exc" ] && [ "${HIL_STRICT_TIMING:-0}" != 1 ]; then
    echo "STARVED ${1}_no_fault  (watchdog faults $exc right after dockd's loop stalled: VM starvation)"
    return 0
  fi
  if [ -n "$unexc" ]; then
    $MATRIX_PY faults-explain "$RD" | sed "s/^/INFO $1 unexcused: /"
  fi
  check "${1}_no_fault" test -z "$unexc$exc"
}

# Value of KEY in a flat one-line JSON object file (dockctl status), without Python (cheap in the VM).
# Wall time of the first inject.log entry NAME.
inject_time() { awk -v n="$1" '$1 == n {print $2; exit}' "$RD/inject.log"; }
# Prints the worst-tick figures of the row from its status snapshot.
# (dockctl status may time out in a starved VM: then dockd's shutdown event, which carries the same statistics.)
tick_figures() {
  local w o
  w=$(json_field "$RD/status.json" tick_worst_us); o=$(json_field "$RD/status.json" tick_overruns)
  if [ -z "$w" ]; then
    w=$(json_field "$RD/record/events.jsonl" worst_tick_us shutdown)
    o=$(json_field "$RD/record/events.jsonl" overruns shutdown)
  fi
  echo "FIGURE ${ROW}_worst_tick_ms $(awk -v u="$w" 'BEGIN{printf "%.1f", u/1000}')"
  echo "FIGURE ${ROW}_tick_overruns $o"
}

# rbg NAME COMMAND...: like bg, but the output goes to the row's directory.
rbg() {
  local name="$1"; shift
  "$@" > "$RD/$name.log" 2>&1 &
  local pid=$!
  HIL_PIDS+=("$pid")
  printf -v "PID_${name//-/_}" '%s' "$pid"
}

# inject NAME: records "NAME <CLOCK_REALTIME>" in the row's inject.log (the case's own fault times). $EPOCHREALTIME
# is read by bash itself: `date` is a process start, which takes up to a second in the loaded VM.
inject() { echo "$1 $EPOCHREALTIME" >> "$RD/inject.log"; }

# row_start NAME [chassis-sim options...]: $ROW_SCENARIO (default scenario), $ROW_SED (sed expressions applied to
# dockd-hil.toml, e.g. to change a key of a table it already has), $ROW_TOML (extra dockd config text appended,
# e.g. a [task] table) and $ROW_READY (what "dockd up" waits for; default dockd_ready: idle, data fresh) apply.
# Starts candump (dockcore ids 0x100-0x1FF only), chassis-sim, dockd.
row_start() {
  ROW="$1"; shift
  RD="$OUT/$ROW"
  rm -rf "$RD"; mkdir -p "$RD"
  ROW_T0=$(hil_now)
  echo "INFO row $ROW begins at ${ROW_T0} s"
  sed -e "s|@OUT@|$RD|g" -e "${ROW_SED:-}" "$SRC/tests/hil/dockd-hil.toml" > "$RD/dockd.toml"
  if [ -n "${ROW_TOML:-}" ]; then printf '%s\n' "$ROW_TOML" >> "$RD/dockd.toml"; fi
  candump -L vcan0,100:700 > "$RD/candump.log" 2> "$RD/candump.stderr" &
  PID_candump=$!; HIL_PIDS+=("$PID_candump")
  rm -f /tmp/dockcore-lidar
  rbg chassis "$BUILD/tools/chassis-sim/chassis-sim" --can vcan0 --lidar-pty /tmp/dockcore-lidar --start 1.2,10,5 \
     --seed 3 --truth "$RD/truth.jsonl" "$@" "${ROW_SCENARIO:-$DEFAULT_SCENARIO}"
  wait_for 10 test -e /tmp/dockcore-lidar
  row_dockd
  # shellcheck disable=SC2086  # ROW_READY is a command with its arguments
  check "${ROW}_dockd_up" wait_for 30 ${ROW_READY:-dockd_ready}
}

# row_dockd: (re)starts dockd with the row's config and record directory (appending to the record).
row_dockd() { rbg dockd "$BUILD/app/dockd" --config "$RD/dockd.toml"; }

# row_dock [SEQ]: dock at dock 0 with a CAN host command frame (cansend), recorded as inject "dock".
row_dock() {
  inject dock
  cansend vcan0 "$("$BUILD/tests/hil/hil_frames" dock 0 "${1:-1}")"
}

# truth_has EVENT: chassis-sim logged that event. motion_after S: the scenario clock passed S seconds.
# truth_has and dockd_logged are polled every 0.2 s while the VM is loaded: a fixed-string search for the compact
# `"event":"NAME"` their writers (chassis-sim, dockd) put in every event line, where starting jq would cost more than
# the wait it serves. Values are read with json_field.
truth_has() { grep -qF "\"event\":\"$1\"" "$RD/truth.jsonl" 2>/dev/null; }
motion_after() {
  tail -n 3 "$RD/truth.jsonl" 2>/dev/null | json_field - motion_t | awk -v s="$1" '{exit !($1 + 0 >= s + 0)}'
}
dockd_logged() { grep -qF "\"event\":\"$1\"" "$RD/record/events.jsonl" 2>/dev/null; }
# wait_state STATE TIMEOUT: poll dockd's status.
wait_state() { wait_for "$2" state_is "$1"; }

# row_stop: status snapshot, SIGTERM dockd, stop chassis-sim and candump.
row_stop() {
  DOCKCTL status > "$RD/status.json" 2>/dev/null || echo '{}' > "$RD/status.json"
  if [ -n "${PID_dockd:-}" ]; then stop_bg "$PID_dockd" TERM; fi
  sleep 0.2
  stop_bg "$PID_chassis" TERM
  stop_bg "$PID_candump" INT
  echo "INFO row $ROW: $(wc -l < "$RD/candump.log") CAN frames, $(awk -v a="$ROW_T0" -v b="$(hil_now)" \
       'BEGIN{printf "%.1f", b-a}') s, worst tick $(json_field "$RD/status.json" tick_worst_us) us," \
       "overruns $(json_field "$RD/status.json" tick_overruns)"
  post tick_figures
}
