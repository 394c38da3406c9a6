# Fault-injection matrix, lidar rows (docs/reliability.md). Each row: fresh chassis-sim + dockd +
# candump, a CAN dock command, the fault injected by chassis-sim on its motion clock (2.0 s after the first non-zero
# wheel command: mid-approach, ALIGN), judged on the host by tests/hil/matrix.py from the candump stamps.
# Fault time = the last good scan: chassis-sim's truth event lidar_last_good_scan, stamped (CLOCK_REALTIME) when the
# last scan before the fault left for the pty. dockd's stale-lidar watchdog (lidar_stale_ms 200) must zero the wheels
# within 200 ms + one 20 ms tick of it: limit 220 ms. Recovery: dockd resumes the dock command after 0.5 s of fresh
# data. 5 % corrupted bytes ruin ~91 % of the LD06 packets (47 bytes each) but some scans still complete: the
# reaction may be the target-lost hold instead (estimate older than 0.5 s: limit 500 ms + one scan + one tick =
# 620 ms), fault 185 when no scan completes for 200 ms.
source "$SRC/tests/hil/matrix_lib.sh"

post_lidar_protocol() {
  check lidar_protocol_never_moved test "$($MATRIX_PY nonzero-count "$RD")" = 0
}
[ -n "${MATRIX_POST:-}" ] && return 0

# lidar_row NAME FAULT_EVENT CLEAR_EVENT CHASSIS-SIM-OPTIONS...
lidar_row() {
  local name="$1" fault="$2" clear="$3"; shift 3
  row_start "$name" "$@"
  row_dock
  wait_for 60 truth_has "$clear"
  # Resume: 0.5 s of fresh scans after the driver reconnected (backoff up to 2 s), then motion.
  [ -z "${JUDGE:-}" ] && wait_for 15 dockd_logged resume
  sleep 1
  row_stop
  # shellcheck disable=SC2086
  judge --fault lidar_last_good_scan --limit-ms "${LIMIT_MS:-220}" --code 185 --clear "$clear" ${JUDGE:---recover resume}
}

lidar_row lidar_unplug lidar_unplug lidar_replug --lidar-unplug-at 2 --lidar-unplug-for 1.5
lidar_row lidar_stall lidar_stall lidar_unstall --lidar-stall-at 2 --lidar-stall-for 1.5
lidar_row lidar_corrupt50 lidar_corrupt lidar_clean --lidar-corrupt 0.5 --lidar-corrupt-at 2 --lidar-corrupt-for 1.5
# 5 %: scans that still complete make the lidar fresh again between trips: the robot may hold and go on; judged by
# the status (never motion while a DockStatus shows a fault) and motion after the corruption ends.
LIMIT_MS=620 JUDGE="--hold-by-status --recover moving" lidar_row lidar_corrupt5 lidar_corrupt lidar_clean --lidar-corrupt 0.05 --lidar-corrupt-at 2 --lidar-corrupt-for 1.5
lidar_row lidar_wrong_baud lidar_wrong_baud lidar_right_baud --lidar-wrong-baud 115200 --lidar-wrong-baud-at 2 \
  --lidar-wrong-baud-for 1.5

# Another protocol: RPLIDAR bytes into dockd's LD06 parser from the start. No scan ever parses: the dock command
# faults 185 at once (the lidar was never fresh). Fault time = the HostCommand frame in the candump log; limit for the
# FAULT/185 status (idle, the status already shows 185 as the watchdog condition): the command is taken on the next
# tick and faults on the one after (GET_TASKING_CMD sees lidar_ok false), status on change: 3 ticks = 60 ms. The robot never moves; the parser counts the garbage.
# The lidar never becomes fresh here: "dockd up" is idle alone.
ROW_READY="state_is NOT_TASKING" row_start lidar_protocol --lidar-protocol rplidar --lidar-rplidar-autostart
sleep 2
row_dock
sleep 3
row_stop
judge --fault first:HostCommand:dock --no-moving-check --code 185 --state 8 --status-limit-ms 60 --recover none
post post_lidar_protocol
check lidar_protocol_no_scans test "$(json_field "$RD/status.json" scans)" = 0
errs=$(( $(json_field "$RD/status.json" lidar_crc_errors) + $(json_field "$RD/status.json" lidar_resyncs) ))
echo "FIGURE lidar_protocol_parser_errors $errs"
# RPLIDAR bytes hold no LD06 packet: every one read is dropped and counted (a CRC error or resync needs a chance
# 0x54 0x2C pair in the stream, which a short or starved row may not contain).
dropped=$(json_field "$RD/status.json" lidar_dropped_bytes)
echo "FIGURE lidar_protocol_dropped_bytes ${dropped:-absent}"
check lidar_protocol_garbage_counted test "${dropped:-0}" -gt 0
