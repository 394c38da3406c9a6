#!/usr/bin/python3
"""Writes the hand-made lidar captures in this directory (an implementation of the byte layouts independent of the
C++ encoders, so the parsers are checked against something they did not produce). Run from anywhere:
    /usr/bin/python3 tests/data/lidar/make_captures.py
Every capture uses the same synthetic turn: point j of a turn (sensor order) has distance 1000 + 10 * (j % 50) mm,
no return when j % 37 == 0, intensity j % 200. Expected parser results are asserted in tests/unit/test_lidar_*.cpp
and tests/cli/lidar_dump_capture.cmake; the comments below say how they follow from the bytes."""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def dist_mm(j):
    return 0 if j % 37 == 0 else 1000 + 10 * (j % 50)


def crc8(data):
    crc = 0
    for b in data:
        crc ^= b
        for _ in range(8):
            crc = ((crc << 1) ^ 0x4D) & 0xFF if crc & 0x80 else (crc << 1) & 0xFF
    return crc


assert crc8(b"123456789") == 0xC3


def ld06_packet(first_j, per_turn=450, speed=3600, ts=0):
    step = 36000 // per_turn
    body = struct.pack("<BBHH", 0x54, 0x2C, speed, (first_j * step) % 36000)
    for i in range(12):
        j = first_j + i
        body += struct.pack("<HB", dist_mm(j % per_turn), (j % per_turn) % 200)
    body += struct.pack("<HH", ((first_j + 11) * step) % 36000, ts % 30000)
    return body + bytes([crc8(body)])


def write_ld06():
    # 3 junk bytes (no 0x54: dropped, no resync since the parser was never in sync), a health packet, an info packet,
    # then 113 packets = 1356 points = 3 turns + 6 points. Packet 50 gets one flipped bit (CRC error; it holds no other
    # 0x54 so exactly its 47 bytes are dropped), packet 80 is cut after 20 bytes (CRC error when the candidate is
    # complete, then its 20 bytes are dropped and packet 81 is found by the rescan).
    # Expected: scans 3, crc_errors 2, resyncs 2, dropped_bytes 3 + 47 + 20 = 70, packets 111, health 1, info 1.
    out = bytearray(b"\x00\x11\x22")
    health = bytes([0x54, 0xE0, 0x00])
    out += health + bytes([crc8(health)])
    info = bytes([0x54, 0x0F]) + struct.pack("<HHIIII", 3600, 1, 0x12345678, 0x9ABCDEF0, 0x100, 0x203)
    out += info + bytes([crc8(info)])
    for p in range(113):
        pkt = bytearray(ld06_packet(12 * p, ts=p * 3))
        if p == 50:
            assert 0x54 not in pkt[1:], "pick another packet to corrupt"
            pkt[10] ^= 0x04
            assert 0x54 not in pkt[1:]
        if p == 80:
            assert 0x54 not in pkt[1:20]
            pkt = pkt[:20]
        out += pkt
    with open(os.path.join(HERE, "ld06_capture.bin"), "wb") as f:
        f.write(out)


def rp_node(j, per_turn=360):
    q6 = round(j * 360 * 64 / per_turn)
    s = 1 if j == 0 else 0
    b0 = ((j % 64) << 2) | (0x01 if s else 0x02)
    return struct.pack("<BHH", b0, (q6 << 1) | 1, dist_mm(j) * 4)


def write_rplidar():
    # 3 zero bytes (dropped, never in sync), a health response (status 0, error 0), the scan descriptor, then
    # 830 nodes = 2 turns + 110 nodes; 4 zero bytes (S = !S = 0: never a node) after node 500.
    # Expected: scans 2, resyncs 1, dropped_bytes 7, packets (nodes) 830, descriptors 1, health 1.
    out = bytearray(b"\x00\x00\x00")
    out += bytes([0xA5, 0x5A, 0x03, 0x00, 0x00, 0x00, 0x06, 0x00, 0x00, 0x00])
    out += bytes([0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81])
    for n in range(830):
        out += rp_node(n % 360)
        if n == 500:
            out += b"\x00\x00\x00\x00"
    with open(os.path.join(HERE, "rplidar_capture.bin"), "wb") as f:
        f.write(out)


def lakibeam_datagram(first_j, per_turn=1440, ts=0):
    step = 36000 // per_turn
    d = bytearray()
    for b in range(12):
        j0 = first_j + 16 * b
        d += struct.pack("<BBH", 0xFF, 0xEE, (j0 * step) % 36000)
        for k in range(16):
            j = (j0 + k) % per_turn
            d += struct.pack("<HBHB", dist_mm(j), j % 200, dist_mm(j), j % 200)
    d += struct.pack("<I", ts) + bytes([0x40, 0x37])
    assert len(d) == 1206
    return d


def write_lakibeam():
    # 20 datagrams of 192 points = 3840 points = 2 turns + 960 points (1440 per turn); datagram 9's third block
    # marker is broken (FF EF): rejected whole. The file is read in 1206-byte datagrams.
    # Expected: scans 2, bad_packets 1, packets 19, dropped_bytes 1206.
    out = bytearray()
    for g in range(20):
        d = lakibeam_datagram(192 * g, ts=g * 1000)
        if g == 9:
            d[200 + 1] = 0xEF
        out += d
    with open(os.path.join(HERE, "lakibeam_capture.bin"), "wb") as f:
        f.write(out)


write_ld06()
write_rplidar()
write_lakibeam()
