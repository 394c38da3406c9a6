# A degraded lidar line (see docs/hil.md for the bytes-vs-packets reading): 5 % of the LD06 packets
# arrive with a flipped bit. Docking must still reach charging, and dockd's CRC counter must show the corruption.
make_dockd_config
start_candump
bg chassis chassis-sim-run --can vcan0 --lidar-pty /tmp/dockcore-lidar --start 1.0,20,-10 --truth "$OUT/truth.jsonl" \
   --seed 9 --lidar-corrupt-packets 0.05 "$SRC/tools/scenarios/default.toml"
wait_for 10 test -e /tmp/dockcore-lidar
bg dockd "$BUILD/app/dockd" --config "$OUT/dockd.toml"
check dockd_up wait_for 20 dockd_ready
check dock_accepted DOCKCTL dock --dock 0
check charging_with_corrupt_lidar wait_for 180 state_is FINISH_TASKING
DOCKCTL status > "$OUT/status.json"
crc=$(json_field "$OUT/status.json" lidar_crc_errors)
scans=$(json_field "$OUT/status.json" scans)
echo "FIGURE lidar_corrupt_crc_errors $crc"
echo "FIGURE lidar_corrupt_scans $scans"
check crc_counter_shows_corruption test "${crc:-0}" -gt 0
read -r c lat yaw <<< "$(/usr/bin/python3 "$SRC/tests/hil/analyze.py" final-error "$OUT/truth.jsonl")"
echo "FIGURE lidar_corrupt_final_lateral_mm $lat"
check contact_error_within_1cm awk -v l="$lat" 'BEGIN{exit !(l != "" && l+0 <= 10 && l+0 >= -10)}'
stop_bg "$PID_dockd" TERM
check dockd_sigterm_exit_0 test "$STOP_STATUS" -eq 0
echo "INFO tick_worst_us $(json_field "$OUT/status.json" tick_worst_us) tick_overruns $(json_field "$OUT/status.json" tick_overruns)"
