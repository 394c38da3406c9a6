# The V4L2 camera driver on a real V4L2 device: the kernel's vivid virtual camera, loaded in the VM from the host's
# /lib/modules (the VM boots that same Debian kernel). Through camera-check (tools/camera-check), which prints the
# driver's stamps and counters as JSON lines:
#   1. grey and YUYV 640x480: frames arrive, stamps from the driver (V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC) strictly
#      increasing and not older than 2 s at dequeue, no corrupt frames, no loss;
#   2. vivid's error injection: dropped buffers show as sequence gaps (dropped > 0), an errored buffer is counted as
#      corrupt and skipped;
#   3. the device vanishes (driver unbound, module removed): the loss is reported (connected false, disconnects 1,
#      the message names the device), the module can be removed because the driver closed it, and when vivid is
#      loaded again the driver reopens it by itself (reconnects 1) and frames flow again.
CC="$BUILD/tools/camera-check"
VIVID_ARGS="n_devs=1 node_types=0x1"  # one instance, video capture node only (/dev/video0)
MODPROBE="$(command -v modprobe || echo /usr/sbin/modprobe)"
RMMOD="$(command -v rmmod || echo /usr/sbin/rmmod)"

summary() { json_select "$1" '.type == "summary"' | tail -1 > "$1.summary"; echo "$1.summary"; }

check vivid_module_loads "$MODPROBE" vivid $VIVID_ARGS
wait_for 20 test -e /dev/video0
check video0_appears test -e /dev/video0

# 1. Grey and YUYV.
"$CC" capture --device /dev/video0 --format grey --width 640 --height 480 --frames 30 --every 1 \
  --give-up-seconds 30 > "$OUT/grey.log" 2>&1
check grey_capture_exit test $? -eq 0
s=$(summary "$OUT/grey.log")
check grey_30_frames test "$(json_field "$s" frames)" = 30
check grey_driver_stamps test "$(json_field "$s" driver_stamps)" = true
check grey_stamps_increase test "$(json_field "$s" stamp_backsteps)" = 0
check grey_no_corrupt test "$(json_field "$s" corrupt)" = 0
check grey_no_loss test "$(json_field "$s" disconnects)" = 0
check grey_age_below_2s test "$(json_field "$s" max_age_us)" -lt 2000000
check grey_frame_lines test "$(json_count "$OUT/grey.log" '.type == "frame"')" -eq 30
echo "FIGURE camera_grey_dropped $(json_field "$s" dropped)"
echo "FIGURE camera_grey_late $(json_field "$s" late)"
echo "FIGURE camera_grey_max_age_us $(json_field "$s" max_age_us)"
# Frame interval from the driver's stamps (vivid's webcam input runs at 30 fps by default; the TCG VM may drop).
awk -F'"stamp_us":' '/"type":"frame"/ { split($2, a, ","); if (p) { d = a[1] - p; s += d; n++ } p = a[1] }
  END { if (n) printf "FIGURE camera_grey_mean_interval_ms %.1f\n", s / n / 1000 }' "$OUT/grey.log"

"$CC" capture --device /dev/video0 --format yuyv --width 640 --height 480 --frames 10 --every 0 \
  --give-up-seconds 30 > "$OUT/yuyv.log" 2>&1
check yuyv_capture_exit test $? -eq 0
s=$(summary "$OUT/yuyv.log")
check yuyv_10_frames test "$(json_field "$s" frames)" = 10
check yuyv_stamps_increase test "$(json_field "$s" stamp_backsteps)" = 0

# A size the device does not give is refused with the ioctl named (exit 3).
"$CC" capture --device /dev/video0 --width 1000 --height 10 --frames 1 > "$OUT/badsize.log" 2>&1
check bad_size_refused test $? -eq 3
check bad_size_names_ioctl grep -q 'camera /dev/video0: VIDIOC_S_FMT' "$OUT/badsize.log"

# 2. Error injection: half the buffers dropped (sequence gaps), then one errored buffer (skipped as corrupt).
"$CC" capture --device /dev/video0 --frames 20 --every 0 --give-up-seconds 30 \
  --control "Percentage of Dropped Buffers=50" > "$OUT/dropped.log" 2>&1
check dropped_capture_exit test $? -eq 0
s=$(summary "$OUT/dropped.log")
check dropped_counted test "$(json_field "$s" dropped)" -gt 0
echo "FIGURE camera_injected_dropped $(json_field "$s" dropped)"
"$CC" capture --device /dev/video0 --frames 1 --every 0 --control "Percentage of Dropped Buffers=0" \
  > /dev/null 2>&1
"$CC" capture --device /dev/video0 --frames 10 --every 0 --give-up-seconds 30 \
  --control "Inject V4L2_BUF_FLAG_ERROR=1" > "$OUT/errored.log" 2>&1
check errored_capture_exit test $? -eq 0
s=$(summary "$OUT/errored.log")
check errored_counted_corrupt test "$(json_field "$s" corrupt)" -ge 1
check errored_still_10_good_frames test "$(json_field "$s" frames)" = 10

# 3. Loss and reconnect.
bg cam "$CC" capture --device /dev/video0 --every 5 --give-up-seconds 90 --reconnect-min-ms 100 \
  --reconnect-max-ms 500 --stop-after-reconnect-frames 10 --expect-reconnect
wait_for 60 json_has "$OUT/cam.log" '.type == "frame"'
check streaming_before_loss json_has "$OUT/cam.log" '.type == "frame"'
# Unbinding the platform device unregisters /dev/video0 under the open descriptor (as an unplug does); rmmod alone
# would refuse while the driver holds the device open.
unbound=0
for dev in /sys/bus/platform/drivers/vivid/vivid*; do
  [ -e "$dev" ] || continue
  echo "INFO unbinding $(basename "$dev")"
  basename "$dev" > /sys/bus/platform/drivers/vivid/unbind && unbound=1
done
check vivid_unbound test "$unbound" -eq 1
wait_for 20 json_has "$OUT/cam.log" '.type == "state" and .connected == false'
check loss_reported json_has "$OUT/cam.log" '.type == "state" and .connected == false and .disconnects == 1'
check loss_names_device json_has "$OUT/cam.log" '.connected == false and (.error | startswith("camera /dev/video0: "))'
"$RMMOD" vivid 2>"$OUT/rmmod.err"
check module_removed_after_close test $? -eq 0
check video0_gone test ! -e /dev/video0
sleep 2  # the driver keeps retrying the open meanwhile (ENOENT)
check vivid_reloads "$MODPROBE" vivid $VIVID_ARGS
wait_for 60 json_has "$OUT/cam.log" '.type == "summary"'
check reconnect_reported json_has "$OUT/cam.log" '.type == "state" and .connected == true and .reconnects == 1'
s=$(summary "$OUT/cam.log")
check reconnect_counted test "$(json_field "$s" reconnects)" = 1
check frames_after_reconnect test "$(json_field "$s" frames)" -gt 10
check stamps_increase_across_reconnect test "$(json_field "$s" stamp_backsteps)" = 0
stop_bg "$PID_cam"
check capture_exit_expect_reconnect test "$STOP_STATUS" -eq 0
"$RMMOD" vivid 2>/dev/null
