#!/usr/bin/env python3
"""Fault-injection matrix analysis, standard library only. Every time is CLOCK_REALTIME seconds: the
candump log's stamps, chassis-sim's truth "wall" field and the case's inject log (`date +%s.%N`) share that clock.

  matrix.py row ROW_DIR --row NAME --fault EVENT [--limit-ms L] [--code C] [--clear EVENT] [--recover KIND]
                [--hold-end EVENT] [--no-moving-check] [--status-limit-ms L] [--status-limit-ticks N]
                [--status-from REF]
      Judges one row from ROW_DIR/{candump.log,decode.json,truth.jsonl,inject.log,record/events.jsonl,status.json}
      and prints PASS/FAIL <row>_<check> and FIGURE <row>_<name> <value> lines. Exit status = number of FAILs.
      EVENT names a truth-log event ("event" field) or an inject.log line ("NAME WALL"); the first one counts;
      "status:C" is the first DockStatus frame with fault C, "last:FRAME:REF" / "first:FRAME:REF" the last FRAME frame
      before / the first at or after another reference, "frame:FRAME" the first FRAME frame of the log; a FRAME written
      "Power[contact=0]" counts only the frames whose signal has that value.
        fault time  t_f = EVENT's time.
        reaction    the WheelCmdA with zero speeds (or enable 0) that starts the lasting stop: the run of zero frames
                    that reaches the clear / hold end (the first zero at all is reported as first_zero_ms; with
                    --hold-by-status the first zero counts); reaction_ms = that - t_f, must be <= L (when given).
        moving      the last WheelCmdA before t_f was non-zero (else the reaction says nothing) unless --no-moving-check.
        fault code  a DockStatus frame with fault C at or after t_f (status_ms = its delay; <= --status-limit-ms
                    plus --status-limit-ticks N ticks, each counted at the window's longest tick, >= 20 ms; with
                    --status-from REF the limit runs from REF instead: status_reference_ms = REF - t_f,
                    status_after_reference_ms = the frame's delay after REF).
        hold        no non-zero WheelCmdA from the reaction until --clear EVENT (the fault clears) or --hold-end
                    EVENT or the end of the log (not with --hold-by-status).
        status hold never a non-zero WheelCmdA while the last DockStatus carried a fault (always checked).
        recovery    KIND: resume (non-zero wheels after the clear, and dockd's "resume" event if the task faulted — a
                    watchdog outage shorter than fault_after_ms only holds the wheels), moving (non-zero wheels
                    after the clear, no new command needed), charging (DockStatus FINISH_TASKING after the clear),
                    none (still no non-zero wheel to the end of the log: faults that wait for a new command).
  matrix.py frame ID HEX14            -> cansend "ID#DATA" with the dockcore v1 CRC-8 appended (7 data bytes given)
  matrix.py last-counter CANDUMP ID   -> counter (byte 6 low nibble) of the last frame with that id in a candump log
  matrix.py json-field FILE KEY       -> the value of KEY in a one-line JSON object file ("" when absent)
  matrix.py frame-stall ROW_DIR FRAME T0 T1 -> longest gap (ms) of FRAME overlapping the wall times T0..T1
  matrix.py wheel-gaps ROW_DIR T0 T1  -> "max_gap_ms count" of dockd's WheelCmdA between wall times T0 and T1
  matrix.py first-wheels ROW_DIR REF  -> zero | moving | none: the first WheelCmdA at or after REF
  matrix.py nonzero-count ROW_DIR [T0 [T1]] -> number of non-zero WheelCmdA frames (between wall times T0, T1)
  matrix.py summary CASE_DIR...       -> one line per row: verdict, failed checks, figures (job.log + post.log)
  matrix.py delta ROW_DIR EV1 EV2     -> ms from the first EV1 to the first EV2 at or after it (truth/inject events)
  matrix.py last-signal ROW_DIR FRAME SIGNAL -> that signal in the last frame of that name (dock-decode names)
  matrix.py faults-split ROW_DIR      -> "UNEXCUSED;EXCUSED" fault codes since the task started (VM-starvation split)
  matrix.py faults-explain ROW_DIR    -> one line per unexcused watchdog fault: time, state, stalls, dockd's reason
  matrix.py retries-split ROW_DIR     -> "UNEXCUSED;EXCUSED" attempts that ended in RETRY, with reason (same split)
  matrix.py table CASE_DIR...         -> the measured table of docs/reliability.md (markdown)
  matrix.py states ROW_DIR            -> deduplicated DockStatus state sequence
"""
import bisect
import json
import os
import sys

ROW_NAMES = ["lidar_unplug", "lidar_stall", "lidar_corrupt50", "lidar_corrupt5", "lidar_wrong_baud", "lidar_protocol",
             "can_silent", "can_down_up", "can_flood", "can_bad_frames", "motion_push_distance", "motion_push_angle",
             "motion_obstacle", "motion_occlude_1s", "motion_occlude_6s", "motion_no_charge", "motion_contact_break",
             "host_flood_udp", "host_flood_can", "host_bad_commands", "process_sigkill", "process_restart"]
STATE = {"NOT_TASKING": 0, "GET_TASKING_CMD": 1, "REACH_TASKING_POINT": 2, "ALIGN": 3, "FINISH_TASKING": 4,
         "WAIT_FOR_CHARGE": 5, "RETRY": 6, "UNDOCKING": 7, "FAULT": 8, "TEST_MODE": 9}
STATE_NAME = {v: k for k, v in STATE.items()}


def crc8_h2f(data):
    crc = 0xFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = ((crc << 1) ^ 0x2F) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc ^ 0xFF


def candump_times(path):
    """Line number (1-based, as dock-decode counts) -> wall time."""
    times = {}
    with open(path, errors="replace") as f:
        for i, line in enumerate(f, 1):
            if line.startswith("("):
                try:
                    times[i] = float(line[1:line.index(")")])
                except ValueError:
                    pass
    return times


class Row:
    def __init__(self, d, log=None):
        # The judged CAN log: candump's (default) or, with MATRIX_LOG / --log, another candump-format log such as
        # dockd's session record record/can.log (the CAN down/up row: candump exits when the link goes down).
        log = log or os.environ.get("MATRIX_LOG", "candump.log")
        self.dir = d
        self.times = candump_times(os.path.join(d, log))
        dj = os.path.join(d, "decode.json" if log == "candump.log" else log.replace("/", "_") + ".decode.json")
        if not os.path.exists(dj):  # decoded on first use (on the host: fast)
            import subprocess
            dd = os.path.join(os.environ.get("BUILD", "build/default"), "tools", "dock-decode", "dock-decode")
            with open(dj, "w") as out:
                subprocess.run([dd, "--json", os.path.join(d, log)], stdout=out, stderr=subprocess.DEVNULL,
                               check=False)
        with open(dj) as f:
            doc = json.load(f)
        self.timeline = []
        for e in doc.get("timeline", []):
            t = self.times.get(e.get("line"))
            if t is not None:
                e["wall"] = t
                self.timeline.append(e)
        self.decode = doc
        self.events = {}  # name -> [wall...]
        self.truth = []  # chassis-sim's truth lines (dicts with "wall"), in file order
        tp = os.path.join(d, "truth.jsonl")
        if os.path.exists(tp):
            with open(tp) as f:
                for line in f:
                    try:
                        j = json.loads(line)
                    except ValueError:
                        continue
                    if "wall" not in j:
                        continue
                    self.truth.append(j)
                    if "event" in j:
                        self.events.setdefault(j["event"], []).append(float(j["wall"]))
        ip = os.path.join(d, "inject.log")
        if os.path.exists(ip):
            with open(ip) as f:
                for line in f:
                    p = line.split()
                    if len(p) >= 2:
                        self.events.setdefault(p[0], []).append(float(p[1]))
        self.dockd_events = []
        ep = os.path.join(d, "record", "events.jsonl")
        if os.path.exists(ep):
            with open(ep) as f:
                for line in f:
                    try:
                        self.dockd_events.append(json.loads(line))
                    except ValueError:
                        pass

    def truth_at(self, t):
        """chassis-sim's last truth line at or before wall time t (None when there is none)."""
        best = None
        for j in self.truth:
            if float(j["wall"]) > t:
                break
            best = j
        return best

    def wheels(self):
        return [e for e in self.timeline if e["name"] == "WheelCmdA"]

    def status(self):
        return [e for e in self.timeline if e["name"] == "DockStatus"]

    def feedback_times(self):
        """Wall times of chassis-sim's 20 ms wheel feedback frames."""
        return [e["wall"] for e in self.timeline if e["name"] == "WheelFbA"]

    def sim_lidar_late_times(self):
        """Wall times (ascending) at which chassis-sim logged that its simulated lidar skipped a turn or sent late."""
        return sorted(self.events.get("sim_scan_skipped", []) + self.events.get("sim_lidar_late", []))

    def event(self, name):
        """Wall time of a reference: a truth/inject event NAME; "status:C" the first DockStatus with fault C;
        "last:FRAME:REF" the last FRAME frame before REF; "first:FRAME:REF" the first FRAME frame at or after REF;
        "frame:FRAME" the first FRAME frame of the log; FRAME may carry one condition, "Power[contact=0]": only the
        frames whose signal has that value count."""
        if name.startswith("status:"):
            code = int(name.split(":", 1)[1])
            st = next((e for e in self.status() if int(e["signals"]["fault"]) == code), None)
            return st["wall"] if st else None
        if name.startswith(("last:", "first:", "frame:")):
            kind, frame, ref = (name.split(":", 2) + [""])[:3]
            want = None
            if frame.endswith("]") and "[" in frame:
                frame, cond = frame[:-1].split("[", 1)
                sig, val = cond.split("=", 1)
                want = (sig, float(val))
            frames = [e for e in self.timeline if e["name"] == frame and
                      (want is None or float(e["signals"].get(want[0], float("nan"))) == want[1])]
            if kind == "frame":
                return frames[0]["wall"] if frames else None
            t = self.event(ref)
            if t is None:
                return None
            if kind == "last":
                before = [e for e in frames if e["wall"] < t]
                return before[-1]["wall"] if before else None
            after = [e for e in frames if e["wall"] >= t]
            return after[0]["wall"] if after else None
        v = self.events.get(name)
        return v[0] if v else None


# Every limit counts one nominal 20 ms tick for the phase of dockd's loop. The tick itself may run late: a wheel-frame
# gap up to 40 ms is still an un-starved loop (starvation is a gap over 40 ms), so a limit may be missed by up to one
# more tick without the VM being called starved. That slack is added here, once, to every timing check.
TICK_SLACK_MS = 20


def nonzero(e):
    s = e["signals"]
    return bool(s.get("enable", 1)) and (s["wheel0"] != 0 or s["wheel1"] != 0)


def max_gap_ms(times, empty=0.0):
    """Longest gap (ms) between consecutive wall times (s, ascending); `empty` when there are fewer than two."""
    return max((b - a) for a, b in zip(times, times[1:])) * 1000 if len(times) > 1 else empty


def stall_ms(times, t0, t1):
    """Longest gap (ms) between consecutive wall times (s, ascending) that overlaps the window [t0, t1], the gaps
    running into and out of the window included: a window that falls inside one long gap reports that whole gap."""
    i = bisect.bisect_left(times, t0)
    j = bisect.bisect_right(times, t1)
    return max_gap_ms(times[max(i - 1, 0):j + 1])


# The margins of dockd's watchdogs over the data's own period: the lidar watchdog (lidar_stale_ms 200, measured from
# the end of the newest turn) sees a turn one 100 ms turn old at best, so a reader or a sensor more than 100 ms late
# trips it; the chassis watchdog (chassis_stale_ms 200) sees feedback 20 ms old at best.
LIDAR_WATCHDOG_MARGIN_MS = 100
CHASSIS_WATCHDOG_MARGIN_MS = 180
# chassis-sim writes sim_lidar_late / sim_scan_skipped when it runs again after a stall: in a loaded HIL run
# (obstacle row) a 240 ms stall of the VM left dockd without scans and the event was stamped 36 ms after the 185 it
# caused. A starved simulator's next loop runs within a tick or two once it is scheduled again.
SIM_LATE_LOGGED_AFTER_S = 0.3


def watchdog_onsets(r):
    """[(wall, code, excuse)] for every fault onset in the status frames from the task's start on; excuse says why a
    watchdog fault (184/185) was the test machine's and not dockd's ("" when nothing excuses it):
    - dockd's own 20 ms wheel frames stalled longer than the watchdog's margin in the 1.5 s before (the VM starved
      dockd: it could not read the data in time);
    - 184: chassis-sim's 20 ms feedback frames stalled longer than the margin (the simulated chassis starved);
    - 185: chassis-sim logged "sim_scan_skipped" (its loop fell a turn behind) or "sim_lidar_late" (a turn or its
      paced packets left late) in the 0.5 s before, or up to 0.3 s after: chassis-sim notices its lateness only when
      it runs again, so a stall of the simulator that starved dockd of scans is logged after the 185 it caused."""
    wheels = [e["wall"] for e in r.wheels()]
    feedback = r.feedback_times()
    skipped = r.sim_lidar_late_times()
    out = []
    prev = 0
    started = False
    for e in r.status():
        # From the task's start on: before the first command the lidar may not have delivered yet (185 idle).
        started = started or int(e["signals"]["state"]) != STATE["NOT_TASKING"]
        if not started:
            continue
        c = int(e["signals"]["fault"])
        if c and c != prev:
            t = e["wall"]
            stall = stall_ms(wheels, t - 1.5, t)
            fb = stall_ms(feedback, t - 1.5, t)
            why = ""
            if c == 185 and stall > LIDAR_WATCHDOG_MARGIN_MS or c == 184 and stall > CHASSIS_WATCHDOG_MARGIN_MS:
                why = f"stall {stall:.0f} ms"
            elif c == 184 and fb > CHASSIS_WATCHDOG_MARGIN_MS:
                why = f"simulated chassis silent {fb:.0f} ms"
            elif c == 185 and any(t - 0.5 <= k <= t + SIM_LATE_LOGGED_AFTER_S for k in skipped):
                why = "simulated lidar skipped a turn or sent late"
            out.append((t, c, why))
        prev = c
    return out


def dockd_wall_offset(r):
    """Seconds to add to dockd's event clock (t_us / 1e6, monotonic) to get wall time: the first DockStatus frame
    with state GET_TASKING_CMD against dockd's state event into it (both in the same tick; None when absent)."""
    ev = next((e for e in r.dockd_events if e.get("event") == "state" and e.get("to") == "GET_TASKING_CMD"), None)
    st = next((e for e in r.status() if int(e["signals"]["state"]) == STATE["GET_TASKING_CMD"]), None)
    if ev is None or st is None:
        return None
    return st["wall"] - ev["t_us"] / 1e6


def explain_onsets(r):
    """One line per unexcused watchdog fault onset (watchdog_onsets): when it came, the stalls around it and what
    dockd's watchdog event said — so a check that failed on a machine that keeps no row logs still says why."""
    wheels = [e["wall"] for e in r.wheels()]
    feedback = r.feedback_times()
    late = r.sim_lidar_late_times()
    status = r.status()
    dock = r.event("dock")
    off = dockd_wall_offset(r)
    lines = []
    for t, c, why in watchdog_onsets(r):
        if why:
            continue
        state = next((int(e["signals"]["state"]) for e in reversed(status) if e["wall"] <= t), -1)
        parts = [f"fault {c} at {t - dock:+.3f} s from the dock command" if dock is not None else f"fault {c}",
                 f"state {STATE_NAME.get(state, '?')}",
                 f"dockd wheel stall {stall_ms(wheels, t - 1.5, t):.0f} ms",
                 f"chassis feedback stall {stall_ms(feedback, t - 1.5, t):.0f} ms"]
        before = [k for k in late if k <= t]
        parts.append(f"last simulated-lidar late/skip {t - before[-1]:.2f} s before" if before
                     else "no simulated-lidar late/skip before")
        if off is not None:
            which = "lidar" if c == 185 else "chassis"
            wd = [e for e in r.dockd_events if e.get("event") == "watchdog" and e.get("which") == which
                  and e.get("stale") is True and abs(e["t_us"] / 1e6 + off - t) < 0.1]
            said = [f"{k} {v}" for k, v in (wd[0].items() if wd else [])
                    if k not in ("t_us", "event", "which", "stale", "fault")]
            if said:
                parts.append("dockd: " + ", ".join(said))
        lines.append("; ".join(parts))
    return lines


# A docking attempt that ends in RETRY because the controller gave up (pressed without contact) after dockd's loop
# stalled: the robot drove blind on its last command (up to the chassis' 500 ms command timeout) and lined up short.
# In dock-sim (host_stall events every second through the approach, 400 starts, [robot.motor] command_timeout_s 0.5)
# stalls up to 300 ms never made a retry; 0.5 s stalls did in 7 of 400 runs (docs/reliability.md).
RETRY_STALL_MS = 300


def retry_onsets(r):
    """[(wall, what, excuse)] for every attempt that ended in RETRY (DockStatus state 6); `what` = dockd's reason and
    phase (its state event) and the true pads then; excuse says why the retry was the test machine's ("" when
    nothing excuses it): the attempt ended in ALIGN with align_failed, the true contacts were open (dockd did not miss
    a contact), and dockd's own 20 ms wheel frames stalled longer than RETRY_STALL_MS during that attempt. The attempt
    runs from its approach (REACH_TASKING_POINT, or ALIGN when it starts there): a stall on the approach leaves the
    robot off the line that ALIGN then cannot correct within its bounds."""
    wheels = [e["wall"] for e in r.wheels()]
    reasons = [e for e in r.dockd_events if e.get("event") == "state" and e.get("to") == "RETRY"]
    out = []
    prev = None
    attempt_t0 = None
    n = 0
    for e in r.status():
        s = int(e["signals"]["state"])
        if s == prev:
            continue
        if s in (STATE["REACH_TASKING_POINT"], STATE["ALIGN"]) and attempt_t0 is None:
            attempt_t0 = e["wall"]
        if s == STATE["RETRY"]:
            t = e["wall"]
            ev = reasons[n] if n < len(reasons) else {}
            n += 1
            reason = ev.get("reason", "?")
            tr = r.truth_at(t)
            pads = "pads unknown"
            if tr is not None:
                pads = (f"pads {float(tr['pad_lateral_m']) * 1000:+.0f} mm, "
                        f"{float(tr['pad_yaw_rad']) * 57.29578:+.1f} deg, contact {tr['contact']}")
            stall = stall_ms(wheels, attempt_t0, t) if attempt_t0 is not None else 0.0
            what = f"{reason} in {ev.get('phase', '?')}, {pads}, longest stall {stall:.0f} ms"
            attempt_t0 = None
            why = ""
            if (prev == STATE["ALIGN"] and reason == "align_failed" and tr is not None and not tr["contact"]
                    and stall > RETRY_STALL_MS):
                why = f"dockd stalled {stall:.0f} ms in the attempt"
            out.append((t, what, why))
        prev = s
    return out


def tick_gap(wheels, t0, t1):
    """Longest gap (ms) between dockd's consecutive wheel frames from the last one before t0 to t1: dockd sends one
    every 20 ms tick, so a longer gap is its loop (or the VM) not running."""
    before = [e["wall"] for e in wheels if e["wall"] < t0]
    return max_gap_ms(before[-1:] + [e["wall"] for e in wheels if t0 <= e["wall"] <= t1])


def judge_row(argv):
    import argparse
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--row", required=True)
    ap.add_argument("--fault", required=True)
    ap.add_argument("--limit-ms", type=float)
    ap.add_argument("--code", type=int)
    ap.add_argument("--status-limit-ms", type=float)
    # Ticks of dockd's loop inside the status limit, each counted at the window's longest tick (>= 20 ms).
    ap.add_argument("--status-limit-ticks", type=int, default=0)
    # The status limit runs from this reference instead of the fault time (e.g. the frame that reported the fault).
    ap.add_argument("--status-from")
    ap.add_argument("--state", type=int, help="the fault status frame must also carry this TaskState (8 = FAULT)")
    ap.add_argument("--clear")
    ap.add_argument("--hold-end")
    ap.add_argument("--recover", default="none", choices=["resume", "moving", "charging", "none"])
    ap.add_argument("--no-moving-check", action="store_true")
    # The fault comes and goes by itself (5 % corruption: some scans still pass): judge the hold by the status frames
    # only (no_motion_while_status_faulted), not by the window reaction..clear.
    ap.add_argument("--hold-by-status", action="store_true")
    ap.add_argument("--log", help="candump-format log to judge, relative to the row (default candump.log)")
    # Push rows: a stall of dockd's own loop longer than this around the fault (1 s either side) means the VM, not the
    # product, decided the row: every failing check is reported STARVED (docs/reliability.md, push rows).
    ap.add_argument("--starved-if-stall-ms", type=float)
    a = ap.parse_args(argv)
    r = Row(a.dir, a.log)
    name = a.row
    fails = 0
    row_stall = None
    if a.starved_if_stall_ms is not None:
        t0 = r.event(a.fault)
        if t0 is not None:
            g = max_gap_ms([e["wall"] for e in r.wheels() if t0 - 1.0 <= e["wall"] <= t0 + 1.0], 2000.0)
            if g > a.starved_if_stall_ms:
                row_stall = g

    def check(what, ok, why="", starved=False):
        nonlocal fails
        if row_stall is not None:
            starved = True
            why = (why + "; " if why else "") + (f"dockd's wheel frames stalled {row_stall:.0f} ms around the fault "
                                                  f"(> {a.starved_if_stall_ms:g} ms): VM starvation")
        # A timing check whose window shows dockd's own 20 ms wheel frames stalled (the TCG VM or the loop not
        # running) cannot judge dockd's reaction: it is reported as STARVED (counted, never silent) instead of
        # failing, unless HIL_STRICT_TIMING=1. Functional checks (codes, holds, recoveries) always count.
        if not ok and starved and os.environ.get("HIL_STRICT_TIMING") != "1":
            print(f"STARVED {name}_{what}  ({why})")
            return
        print(("PASS" if ok else "FAIL") + f" {name}_{what}" + (f"  ({why})" if why and not ok else ""))
        if not ok:
            fails += 1

    def figure(what, v):
        print(f"FIGURE {name}_{what} {v}")

    t_f = r.event(a.fault)
    if t_f is None:
        check("fault_injected", False, f"no event {a.fault} in truth/inject logs")
        return fails
    wheels = r.wheels()
    before = [e for e in wheels if e["wall"] < t_f]
    if not a.no_moving_check:
        # A watchdog hold caused by dockd's own loop stalling just before the fault (the VM starved) can leave the
        # robot standing at the fault time: that row cannot show a reaction, reported as STARVED.
        pre_stall = stall_ms([e["wall"] for e in wheels], t_f - 0.5, t_f)
        check("moving_at_fault", bool(before) and nonzero(before[-1]),
              "the last wheel command before the fault was zero: nothing to stop" +
              (f"; dockd's wheel frames stalled {pre_stall:.0f} ms in the 0.5 s before: VM starvation"
               if pre_stall > 100 else ""), starved=pre_stall > 100)
    first_zero = next((e for e in wheels if e["wall"] >= t_f and not nonzero(e)), None)
    t_c0 = r.event(a.clear) if a.clear else None
    t_end0 = t_c0 if t_c0 is not None else (r.event(a.hold_end) if a.hold_end else float("inf"))
    if a.hold_by_status:
        zero = first_zero
    else:
        # The reaction is the stop that lasts: the start of the run of zero frames that reaches the end of the hold
        # (a loaded VM adds short watchdog holds before it; they are not the reaction to this fault).
        zero = None
        for e in wheels:
            if e["wall"] < t_f:
                continue
            if e["wall"] >= t_end0:
                break
            if nonzero(e):
                zero = None
            elif zero is None:
                zero = e
    if first_zero is not None:
        figure("first_zero_ms", f"{(first_zero['wall'] - t_f) * 1000:.1f}")
    t_z = zero["wall"] if zero else None
    if t_z is None:
        check("reaction", False, "no lasting stop after the fault (non-zero wheel commands until the fault cleared)")
        figure("reaction_ms", "none")
    else:
        ms = (t_z - t_f) * 1000
        figure("reaction_ms", f"{ms:.1f}")
        # dockd sends a wheel frame every 20 ms tick: a longer gap inside the reaction window is the loop (or the
        # VM) not running — starvation, reported with the verdict so it is not mistaken for a slow watchdog.
        stall = tick_gap(wheels, t_f, t_z)
        figure("tick_gap_in_reaction_ms", f"{stall:.1f}")
        if a.limit_ms is not None:
            why = f"{ms:.1f} ms > {a.limit_ms:g} ms + {TICK_SLACK_MS} ms tick slack"
            if stall > 40:
                why += f"; dockd's wheel frames stalled {stall:.0f} ms inside the window: VM starvation"
            check("reaction", ms <= a.limit_ms + TICK_SLACK_MS, why, starved=stall > 40)
    # The longest gap between dockd's wheel commands around the fault: a starved VM shows here (nominal 20 ms).
    gap = max_gap_ms([e["wall"] for e in wheels if t_f - 1.0 <= e["wall"] <= t_f + 1.0], float("nan"))
    figure("wheel_gap_near_fault_ms", f"{gap:.1f}")
    t_c = r.event(a.clear) if a.clear else None
    if a.clear and t_c is None:
        check("fault_cleared", False, f"no event {a.clear}")
    if a.code is not None:
        st = next((e for e in r.status() if e["wall"] >= t_f and int(e["signals"]["fault"]) == a.code and
                   (a.state is None or int(e["signals"]["state"]) == a.state)), None)
        # A watchdog fault that the VM's starvation explains (watchdog_onsets) can take the task to FAULT first and
        # so decide which code the status shows: then the missing code is STARVED, reported with that cause.
        wd = [f"{c}({why})" for t, c, why in watchdog_onsets(r) if why and t >= t_f - 0.5 and c != a.code]
        check(f"fault_code_{a.code}", st is not None,
              "status faults after the fault time: " +
              " ".join(sorted({str(int(e["signals"]["fault"])) for e in r.status() if e["wall"] >= t_f})) +
              (f"; watchdog faults {' '.join(wd)} came first: VM starvation" if wd else ""), starved=bool(wd))
        if st is not None:
            ms = (st["wall"] - t_f) * 1000
            figure("status_ms", f"{ms:.1f}")
            # The limit may run from a later reference: the frame that told dockd of the fault.
            t_s0 = r.event(a.status_from) if a.status_from else t_f
            if a.status_from:
                if t_s0 is None or t_s0 > st["wall"]:
                    check("status_reference", False, f"no {a.status_from} before the status frame")
                    t_s0 = t_f
                else:
                    figure("status_reference_ms", f"{(t_s0 - t_f) * 1000:.1f}")
                    ms = (st["wall"] - t_s0) * 1000
                    figure("status_after_reference_ms", f"{ms:.1f}")
            if a.status_limit_ms is not None:
                stall = tick_gap(wheels, t_s0, st["wall"])
                # Waits for a tick are counted at the longest tick the window had (at least the nominal 20 ms): a
                # loop that ran late but within the starvation bound still met its contract.
                limit = a.status_limit_ms + a.status_limit_ticks * max(20.0, stall)
                why = f"{ms:.1f} ms > {limit:g} ms + {TICK_SLACK_MS} ms tick slack"
                if stall > 40:
                    why += f"; dockd's wheel frames stalled {stall:.0f} ms inside the window: VM starvation"
                check("status_in_time", ms <= limit + TICK_SLACK_MS, why, starved=stall > 40)
    t_hold_end = t_c if t_c is not None else (r.event(a.hold_end) if a.hold_end else None)
    if t_hold_end is None:
        t_hold_end = float("inf")
    if t_z is not None and not a.hold_by_status:
        bad = [e for e in wheels if t_z <= e["wall"] < t_hold_end and nonzero(e)]
        check("no_motion_while_fault", not bad,
              f"{len(bad)} non-zero wheel commands, first at +{(bad[0]['wall'] - t_f) * 1000:.0f} ms" if bad else "")
    # The status and the wheels must agree: a non-zero wheel command is never sent while the last DockStatus frame
    # (sent on every change) carried a fault, the latched task fault or the watchdog condition. dockd sends the
    # tick's wheel frame before its status frame, so a status clearing the fault before the next wheel frame belongs
    # to the same tick and excuses it.
    st = r.status()
    bad = []
    j = 0
    for i, e in enumerate(wheels):
        if not nonzero(e):
            continue
        while j + 1 < len(st) and st[j + 1]["wall"] <= e["wall"]:
            j += 1
        if st and st[j]["wall"] <= e["wall"] and int(st[j]["signals"]["fault"]) != 0:
            nxt = st[j + 1] if j + 1 < len(st) else None
            next_wheel = wheels[i + 1]["wall"] if i + 1 < len(wheels) else float("inf")
            if not (nxt and int(nxt["signals"]["fault"]) == 0 and nxt["wall"] < next_wheel):
                bad.append(e)
    check("no_motion_while_status_faulted", not bad,
          f"{len(bad)} non-zero wheel commands while the status showed a fault, first at "
          f"{(bad[0]['wall'] - t_f) * 1000:+.0f} ms" if bad else "")
    if a.recover != "none" and t_c is None and a.recover != "charging":
        check("recovered", False, "no clear time")
    elif a.recover == "resume":
        # dockd holds the wheels at once but faults the task only when the data stays away for [watchdog]
        # fault_after_ms (1 s): a shorter outage just continues; a task fault (FAULT in the status) must be
        # followed by dockd's resume (0.5 s of fresh data). Either way the robot moves again after the clear.
        faulted = any(e["wall"] >= t_f and int(e["signals"]["state"]) == STATE["FAULT"] for e in r.status())
        resumed = any(e.get("event") == "resume" for e in r.dockd_events)
        moved = next((e for e in wheels if e["wall"] >= t_c and nonzero(e)), None)
        check("recovered", (resumed or not faulted) and moved is not None,
              f"task fault {'yes' if faulted else 'no'}, resume event {'yes' if resumed else 'no'}, "
              f"motion after clear {'yes' if moved else 'no'}")
        if moved:
            figure("recovery_s", f"{moved['wall'] - t_c:.2f}")
    elif a.recover == "moving":
        moved = next((e for e in wheels if e["wall"] >= t_c and nonzero(e)), None)
        check("recovered", moved is not None, "no motion after the fault cleared")
        if moved:
            figure("recovery_s", f"{moved['wall'] - t_c:.2f}")
    elif a.recover == "charging":
        t0 = t_c if t_c is not None else t_f
        ch = next((e for e in r.status() if e["wall"] >= t0 and int(e["signals"]["state"]) == STATE["FINISH_TASKING"]), None)
        check("recovered_to_charging", ch is not None, "FINISH_TASKING never reported after the fault")
    elif t_z is not None and t_c is None and not a.hold_end:
        pass  # hold checked to the end of the log above
    return fails


def print_split(items):
    """Prints "UNEXCUSED;EXCUSED" from (unexcused text, excused text, excuse) triples: the excused text when there
    is an excuse."""
    unexcused, excused = [], []
    for plain, with_excuse, why in items:
        (excused if why else unexcused).append(with_excuse if why else plain)
    print(" ".join(unexcused) + ";" + " ".join(excused))


def main(argv):
    if len(argv) < 2:
        print(__doc__)
        return 2
    cmd = argv[1]
    if cmd == "row":
        return judge_row(argv[2:])
    if cmd == "frame":
        ident = int(argv[2], 16)
        data = bytes.fromhex(argv[3])[:7]
        crc = crc8_h2f([ident & 0xFF, (ident >> 8) & 0x07] + list(data))
        print(f"{ident:03X}#{data.hex().upper()}{crc:02X}")
        return 0
    if cmd == "last-counter":
        ident = argv[3].upper().lstrip("0") or "0"
        last = None
        with open(argv[2], errors="replace") as f:
            for line in f:
                p = line.split()
                if len(p) == 3 and "#" in p[2]:
                    i, d = p[2].split("#", 1)
                    if (i.lstrip("0") or "0") == ident and len(d) >= 14:
                        last = int(d[12:14], 16) & 0x0F
        print("" if last is None else last)
        return 0 if last is not None else 1
    if cmd == "json-field":
        try:
            with open(argv[2]) as f:
                v = json.loads(f.readline()).get(argv[3], "")
        except (OSError, ValueError):
            v = ""
        print(str(v).lower() if isinstance(v, bool) else v)
        return 0
    if cmd == "frame-stall":
        # Longest gap (ms) of FRAME overlapping [T0, T1] (stall_ms): e.g. chassis-sim's 20 ms WheelFbA.
        r = Row(argv[2])
        ts = [e["wall"] for e in r.timeline if e["name"] == argv[3]]
        print(f"{stall_ms(ts, float(argv[4]), float(argv[5])):.1f}")
        return 0
    if cmd == "wheel-gaps":
        r = Row(argv[2])
        t0, t1 = float(argv[3]), float(argv[4])
        ts = [e["wall"] for e in r.wheels() if t0 <= e["wall"] <= t1]
        print(f"{max_gap_ms(ts, float('nan')):.1f} {len(ts)}")
        return 0
    if cmd in ("summary", "table"):
        # Per row of one or more case results dirs: verdict, failed checks and every FIGURE (for docs/reliability.md).
        rows = {}
        for d in argv[2:]:
            for name in ("job.log", "post.log"):
                p = os.path.join(d, name)
                if not os.path.exists(p):
                    continue
                with open(p, errors="replace") as f:
                    for line in f:
                        parts = line.split()
                        if len(parts) < 2 or parts[0] not in ("PASS", "FAIL", "STARVED", "FIGURE"):
                            continue
                        row = next((r for r in ROW_NAMES if parts[1].startswith(r + "_")), parts[1].split("_")[0])
                        e = rows.setdefault(row, {"fail": [], "pass": 0, "fig": {}, "starved": []})
                        if parts[0] == "STARVED":
                            e["starved"].append(parts[1][len(row) + 1:])
                        elif parts[0] == "FAIL":
                            e["fail"].append(parts[1][len(row) + 1:])
                        elif parts[0] == "PASS":
                            e["pass"] += 1
                        else:
                            e["fig"][parts[1][len(row) + 1:]] = parts[2] if len(parts) > 2 else ""
        if cmd == "table":
            # Markdown rows for docs/reliability.md's measured table, in ROW_NAMES order.
            print("| row | reaction (candump) | fault status | recovery | worst tick | other figures | verdict |")
            print("|---|---|---|---|---|---|---|")
            for row in ROW_NAMES:
                e = rows.get(row)
                if e is None:
                    continue
                f = dict(e["fig"])
                react = f.pop("reaction_ms", "—")
                if react not in ("—", "n/a", "none"):
                    react += " ms"
                gap = f.pop("tick_gap_in_reaction_ms", None)
                if gap is not None and react.endswith(" ms"):
                    react += f" (tick gap {float(gap):.0f} ms)"
                status = f.pop("status_ms", None)
                rec = f.pop("recovery_s", None)
                worst = f.pop("worst_tick_ms", None)
                for k in ("first_zero_ms", "wheel_gap_near_fault_ms", "tick_overruns"):
                    f.pop(k, None)
                other = ", ".join(f"{k} {v}" for k, v in f.items())
                verdict = ("FAIL " + ",".join(e["fail"])) if e["fail"] else "PASS"
                if e["starved"]:
                    verdict += " (STARVED: " + ",".join(e["starved"]) + ")"
                print(f"| `{row}` | {react} | {status + ' ms' if status else '—'} | {rec + ' s' if rec else '—'} | "
                      f"{worst + ' ms' if worst else '—'} | {other or '—'} | {verdict} |")
            return 0
        for row, e in rows.items():
            figs = " ".join(f"{k}={v}" for k, v in e["fig"].items())
            starved = f" starved: {','.join(e['starved'])}" if e["starved"] else ""
            print(f"{row}: {'FAIL ' + ','.join(e['fail']) if e['fail'] else 'PASS'} ({e['pass']} pass){starved} {figs}")
        return 0
    if cmd == "delta":
        r = Row(argv[2])
        t1 = r.event(argv[3])
        later = [t for t in r.events.get(argv[4], []) if t1 is not None and t >= t1]
        if not later and t1 is not None and argv[4].startswith(("first:", "last:", "status:", "frame:")):
            t2 = r.event(argv[4])
            later = [t2] if t2 is not None else []
        print(f"{(later[0] - t1) * 1000:.1f}" if later else "none")
        return 0 if later else 1
    if cmd == "reopen-limit":
        # can_down_up: dockd's socket fails on its first write after the link went down (<= one tick after the
        # last frame that got out) and is reopened by service() after 100 ms, then 300, 700, 1500 ms ... (delays
        # double to a 2 s cap; docs/can.md). The first frame after the link is up comes at the first retry at or
        # after UP, plus one tick. Prints "limit_ms reaction_ms" relative to UP.
        r = Row(argv[2])
        t_last = r.event("last:WheelCmdA:" + argv[3])
        t_up = r.event(argv[3])
        first = r.event("first:WheelCmdA:" + argv[3])
        if None in (t_last, t_up, first):
            print("none none")
            return 1
        t, delay = t_last + 0.020, 0.1
        while t + delay < t_up:
            t += delay
            delay = min(delay * 2, 2.0)
        print(f"{(t + delay + 0.020 - t_up) * 1000:.1f} {(first - t_up) * 1000:.1f}")
        return 0
    if cmd == "record-check":
        # The session record survives SIGKILL up to the last event: every line of events.jsonl (copied right after
        # the kill) is whole JSON, and its last state event is the state the last DockStatus frame before the kill
        # showed on the bus (candump) — what dockd had done, it had written.
        r = Row(argv[2])
        t_kill = r.event(argv[4])
        with open(argv[3]) as f:
            text = f.read()
        if not text.endswith("\n"):
            print("torn last line")
            return 1
        ev = [json.loads(line) for line in text.splitlines()]
        states = [e["to"] for e in ev if e.get("event") == "state"]
        st = [e for e in r.status() if e["wall"] <= t_kill]
        bus = STATE_NAME.get(int(st[-1]["signals"]["state"])) if st else None
        print(f"record {len(ev)} events, last state {states[-1] if states else None}; bus before the kill: {bus}")
        return 0 if states and bus == states[-1] else 1
    if cmd == "first-wheels":
        r = Row(argv[2])
        t = r.event(argv[3])
        e = next((e for e in r.wheels() if t is not None and e["wall"] >= t), None)
        print("none" if e is None else ("zero" if not nonzero(e) else "moving"))
        return 0
    if cmd == "faults-split":
        # "UNEXCUSED;EXCUSED": fault codes of the status frames, split by cause (watchdog_onsets): a watchdog fault
        # that the test machine's starvation explains is listed as excused, with that cause.
        print_split((str(c), f"{c}({why})", why) for _, c, why in watchdog_onsets(Row(argv[2])))
        return 0
    if cmd == "faults-explain":
        for line in explain_onsets(Row(argv[2])):
            print(line)
        return 0
    if cmd == "retries-split":
        # "UNEXCUSED;EXCUSED": the attempts that ended in RETRY, split by cause (retry_onsets), each with its reason.
        print_split((f"({what})", f"({what}; {why})", why) for _, what, why in retry_onsets(Row(argv[2])))
        return 0
    if cmd == "last-signal":
        r = Row(argv[2])
        fr = [e for e in r.timeline if e["name"] == argv[3]]
        print(f'{fr[-1]["signals"][argv[4]]:g}' if fr else "none")
        return 0 if fr else 1
    if cmd == "nonzero-count":
        r = Row(argv[2])
        t0 = float(argv[3]) if len(argv) > 3 else 0.0
        t1 = float(argv[4]) if len(argv) > 4 else float("inf")
        print(sum(1 for e in r.wheels() if t0 <= e["wall"] < t1 and nonzero(e)))
        return 0
    if cmd == "states":
        r = Row(argv[2])
        seq = []
        for e in r.status():
            s = int(e["signals"]["state"])
            if not seq or seq[-1] != s:
                seq.append(s)
        print(" ".join(map(str, seq)))
        return 0
    print(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
