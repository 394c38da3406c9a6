#!/usr/bin/env bash
# Smoke test of `dock-sim perception --sections generated` on a tiny run: the figures do not depend on --jobs, a
# different seed gives different figures, every factor table and target is in the JSON, and tools/perception-report
# renders it. Usage: perception_generated_smoke.sh <dock-sim> <perception-report>.
set -euo pipefail
docksim="$1"
report="$2"
dir="$(mktemp -d)"
trap 'rm -rf "$dir"' EXIT

"$docksim" perception --sections generated --gen-scenes 60 --seed 3 --jobs 1 --json >"$dir/a.json" 2>/dev/null
"$docksim" perception --sections generated --gen-scenes 60 --seed 3 --jobs 2 --json >"$dir/b.json" 2>/dev/null
"$docksim" perception --sections generated --gen-scenes 60 --seed 4 --jobs 2 --json >"$dir/c.json" 2>/dev/null
cmp -s "$dir/a.json" "$dir/b.json" || { echo "figures depend on --jobs" >&2; exit 1; }
if cmp -s "$dir/a.json" "$dir/c.json"; then echo "another seed gave the same figures" >&2; exit 1; fi

/usr/bin/python3 - "$dir/a.json" <<'PY'
import json, sys
g = json.load(open(sys.argv[1]))["generated"]
fail = []
for f in ("profile", "mounting", "clutter", "lidar", "noise", "range", "bearing", "dock-yaw"):
    if f not in g["factors"] or not g["factors"][f]:
        fail.append("factor %s missing" % f)
scenes = sum(r["told"]["scenes"] + r["excluded"] for r in g["factors"]["mounting"])
if scenes != 60:
    fail.append("mounting rows hold %d docking scenes, not 60" % scenes)
if len(g["targets"]["told"]) != 8 or len(g["targets"]["unknown"]) != 8:
    fail.append("targets missing")
if len(g["random_profiles"]) != 100:
    fail.append("random profile report missing")
if fail:
    print("\n".join(fail), file=sys.stderr)
    sys.exit(1)
PY
# --min-evidence-nats reaches every estimator: far above any dock's evidence nothing is found, far below it no
# fewer docks are found than with the default, and the JSON says which floor was used.
"$docksim" perception --sections generated --gen-scenes 60 --seed 3 --jobs 2 --json --min-evidence-nats 100 \
  >"$dir/hi.json" 2>/dev/null
"$docksim" perception --sections generated --gen-scenes 60 --seed 3 --jobs 2 --json --min-evidence-nats=-100 \
  >"$dir/lo.json" 2>/dev/null
/usr/bin/python3 - "$dir/a.json" "$dir/hi.json" "$dir/lo.json" <<'PY'
import json, sys
a, hi, lo = (json.load(open(p)) for p in sys.argv[1:4])
found = lambda j: j["generated"]["overall"]["told"]["found"] + j["generated"]["overall"]["unknown"]["found"]
fail = []
if "overrides" in a:
    fail.append("a default run reports an override")
if hi.get("overrides", {}).get("min_evidence_nats") != 100:
    fail.append("the override is not in the JSON")
if found(hi) != 0:
    fail.append("%d docks found with a floor of 100 nats" % found(hi))
if found(lo) < found(a) or found(a) == 0:
    fail.append("floor -100 found %d docks, the default %d" % (found(lo), found(a)))
if fail:
    print("\n".join(fail), file=sys.stderr)
    sys.exit(1)
PY
# --max-candidates reaches every estimator: one candidate finds fewer docks than the default's twelve, and the JSON
# says so.
"$docksim" perception --sections generated --gen-scenes 60 --seed 3 --jobs 2 --json --max-candidates 1 \
  >"$dir/one.json" 2>/dev/null
/usr/bin/python3 - "$dir/a.json" "$dir/one.json" <<'PY'
import json, sys
a, one = (json.load(open(p)) for p in sys.argv[1:3])
found = lambda j: j["generated"]["overall"]["told"]["found"] + j["generated"]["overall"]["unknown"]["found"]
fail = []
if one.get("overrides", {}).get("max_candidates") != 1:
    fail.append("the max_candidates override is not in the JSON")
if not found(one) < found(a):
    fail.append("one candidate found %d docks, twelve %d" % (found(one), found(a)))
if fail:
    print("\n".join(fail), file=sys.stderr)
    sys.exit(1)
PY
# To a file first: `grep -q` would close the pipe on its match while the report still writes (EPIPE under pipefail).
/usr/bin/python3 "$report" "$dir/a.json" >"$dir/a.md"
grep -q "^#### Targets" "$dir/a.md" || { echo "perception-report lost the section" >&2; exit 1; }
echo "perception generated smoke: ok"
