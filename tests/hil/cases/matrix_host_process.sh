# Fault-injection matrix, host and process rows (docs/reliability.md), judged on the host by
# tests/hil/matrix.py from the candump stamps.
source "$SRC/tests/hil/matrix_lib.sh"
HF="$BUILD/tests/hil/hil_frames"
UDP="$BUILD/tests/hil/hil_udp"

# Host-side checks (tests/hil/matrix.py).
post_flood() {
  local gap n f states
  read -r gap n <<< "$($MATRIX_PY wheel-gaps "$RD" "$(inject_time flood_start)" "$(inject_time flood_end)")"
  echo "FIGURE ${ROW}_reaction_ms n/a"
  echo "FIGURE ${ROW}_max_wheel_period_ms $gap"
  echo "FIGURE ${ROW}_wheel_frames_during_flood $n"
  check_no_fault "$ROW"
  states=$($MATRIX_PY states "$RD"); echo "INFO $ROW states: $states"
  local retries unexc_r exc_r
  retries=$($MATRIX_PY retries-split "$RD"); unexc_r=${retries%%;*}; exc_r=${retries#*;}
  echo "INFO $ROW retries: '$unexc_r' starvation-excused: '$exc_r'"
  # The docking ran once through to charging (4), never cancelled back to NOT_TASKING (0) on the way. A watchdog
  # FAULT (8) with its resume (1 2 3 ...) is allowed only when check_no_fault excused it as starvation above; a
  # RETRY (6) and the attempt after it only when retry_onsets excused it (dockd stalled in that attempt and the robot
  # pressed off the contacts): then STARVED.
  if { [ "$FAULTS_SPLIT" = ";" ] && [ "$retries" = ";" ]; } || [ "${HIL_STRICT_TIMING:-0}" = 1 ]; then
    check "${ROW}_state_sequence" grep -qE '^0 1 (2 )?3 5 4$' <<< "$states"
  elif [ -n "$unexc_r" ]; then
    check "${ROW}_state_sequence" false
  elif [ -n "$exc_r" ] && grep -qE '^0 1 (2 )?3 ([0-9 ]* )?5 4$' <<< "${states// 0 / X }"; then
    echo "STARVED ${ROW}_state_sequence  (retried: $exc_r: VM starvation)"
  else
    check "${ROW}_state_sequence" grep -qE '^0 1 (2 )?3 ([0-9 ]* )?5 4$' <<< "${states// 0 / X }"
  fi
  if [ "$ROW" = host_flood_udp ]; then
    # Every request answered — unless dockd's loop stalled longer than the socket buffer holds at 1000/s (the
    # kernel drops datagrams while nobody reads; dockd cannot count those): then STARVED.
    if awk '{exit !($2 > 0 && $4 >= $2)}' "$RD/flood.txt"; then
      echo "PASS host_flood_udp_all_answered"
    elif awk -v g="$gap" 'BEGIN{exit !(g > 200)}' && [ "${HIL_STRICT_TIMING:-0}" != 1 ]; then
      echo "STARVED host_flood_udp_all_answered  ($(cat "$RD/flood.txt"); dockd's wheel frames stalled $gap ms during the flood: VM starvation)"
    else
      check host_flood_udp_all_answered false
    fi
  fi
}
post_bad_commands() {
  echo "FIGURE host_bad_commands_reaction_ms n/a"
  check host_bad_commands_never_moved test "$($MATRIX_PY nonzero-count "$RD")" = 0
}
post_sigkill() {
  local base
  base=$($MATRIX_PY delta "$RD" last_wheel_cmd command_timeout)
  echo "FIGURE process_sigkill_reaction_ms $base"
  # chassis-sim checks its command timeout every loop iteration and sends its feedback every 20 ms: a feedback gap
  # over 45 ms (20 ms + the limit's 25 ms) around the timeout is the simulated chassis not running (VM starvation).
  local sim_stall t_last
  t_last=$(inject_time last_wheel_cmd)
  sim_stall=$($MATRIX_PY frame-stall "$RD" WheelFbA "$t_last" \
    "$(awk -v t="$t_last" -v m="$base" 'BEGIN{printf "%.6f", t + (m == "none" ? 1 : m / 1000)}')")
  echo "FIGURE process_sigkill_sim_feedback_gap_ms $sim_stall"
  if awk -v m="$base" 'BEGIN{exit !(m != "none" && m + 0 <= 525)}'; then
    echo "PASS process_sigkill_base_stops_by_timeout"
  elif [ "$base" != none ] && awk -v g="$sim_stall" 'BEGIN{exit !(g > 45)}' && [ "${HIL_STRICT_TIMING:-0}" != 1 ]; then
    echo "STARVED process_sigkill_base_stops_by_timeout  ($base ms > 525 ms; chassis-sim's feedback stalled $sim_stall ms: VM starvation)"
  else
    check process_sigkill_base_stops_by_timeout false
  fi
  # The record up to the kill: every line whole JSON, the last state event = the last DockStatus state on the bus.
  $MATRIX_PY record-check "$RD" "$RD/events_at_kill.jsonl" sigkill | sed 's/^/INFO process_sigkill /'
  check process_sigkill_record_intact $MATRIX_PY record-check "$RD" "$RD/events_at_kill.jsonl" sigkill
  check process_sigkill_canlog_intact /usr/bin/python3 -c '
import sys
t = open(sys.argv[1]).read()
assert t.endswith("\n"), "torn can.log"
last = t.rstrip("\n").rsplit("\n", 1)[-1]
assert float(last[1:last.index(")")]) > float(sys.argv[2]) - 0.1, last
' "$RD/canlog_at_kill.log" "$(inject_time sigkill)"
  check process_restart_no_motion test "$($MATRIX_PY nonzero-count "$RD" "$(inject_time restart)" "$(inject_time redock)")" = 0
  check process_restart_moves_on_new_command test "$($MATRIX_PY nonzero-count "$RD" "$(inject_time redock)")" -gt 0
}
[ -n "${MATRIX_POST:-}" ] && return 0

# Host command flood on UDP: 1000 requests/s for 10 s (status and dock alternately; hil_udp) during a docking.
# Expected: every request answered, the extra docks rejected (6), the docking completes, the 50 Hz loop holds.
row_start host_flood_udp
row_dock
wait_for 30 motion_after 0.5
inject flood_start
"$UDP" flood 7300 1000 10 > "$RD/flood.txt" 2>&1
inject flood_end
echo "INFO host_flood_udp: $(cat "$RD/flood.txt")"
echo "FIGURE host_flood_udp_rate_per_s $(awk '{print $6}' "$RD/flood.txt")"
check host_flood_udp_docked wait_state FINISH_TASKING 90
row_stop
post post_flood

# Host command flood on CAN: 10000 HostCommand frames at 1 ms (canplayer) during a docking: valid checksums and
# counters, all replaying the dock's sequence 1 — each passes the frame checks and is rejected by the sequence rule.
row_start host_flood_can
frames=(); for c in $(seq 0 15); do frames+=("$("$HF" dock 0 1 "$c")"); done
for ((i = 0; i < 10000; i++)); do
  printf '(%d.%06d) vcan0 %s\n' $((1000 + i / 1000)) $(((i % 1000) * 1000)) "${frames[$(((2 + i) % 16))]}"
done > "$RD/flood.log"
row_dock
wait_for 30 motion_after 0.5
inject flood_start
canplayer -I "$RD/flood.log" vcan0=vcan0 2> "$RD/canplayer.log"
inject flood_end
t0=$(inject_time flood_start); t1=$(inject_time flood_end)
echo "FIGURE host_flood_can_rate_per_s $(awk -v a="$t0" -v b="$t1" 'BEGIN{printf "%.0f", 10000/(b-a)}')"
check host_flood_can_docked wait_state FINISH_TASKING 90
row_stop
post post_flood
# Every replay that reaches dockd is rejected by the sequence rule (can_host_rejected); frames the kernel dropped
# from dockd's full socket queue while it was starved never arrive (reported: 10000 - rejected - bad frames).
rej=$(json_field "$RD/status.json" can_host_rejected)
echo "FIGURE host_flood_can_can_host_rejected ${rej:-absent}"
echo "FIGURE host_flood_can_not_received $(( 10000 - ${rej:-0} - $(json_field "$RD/status.json" can_bad_frames) ))"
check host_flood_can_replays_rejected test "${rej:-0}" -gt 0

# Bad host requests (idle robot): malformed JSON -> 1, unknown command -> 2, unknown dock id -> 5 (UDP); on CAN an
# unknown command code and an unknown dock id -> rejected (commands_rejected), the state stays NOT_TASKING.
row_start host_bad_commands
"$UDP" send 7300 '{"cmd":"dock",' > "$RD/replies.txt"
"$UDP" send 7300 '{"cmd":"fly"}' >> "$RD/replies.txt"
"$UDP" send 7300 '{"cmd":"dock","dock_id":9}' >> "$RD/replies.txt"
sed 's/^/INFO host_bad_commands reply: /' "$RD/replies.txt"
reply_code() { [ "$(sed -n "${1}p" "$RD/replies.txt" | json_field - code)" = "$2" ]; }
check host_bad_commands_malformed_1 reply_code 1 1
check host_bad_commands_unknown_command_2 reply_code 2 2
check host_bad_commands_unknown_dock_5 reply_code 3 5
cansend vcan0 "$("$HF" 9 0 1)"
cansend vcan0 "$("$HF" dock 9 2)"
sleep 1
check host_bad_commands_state_unchanged state_is NOT_TASKING
row_stop
post post_bad_commands
rej=$(json_field "$RD/status.json" commands_rejected)
echo "FIGURE host_bad_commands_rejected $rej"
# 3 on UDP (malformed and unknown command refused by the host protocol's parser, unknown dock id by dockd) + 2 on CAN
# (the task manager's rejected_unknown / rejected_dock_id): all in commands_rejected.
check host_bad_commands_all_counted test "${rej:-0}" -ge 5
# CAN: the task manager's verdicts, in the event log and in DockStatus LastResult (CommandResult).
check host_bad_commands_can_unknown_rejected json_has "$RD/record/events.jsonl" \
  '.source == "can" and .command == 9 and .result == "rejected_unknown"'
check host_bad_commands_can_dock_id_rejected json_has "$RD/record/events.jsonl" \
  '.source == "can" and .command == 1 and .dock_id == 9 and .result == "rejected_dock_id"'

# SIGKILL mid-approach (2 s into the motion): nothing stops the robot but the base's own command timeout (500 ms
# after the last wheel command; chassis-sim truth event command_timeout): limit 500 ms + one 5 ms physics step +
# one 20 ms loop wake-up = 525 ms. The session record must hold every event up to the kill. Restarted, dockd comes up
# idle, reports the interrupted session (event previous_session) and sends only zero wheel commands until a new
# dock command.
row_start process_sigkill
row_dock
wait_for 30 motion_after 2
inject sigkill
stop_bg "$PID_dockd" KILL
inject sigkill_done   # the kill lies between the two stamps
PID_dockd=
cp "$RD/record/events.jsonl" "$RD/events_at_kill.jsonl"
cp "$RD/record/can.log" "$RD/canlog_at_kill.log"
wait_for 10 truth_has command_timeout
last_cmd=$(grep ' 100#' "$RD/candump.log" | tail -1 | sed 's/^(\([0-9.]*\)).*/\1/')
echo "last_wheel_cmd $last_cmd" >> "$RD/inject.log"
check process_sigkill_no_frame_after_kill awk -v a="$last_cmd" -v k="$(inject_time sigkill_done)" \
  'BEGIN{exit !(a + 0 <= k + 0)}'
inject restart
row_dockd
check process_restart_idle wait_for 30 state_is NOT_TASKING
sleep 2
check process_restart_reports_interrupted json_has "$RD/record/events.jsonl" '.event == "previous_session" and .clean == false'
json_select "$RD/record/events.jsonl" '.event == "previous_session"' | sed 's/^/INFO /'
inject redock
cansend vcan0 "$("$HF" dock 0 1)"
sleep 3
row_stop
post post_sigkill
