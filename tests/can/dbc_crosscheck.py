#!/usr/bin/python3
"""Cross-checks core's CAN encoders against the DBC files with python3-canmatrix (an independent DBC decoder).

Reads the JSON lines of can_vectors (id, data bytes, physical signal values), decodes each frame's bytes from the
DBC with canmatrix and compares every signal; for dockcore v1 frames it also recomputes the documented checksum
(CRC-8 poly 0x2F, init 0xFF, xorout 0xFF over id low, id high, bytes 0..6) and the counter position here, in Python,
from docs/can.md's definition. Also fails when the DBC has a signal the vectors do not cover, or the reverse.

usage: dbc_crosscheck.py VECTORS_PROGRAM DBC_DIR [--mutate MSG.SIGNAL]
--mutate doubles that signal's factor in a temporary copy of its DBC: the check must then fail (ctest WILL_FAIL).
"""
import json
import os
import subprocess
import sys
import tempfile

import canmatrix.formats


def crc8_h2f(data):
    crc = 0xFF
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = ((crc << 1) ^ 0x2F) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc ^ 0xFF


def load(path):
    dbs = canmatrix.formats.loadp(path)
    return dbs[next(iter(dbs))]


def mutate(path, target, outdir):
    msg, sig = target.split(".")
    lines = open(path).read().split("\n")
    current = None
    done = False
    for i, line in enumerate(lines):
        s = line.strip()
        if s.startswith("BO_ "):
            current = s.split()[2].rstrip(":")
        elif s.startswith("SG_ ") and current == msg and s.split()[1] == sig:
            a = line.index("(")
            b = line.index(",", a)
            factor = float(line[a + 1:b])
            lines[i] = line[:a + 1] + repr(factor * 2) + line[b:]
            done = True
    if not done:
        sys.exit("mutate: no signal %s" % target)
    out = os.path.join(outdir, os.path.basename(path))
    open(out, "w").write("\n".join(lines))
    return out


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    prog, dbc_dir = sys.argv[1], sys.argv[2]
    target = sys.argv[4] if len(sys.argv) >= 5 and sys.argv[3] == "--mutate" else None
    tmp = tempfile.mkdtemp(prefix="dbc_crosscheck_")
    paths = {n: os.path.join(dbc_dir, n + ".dbc") for n in ("dockcore", "agilex_v2")}
    if target:
        for n in paths:
            text = open(paths[n]).read()
            if (" " + target.split(".")[0] + ":") in text:
                paths[n] = mutate(paths[n], target, tmp)
    dbs = {n: load(p) for n, p in paths.items()}
    out = subprocess.run([prog], check=True, capture_output=True, text=True).stdout
    failures, frames, signals = 0, 0, 0
    covered = {n: set() for n in dbs}
    for line in out.splitlines():
        v = json.loads(line)
        db = dbs[v["dbc"]]
        data = bytes.fromhex(v["data"])
        msg = db.frame_by_id(canmatrix.ArbitrationId(v["id"]))
        if msg is None:
            print("FAIL id 0x%X not in %s.dbc" % (v["id"], v["dbc"]))
            failures += 1
            continue
        if msg.size != len(data):
            print("FAIL %s: DBC length %d, encoder %d" % (msg.name, msg.size, len(data)))
            failures += 1
        decoded = msg.decode(data)
        frames += 1
        names = {s.name for s in msg.signals}
        if names != set(v["signals"]):
            print("FAIL %s: DBC signals %s, vectors %s" % (msg.name, sorted(names), sorted(v["signals"])))
            failures += 1
        for name, want in v["signals"].items():
            covered[v["dbc"]].add((msg.name, name))
            if name not in decoded:
                continue
            got = float(decoded[name].phys_value)
            signals += 1
            if abs(got - want) > 1e-6 * max(1.0, abs(want)):
                print("FAIL %s.%s bytes %s: DBC says %r, encoder %r" % (msg.name, name, v["data"], got, want))
                failures += 1
        if v["dbc"] == "dockcore":
            ident = v["id"]
            crc = crc8_h2f([ident & 0xFF, (ident >> 8) & 0x07] + list(data[:7]))
            if crc != data[7]:
                print("FAIL %s checksum: documented CRC gives 0x%02X, encoder 0x%02X" % (msg.name, crc, data[7]))
                failures += 1
            if v["signals"]["Counter"] != (data[6] & 0x0F):
                print("FAIL %s counter not in byte 6 bits 0..3" % msg.name)
                failures += 1
    for n, db in dbs.items():
        for m in db.frames:
            for s in m.signals:
                if (m.name, s.name) not in covered[n]:
                    print("FAIL %s.dbc %s.%s never exercised" % (n, m.name, s.name))
                    failures += 1
    print("dbc_crosscheck: %d frames, %d signals compared, %d failures" % (frames, signals, failures))
    return 1 if failures or frames == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
