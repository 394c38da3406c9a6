#!/usr/bin/env bash
# Smoke test of `dock-sim perception --sections reflectors` on a tiny run: the figures do not depend on --jobs, a
# different seed gives different figures, and every table, the readable-range rows and the targets are in the JSON.
# Usage: perception_reflectors_smoke.sh <dock-sim>.
set -euo pipefail
docksim="$1"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT

args=(perception --sections reflectors --refl-scenes 80 --read-range --read-range-scenes 40 --json)
"$docksim" "${args[@]}" --seed 3 --jobs 1 >"$dir/a.json" 2>/dev/null
"$docksim" "${args[@]}" --seed 3 --jobs 2 >"$dir/b.json" 2>/dev/null
"$docksim" "${args[@]}" --seed 4 --jobs 2 >"$dir/c.json" 2>/dev/null
cmp -s "$dir/a.json" "$dir/b.json" || { echo "figures depend on --jobs" >&2; exit 1; }
if cmp -s "$dir/a.json" "$dir/c.json"; then echo "another seed gave the same figures" >&2; exit 1; fi

/usr/bin/python3 - "$dir/a.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))["reflectors"]
fail = []
for k in ("detection", "by_range", "by_bearing", "by_incidence", "by_face_reflectivity", "misses",
          "confident_wrong_id", "false_positives", "detections_elsewhere_by_object", "look_alikes", "reflective_clutter",
          "read_range", "targets"):
    if k not in r:
        fail.append("%s missing" % k)
if len(r.get("by_range", [])) != 5:
    fail.append("by_range has not 5 bins")
looks = [row["look_alike"] for row in r.get("look_alikes", [])]
for la in ("other-code", "untaped", "taped-board"):
    if la not in looks:
        fail.append("look-alike %s missing" % la)
if len(r.get("read_range", [])) != 6:
    fail.append("read_range has not 6 rows (2 lidars x 3 widths)")
if "upper95" not in r["false_positives"]["intensity"]["fp_per_confirmation"]:
    fail.append("no upper bound on the false positives")
if len(r.get("targets", [])) != 3:
    fail.append("targets missing")
if fail:
    print("\n".join(fail), file=sys.stderr)
    sys.exit(1)
PY
# The text tables print too.
"$docksim" perception --sections reflectors --refl-scenes 20 --seed 3 >"$dir/a.txt" 2>/dev/null
grep -q "^== Targets, reflector docks" "$dir/a.txt" || { echo "text tables missing" >&2; exit 1; }
echo "perception reflectors smoke: ok"
