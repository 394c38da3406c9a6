# valgrind memcheck over dockd on the real vcan bus: dockd under memcheck with chassis-sim and its
# lidar, a dock command, ~20 s of running (under memcheck inside the TCG VM dockd is ~100x slower than native, so
# it will trip its own watchdogs — that is fine: the point is every code path it runs, including faults), dockctl
# status, SIGTERM. memcheck must report no errors and nothing definitely or indirectly lost.
make_dockd_config
bg chassis chassis-sim-run --can vcan0 --lidar-pty /tmp/dockcore-lidar --start 1.0,0,0 --seed 2 \
   "$SRC/tools/scenarios/default.toml"
wait_for 10 test -e /tmp/dockcore-lidar
bg dockd valgrind --tool=memcheck --error-exitcode=99 --leak-check=full --errors-for-leak-kinds=definite,indirect \
   --log-file="$OUT/memcheck.txt" "$BUILD/app/dockd" --config "$OUT/dockd.toml"
check dockd_up_under_memcheck wait_for 240 state_is NOT_TASKING
DOCKCTL dock --dock 0 > "$OUT/dock.json" || true
sleep 15
DOCKCTL_TIMEOUT_S=10 DOCKCTL status > "$OUT/status.json" || true
DOCKCTL stop > /dev/null || true
stop_bg "$PID_dockd" TERM
echo "INFO dockd under memcheck exit $STOP_STATUS; status: $(cut -c1-160 "$OUT/status.json")"
grep -E "total heap usage|ERROR SUMMARY|definitely lost|indirectly lost|possibly lost" "$OUT/memcheck.txt" | sed 's/^==[0-9]*== /INFO /'
check status_answered_under_memcheck json_has "$OUT/status.json" 'has("state")'
check memcheck_exit_0 test "$STOP_STATUS" -eq 0
check memcheck_no_errors grep -q "ERROR SUMMARY: 0 errors" "$OUT/memcheck.txt"
