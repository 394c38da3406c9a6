// RPLIDAR legacy standard scan: requests, node layout and validity bits, descriptor detection, resync, health,
// the clockwise-from-the-back convention, round trip, splits at every byte, turn starts near 360 deg and stray S
// nodes, byte accounting, the recorded capture, and the real RPLIDAR A1 captures of the realdata folder (every
// complete rotation published, corrupted variants).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "dockcore/perception/intensity_check.hpp"
#include "dockcore/protocols/lidar/lidar_rplidar.hpp"

#include "lidar_capture.hpp"
#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using lidar_test::capture_dist_mm;
using lidar_test::check_accounting;
using lidar_test::read_capture;
using lidar_test::replay_bytes;
using lidar_test::replay_scan_stamps;

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

// One node's bytes.
void put_node(std::vector<std::uint8_t>& s, bool start, double deg, int dist_mm, int quality = 15) {
  RplidarNode n;
  n.start = start;
  n.quality = static_cast<std::uint8_t>(quality);
  n.angle_q6 = static_cast<std::uint16_t>(std::lround(deg * 64.0));
  n.distance_q2 = static_cast<std::uint16_t>(dist_mm * 4);
  std::uint8_t b[5];
  rplidar_encode_node(n, b);
  s.insert(s.end(), b, b + 5);
}

// Every byte is in exactly one category, and the accepted ones are the nodes, descriptors and responses.
void check_byte_account(const RplidarParser& p) {
  const auto& c = p.counters();
  const RplidarByteAccount a = rplidar_byte_account(c, p.buffered());
  CHECK_EQUAL(c.bytes, a.total());
  CHECK_EQUAL(c.bytes_accepted, a.node_bytes + a.descriptor_bytes + a.response_bytes);
  CHECK_EQUAL(static_cast<std::uint64_t>(c.dropped_bytes), a.resync_bytes + a.idle_bytes);
  check_accounting(p);
}

// ---- Independent reference for the real captures (shares no code with the parser) ----
// Segments as the realdata README describes them: each scan descriptor A5 5A 05 00 00 40 81 up to the next one or
// the relay's FF FF FF FF frame-end marker. Nodes by the bit rule (S != !S, check bit 1, angle < 360 deg; else move
// on one byte). A rotation runs from an S=1 node to the next S=1 node of the same segment. An S=1 node whose first
// byte is A5 is the relay's echo of a request (A5 25, STOP, at the end of each turret segment), not a node: the A1 of
// these captures reports quality <= 15, and A5 would say 41. A rotation is complete when its node angles leave no
// gap wider than 12 deg (complete A1 rotations leave at most ~9 deg; turns cut by the STOP miss 17 deg or more).
struct RefCapture {
  std::vector<std::size_t> complete;  // stream offset of each complete rotation's S=1 node
  std::size_t boundaries = 0;         // S=1 to S=1 pairs, complete or not
  std::size_t descriptors = 0;
  std::size_t health = 0;            // A5 5A 03 00 00 00 06 + 3 bytes
  std::size_t first_descriptor = 0;  // offset (size of the stream when there is none)
  std::size_t health_before_first = 0;
};

bool match_at(const std::vector<std::uint8_t>& d, std::size_t i, const std::uint8_t* pat, std::size_t n) {
  return i + n <= d.size() && std::memcmp(d.data() + i, pat, n) == 0;
}

RefCapture reference_rotations(const std::vector<std::uint8_t>& d) {
  static const std::uint8_t kDesc[7] = {0xA5, 0x5A, 0x05, 0x00, 0x00, 0x40, 0x81};
  static const std::uint8_t kHealth[7] = {0xA5, 0x5A, 0x03, 0x00, 0x00, 0x00, 0x06};
  static const std::uint8_t kEnd[4] = {0xFF, 0xFF, 0xFF, 0xFF};
  RefCapture r;
  std::vector<std::size_t> starts;
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (match_at(d, i, kDesc, 7)) starts.push_back(i);
    if (match_at(d, i, kHealth, 7) && i + 10 <= d.size()) {
      ++r.health;
      if (starts.empty()) ++r.health_before_first;
    }
  }
  r.descriptors = starts.size();
  r.first_descriptor = starts.empty() ? d.size() : starts[0];
  for (std::size_t k = 0; k < starts.size(); ++k) {
    std::size_t end = k + 1 < starts.size() ? starts[k + 1] : d.size();
    for (std::size_t i = starts[k] + 7; i + 4 <= end; ++i)
      if (match_at(d, i, kEnd, 4)) {
        end = i;
        break;
      }
    struct Node {
      std::size_t off;
      bool start;
      double deg;
    };
    std::vector<Node> nodes;
    for (std::size_t p = starts[k] + 7; p + 5 <= end;) {
      const std::uint8_t* b = d.data() + p;
      const int s = b[0] & 1, ns = (b[0] >> 1) & 1;
      const int q6 = (b[1] | (b[2] << 8)) >> 1;
      if (s == ns || (b[1] & 1) == 0 || q6 >= 360 * 64) {
        ++p;
        continue;
      }
      nodes.push_back(Node{p, s == 1 && b[0] != 0xA5, q6 / 64.0});
      p += 5;
    }
    std::size_t open = nodes.size();  // index of the S=1 node opening the rotation in progress
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      if (!nodes[i].start) continue;
      if (open < nodes.size()) {
        ++r.boundaries;
        std::vector<double> a;
        for (std::size_t j = open; j < i; ++j) a.push_back(nodes[j].deg);
        std::sort(a.begin(), a.end());
        double gap = a.front() + 360.0 - a.back();
        for (std::size_t j = 1; j < a.size(); ++j) gap = std::max(gap, a[j] - a[j - 1]);
        if (gap <= 12.0) r.complete.push_back(nodes[open].off);
      }
      open = i;
    }
  }
  return r;
}

std::vector<std::string> real_captures(const std::string& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir + "/raw-rplidar", ec))
    if (e.path().extension() == ".bin") out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::uint64_t> offsets(std::size_t n) {
  std::vector<std::uint64_t> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = i;
  return v;
}

// Complete reference rotations that no published scan starts (scan stamp = offset of its S node's first byte).
std::vector<std::size_t> lost_rotations(const std::vector<std::size_t>& complete,
                                        const std::vector<std::uint64_t>& stamps) {
  const std::set<std::uint64_t> got(stamps.begin(), stamps.end());
  std::vector<std::size_t> lost;
  for (std::size_t off : complete)
    if (got.count(off) == 0) lost.push_back(off);
  return lost;
}
std::size_t count_lost(const std::vector<std::size_t>& complete, const std::vector<std::uint64_t>& stamps) {
  return lost_rotations(complete, stamps).size();
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

TEST(Rplidar, TurnStartsAnywhereNear360AndTheSNodeOpensTheNewTurn) {
  // A real A1 reports its S node at 350..359 deg (or ~0): the boundary must not depend on that angle. Turn t has
  // range 1000 + 100 t mm, so a bin tells which turn filled it.
  for (double first : {358.0, 351.0, 0.5, 0.0}) {
    std::vector<std::uint8_t> s(kRplidarScanDescriptor, kRplidarScanDescriptor + 7);
    for (int t = 0; t < 4; ++t)
      for (int j = 0; j < 300; ++j) put_node(s, j == 0, std::fmod(first + 1.2 * j, 360.0), 1000 + 100 * t);
    auto p = make_parser();
    std::vector<LaserScan> scans = replay_bytes(*p, s);
    CHECK_EQUAL(3u, scans.size());
    CHECK_EQUAL(0u, p->counters().stray_start);
    CHECK_EQUAL(1200u, p->counters().samples);
    for (std::size_t t = 0; t < scans.size(); ++t) {
      // The S node's own bin (its angle) and the last node before the next S both belong to turn t.
      Real r = 0, i = 0;
      CHECK(scan_lookup(scans[t].view(), kPi - deg_to_rad(first), &r, &i));
      REAL_EQUAL((1000 + 100 * static_cast<int>(t)) / 1000.0, r, 1e-9);
      CHECK(scan_lookup(scans[t].view(), kPi - deg_to_rad(std::fmod(first + 1.2 * 299, 360.0)), &r, &i));
      REAL_EQUAL((1000 + 100 * static_cast<int>(t)) / 1000.0, r, 1e-9);
    }
    check_byte_account(*p);
  }
}

TEST(Rplidar, StraySNodesNeitherSplitATurnNorAddASample) {
  std::vector<std::uint8_t> s(kRplidarScanDescriptor, kRplidarScanDescriptor + 7);
  for (int t = 0; t < 3; ++t) {
    for (int j = 0; j < 360; ++j) {
      put_node(s, j == 0, j, 1000 + j);
      if (t == 1 && j == 90) put_node(s, true, 200, 300);   // out of sequence (a misaligned node)
      if (t == 1 && j == 120) put_node(s, true, 121, 300);  // in sequence, but the turn has swept only 120 deg
    }
  }
  put_node(s, true, 0, 1000);
  auto p = make_parser();
  std::vector<LaserScan> scans = replay_bytes(*p, s);
  CHECK_EQUAL(3u, scans.size());
  CHECK_EQUAL(2u, p->counters().stray_start);
  CHECK_EQUAL(3u * 360u + 1u, p->counters().samples);
  Real r = 0, i = 0;
  CHECK(scan_lookup(scans[1].view(), kPi - deg_to_rad(200), &r, &i));
  REAL_EQUAL(1.2, r, 1e-9);  // the stray node's 0.3 m did not win the bin
  CHECK(scan_lookup(scans[1].view(), kPi - deg_to_rad(121), &r, &i));
  REAL_EQUAL(1.121, r, 1e-9);
  check_byte_account(*p);
}

TEST(Rplidar, TurnWhoseSNodeIsLostMergesIntoOneScanThenResumes) {
  std::vector<std::uint8_t> s(kRplidarScanDescriptor, kRplidarScanDescriptor + 7);
  for (int t = 0; t < 5; ++t)
    for (int j = 0; j < 360; ++j)
      if (!(t == 2 && j == 0)) put_node(s, j == 0, j, 1000 + j);
  put_node(s, true, 0, 1000);
  auto p = make_parser();
  const std::vector<LaserScan> scans = replay_bytes(*p, s);
  CHECK_EQUAL(4u, scans.size());                    // turns 1 and 2 come out as one scan
  CHECK_EQUAL(359u, p->counters().bin_collisions);  // turn 2's nodes on turn 1's bins, but for the lost 0 deg one
  check_byte_account(*p);
}

TEST(Rplidar, ADescriptorInsideACandidateNodeWins) {
  // A relay echoes the host's requests into the stream: after the last node come A5 52 A5 20, then the health
  // response and the scan descriptor. "52 A5 20 A5 5A" passes a node's bit tests; the health descriptor must win.
  std::vector<std::uint8_t> s(kRplidarScanDescriptor, kRplidarScanDescriptor + 7);
  for (int j = 0; j < 400; ++j) put_node(s, j % 360 == 0, j % 360, 1000);
  const std::uint8_t echo[] = {0xA5, 0x52, 0xA5, 0x20};
  s.insert(s.end(), echo, echo + 4);
  std::uint8_t health[10];
  RplidarEncoder::write_health(RplidarHealth{0, 0}, health);
  s.insert(s.end(), health, health + 10);
  s.insert(s.end(), kRplidarScanDescriptor, kRplidarScanDescriptor + 7);
  for (int j = 0; j < 361; ++j) put_node(s, j % 360 == 0, j % 360, 1000);
  auto p = make_parser();
  p->feed(s.data(), s.size(), 0);
  const auto& c = p->counters();
  CHECK_EQUAL(1u, c.health_packets);
  CHECK_EQUAL(2u, c.descriptors);
  CHECK_EQUAL(4u, c.dropped_bytes);
  CHECK_EQUAL(761u, c.packets);
  CHECK_EQUAL(2u, c.scans);
  check_byte_account(*p);
}

TEST(Rplidar, BytesBeforeTheFirstDescriptorAreIdle) {
  auto s = stream(400);
  std::vector<std::uint8_t> pre(s.begin() + 7, s.begin() + 7 + 5 * 50);  // a stream joined mid-scan
  const std::uint8_t echo[] = {0xA5, 0x25, 0xA5, 0x20};
  pre.insert(pre.end(), echo, echo + 4);
  s.insert(s.begin(), pre.begin(), pre.end());
  auto p = make_parser();
  p->feed(s.data(), s.size(), 0);
  const RplidarByteAccount a = rplidar_byte_account(p->counters(), p->buffered());
  CHECK_EQUAL(pre.size(), a.idle_bytes);
  CHECK_EQUAL(0u, a.resync_bytes);
  CHECK_EQUAL(400u * 5u, a.node_bytes);
  CHECK_EQUAL(7u, a.descriptor_bytes);
  check_byte_account(*p);
}

TEST(Rplidar, RealCapturesPublishEveryCompleteRotation) {
  const std::string dir = lidar_test::realdata_dir("Rplidar.RealCapturesPublishEveryCompleteRotation");
  if (dir.empty()) return;
  const auto files = real_captures(dir);
  CHECK(!files.empty());
  std::size_t total_complete = 0, total_scans = 0;
  for (const auto& f : files) {
    const auto bytes = lidar_test::read_file_bytes(f);
    CHECK(!bytes.empty());
    const RefCapture ref = reference_rotations(bytes);
    auto p = make_parser();
    const std::vector<std::uint64_t> stamps = replay_scan_stamps(*p, bytes, offsets(bytes.size()));
    const auto& c = p->counters();
    const std::size_t lost = count_lost(ref.complete, stamps);
    const std::set<std::uint64_t> want(ref.complete.begin(), ref.complete.end());
    std::size_t extra = 0;
    for (std::uint64_t st : stamps)
      if (want.count(st) == 0) ++extra;
    const RplidarByteAccount a = rplidar_byte_account(c, p->buffered());
    std::printf(
        "%s: %zu B, S-to-S runs %zu, complete rotations %zu, scans %u (extra %zu), lost %zu, stray S %u; bytes: "
        "nodes %llu, descriptors %llu, responses %llu, resync %llu, idle %llu, pending %llu\n",
        std::filesystem::path(f).filename().c_str(), bytes.size(), ref.boundaries, ref.complete.size(), c.scans, extra,
        lost, c.stray_start, static_cast<unsigned long long>(a.node_bytes),
        static_cast<unsigned long long>(a.descriptor_bytes), static_cast<unsigned long long>(a.response_bytes),
        static_cast<unsigned long long>(a.resync_bytes), static_cast<unsigned long long>(a.idle_bytes),
        static_cast<unsigned long long>(a.pending_bytes));
    CHECK_EQUAL(0u, lost);  // 100 %: every complete rotation is published, stamped at its S node
    CHECK_EQUAL(stamps.size(), static_cast<std::size_t>(c.scans));
    // A scan that starts no complete rotation is a turn cut short where the STOP echo reads as an S node in
    // sequence: at most one per segment end.
    CHECK(extra <= ref.descriptors);
    CHECK(extra * 100 <= ref.complete.size() + 99);
    CHECK_EQUAL(ref.descriptors, static_cast<std::size_t>(c.descriptors));
    CHECK_EQUAL(ref.health, static_cast<std::size_t>(c.health_packets));
    CHECK_EQUAL(ref.first_descriptor - 10 * ref.health_before_first, static_cast<std::size_t>(a.idle_bytes));
    check_byte_account(*p);
    total_complete += ref.complete.size();
    total_scans += c.scans;
  }
  std::printf("all: complete rotations %zu, scans %zu\n", total_complete, total_scans);
}

// A real A1's standard-scan quality reads 15 on nearly every return (the realdata README: 96 % of the flat captures
// returns, 87 % of the turret's): the intensity check must call every capture flat, never usable.
TEST(Rplidar, RealA1QualityIsJudgedFlat) {
  const std::string dir = lidar_test::realdata_dir("Rplidar.RealA1QualityIsJudgedFlat");
  if (dir.empty()) return;
  const auto files = real_captures(dir);
  CHECK(!files.empty());
  auto scan = std::make_unique<LaserScan>();
  for (const auto& f : files) {
    const auto bytes = lidar_test::read_file_bytes(f);
    auto p = make_parser();
    IntensityCheck check;
    double share_sum = 0;
    for (std::size_t i = 0; i < bytes.size(); ++i) {
      if (!p->feed(bytes[i], i)) continue;
      CHECK(p->take_scan(*scan));
      const IntensityScan r = check.add(scan->view());
      if (r.judged) share_sum += static_cast<double>(r.share);
    }
    std::printf("%s: scans %u, judged %u, flat %u, mean share %.3f, verdict %s\n",
                std::filesystem::path(f).filename().c_str(), check.scans(), check.scans_judged(), check.scans_flat(),
                check.scans_judged() > 0 ? share_sum / check.scans_judged() : 0.0, to_string(check.verdict()));
    CHECK(IntensityVerdict::kUsable != check.verdict());
    CHECK(check.verdict_changes() <= 1);  // unknown, then flat for good
    if (check.scans_judged() >= check.params().window_scans) CHECK(IntensityVerdict::kFlat == check.verdict());
  }
}

TEST(Rplidar, CorruptedRealCaptureLosesRotationsOnlyNearTheDamage) {
  const std::string dir = lidar_test::realdata_dir("Rplidar.CorruptedRealCaptureLosesRotationsOnlyNearTheDamage");
  if (dir.empty()) return;
  const auto bytes = lidar_test::read_file_bytes(dir + "/raw-rplidar/turret-living_room_90_steps.bin");
  if (bytes.empty()) {
    std::printf("skipped: %s/raw-rplidar/turret-living_room_90_steps.bin not readable\n", dir.c_str());
    return;
  }
  const RefCapture ref = reference_rotations(bytes);
  std::mt19937 rng(20240611u);
  // Feeds a damaged stream whose byte i came from original offset st[i] (the parser's stamps, so a published scan
  // names the original rotation it starts) and checks what it lost among the complete rotations closed before `cut`.
  // hit: the damaged original offsets. Every lost rotation must have damage within kNear bytes of its S node
  // (~2.5 rotations of ~1.5 kB): the loss stays next to the damage.
  constexpr std::size_t kNear = 4000;
  auto run = [&](const char* what, int events, const std::vector<std::uint8_t>& v, const std::vector<std::uint64_t>& st,
                 std::size_t cut, const std::vector<std::size_t>& hit) {
    auto p = make_parser();
    const std::vector<std::uint64_t> stamps = replay_scan_stamps(*p, v, st);
    std::vector<std::size_t> reachable;
    for (std::size_t off : ref.complete)
      if (off + 5 * 400 < cut) reachable.push_back(off);
    const std::vector<std::size_t> lost = lost_rotations(reachable, stamps);
    std::size_t far = 0, worst = 0;
    for (std::size_t off : lost) {
      std::size_t d = SIZE_MAX;
      for (std::size_t h : hit) d = std::min(d, h > off ? h - off : off - h);
      worst = std::max(worst, d);
      if (d > kNear) ++far;
    }
    std::printf(
        "variant %s x%d: %zu B fed, scans %u, lost %zu of %zu (farthest from damage: %zu B), stray S %u, "
        "resync bytes %llu\n",
        what, events, v.size(), p->counters().scans, lost.size(), reachable.size(), worst, p->counters().stray_start,
        static_cast<unsigned long long>(rplidar_byte_account(p->counters(), p->buffered()).resync_bytes));
    CHECK(lost.size() <= 2u * static_cast<std::size_t>(events));
    CHECK_EQUAL(0u, far);
    check_byte_account(*p);
  };
  for (bool drop : {false, true}) {
    for (int events : {1, 10, 100, 1000}) {
      std::vector<bool> damaged(bytes.size(), false);
      std::vector<std::size_t> hit;
      for (int e = 0; e < events; ++e) {
        const std::size_t at = std::uniform_int_distribution<std::size_t>(0, bytes.size() - 41)(rng);
        const std::size_t len = drop ? std::uniform_int_distribution<std::size_t>(1, 40)(rng) : 1;
        for (std::size_t k = 0; k < len; ++k) damaged[at + k] = true;
        hit.push_back(at);
      }
      std::vector<std::uint8_t> v;
      std::vector<std::uint64_t> st;
      for (std::size_t i = 0; i < bytes.size(); ++i) {
        if (damaged[i] && drop) continue;
        v.push_back(damaged[i] ? static_cast<std::uint8_t>(bytes[i] ^ (1u << (i % 8))) : bytes[i]);
        st.push_back(i);
      }
      // Each damaged spot costs at most the rotation it hits and the next one (whose S then closes a merged or
      // shortened turn), and only rotations next to it.
      run(drop ? "drop 1..40 B" : "flip 1 bit", events, v, st, bytes.size(), hit);
    }
  }
  for (int k = 0; k < 10; ++k) {
    const std::size_t cut = std::uniform_int_distribution<std::size_t>(1, bytes.size() - 1)(rng);
    const std::vector<std::uint8_t> v(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(cut));
    run("truncate", 1, v, offsets(cut), cut, std::vector<std::size_t>{cut});
  }
}

TEST(Rplidar, ResetDropsBufferedBytesAndTheOpenTurnAndWaitsForADescriptor) {
  auto p = make_parser();
  auto s = stream(200);  // one turn opened at node 0, not closed
  s.push_back(s[7]);     // the first 3 bytes of a node, left in the buffer
  s.push_back(s[8]);
  s.push_back(s[9]);
  p->feed(s.data(), s.size(), 0);
  CHECK(p->in_scan_mode());
  CHECK_EQUAL(3u, p->buffered());
  const LidarParserCounters before = p->counters();
  p->reset();
  CHECK_FALSE(p->in_scan_mode());
  CHECK_EQUAL(0u, p->buffered());
  CHECK_EQUAL(before.dropped_bytes + 3, p->counters().dropped_bytes);
  CHECK_EQUAL(before.samples_discarded + 200, p->counters().samples_discarded);
  check_byte_account(*p);
  // Nodes without a new descriptor are idle bytes now; the next descriptor starts over, and only a whole turn
  // after it is published.
  std::vector<std::uint8_t> nodes;
  for (int j = 0; j < 50; ++j) put_node(nodes, j == 0, j, 700);
  p->feed(nodes.data(), nodes.size(), 0);
  CHECK_EQUAL(before.packets, p->counters().packets);
  CHECK_FALSE(p->scan_ready());
  const auto again = stream(400);
  p->feed(again.data(), again.size(), 0);
  CHECK_EQUAL(before.packets + 400, p->counters().packets);
  LaserScan scan;
  CHECK(p->take_scan(scan));
  Real r = 0;
  Real i = 0;
  CHECK(scan_lookup(scan.view(), kPi - deg_to_rad(10), &r, &i));
  REAL_EQUAL(0.510, r, 1e-9);
  check_byte_account(*p);
}

TEST(Rplidar, DeviceInfoResponseIsCountedAndSkipped) {
  auto p = make_parser();
  std::vector<std::uint8_t> s(kRplidarInfoDescriptor, kRplidarInfoDescriptor + kRplidarDescriptorBytes);
  for (std::size_t k = 0; k < kRplidarInfoBytes; ++k) s.push_back(static_cast<std::uint8_t>(0xA5 + k));  // any payload
  const auto scan_bytes = stream(400);
  s.insert(s.end(), scan_bytes.begin(), scan_bytes.end());
  p->feed(s.data(), s.size(), 0);
  const auto& c = p->counters();
  CHECK_EQUAL(1u, c.info_packets);
  CHECK_EQUAL(400u, c.packets);
  CHECK_EQUAL(1u, c.scans);
  CHECK_EQUAL(0u, c.dropped_bytes);
  CHECK_EQUAL(static_cast<std::uint64_t>(kRplidarDescriptorBytes + kRplidarInfoBytes),
              rplidar_byte_account(c, p->buffered()).response_bytes);
  check_byte_account(*p);
}

TEST(Rplidar, EncoderWritesWholeNodesAndCountsTheRest) {
  LaserScan in;
  in.reset(360, -kPi, kTwoPi / 360, 0);
  for (std::size_t i = 0; i < 360; ++i) in.ranges_m[i] = 1.0;
  RplidarEncoder enc;
  std::uint8_t out[5 * 100 + 3];
  CHECK_EQUAL(5u * 100u, enc.encode_scan(in.view(), out, sizeof out));
  CHECK_EQUAL(260u, enc.points_lost());
  CHECK_EQUAL(0u, enc.encode_scan(in.view(), out, 4));
  CHECK_EQUAL(260u + 360u, enc.points_lost());
}
