#!/usr/bin/env bash
# Smoke test of tools/bench-cost: one tiny run per detector (360 points, 2 and 4 scans) on an already built dock-sim.
# Checks that every detector's entry points were found and counted, that nothing outside the detector was counted,
# that the K-difference is consistent with the per-scan dumps, and the obvious ordering of costs.
# Usage: bench_cost_smoke.sh <dock-sim> [bench-cost]. Exit 77 (skipped) when valgrind is not installed.
set -euo pipefail
docksim="$1"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
bench="${2:-$here/tools/bench-cost}"
out="$(mktemp)"
trap 'rm -f "$out"' EXIT

status=0
"$bench" --dock-sim "$docksim" --no-install --points 360,720 --scans 2,4 --native-scans 3 --jobs 2 --top 3 --json \
  >"$out" || status=$?
[ "$status" -eq 77 ] && exit 77
if [ "$status" -ne 0 ]; then
  echo "bench-cost exited $status" >&2
  exit 1
fi

/usr/bin/python3 - "$out" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
rows = {(r["detector"], r["points"]): r for r in j["rows"]}
fail = []
def check(ok, what):
    if not ok:
        fail.append(what)
for d in ("estimator", "estimator-tracking", "breakpoint", "vmarker"):
    for n in (360, 720):
        r = rows.get((d, n))
        if r is None:
            fail.append("missing row %s %d" % (d, n))
            continue
        tag = "%s@%d: " % (d, n)
        check(r["counting_ok"], tag + "counting check failed")
        check(r["non_detector_share"] == 0, tag + "counted outside the detector: %s" % r["non_detector_functions"])
        check(r["instructions_per_scan"] > 1000, tag + "implausibly few instructions: %d" % r["instructions_per_scan"])
        if d == "vmarker":  # three entry points: no per-scan dumps
            check(r["per_scan_median"] is None, tag + "per-scan figures without dumps")
        else:
            check(r["per_scan_min"] <= r["per_scan_median"] <= r["per_scan_max"], tag + "per-scan order")
            # The mean over scans 3..4 from the K-difference is the mean of those scans' own dumps: (a + b) / 2
            # lies between them.
            check(r["per_scan_min"] <= r["instructions_per_scan"] <= r["per_scan_max"],
                  tag + "mean %d outside the per-scan range %d..%d"
                  % (r["instructions_per_scan"], r["per_scan_min"], r["per_scan_max"]))
        check(r["ns_per_scan_median"] > 0, tag + "no native timing")
        # At most --top functions: a detector may spend its instructions in fewer.
        check(1 <= len(r["top_self"]) <= 3 and r["top_self"][0]["share"] > 0.1, tag + "top functions")
        check(all(t["function"].startswith("dockcore::") or "::" not in t["function"] for t in r["top_self"]),
              tag + "top function outside core: %s" % [t["function"] for t in r["top_self"]])
    # Collection really is per scan: twice the points, between 1.3x and 3x the instructions. Tracking reads only
    # the beams on the dock, and its fixed cost per iteration (placing the profile, trigonometry, the 3x3 solve) is
    # a large share at 360 points: it must grow, less.
    if (d, 360) in rows and (d, 720) in rows:
        g = rows[(d, 720)]["instructions_per_scan"] / rows[(d, 360)]["instructions_per_scan"]
        lo = 1.05 if d == "estimator-tracking" else 1.3
        check(lo < g < 3.0, "%s: 360 -> 720 points grew %.2fx" % (d, g))
for (d, n), r in rows.items():
    check(r["toggle_collect"] and all("(" in p for p in r["toggle_collect"]), "%s: toggle patterns %s" % (d, r["toggle_collect"]))
check(rows[("breakpoint", 360)]["ratio_to_breakpoint"] == 1.0, "breakpoint ratio to itself")
check(rows[("breakpoint", 360)]["ir_ratio_ok"], "breakpoint Ir(K2)/Ir(K1) = %.3f, want 2" % rows[("breakpoint", 360)]["ir_ratio"])
check(rows[("estimator", 720)]["instructions_per_scan"] > rows[("estimator-tracking", 720)]["instructions_per_scan"],
      "global search not dearer than tracking")
check(len(rows[("vmarker", 360)]["toggle_collect"]) == 3, "vmarker counts scan_to_points, segments and detect")
if fail:
    print("bench_cost_smoke: FAILED\n  " + "\n  ".join(fail))
    sys.exit(1)
print("bench_cost_smoke: ok (%d rows)" % len(rows))
PY
