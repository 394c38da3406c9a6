#!/usr/bin/env bash
# Smoke test of camera-check without a camera: the benchmark on its drawn frame finds its four tags, detect on a real
# photo of the realdata folder (skipped without it) prints its tags with poses, an unknown family is refused (exit 2,
# naming it), capture from an absent device gives up with exit 3 naming the device and the call, and calib without a
# distance or a tag size, or on a missing image, is a usage error (exit 2).
# Usage: camera_check_smoke.sh <camera-check> <realdata dir> ($DOCKCORE_REALDATA wins when set).
set -euo pipefail
cc="$1"
realdata="${DOCKCORE_REALDATA:-$2}"
out="$("$cc" bench --frames 3)"
grep -q '"tags":4,' <<<"$out" || { echo "bench on the drawn frame: $out" >&2; exit 1; }
photo="$realdata/apriltag/34139872896_defdb2f8d9_c.jpg"
if [ -f "$photo" ]; then
  n="$("$cc" detect --image "$photo" --decimate 1 --refine-edges false --fx 700 --tag-size 0.05 | grep -c '"z_m":')"
  [ "$n" -eq 10 ] || { echo "detect on $photo: $n tags with a pose, want 10" >&2; exit 1; }
else
  echo "camera-check detect: skipped, no real tag photos at $realdata/apriltag"
fi
set +e
err="$("$cc" bench --frames 1 --family tag99h9 2>&1)"; rc=$?
set -e
[ $rc -eq 2 ] && grep -q "tag family 'tag99h9'" <<<"$err" || { echo "unknown family: rc $rc, $err" >&2; exit 1; }
set +e
err="$("$cc" capture --device /nonexistent/video9 --frames 1 --give-up-seconds 0.3 2>&1)"; rc=$?
set -e
[ $rc -eq 3 ] && grep -q 'camera /nonexistent/video9: open: No such file' <<<"$err" || { echo "absent device: rc $rc, $err" >&2; exit 1; }
set +e
err="$("$cc" calib --image /nonexistent/a.jpg --fx 600 --tag-size 0.1 2>&1)"; rc=$?
set -e
[ $rc -eq 2 ] && grep -q -- '--distance is required' <<<"$err" || { echo "calib without --distance: rc $rc, $err" >&2; exit 1; }
set +e
err="$("$cc" calib --distance 1 --image /nonexistent/a.jpg --fx 600 --tag-size 0.1 2>&1)"; rc=$?
set -e
[ $rc -eq 2 ] && grep -q '/nonexistent/a.jpg: cannot open' <<<"$err" || { echo "calib on a missing image: rc $rc, $err" >&2; exit 1; }
set +e
err="$("$cc" calib --distance 1 --image /nonexistent/a.jpg --fx 600 2>&1)"; rc=$?
set -e
[ $rc -eq 2 ] && grep -q -- '--tag-size .* is required' <<<"$err" || { echo "calib without --tag-size: rc $rc, $err" >&2; exit 1; }
echo "camera-check smoke: ok"
