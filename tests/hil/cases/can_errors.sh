# CAN error frames on the bus (docs/can.md, "SocketCAN driver"): cansend injects error frames on vcan0 (an 8-digit
# id with CAN_ERR_FLAG 0x20000000 is an error frame to can-utils; vcan loops it back to every other socket, and
# dockd's CAN_RAW_ERR_FILTER lets it through). dockd must count each one — the `can_error` events of its session
# record carry the totals `bus_errors` and `bus_off` (docs/dockd.md, "Session record") — and carry on: error frames
# are not bad data frames, the chassis feedback stays fresh, dockd stays idle, answers and exits 0 on SIGTERM.
make_dockd_config
start_candump
bg chassis chassis-sim-run --can vcan0 --lidar-pty /tmp/dockcore-lidar --start 1.2,10,5 --seed 3 \
   "$SRC/tools/scenarios/default.toml"
wait_for 10 test -e /tmp/dockcore-lidar
bg dockd "$BUILD/app/dockd" --config "$OUT/dockd.toml"
check dockd_up wait_for 20 dockd_ready

EV="$OUT/record/events.jsonl"
# last_total FIELD: that field of the newest can_error event (0 when there is none yet).
last_total() {
  local v
  v=$(json_field "$EV" "$1" can_error)
  echo "${v:-0}"
}
total_is() { [ "$(last_total "$1")" = "$2" ]; }
status_field() { DOCKCTL status --field "$1" 2>/dev/null; }

check no_error_event_before test "$(json_count "$EV" '.event == "can_error"')" -eq 0
bad_before=$(status_field can_bad_frames)

# One frame of each kind dockd's error filter takes (linux/can/error.h): controller with data[1] = TX error passive,
# protocol violation, bus error, no ACK, transmit timeout; then bus-off and restarted.
cansend vcan0 20000004#0020000000000000   # CAN_ERR_CRTL, CAN_ERR_CRTL_TX_PASSIVE
cansend vcan0 20000008#0000000000000000   # CAN_ERR_PROT
cansend vcan0 20000080#0000000000000000   # CAN_ERR_BUSERROR
cansend vcan0 20000020#0000000000000000   # CAN_ERR_ACK
cansend vcan0 20000001#0000000000000000   # CAN_ERR_TX_TIMEOUT
check five_errors_counted wait_for 10 total_is bus_errors 5
check no_bus_off_yet total_is bus_off 0
cansend vcan0 20000040#0000000000000000   # CAN_ERR_BUSOFF
check bus_off_counted wait_for 10 total_is bus_off 1
check bus_off_is_a_bus_error total_is bus_errors 6
check bus_off_event json_has "$EV" '.event == "can_error" and .bus_off == 1'
cansend vcan0 20000100#0000000000000000   # CAN_ERR_RESTARTED
check restart_counted wait_for 10 total_is bus_errors 7
check one_bus_off total_is bus_off 1

# A burst: every frame counted, none lost (the socket queue holds far more than 20).
for i in $(seq 1 20); do cansend vcan0 20000080#0000000000000000; done
check burst_counted wait_for 15 total_is bus_errors 27
# The events' `new` fields add up to the total: no error frame counted twice or skipped.
new_sum=$(json_values "$EV" new can_error | awk '{s += $1} END {print s + 0}')
echo "INFO can_error events: $(json_count "$EV" '.event == "can_error"'), new frames in them: $new_sum"
check events_add_up test "$new_sum" -eq 27

DOCKCTL status > "$OUT/status.json"
check error_frames_are_not_bad_frames test "$(status_field can_bad_frames)" = "$bad_before"
check chassis_still_fresh json_has "$OUT/status.json" '.chassis_stale == false'
check still_idle json_has "$OUT/status.json" '.state == "NOT_TASKING" and .state_code == 0'

stop_bg "$PID_dockd" TERM
check dockd_sigterm_exit_0 test "$STOP_STATUS" -eq 0
sleep 0.3
stop_bg "$PID_candump" INT
