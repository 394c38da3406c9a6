# Dockings on vcan0 with bases other than the default one: chassis-sim plays each base, dockd drives it with the
# HIL config (its robot geometry is the same in both rows).
#  - agilex: the default robot behind the AgileX V2 profile (0x421 control mode, 0x111 motion command, 0x221/0x311
#    feedback, charging seen as BMS current). dockd is told only `protocol = "agilex-v2"`.
#  - heavy: tools/scenarios/heavy-base.toml on dockcore CAN v1: 60 ms command latency, 0.2 s motor time constant,
#    wheels that stand below 1.0 rad/s (above the creep the controller asks for), 2-3 % odometry errors. dockd is
#    not told the deadband: it must learn it from the wheel feedback (status deadband_fwd_radps) to reach the contacts.
#    One wheel's floor is enough when the other never stalls again: the whole command is scaled to the highest floor.
# Each row: fresh chassis-sim + dockd + candump, a dockctl dock, charging confirmed with the contacts within 1 cm,
# an undock, SIGTERM with exit 0 and the last wheel command on the bus zero; dock-decode reads the bus log with no
# error under the row's profile.

# base_row NAME SCENARIO PROTOCOL START: one docking and undocking of the base.
base_row() {
  local name="$1" scenario="$2" proto="$3" start="$4"
  local dir="$OUT/$name"
  mkdir -p "$dir"
  make_dockd_config -e "s|protocol = \"dockcore-v1\"|protocol = \"$proto\"|" -e "s|@OUT@/record|$dir/record|" \
    -e "s|@OUT@/dockd.state|$dir/dockd.state|"
  bg candump candump -L vcan0
  bg chassis "$BUILD/tools/chassis-sim/chassis-sim" --can vcan0 --protocol "$proto" --lidar-pty /tmp/dockcore-lidar --start "$start" \
    --seed 5 --truth "$dir/truth.jsonl" "$scenario"
  wait_for 10 test -e /tmp/dockcore-lidar
  bg dockd "$BUILD/app/dockd" --config "$OUT/dockd.toml"
  check "${name}_dockd_up" wait_for 20 dockd_ready

  local t0; t0=$(hil_now)
  check "${name}_dock_accepted" DOCKCTL dock --dock 0
  check "${name}_charging" wait_for 150 state_is FINISH_TASKING
  echo "FIGURE ${name}_time_to_charging_s $(awk -v a="$t0" -v b="$(hil_now)" 'BEGIN{printf "%.1f", b-a}')"
  local c lat yaw
  read -r c lat yaw <<< "$(/usr/bin/python3 "$SRC/tests/hil/analyze.py" final-error "$dir/truth.jsonl")"
  echo "FIGURE ${name}_final_lateral_mm $lat"
  echo "FIGURE ${name}_final_yaw_deg $yaw"
  check "${name}_contact_error_within_1cm" awk -v l="$lat" 'BEGIN{exit !(l != "" && l+0 <= 10 && l+0 >= -10)}'
  DOCKCTL status > "$dir/status.json"
  local db db_raises
  db=$(json_field "$dir/status.json" deadband_fwd_radps)
  db_raises=$(json_field "$dir/status.json" deadband_raises)
  echo "INFO ${name} learned deadband forward ${db} rad/s (${db_raises} raises), fault $(json_field "$dir/status.json" fault)"
  [ "$name" = heavy ] && check heavy_deadband_learned \
    jq -e '.deadband_fwd_radps | (max >= 0.9)' "$dir/status.json" > /dev/null
  check "${name}_undock_accepted" DOCKCTL undock
  check "${name}_undocked" wait_for 60 state_is NOT_TASKING

  stop_bg "$PID_dockd" TERM
  check "${name}_dockd_sigterm_exit_0" test "$STOP_STATUS" -eq 0
  sleep 0.3
  stop_bg "$PID_candump" INT
  stop_bg "$PID_chassis" TERM
  mv "$OUT/candump.log" "$OUT/chassis.log" "$OUT/dockd.log" "$dir/"
  "$BUILD/tools/dock-decode/dock-decode" --profile "$proto" --json "$dir/candump.log" > "$dir/decode.json"
  check "${name}_dock_decode_strict_no_errors" \
    "$BUILD/tools/dock-decode/dock-decode" --profile "$proto" -q --strict "$dir/candump.log"
  check "${name}_last_wheel_command_zero" \
    test "$(/usr/bin/python3 "$SRC/tests/hil/analyze.py" last-wheels "$dir/decode.json")" = "0 0"
  rm -f /tmp/dockcore-lidar
}

base_row agilex "$SRC/tools/scenarios/default.toml" agilex-v2 1.3,-15,10
base_row heavy "$SRC/tools/scenarios/heavy-base.toml" dockcore-v1 1.5,20,-10
