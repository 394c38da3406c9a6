# Fault-injection matrix, motion rows (docs/reliability.md). Scenario events (tests/hil/scenarios/*.toml,
# chassis-sim's motion clock: 2.0 s after the first non-zero wheel command, mid-approach in ALIGN) or chassis-sim
# options; fault time = chassis-sim's truth event; judged on the host by tests/hil/matrix.py from the candump stamps.
source "$SRC/tests/hil/matrix_lib.sh"
SC="$SRC/tests/hil/scenarios"

# Host-side checks (tests/hil/matrix.py).
post_no_fault() {
  check_no_fault "$ROW"
}
post_no_charge() {
  local states; states=$($MATRIX_PY states "$RD"); echo "INFO motion_no_charge states: $states"
  check motion_no_charge_retried grep -qE '(^| )6( |$)' <<< "$states"
  check motion_no_charge_ends_faulted grep -qE ' 8$' <<< "$states"
  check motion_no_charge_request_off test "$($MATRIX_PY last-signal "$RD" ChargeRequest charge_enable)" = 0
}
post_request_off() {
  check "${ROW}_request_off" test "$($MATRIX_PY last-signal "$RD" ChargeRequest charge_enable)" = 0
}
[ -n "${MATRIX_POST:-}" ] && return 0

# Push rows: the lidar sees the dock jump while odometry did not move. docs/faults.md: raised on the second
# consecutive agreeing detection after the push. The first turn rendered after the push starts <= 100 ms after it,
# the second 100 ms later, and a turn is published when its last packet has left (paced over the turn, as the sensor
# sends) and the next turn's first one shows the wrap: the second post-push turn is parsed <= 300 ms after the push,
# plus one 20 ms tick: 320 ms when the first two post-push detections both count. They do not always: in dock-sim
# (these scenarios, seeds 1-200) the fault came on the 2nd post-push turn in 154/176 runs (angle/distance), the 3rd in
# 39/21 and the 4th in 7/3 (docs/reliability.md), and a HIL run saw 372 ms with dockd's loop on time. The limit allows
# those two more turns: 520 ms. If dockd's own loop stalled over 500 ms (target_lost_after) around the push, the
# VM decided the row (the target is lost and reacquired at the pushed pose): its failed checks count as STARVED
# (docs/reliability.md). Not a watchdog fault: no resume; the
# robot holds until a new dock command (sent 1.5 s later, sequence 2), then moves again.
push_row() {
  local name="$1" scenario="$2" code="$3"
  ROW_SCENARIO="$SC/$scenario" row_start "$name"
  row_dock
  wait_for 60 truth_has push
  sleep 1.5
  inject redock
  cansend vcan0 "$("$BUILD/tests/hil/hil_frames" dock 0 2)"
  sleep 1.5
  row_stop
  judge --fault push --limit-ms 520 --code "$code" --clear redock --recover moving --starved-if-stall-ms 500
}
push_row motion_push_distance push_distance.toml 178
push_row motion_push_angle push_angle.toml 179

# Obstacle: a 12 cm disc appears 0.30 m ahead of the robot's centre, 1.5 cm from its bumper (inside the self margin, see
# tests/hil/scenarios/obstacle.toml) for 2 s. Its bearing is swept within 100 ms, but a turn is published only when
# the sweep wraps past 0 deg (the LD06 parser closes a turn on the next turn's first point; the emitter, like the
# sensor, sends the turn's last points with the next turn's first ones), up to one more turn later: two scan periods
# + one tick = limit 220 ms; no fault (obstacle_timeout 10 s); the robot moves again when it is gone.
ROW_SCENARIO="$SC/obstacle.toml" row_start motion_obstacle
row_dock
wait_for 60 truth_has obstacle_gone
sleep 1.5
row_stop
judge --fault obstacle --limit-ms 220 --clear obstacle_gone --recover moving
post post_no_fault

# Dock occluded 1 s: the estimate ages past target_lost_after (0.5 s): the robot holds. The last scan with the dock
# left <= the occlusion start; one more scan period (the previous detection may be the last one) + a tick: limit
# 620 ms. No fault; it moves again on reacquisition.
ROW_SCENARIO="$SC/occlude_1s.toml" row_start motion_occlude_1s
row_dock
wait_for 60 truth_has occlude_dock_end
sleep 1.5
row_stop
judge --fault occlude_dock --limit-ms 620 --clear occlude_dock_end --recover moving
post post_no_fault

# Dock occluded 6 s: held as above, then fault 181 once lost for more than target_lost_timeout (5 s) — lost from
# ~0.5 s, so the fault comes ~5.5 s after the occlusion starts (limit 5.5 s + scan + tick = 5640 ms). A 5 s occlusion
# recovers by design (lost 4.5 s < 5 s): docs/reliability.md. Not a watchdog fault: no motion after the dock is back.
ROW_SCENARIO="$SC/occlude_6s.toml" row_start motion_occlude_6s
row_dock
wait_for 60 truth_has occlude_dock_end
sleep 1.5
row_stop
judge --fault occlude_dock --limit-ms 620 --code 181 --status-limit-ms 5640 --recover none

# Charging never starts (--no-charge): every attempt reaches the contacts, no current; retries (here max_retries 1,
# charge_confirm_timeout 2 s to keep the row short), then fault 182 after backing off to the staging distance.
# Fault time = the first DockStatus with 182; the robot must already stand: the next tick's wheel frame is zero
# (limit two ticks, 40 ms: a tick may run up to 20 ms late before matrix.py calls the VM starved).
# This row is about the charge confirmation, not the watchdogs (their own rows): it widens them to 1.5 s so a stall
# of the TCG VM (up to ~1 s seen) cannot turn it into a 185 row with a resume.
ROW_SED='s/^lidar_stale_ms = 200$/lidar_stale_ms = 1500/;s/^chassis_stale_ms = 200$/chassis_stale_ms = 1500/' \
ROW_TOML=$'[task]\nmax_retries = 1\ncharge_confirm_timeout_s = 2.0' row_start motion_no_charge --no-charge
row_dock
wait_for 150 state_is FAULT
sleep 1
row_stop
judge --fault status:182 --no-moving-check --code 182 --limit-ms 40 --recover none
post post_no_charge
press=$(tail -2 "$RD/truth.jsonl" | head -1 | json_field - press_m)
echo "FIGURE motion_no_charge_final_distance_m ${press#-}"
check motion_no_charge_backed_off awk -v p="$press" 'BEGIN{exit !(p != "" && p + 0 <= -0.3)}'

# Contacts break while charging (--break-contact-after 1: the robot is nudged 3 cm back 1 s after charging began).
# The contact flag comes in chassis-sim's 100 ms power frame; dockd's limit runs from that frame (the simulated
# chassis' own lateness on a loaded VM is not dockd's, printed as status_reference_ms; status_ms still counts from
# the break): the next tick reads it, contact_lost_debounce 0.3 s runs on the tick clock, 183 goes out in the status
# at the first tick past it: 300 ms + two ticks; the charge request goes off; the robot does not move (it was
# standing).
row_start motion_contact_break --break-contact-after 1.0
row_dock
wait_for 90 truth_has contact_break
sleep 1.5
row_stop
judge --fault contact_break --status-from 'first:Power[contact=0]:contact_break' --no-moving-check --code 183 \
  --status-limit-ms 300 --status-limit-ticks 2 --recover none
post post_request_off
