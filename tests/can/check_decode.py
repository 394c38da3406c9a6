#!/usr/bin/python3
"""dock-decode on tests/data/can/docking_v1.log (made by tests/can/make_can_log.cpp with one injected counter jump on
WheelFbA, one ChassisStatus gap, one CAN FD, one RTR and one malformed line): the summary must report exactly those.
Also: --strict exits 1 on that log; a log cut to its first 0.5 s (before any injected fault) passes --strict;
command-line errors exit 2 and --help exits 0.
usage: check_decode.py DOCK_DECODE LOG WORKDIR"""
import json
import os
import subprocess
import sys

exe, log, work = sys.argv[1:4]
os.makedirs(work, exist_ok=True)
fails = []


def expect(cond, what):
    if not cond:
        fails.append(what)


r = subprocess.run([exe, log, "--json", "--svg", os.path.join(work, "decode.svg")], capture_output=True, text=True)
expect(r.returncode == 0, "exit status without --strict: %d (%s)" % (r.returncode, r.stderr))
doc = json.loads(r.stdout)
expect(doc["errors"] == {"counter_jump": 1}, "errors %s" % doc["errors"])
expect(doc["error_total"] == 1, "error_total %s" % doc["error_total"])
ids = {e["name"]: e for e in doc["per_id"]}
expect(ids["WheelFbA"]["errors"] == 1, "WheelFbA errors %s" % ids["WheelFbA"])
expect(ids["WheelCmdA"]["frames"] == 200 and ids["WheelCmdA"]["errors"] == 0, "WheelCmdA %s" % ids["WheelCmdA"])
expect(len(doc["gaps"]) == 1 and doc["gaps"][0]["name"] == "ChassisStatus" and
       590 < doc["gaps"][0]["gap_ms"] < 610, "gaps %s" % doc["gaps"])
expect(doc["skipped"]["canfd"] == 1 and doc["skipped"]["rtr"] == 1, "skipped %s" % doc["skipped"])
expect(len(doc["malformed"]) == 1 and doc["malformed"][0]["line"] == 329, "malformed %s" % doc["malformed"])
states = [e["signals"]["state"] for e in doc["timeline"] if e["name"] == "DockStatus"]
expect(states[0] == 0 and 3 in states and states[-1] == 4, "task states %s" % sorted(set(states)))
svg = open(os.path.join(work, "decode.svg")).read()
expect(svg.startswith("<svg") or "<svg" in svg[:200], "no SVG written")
expect(svg.count("<polyline") >= 5, "SVG has %d polylines" % svg.count("<polyline"))

r = subprocess.run([exe, log, "--strict", "-q"], capture_output=True, text=True)
expect(r.returncode == 1, "--strict exit status %d" % r.returncode)
expect("counter_jump=1" in r.stdout and "line 329" in r.stdout, "text summary:\n" + r.stdout)

clean = os.path.join(work, "first_half_second.log")
with open(log) as f, open(clean, "w") as g:
    for line in f:
        if line.startswith("(") and float(line[1:line.index(")")]) >= 1700000000.5:
            break
        g.write(line)
r = subprocess.run([exe, clean, "--strict", "--strict-gaps", "-q"], capture_output=True, text=True)
expect(r.returncode == 0, "--strict on the clean first 0.5 s: %d\n%s" % (r.returncode, r.stdout))

# Command-line errors exit 2 with CLI11's message (not CLI11's own codes 104-114); --help exits 0.
for args, what in (([log, "--profile", "nope"], "bad --profile"), ([log, "--bogus"], "unknown option"),
                   ([], "missing log"), ([log, "extra"], "extra positional")):
    r = subprocess.run([exe] + args, capture_output=True, text=True)
    expect(r.returncode == 2 and r.stderr.strip() != "", "%s: exit %d, stderr %r" % (what, r.returncode, r.stderr))
r = subprocess.run([exe, "--help"], capture_output=True, text=True)
expect(r.returncode == 0 and "--profile" in r.stdout, "--help: exit %d" % r.returncode)

for f in fails:
    print("FAIL", f)
print("check_decode: %d failures" % len(fails))
sys.exit(1 if fails else 0)
