# Soak on vcan0 (docs/reliability.md "Soak"): one chassis-sim, one dockd, K dock -> charge -> undock
# cycles commanded with dockctl. K = 5 (CI); HIL_SOAK_CYCLES=50 for the long mode (then give run-case a timeout of
# about 60 s per cycle: tests/hil/run-case soak BUILD '' 3600). chassis-sim keeps the robot where the undock left it,
# so cycle 1 starts at 1.2 m and every later cycle at the staging distance (0.6 m straight out).
# In the VM (live): each cycle's dock accepted, charging confirmed within 150 s, on the charger CHARGE_S, undocked
# within 60 s; dockd's VmRSS (/proc/PID/status) after each cycle into $OUT/cycles.txt. On the host (post.sh, Python is
# too slow in the TCG VM): faults in the status frames (dock-decode), final lateral/yaw per cycle from the truth log
# (analyze.py contact-errors), RSS flat from cycle 2 on (cycle 1 includes lazy first-use pages).
SOAK_CYCLES="${HIL_SOAK_CYCLES:-5}"
SOAK_CHARGE_S=2
SOAK_RSS_SLACK_KIB=16  # four pages: the kernel's accounting of the stack and stdio buffers, not heap

post_soak() {
  local n ok rss1 rss2 rssl rssmax
  n=$(wc -l < "$OUT/cycles.txt")
  ok=$(awk '$2 == 1 && $3 == 1' "$OUT/cycles.txt" | wc -l)
  echo "FIGURE soak_cycles $n"
  echo "FIGURE soak_successes $ok"
  [ -f "$OUT/decode.json" ] || "$BUILD/tools/dock-decode/dock-decode" --json "$OUT/candump.log" > "$OUT/decode.json"
  # Fault codes in the status frames, as "code x times raised". Watchdog stops (184 chassis / 185 lidar stale) show
  # there on the tick the data goes stale; stale past fault_after_ms the task faults (FAULT, 8, in the state
  # sequence) and dockd re-issues the interrupted command once the data is fresh again (docs/dockd.md, "Watchdogs"):
  # in the starved TCG VM (ticks of seconds, see the tick figures) that is the documented recovery, and the cycle
  # still has to succeed. Any other fault code fails the case.
  local faults; faults=$(/usr/bin/python3 "$SRC/tests/hil/analyze.py" faults "$OUT/decode.json")
  echo "FIGURE soak_fault_codes '$(tr ' ' '\n' <<< "$faults" | sort -n | uniq -c | awk 'NF == 2 {printf "%s%sx%s", s, $2, $1; s = " "}')'"
  local states; states=$(/usr/bin/python3 "$SRC/tests/hil/analyze.py" states "$OUT/decode.json")
  echo "INFO state sequence: $states"
  echo "FIGURE soak_task_faults $(tr ' ' '\n' <<< "$states" | grep -cx 8)"
  check soak_only_watchdog_faults awk '{for (i = 1; i <= NF; i++) if ($i != 184 && $i != 185) exit 1}' <<< "$faults"
  /usr/bin/python3 "$SRC/tests/hil/analyze.py" contact-errors "$OUT/truth.jsonl" > "$OUT/contact_errors.txt"
  local i=0 lat yaw c
  while read -r c lat yaw; do
    i=$((i + 1))
    echo "FIGURE soak_cycle${i}_final_lateral_mm $lat"
    echo "FIGURE soak_cycle${i}_final_yaw_deg $yaw"
  done < "$OUT/contact_errors.txt"
  local docked; docked=$(awk '$2 == 1' "$OUT/cycles.txt" | wc -l)
  check soak_one_contact_episode_per_docked_cycle test "$i" -eq "$docked"
  check soak_lateral_within_1cm_every_cycle awk '{if ($2 > 10 || $2 < -10) exit 1}' "$OUT/contact_errors.txt"
  check soak_last_wheel_command_zero test "$(/usr/bin/python3 "$SRC/tests/hil/analyze.py" last-wheels "$OUT/decode.json")" = "0 0"
  read -r rss1 rss2 rssl rssmax <<< "$(awk 'NR == 1 {a = $5} NR == 2 {b = $5} {l = $5; if ($5 > m) m = $5} END {print a, b, l, m}' "$OUT/cycles.txt")"
  echo "FIGURE soak_dockd_rss_kib_after_cycle1 $rss1"
  echo "FIGURE soak_dockd_rss_kib_after_cycle2 $rss2"
  echo "FIGURE soak_dockd_rss_kib_after_last $rssl"
  echo "FIGURE soak_dockd_rss_kib_max $rssmax"
}
[ -n "${MATRIX_POST:-}" ] && return 0

make_dockd_config
start_candump
bg chassis chassis-sim-run --can vcan0 --lidar-pty /tmp/dockcore-lidar --start 1.2,10,5 --truth "$OUT/truth.jsonl" \
   --seed 3 "$SRC/tools/scenarios/default.toml"
wait_for 10 test -e /tmp/dockcore-lidar
bg dockd "$BUILD/app/dockd" --config "$OUT/dockd.toml"
check dockd_up wait_for 20 dockd_ready

dockd_rss_kib() { awk '/^VmRSS:/ {print $2}' "/proc/$PID_dockd/status" 2>/dev/null; }
# The task state, asking again while dockd does not answer within dockctl's 2 s (the starved TCG VM: ticks of seconds).
known_state() {
  local k s
  for k in 1 2 3 4 5; do
    s=$(dock_state); [ -n "$s" ] && { echo "$s"; return 0; }
  done
  return 1
}
# soak_command STATE_BEFORE DOCKCTL_ARGS...: sends a command with dockctl; when no reply came, it is sent again only
# while the state shows it did not arrive (a lost reply is not a lost command). Retries counted in SOAK_RETRIES.
SOAK_RETRIES=0
soak_command() {
  local before="$1" k s; shift
  for k in 1 2 3; do
    DOCKCTL "$@" > /dev/null 2>&1 && return 0
    s=$(known_state) || continue
    [ "$s" != "$before" ] && return 0
    SOAK_RETRIES=$((SOAK_RETRIES + 1))
  done
  return 1
}
echo "FIGURE soak_dockd_rss_kib_at_start $(dockd_rss_kib)"
: > "$OUT/cycles.txt"  # cycle docked(0/1) undocked(0/1) time_to_charging_s rss_kib
soak_failed=0
for i in $(seq 1 "$SOAK_CYCLES"); do
  t0=$(hil_now)
  docked=0; undocked=0; tc=nan
  if soak_command NOT_TASKING dock --dock 0 && wait_for 150 state_is FINISH_TASKING; then
    docked=1
    tc=$(awk -v a="$t0" -v b="$(hil_now)" 'BEGIN{printf "%.1f", b-a}')
    sleep "$SOAK_CHARGE_S"
    # Still charging after CHARGE_S, then undock.
    if [ "$(known_state)" = FINISH_TASKING ] && soak_command FINISH_TASKING undock && wait_for 60 state_is NOT_TASKING; then
      undocked=1
    fi
  fi
  if [ $docked -eq 0 ] || [ $undocked -eq 0 ]; then
    soak_failed=$((soak_failed + 1))
    echo "INFO cycle $i failed in state $(dock_state): $(DOCKCTL status 2>/dev/null)"
    # Leave the robot off the charger for the next cycle: stop (clears a fault), then undock (refused unless on the
    # contacts).
    DOCKCTL stop > /dev/null 2>&1
    wait_for 30 state_is NOT_TASKING
    DOCKCTL undock > /dev/null 2>&1
    wait_for 60 state_is NOT_TASKING
  fi
  rss=$(dockd_rss_kib)
  echo "$i $docked $undocked $tc $rss" >> "$OUT/cycles.txt"
  echo "INFO cycle $i: docked $docked undocked $undocked time_to_charging_s $tc dockd_rss_kib $rss (at $(hil_now) s)"
done
echo "FIGURE soak_dockctl_resends $SOAK_RETRIES"
check soak_every_cycle_docked_charged_undocked test "$soak_failed" -eq 0
check soak_dockd_alive kill -0 "$PID_dockd"
# Flat memory: from cycle 2 on (cycle 1 pays first-use pages: stdio, log files, the first subscriber) VmRSS may not
# grow by more than the slack.
check soak_dockd_rss_flat awk -v s="$SOAK_RSS_SLACK_KIB" 'NR == 2 {b = $5} NR > 2 && $5 > b + s {bad = 1} $5 == "" {bad = 1} END {exit bad}' "$OUT/cycles.txt"

# How starved the VM was: dockd's own tick statistics and watchdog resumes.
DOCKCTL status > "$OUT/status_end.json" 2>/dev/null
for f in ticks tick_worst_us tick_overruns tick_work_worst_us resumes; do
  echo "FIGURE soak_dockd_$f $(json_field "$OUT/status_end.json" "$f")"
done
stop_bg "$PID_dockd" TERM
check dockd_sigterm_exit_0 test "$STOP_STATUS" -eq 0
sleep 0.3
stop_bg "$PID_candump" INT
# Host-side judgement of the logs (faults, per-cycle contact errors, RSS figures).
echo "post_soak" > "$OUT/post.sh"
