# A whole docking session on vcan0: chassis-sim (robot base + LD06 on a pty), dockd, candump.
# Run 1 is commanded with a CAN host command frame (cansend), run 2 with dockctl; both must reach charging
# confirmed (FINISH_TASKING) and undock. Then SIGTERM: dockd exits 0 leaving zero on the bus. dock-decode must read the
# candump log with zero counter/checksum errors, and the status frames must show the expected state sequence. dockd
# records every call into its core (--record-loop); dock-sim replay must reproduce every tick of the session.
make_dockd_config
start_candump
bg chassis chassis-sim-run --can vcan0 --lidar-pty /tmp/dockcore-lidar --start 1.2,10,5 --truth "$OUT/truth.jsonl" \
   --seed 3 "$SRC/tools/scenarios/default.toml"
wait_for 10 test -e /tmp/dockcore-lidar
bg dockd "$BUILD/app/dockd" --config "$OUT/dockd.toml" --record-loop
check dockd_up wait_for 20 dockd_ready

# Run 1: CAN host command (dock at dock 0, sequence 1).
t0=$(hil_now)
cansend vcan0 "$("$BUILD/tests/hil/hil_frames" dock 0 1)"
check run1_charging wait_for 150 state_is FINISH_TASKING
echo "FIGURE run1_time_to_charging_s $(awk -v a="$t0" -v b="$(hil_now)" 'BEGIN{printf "%.1f", b-a}')"
read -r c lat yaw <<< "$(/usr/bin/python3 "$SRC/tests/hil/analyze.py" final-error "$OUT/truth.jsonl")"
echo "FIGURE run1_final_lateral_mm $lat"
echo "FIGURE run1_final_yaw_deg $yaw"
check run1_contact_error_within_1cm awk -v l="$lat" 'BEGIN{exit !(l != "" && l+0 <= 10 && l+0 >= -10)}'
DOCKCTL undock > "$OUT/undock1.json"
check run1_undocked wait_for 60 state_is NOT_TASKING

# Run 2: dockctl.
t0=$(hil_now)
check run2_dockctl_accepted DOCKCTL dock --dock 0
check run2_charging wait_for 150 state_is FINISH_TASKING
echo "FIGURE run2_time_to_charging_s $(awk -v a="$t0" -v b="$(hil_now)" 'BEGIN{printf "%.1f", b-a}')"
read -r c lat yaw <<< "$(/usr/bin/python3 "$SRC/tests/hil/analyze.py" final-error "$OUT/truth.jsonl")"
echo "FIGURE run2_final_lateral_mm $lat"
echo "FIGURE run2_final_yaw_deg $yaw"
check run2_contact_error_within_1cm awk -v l="$lat" 'BEGIN{exit !(l != "" && l+0 <= 10 && l+0 >= -10)}'
check run2_undock_accepted DOCKCTL undock
check run2_undocked wait_for 60 state_is NOT_TASKING

# Shutdown: SIGTERM -> zero-velocity frames, exit 0.
stop_bg "$PID_dockd" TERM
check dockd_sigterm_exit_0 test "$STOP_STATUS" -eq 0
sleep 0.3
stop_bg "$PID_candump" INT
"$BUILD/tools/dock-decode/dock-decode" --json "$OUT/candump.log" > "$OUT/decode.json"
"$BUILD/tools/dock-decode/dock-decode" -q "$OUT/candump.log" > "$OUT/decode.txt" 2>&1
check dock_decode_strict_no_errors "$BUILD/tools/dock-decode/dock-decode" -q --strict "$OUT/candump.log"
states=$(/usr/bin/python3 "$SRC/tests/hil/analyze.py" states "$OUT/decode.json")
echo "INFO state sequence: $states"
# NOT_TASKING GET_TASKING_CMD REACH_TASKING_POINT ALIGN WAIT_FOR_CHARGE FINISH_TASKING UNDOCKING NOT_TASKING, twice.
check state_sequence_two_sessions grep -qE '^0 1 (2 )?3 5 4 7 0 1 (2 )?3 5 4 7 0$' <<< "$states"
check last_wheel_command_zero test "$(/usr/bin/python3 "$SRC/tests/hil/analyze.py" last-wheels "$OUT/decode.json")" = "0 0"
grep -E "^errors|^malformed|^summary" "$OUT/decode.txt" | sed 's/^/INFO /'
# The session's core calls through a fresh core: every tick's output bit for bit.
replay_rc=0
"$BUILD/tools/dock-sim" replay "$OUT/record/loop.rec" > "$OUT/replay.txt" 2>&1 || replay_rc=$?
sed 's/^/INFO /' "$OUT/replay.txt"
check loop_record_replays_bit_for_bit test "$replay_rc" -eq 0
