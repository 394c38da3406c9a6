# The base goes silent mid-approach: chassis-sim stops answering 2 s after motion starts, for 3 s.
# dockd must command zero at once, report fault 184 (chassis stale) on the bus, send no non-zero wheel command while
# the base is silent, and finish the docking once the base answers again.
make_dockd_config
start_candump
bg chassis chassis-sim-run --can vcan0 --lidar-pty /tmp/dockcore-lidar --start 1.5,-15,10 --truth "$OUT/truth.jsonl" \
   --seed 5 --silent-at 2 --silent-for 3 "$SRC/tools/scenarios/default.toml"
wait_for 10 test -e /tmp/dockcore-lidar
bg dockd "$BUILD/app/dockd" --config "$OUT/dockd.toml"
check dockd_up wait_for 20 dockd_ready
check dock_accepted DOCKCTL dock --dock 0
check charging_after_recovery wait_for 180 state_is FINISH_TASKING
DOCKCTL status > "$OUT/status.json"
stop_bg "$PID_dockd" TERM
check dockd_sigterm_exit_0 test "$STOP_STATUS" -eq 0
sleep 0.3
stop_bg "$PID_candump" INT
source "$SRC/tests/hil/canlog.sh"
L="$OUT/candump.log"
silent_at=$(json_values "$OUT/truth.jsonl" wall chassis_silent | head -1)
answers_at=$(json_values "$OUT/truth.jsonl" wall chassis_answers | head -1)
echo "INFO base silent from $silent_at to $answers_at (CLOCK_REALTIME); DockStatus faults: $(canlog_faults "$L")"
check silence_happened test -n "$silent_at" -a -n "$answers_at"
check fault_184_reported grep -qw 184 <<< "$(canlog_faults "$L")"
# Documented reaction: the chassis watchdog trips 200 ms after the last feedback frame, on the next 20 ms tick.
reaction=$(ms "$silent_at" "$(canlog_first_zero "$L" "$silent_at")")
echo "FIGURE chassis_lost_reaction_ms $reaction"
check zero_within_300ms_of_silence test "$reaction" != none -a "${reaction/none/99999}" -le 300
hold_nonzero=$(canlog_nonzero "$L" "$(awk -v s="$silent_at" 'BEGIN{printf "%.6f", s + 0.3}')" "$answers_at")
echo "INFO non-zero wheel commands while the base was silent (after the reaction): $hold_nonzero"
check no_motion_while_silent test "$hold_nonzero" -eq 0
echo "INFO tick_worst_us $(json_field "$OUT/status.json" tick_worst_us) tick_overruns $(json_field "$OUT/status.json" tick_overruns)"
