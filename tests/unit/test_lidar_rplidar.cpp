// RPLIDAR legacy standard scan: requests, node layout and validity bits, descriptor detection, resync, health,
// the clockwise-from-the-back convention, round trip, splits at every byte, the recorded capture.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/lidar_rplidar.hpp"

#include "lidar_capture.hpp"
#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using lidar_test::capture_dist_mm;
using lidar_test::check_accounting;
using lidar_test::read_capture;
using lidar_test::replay_bytes;

namespace {

std::unique_ptr<RplidarParser> make_parser(bool require_descriptor = true) {
  auto p = std::make_unique<RplidarParser>();
  RplidarConfig c;
  c.require_descriptor = require_descriptor;
  CHECK(p->configure(c));
  return p;
}

// Descriptor + n nodes at 1 deg steps from sensor 0 deg, 360 per turn, range 500 + j mm.
std::vector<std::uint8_t> stream(int n_nodes) {
  std::vector<std::uint8_t> s(kRplidarScanDescriptor, kRplidarScanDescriptor + 7);
  for (int j = 0; j < n_nodes; ++j) {
    RplidarNode n;
    n.start = j % 360 == 0;
    n.quality = static_cast<std::uint8_t>(j % 64);
    n.angle_q6 = static_cast<std::uint16_t>((j % 360) * 64);
    n.distance_q2 = static_cast<std::uint16_t>((500 + j % 360) * 4);
    std::uint8_t b[5];
    rplidar_encode_node(n, b);
    s.insert(s.end(), b, b + 5);
  }
  return s;
}

}  // namespace

TEST_GROUP(Rplidar){};

TEST(Rplidar, RequestsAreTwoBytes) {
  std::uint8_t b[2];
  CHECK_EQUAL(2u, rplidar_encode_request(kRplidarCmdScan, b));
  CHECK_EQUAL(0xA5, b[0]);
  CHECK_EQUAL(0x20, b[1]);
  rplidar_encode_request(kRplidarCmdStop, b);
  CHECK_EQUAL(0x25, b[1]);
  rplidar_encode_request(kRplidarCmdReset, b);
  CHECK_EQUAL(0x40, b[1]);
  rplidar_encode_request(kRplidarCmdGetHealth, b);
  CHECK_EQUAL(0x52, b[1]);
  rplidar_encode_request(kRplidarCmdGetInfo, b);
  CHECK_EQUAL(0x50, b[1]);
}

TEST(Rplidar, NodeLayoutAndValidityBits) {
  RplidarNode n;
  n.start = true;
  n.quality = 47;
  n.angle_q6 = 90 * 64;
  n.distance_q2 = 1234 * 4;
  std::uint8_t b[5];
  rplidar_encode_node(n, b);
  CHECK_EQUAL((47 << 2) | 0x01, b[0]);
  CHECK_EQUAL(((90 * 64) << 1 | 1) & 0xFF, b[1]);
  CHECK_EQUAL(((90 * 64) << 1 | 1) >> 8, b[2]);
  CHECK_EQUAL((1234 * 4) & 0xFF, b[3]);
  RplidarNode d;
  CHECK(rplidar_decode_node(b, d));
  CHECK(d.start);
  CHECK_EQUAL(90 * 64, d.angle_q6);
  CHECK_EQUAL(1234 * 4, d.distance_q2);
  std::uint8_t bad[5];
  std::memcpy(bad, b, 5);
  bad[0] |= 0x03;  // S == !S
  CHECK_FALSE(rplidar_decode_node(bad, d));
  std::memcpy(bad, b, 5);
  bad[0] &= static_cast<std::uint8_t>(~0x03);
  CHECK_FALSE(rplidar_decode_node(bad, d));
  std::memcpy(bad, b, 5);
  bad[1] &= 0xFE;  // check bit
  CHECK_FALSE(rplidar_decode_node(bad, d));
  std::memcpy(bad, b, 5);
  bad[2] = 0xFF;  // angle > 360 deg
  CHECK_FALSE(rplidar_decode_node(bad, d));
}

TEST(Rplidar, NodesNeedTheDescriptorUnlessConfigured) {
  auto s = stream(800);
  std::vector<std::uint8_t> no_desc(s.begin() + 7, s.end());
  auto p = make_parser();
  p->feed(no_desc.data(), no_desc.size(), 0);
  CHECK_EQUAL(0u, p->counters().scans);
  CHECK_EQUAL(no_desc.size(), p->counters().dropped_bytes + p->buffered());
  auto q = make_parser(false);
  q->feed(no_desc.data(), no_desc.size(), 0);
  CHECK_EQUAL(2u, q->counters().scans);
  check_accounting(*p);
  check_accounting(*q);
}

TEST(Rplidar, TurnsStartAtTheSBitAndAnglesConvert) {
  auto p = make_parser();
  const auto s = stream(800);
  CHECK_EQUAL(2u, p->feed(s.data(), s.size(), 0));
  const auto& c = p->counters();
  CHECK_EQUAL(1u, c.descriptors);
  CHECK_EQUAL(800u, c.packets);
  CHECK_EQUAL(0u, c.dropped_bytes);
  LaserScan scan;
  CHECK(p->take_scan(scan));
  CHECK_EQUAL(360u, scan.count);
  // Sensor 0 deg (clockwise from the back) = core 180 deg; sensor 90 deg = core +90 deg (left).
  Real r = 0, i = 0;
  CHECK(scan_lookup(scan.view(), kPi, &r, &i));
  REAL_EQUAL(0.5, r, 1e-9);
  CHECK(scan_lookup(scan.view(), kPi / 2, &r, &i));
  REAL_EQUAL(0.59, r, 1e-9);
  CHECK(scan_lookup(scan.view(), -kPi / 2, &r, &i));
  REAL_EQUAL(0.77, r, 1e-9);
  check_accounting(*p);
}

TEST(Rplidar, GarbageAndHealthResponseMidStream) {
  auto p = make_parser();
  auto s = stream(400);
  const std::uint8_t junk[] = {0x00, 0x00, 0xFF};  // 0xFF has S = !S = 1: never a node start
  s.insert(s.begin() + 7 + 5 * 100, junk, junk + 3);
  std::uint8_t health[10];
  RplidarEncoder::write_health(RplidarHealth{2, 0x1234}, health);
  s.insert(s.begin(), health, health + 10);
  p->feed(s.data(), s.size(), 0);
  const auto& c = p->counters();
  CHECK_EQUAL(1u, c.health_packets);
  CHECK_EQUAL(2, p->last_health().status);
  CHECK_EQUAL(0x1234, p->last_health().error_code);
  CHECK_EQUAL(400u, c.packets);
  CHECK_EQUAL(3u, c.dropped_bytes);
  CHECK_EQUAL(1u, c.resyncs);
  CHECK_EQUAL(1u, c.scans);
  check_accounting(*p);
}

TEST(Rplidar, TruncatedNodeResynchronises) {
  auto p = make_parser();
  auto s = stream(1100);
  // Cut 2 bytes out of node 50: the parser may accept a few misaligned nodes (no checksum in this mode), but it
  // must drop bytes, count a resync and lock back on so later turns are exact.
  s.erase(s.begin() + 7 + 5 * 50 + 3, s.begin() + 7 + 5 * 50 + 5);
  p->feed(s.data(), s.size(), 0);
  const auto& c = p->counters();
  CHECK(c.dropped_bytes > 0);
  CHECK(c.resyncs >= 1);
  CHECK(c.packets >= 1090);
  LaserScan scan;
  CHECK(p->take_scan(scan));  // turn 3 (nodes 720..1079) is clean
  for (int j = 0; j < 360; ++j) {
    Real r = 0, i = 0;
    CHECK(scan_lookup(scan.view(), kPi - deg_to_rad(j), &r, &i));
    REAL_EQUAL((500 + j) / 1000.0, r, 1e-9);
  }
  check_accounting(*p);
}

TEST(Rplidar, SplitAtEveryByteBoundary) {
  const auto s = stream(400);
  auto ref = make_parser();
  ref->feed(s.data(), s.size(), 0);
  LaserScan a;
  CHECK(ref->take_scan(a));
  for (std::size_t k = 0; k <= s.size(); ++k) {
    auto p = make_parser();
    p->feed(s.data(), k, 0);
    p->feed(s.data() + k, s.size() - k, 0);
    CHECK_EQUAL(400u, p->counters().packets);
    LaserScan b;
    CHECK(p->take_scan(b));
    CHECK_EQUAL(0, std::memcmp(a.ranges_m, b.ranges_m, sizeof(Real) * a.count));
  }
}

TEST(Rplidar, EncoderRoundTrip) {
  LaserScan in;
  in.reset(360, -kPi, kTwoPi / 360, 0);
  for (std::size_t i = 0; i < 360; ++i) {
    in.ranges_m[i] = (i % 17 == 0) ? 0.0 : 0.2 + 0.013 * static_cast<double>(i);
    in.intensities[i] = static_cast<double>(i % 64);
  }
  RplidarEncoder enc;
  enc.configure(LidarAngleConvention{true, kPi});
  std::vector<std::uint8_t> bytes(20000);
  std::size_t n = RplidarEncoder::write_descriptor(bytes.data());
  for (int t = 0; t < 2; ++t) n += enc.encode_scan(in.view(), bytes.data() + n, bytes.size() - n);
  std::uint8_t tail[5];
  RplidarNode start;
  start.start = true;
  rplidar_encode_node(start, tail);  // the next turn's S node closes turn 2
  auto p = make_parser();
  p->feed(bytes.data(), n, 0);
  p->feed(tail, 5, 0);
  CHECK_EQUAL(2u, p->counters().scans);
  LaserScan out;
  CHECK(p->take_scan(out));
  for (std::size_t i = 0; i < 360; ++i) {
    REAL_EQUAL(in.ranges_m[i], out.ranges_m[i], 0.000125 + 1e-12);
    REAL_EQUAL(in.ranges_m[i] > 0 ? in.intensities[i] : 0.0, out.intensities[i], 1e-9);
  }
  CHECK_EQUAL(0u, p->counters().bin_collisions);
}

TEST(Rplidar, RecordedCaptureGivesExactCounters) {
  const auto cap = read_capture("rplidar_capture.bin");
  CHECK_EQUAL(4174u, cap.size());
  auto p = make_parser();
  const std::vector<LaserScan> scans = replay_bytes(*p, cap);
  const auto& c = p->counters();
  CHECK_EQUAL(2u, c.scans);
  CHECK_EQUAL(1u, c.resyncs);
  CHECK_EQUAL(7u, c.dropped_bytes);
  CHECK_EQUAL(830u, c.packets);
  CHECK_EQUAL(1u, c.descriptors);
  CHECK_EQUAL(1u, c.health_packets);
  CHECK_EQUAL(0u, c.crc_errors);
  check_accounting(*p);
  for (int j = 0; j < 360; ++j) {
    Real r = -1, i = -1;
    CHECK(scan_lookup(scans[1].view(), kPi - deg_to_rad(j), &r, &i));
    REAL_EQUAL(capture_dist_mm(j) / 1000.0, r, 1e-9);
  }
}
