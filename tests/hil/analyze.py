#!/usr/bin/env python3
"""HIL log analysis (standard library only): reads dock-decode --json output and chassis-sim's truth log.

  analyze.py states DECODE.json             -> the DockStatus state sequence, deduplicated, e.g. "0 1 2 3 5 4"
  analyze.py last-wheels DECODE.json        -> "0 0" when the last wheel command commands zero: WheelCmdA (enable or
                                               not), or AgileX's MotionCommand (linear, angular)
  analyze.py nonzero-wheels DECODE.json T0 T1 -> count of non-zero WheelCmdA frames with T0 <= t < T1 (log time)
  analyze.py first-zero-after DECODE.json T -> log time of the first zero WheelCmdA at or after T
  analyze.py final-error TRUTH.jsonl        -> "contact lateral_mm yaw_deg" at the last truth line with contact
  analyze.py faults DECODE.json             -> distinct non-zero DockStatus fault codes in order
  analyze.py contact-errors TRUTH.jsonl     -> one "episode lateral_mm yaw_deg" line per contact episode (contacts
                                               closed, then opened or the log ended), at its last line with contact
"""
import json
import math
import sys


def frames(path, name):
    with open(path) as f:
        doc = json.load(f)
    return [e for e in doc.get("timeline", []) if e.get("name") == name]


def main(argv):
    cmd = argv[1]
    if cmd == "states":
        seq = []
        for e in frames(argv[2], "DockStatus"):
            s = int(e["signals"]["state"])
            if not seq or seq[-1] != s:
                seq.append(s)
        print(" ".join(map(str, seq)))
    elif cmd == "faults":
        seq = []
        for e in frames(argv[2], "DockStatus"):
            c = int(e["signals"]["fault"])
            if c and (not seq or seq[-1] != c):
                seq.append(c)
        print(" ".join(map(str, seq)))
    elif cmd == "last-wheels":
        w = frames(argv[2], "WheelCmdA")
        keys = ("wheel0", "wheel1")
        if not w:
            w = frames(argv[2], "MotionCommand")
            keys = ("linear", "angular")
        if not w:
            print("none")
            return 1
        s = w[-1]["signals"]
        print(f'{s[keys[0]]:g} {s[keys[1]]:g}')
    elif cmd == "nonzero-wheels":
        t0, t1 = float(argv[3]), float(argv[4])
        n = 0
        for e in frames(argv[2], "WheelCmdA"):
            s = e["signals"]
            if t0 <= e["t_s"] < t1 and s.get("enable", 1) and (s["wheel0"] != 0 or s["wheel1"] != 0):
                n += 1
        print(n)
    elif cmd == "first-zero-after":
        t = float(argv[3])
        for e in frames(argv[2], "WheelCmdA"):
            s = e["signals"]
            if e["t_s"] >= t and (not s.get("enable", 1) or (s["wheel0"] == 0 and s["wheel1"] == 0)):
                print(f'{e["t_s"]:.4f}')
                return 0
        print("none")
        return 1
    elif cmd == "final-error":
        last = None
        with open(argv[2]) as f:
            for line in f:
                try:
                    d = json.loads(line)
                except ValueError:
                    continue
                if d.get("contact"):
                    last = d
        if last is None:
            print("no-contact")
            return 1
        print(f'1 {last["pad_lateral_m"] * 1000:.1f} {math.degrees(last["pad_yaw_rad"]):.2f}')
    elif cmd == "contact-errors":
        episodes, last = [], None
        with open(argv[2]) as f:
            for line in f:
                try:
                    d = json.loads(line)
                except ValueError:
                    continue
                if d.get("contact"):
                    last = d
                elif last is not None:
                    episodes.append(last)
                    last = None
        if last is not None:
            episodes.append(last)
        for i, e in enumerate(episodes, 1):
            print(f'{i} {e["pad_lateral_m"] * 1000:.1f} {math.degrees(e["pad_yaw_rad"]):.2f}')
    else:
        print(__doc__)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
