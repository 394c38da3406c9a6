// LD06 parser and encoder: CRC, packet layout, angle interpolation and the 360 deg wrap, the clockwise convention,
// scan assembly, rescan after CRC errors, garbage, truncation, splits at every byte, the recorded capture.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/protocols/lidar/lidar_ld06.hpp"

#include "lidar_capture.hpp"
#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using lidar_test::capture_dist_mm;
using lidar_test::check_accounting;
using lidar_test::read_capture;
using lidar_test::replay_bytes;

namespace {

std::vector<std::uint8_t> packet(std::uint16_t start, std::uint16_t end, std::uint16_t dist = 1500,
                                 std::uint16_t speed = 3600) {
  Ld06Packet p;
  p.speed_dps = speed;
  p.start_cdeg = start;
  p.end_cdeg = end;
  for (std::size_t i = 0; i < kLd06PointsPerPacket; ++i) {
    p.distance_mm[i] = static_cast<std::uint16_t>(dist + i);
    p.intensity[i] = static_cast<std::uint8_t>(100 + i);
  }
  std::vector<std::uint8_t> b(kLd06PacketBytes);
  ld06_encode_packet(p, b.data());
  return b;
}

// Packets of a full stream: n packets of 12 points at 0.8 deg steps starting at sensor angle 0.
std::vector<std::uint8_t> stream(int n_packets, std::vector<std::size_t>* starts = nullptr) {
  std::vector<std::uint8_t> s;
  for (int p = 0; p < n_packets; ++p) {
    if (starts) starts->push_back(s.size());
    const auto a0 = static_cast<std::uint16_t>((p * 12 * 80) % 36000);
    const auto a1 = static_cast<std::uint16_t>(((p * 12 + 11) * 80) % 36000);
    const auto pk = packet(a0, a1, static_cast<std::uint16_t>(1000 + p));
    s.insert(s.end(), pk.begin(), pk.end());
  }
  return s;
}

std::unique_ptr<Ld06Parser> make_parser() {
  auto p = std::make_unique<Ld06Parser>();
  CHECK(p->configure(Ld06Config{}));
  return p;
}

}  // namespace

TEST_GROUP(Ld06){};

TEST(Ld06, Crc8CheckValue) {
  const char* s = "123456789";
  CHECK_EQUAL(0xC3, ld06_crc8(reinterpret_cast<const std::uint8_t*>(s), 9));
  CHECK_EQUAL(0x00, ld06_crc8(nullptr, 0));
}

TEST(Ld06, PacketLayoutIsLittleEndianWithCrc) {
  const auto b = packet(1000, 1880, 0x1234, 0x0E10);
  CHECK_EQUAL(0x54, b[0]);
  CHECK_EQUAL(0x2C, b[1]);
  CHECK_EQUAL(0x10, b[2]);
  CHECK_EQUAL(0x0E, b[3]);
  CHECK_EQUAL(1000 & 0xFF, b[4]);
  CHECK_EQUAL(0x34, b[6]);
  CHECK_EQUAL(0x12, b[7]);
  CHECK_EQUAL(100, b[8]);
  CHECK_EQUAL(1880 & 0xFF, b[42]);
  CHECK_EQUAL(ld06_crc8(b.data(), 46), b[46]);
  Ld06Packet p;
  CHECK(ld06_decode_packet(b.data(), p));
  CHECK_EQUAL(0x1234 + 11, p.distance_mm[11]);
  auto bad = b;
  bad[20] ^= 1;
  CHECK_FALSE(ld06_decode_packet(bad.data(), p));
}

TEST(Ld06, AngleInterpolationWrapsAt360) {
  REAL_EQUAL(1000.0, ld06_point_angle_cdeg(1000, 1880, 0), 1e-9);
  REAL_EQUAL(1080.0, ld06_point_angle_cdeg(1000, 1880, 1), 1e-9);
  REAL_EQUAL(1880.0, ld06_point_angle_cdeg(1000, 1880, 11), 1e-9);
  // 355.00 -> 3.80 deg: span 880 across the wrap; point 7 is at 355 + 560/100 = 360.6 -> 0.6 deg.
  REAL_EQUAL(35580.0, ld06_point_angle_cdeg(35500, 380, 1), 1e-9);
  REAL_EQUAL(60.0, ld06_point_angle_cdeg(35500, 380, 7), 1e-9);
  REAL_EQUAL(380.0, ld06_point_angle_cdeg(35500, 380, 11), 1e-9);
}

TEST(Ld06, ClockwiseSensorAngleBecomesCounterClockwiseCoreAngle) {
  const LidarAngleConvention c{true, 0};
  // Sensor 90 deg clockwise = the lidar's right = core -90 deg.
  REAL_EQUAL(-kPi / 2, c.to_core(kPi / 2), 1e-12);
  REAL_EQUAL(3 * kPi / 2, c.to_sensor(kPi / 2), 1e-12);
  const LidarAngleConvention rp{true, kPi};
  REAL_EQUAL(kPi, rp.to_core(0), 1e-12);       // RPLIDAR 0 deg points backwards
  REAL_EQUAL(kPi / 2, rp.to_core(kPi / 2), 1e-12);  // its 90 deg (clockwise from the back) is the left
}

TEST(Ld06, StreamAssemblesTurnsAtTheWrap) {
  auto p = make_parser();
  // 450 points per turn = 37.5 packets; 80 packets = 2 turns + 60 points.
  const auto s = stream(80);
  const std::size_t scans = p->feed(s.data(), s.size(), 5'000'000);
  CHECK_EQUAL(2u, scans);
  const auto& c = p->counters();
  CHECK_EQUAL(2u, c.scans);
  CHECK_EQUAL(1u, c.scans_overwritten);  // nobody took the first one
  CHECK_EQUAL(80u, c.packets);
  CHECK_EQUAL(0u, c.crc_errors);
  CHECK_EQUAL(0u, c.dropped_bytes);
  CHECK_EQUAL(0u, c.bin_collisions);
  check_accounting(*p);
  LaserScan scan;
  CHECK(p->take_scan(scan));
  LaserScan again;
  CHECK_FALSE(p->take_scan(again));
  CHECK_EQUAL(450u, scan.count);
  CHECK(scan.view().wraps());
  // Turn 2 = sensor points 450..899; sensor point j of packet P = j / 12 has range 1000 + P + j % 12 mm and sits at
  // sensor 0.8 * (j - 450) deg = core -0.8 * (j - 450) deg.
  for (int j = 450; j < 900; ++j) {
    const Real core = -deg_to_rad(0.8 * (j - 450));
    Real r = 0, inten = 0;
    CHECK(scan_lookup(scan.view(), core, &r, &inten));
    REAL_EQUAL((1000 + j / 12 + j % 12) / 1000.0, r, 1e-9);
    REAL_EQUAL(100 + j % 12, inten, 1e-9);
  }
}

TEST(Ld06, TakenScanStaysInPlaceUntilTheNextOneIsPublished) {
  // take_scan() without an argument hands out the parser's own buffer (no copy): it must not change while the
  // next turn is built, and the next published turn must come in the other buffer.
  auto p = make_parser();
  const auto s = stream(120);  // 3 turns + 15 points
  // Feed up to the first turn's end (the wrap inside packet 38 publishes turn 1, the partial first turn is dropped).
  std::size_t off = 0;
  while (p->counters().scans < 1 && off < s.size()) p->feed(&s[off++], 1, 5'000'000);
  const LaserScan* first = p->take_scan();
  CHECK(first != nullptr);
  CHECK(p->take_scan() == nullptr);
  const auto copy = std::make_unique<LaserScan>(*first);
  // Most of the next turn: the taken scan is untouched.
  const std::uint32_t samples_at_take = p->counters().samples;
  while (off < s.size() && p->counters().samples < samples_at_take + 400) p->feed(&s[off++], 1, 5'000'000);
  CHECK_EQUAL(1u, p->counters().scans);
  CHECK_EQUAL(copy->count, first->count);
  CHECK_EQUAL(copy->stamp_us, first->stamp_us);
  for (std::size_t i = 0; i < copy->count; ++i) {
    CHECK_TRUE(copy->ranges_m[i] == first->ranges_m[i]);
    CHECK_TRUE(copy->intensities[i] == first->intensities[i]);
  }
  while (p->counters().scans < 2 && off < s.size()) p->feed(&s[off++], 1, 5'000'000);
  const LaserScan* second = p->take_scan();
  CHECK(second != nullptr);
  CHECK(second != first);
  CHECK_EQUAL(450u, second->count);
  CHECK_TRUE(second->ranges_m[0] != copy->ranges_m[0]);  // ranges carry their packet's number
  // The copying take gives what the in-place one would.
  while (p->counters().scans < 3 && off < s.size()) p->feed(&s[off++], 1, 5'000'000);
  const LaserScan& waiting = *p->take_scan();
  const auto third = std::make_unique<LaserScan>(waiting);
  CHECK_EQUAL(450u, third->count);
  CHECK_TRUE(third->ranges_m[10] == waiting.ranges_m[10]);
  CHECK_EQUAL(3u, p->counters().scans);
  CHECK_EQUAL(0u, p->counters().scans_overwritten);
}

TEST(Ld06, ScanStampIsFirstPointTime) {
  // Arrival stamps (the test packets' timestamps are all 0); the sensor clock has its own tests below.
  auto p = std::make_unique<Ld06Parser>();
  Ld06Config cfg;
  cfg.sensor_clock = false;
  CHECK(p->configure(cfg));
  const auto s = stream(80);
  std::vector<std::size_t> starts;
  stream(80, &starts);
  // Byte k arrives at 1000 + k µs. Turn 2 starts at point 450 = packet 37 point 6.
  for (std::size_t k = 0; k < s.size(); ++k) p->feed(s[k], 1000 + k);
  LaserScan scan;
  CHECK(p->take_scan(scan));
  const double period = 1e6 / 4500.0;
  const auto expect = static_cast<std::uint64_t>(1000 + starts[37] - static_cast<std::uint64_t>(6 * period));
  CHECK(scan.stamp_us + 1 >= expect && scan.stamp_us <= expect + 1);
}

namespace {

// One packet per element: packet k covers sensor points 12k..12k+11 at 0.8 deg (450 points = 10 Hz at 4500 Hz),
// carries sensor timestamp ts_ms[k] and arrives (its bytes) at arrival_us[k].
void feed_timed(Ld06Parser& p, const std::vector<std::uint32_t>& ts_ms, const std::vector<std::uint64_t>& arrival_us) {
  for (std::size_t k = 0; k < ts_ms.size(); ++k) {
    Ld06Packet pk;
    pk.speed_dps = 3600;
    pk.start_cdeg = static_cast<std::uint16_t>((k * 12 * 80) % 36000);
    pk.end_cdeg = static_cast<std::uint16_t>(((k * 12 + 11) * 80) % 36000);
    pk.timestamp_ms = static_cast<std::uint16_t>(ts_ms[k] % kLd06TimestampWrapMs);
    for (std::size_t i = 0; i < kLd06PointsPerPacket; ++i) pk.distance_mm[i] = 1000;
    std::uint8_t b[kLd06PacketBytes];
    ld06_encode_packet(pk, b);
    p.feed(b, sizeof b, arrival_us[k]);
  }
}

constexpr std::uint64_t kPacketUs = 2667;  // 12 points at 4500 Hz

}  // namespace

TEST(Ld06, SensorClockKeepsABackloggedTurnsOwnTime) {
  // 150 packets = 4 turns. The first 50 arrive live (1 ms transport delay); the reader then stalls and the other
  // 100 (turns 2-3, 267 ms of data) arrive at once, 1.5 s after the stall began.
  auto p = make_parser();
  std::vector<std::uint32_t> ts;
  std::vector<std::uint64_t> at;
  const std::uint64_t t0 = 10'000'000;
  for (std::size_t k = 0; k < 150; ++k) {
    ts.push_back(static_cast<std::uint32_t>(5000 + k * kPacketUs / 1000));
    at.push_back(k < 50 ? t0 + k * kPacketUs + 1000 : t0 + 50 * kPacketUs + 1'500'000);
  }
  feed_timed(*p, ts, at);
  CHECK(p->sensor_clock_active());
  LaserScan scan;
  CHECK(p->take_scan(scan));
  // The newest complete turn starts at point 900 = packet 75: measured ~t0 + 75 packets, not at the late arrival.
  // (ms timestamps: up to 1 ms off; the first point is 12 point periods before its packet's time.)
  const std::uint64_t expect = t0 + 75 * kPacketUs + 1000 - 12 * 222;
  CHECK_TEXT(scan.stamp_us + 2000 >= expect && scan.stamp_us <= expect + 2000,
             ("stamp " + std::to_string(scan.stamp_us) + " expected ~" + std::to_string(expect)).c_str());
  CHECK_EQUAL(0u, p->counters().clock_resyncs);

  // With the sensor clock off the same bytes would pass for fresh: the turn is stamped at the late arrival.
  auto q = std::make_unique<Ld06Parser>();
  Ld06Config cfg;
  cfg.sensor_clock = false;
  CHECK(q->configure(cfg));
  feed_timed(*q, ts, at);
  CHECK(q->take_scan(scan));
  CHECK(scan.stamp_us > t0 + 1'400'000);
}

TEST(Ld06, SensorClockUnwrapsAt30000) {
  auto p = make_parser();
  std::vector<std::uint32_t> ts;
  std::vector<std::uint64_t> at;
  for (std::size_t k = 0; k < 120; ++k) {
    ts.push_back(static_cast<std::uint32_t>(29900 + k * kPacketUs / 1000));  // wraps after ~37 packets
    at.push_back(1'000'000 + k * kPacketUs);
  }
  feed_timed(*p, ts, at);
  LaserScan scan;
  CHECK(p->take_scan(scan));
  const std::uint64_t expect = 1'000'000 + 75 * kPacketUs - 12 * 222;
  CHECK(scan.stamp_us + 2000 >= expect && scan.stamp_us <= expect + 2000);
  CHECK_EQUAL(0u, p->counters().clock_resyncs);
  CHECK(p->sensor_clock_active());
}

TEST(Ld06, FrozenSensorClockFallsBackToArrival) {
  auto p = make_parser();
  std::vector<std::uint32_t> ts(120, 777);
  std::vector<std::uint64_t> at;
  for (std::size_t k = 0; k < 120; ++k) at.push_back(2'000'000 + k * kPacketUs);
  feed_timed(*p, ts, at);
  CHECK_FALSE(p->sensor_clock_active());
  CHECK_EQUAL(1u, p->counters().clock_resyncs);
  LaserScan scan;
  CHECK(p->take_scan(scan));
  const std::uint64_t expect = 2'000'000 + 75 * kPacketUs - 12 * 222;
  CHECK(scan.stamp_us + 500 >= expect && scan.stamp_us <= expect + 500);
}

TEST(Ld06, PausedSensorClockRelocksAfterALastingLag) {
  // Live packets, then the sensor's count pauses for 1.5 s while its data keeps arriving late by that much: a backlog
  // would drain, this lag stays. After sensor_clock_relock_ms (1 s) of it the mapping restarts from arrival.
  auto p = make_parser();
  std::vector<std::uint32_t> ts;
  std::vector<std::uint64_t> at;
  for (std::size_t k = 0; k < 1000; ++k) {
    ts.push_back(static_cast<std::uint32_t>(k * kPacketUs / 1000));
    at.push_back(3'000'000 + k * kPacketUs + (k >= 100 ? 1'500'000 : 0));
  }
  feed_timed(*p, ts, at);
  CHECK_EQUAL(1u, p->counters().clock_resyncs);
  CHECK(p->sensor_clock_active());
  LaserScan scan;
  CHECK(p->take_scan(scan));
  // The newest complete turn (points 11250.. = packet 937, point 6) is stamped from its arrival again.
  const std::uint64_t expect = 3'000'000 + 1'500'000 + 937 * kPacketUs - 6 * 222;
  CHECK_TEXT(scan.stamp_us + 3000 >= expect && scan.stamp_us <= expect + 3000,
             ("stamp " + std::to_string(scan.stamp_us) + " expected ~" + std::to_string(expect)).c_str());
}

TEST(Ld06, PacketStraddlingZeroIsSplitExactly) {
  auto p = make_parser();
  // A turn from 0 to 352.8 deg (37 packets minus the last 6 points) then a packet 355.2 .. 4.0 deg.
  std::vector<std::uint8_t> s;
  for (int k = 0; k < 37; ++k) {
    const auto pk = packet(static_cast<std::uint16_t>(k * 960), static_cast<std::uint16_t>(k * 960 + 880), 2000);
    s.insert(s.end(), pk.begin(), pk.end());
  }
  const auto wrap = packet(35520, 400, 3000);  // points at 355.2, 356.0, ... 359.2 | 0.0, 0.8, ... 4.0
  s.insert(s.end(), wrap.begin(), wrap.end());
  p->feed(s.data(), s.size(), 0);
  CHECK_EQUAL(1u, p->counters().scans);
  LaserScan scan;
  CHECK(p->take_scan(scan));
  Real r = 0, inten = 0;
  CHECK(scan_lookup(scan.view(), -deg_to_rad(359.2), &r, &inten));
  REAL_EQUAL(3.005, r, 1e-9);  // point 5 of the wrap packet went into the closing turn
  CHECK(scan_lookup(scan.view(), 0, &r, &inten));
  REAL_EQUAL(2.0, r, 1e-9);  // 0 deg holds the first turn's point, not the wrap packet's point 6
}

TEST(Ld06, CrcErrorRescansSoTheNextPacketSurvives) {
  auto p = make_parser();
  std::vector<std::size_t> starts;
  auto s = stream(10, &starts);
  // Truncate packet 3 to 30 bytes: the vendor would drop 47 bytes and lose packet 4 as well.
  s.erase(s.begin() + static_cast<long>(starts[3] + 30), s.begin() + static_cast<long>(starts[4]));
  p->feed(s.data(), s.size(), 0);
  const auto& c = p->counters();
  CHECK_EQUAL(9u, c.packets);
  CHECK(c.crc_errors >= 1);
  CHECK_EQUAL(1u, c.resyncs);
  CHECK_EQUAL(30u, c.dropped_bytes);
  check_accounting(*p);
}

TEST(Ld06, BitFlipCostsOnePacketAndIsCounted) {
  auto p = make_parser();
  std::vector<std::size_t> starts;
  auto s = stream(10, &starts);
  s[starts[5] + 17] ^= 0x20;
  p->feed(s.data(), s.size(), 0);
  const auto& c = p->counters();
  CHECK_EQUAL(9u, c.packets);
  CHECK_EQUAL(1u, c.crc_errors);
  CHECK_EQUAL(1u, c.resyncs);
  CHECK_EQUAL(47u, c.dropped_bytes);
  check_accounting(*p);
}

TEST(Ld06, GarbageBetweenPacketsIsDroppedAndCounted) {
  auto p = make_parser();
  std::vector<std::size_t> starts;
  auto s = stream(6, &starts);
  const std::uint8_t junk[] = {0x01, 0x54, 0x99, 0x54, 0x54, 0x2C, 0x00};  // includes false headers
  s.insert(s.begin() + static_cast<long>(starts[2]), junk, junk + sizeof junk);
  p->feed(s.data(), s.size(), 0);
  const auto& c = p->counters();
  CHECK_EQUAL(6u, c.packets);
  CHECK_EQUAL(sizeof junk, c.dropped_bytes);
  CHECK_EQUAL(1u, c.resyncs);
  // "54 2C 00" + the next 44 bytes make a 47-byte candidate whose CRC fails (rescanned, not lost).
  CHECK(c.crc_errors >= 1);
  check_accounting(*p);
}

TEST(Ld06, SplitAtEveryByteBoundaryGivesTheSameResult) {
  const auto s = stream(45);
  auto ref = make_parser();
  ref->feed(s.data(), s.size(), 0);
  LaserScan a;
  CHECK(ref->take_scan(a));
  for (std::size_t k = 0; k <= s.size(); k += 1) {
    auto p = make_parser();
    p->feed(s.data(), k, 0);
    p->feed(s.data() + k, s.size() - k, 0);
    CHECK_EQUAL(ref->counters().packets, p->counters().packets);
    CHECK_EQUAL(1u, p->counters().scans);
    LaserScan b;
    CHECK(p->take_scan(b));
    CHECK_EQUAL(0, std::memcmp(a.ranges_m, b.ranges_m, sizeof(Real) * a.count));
  }
}

TEST(Ld06, HealthInfoAndSpanCheck) {
  auto p = make_parser();
  std::uint8_t health[4] = {0x54, 0xE0, 0x07, 0};
  health[3] = ld06_crc8(health, 3);
  p->feed(health, 4, 0);
  CHECK_EQUAL(1u, p->counters().health_packets);
  CHECK_EQUAL(7, p->last_health_error());
  std::uint8_t info[23] = {0x54, 0x0F};
  info[22] = ld06_crc8(info, 22);
  p->feed(info, 23, 0);
  CHECK_EQUAL(1u, p->counters().info_packets);
  // At 3600 deg/s a packet spans 9.6 deg; 15 deg is within 1.5x (14.4 deg)? No: rejected. 14 deg passes.
  auto wide = packet(1000, 2500);
  p->feed(wide.data(), wide.size(), 0);
  CHECK_EQUAL(1u, p->counters().bad_span);
  CHECK_EQUAL(0u, p->counters().packets);
  auto ok = packet(1000, 2400);
  p->feed(ok.data(), ok.size(), 0);
  CHECK_EQUAL(1u, p->counters().bad_span);
  CHECK_EQUAL(1u, p->counters().packets);
  auto bad_angle = packet(36500, 100);
  p->feed(bad_angle.data(), bad_angle.size(), 0);
  CHECK_EQUAL(2u, p->counters().bad_span);
  check_accounting(*p);
}

TEST(Ld06, EncoderRoundTripWithinQuantisation) {
  LaserScan in;
  in.reset(450, -kPi, kTwoPi / 450, 0);
  for (std::size_t i = 0; i < 450; ++i) {
    in.ranges_m[i] = (i % 29 == 0) ? 0.0 : 0.3 + 0.01 * static_cast<double>(i) + 0.0004;
    in.intensities[i] = static_cast<double>(i % 250);
  }
  Ld06StreamEncoder enc;
  enc.configure(LidarAngleConvention{true, 0}, 3600);
  std::vector<std::uint8_t> bytes(64 * 1024);
  std::size_t n = 0;
  for (int t = 0; t < 3; ++t) n += enc.encode_scan(in.view(), static_cast<std::uint16_t>(t * 100), bytes.data() + n, bytes.size() - n);
  CHECK_EQUAL(0u, enc.points_lost());
  CHECK_EQUAL(0u, n % kLd06PacketBytes);
  auto p = make_parser();
  CHECK_EQUAL(2u, p->feed(bytes.data(), n, 0));
  LaserScan out;
  CHECK(p->take_scan(out));
  CHECK_EQUAL(in.count, out.count);
  REAL_EQUAL(in.angle_min_rad, out.angle_min_rad, 1e-12);
  for (std::size_t i = 0; i < 450; ++i) {
    REAL_EQUAL(in.ranges_m[i], out.ranges_m[i], 0.0005 + 1e-12);
    // A no-return carries no intensity.
    REAL_EQUAL(in.ranges_m[i] > 0 ? in.intensities[i] : 0.0, out.intensities[i], 1e-9);
  }
  CHECK_EQUAL(0u, p->counters().bin_collisions);
}

TEST(Ld06, RecordedCaptureGivesExactCounters) {
  const auto cap = read_capture("ld06_capture.bin");
  CHECK_EQUAL(5314u, cap.size());
  auto p = make_parser();
  const std::vector<LaserScan> scans = replay_bytes(*p, cap);
  const auto& c = p->counters();
  CHECK_EQUAL(3u, c.scans);
  CHECK_EQUAL(2u, c.crc_errors);
  CHECK_EQUAL(2u, c.resyncs);
  CHECK_EQUAL(70u, c.dropped_bytes);
  CHECK_EQUAL(111u, c.packets);
  CHECK_EQUAL(1u, c.health_packets);
  CHECK_EQUAL(1u, c.info_packets);
  CHECK_EQUAL(0u, c.bad_span);
  check_accounting(*p);
  CHECK_EQUAL(3u, scans.size());
  // Turn 1 is complete: sensor point j at sensor 0.8 j deg (clockwise) = core -0.8 j deg.
  for (int j = 0; j < 450; ++j) {
    Real r = -1, inten = -1;
    CHECK(scan_lookup(scans[0].view(), -deg_to_rad(0.8 * j), &r, &inten));
    REAL_EQUAL(capture_dist_mm(j) / 1000.0, r, 1e-9);
  }
  // Turn 2 lost packet 50 (points 600..611 = turn points 150..161): no return there.
  Real r = -1, inten = -1;
  CHECK(scan_lookup(scans[1].view(), -deg_to_rad(0.8 * 155), &r, &inten));
  REAL_EQUAL(0.0, r, 0.0);
  CHECK(scan_lookup(scans[1].view(), -deg_to_rad(0.8 * 149), &r, &inten));
  REAL_EQUAL(capture_dist_mm(149) / 1000.0, r, 1e-9);
}

TEST(Ld06, ResetCountsBufferedBytesAndPartialTurn) {
  auto p = make_parser();
  const auto s = stream(5);
  p->feed(s.data(), s.size() - 10, 0);
  const auto before = p->counters();
  p->reset();
  CHECK_EQUAL(before.dropped_bytes + 37u, p->counters().dropped_bytes);
  CHECK_EQUAL(48u, p->counters().samples_discarded);
  CHECK_EQUAL(0u, p->buffered());
  check_accounting(*p);
}

TEST(Ld06, FirstPartialTurnIsDiscarded) {
  auto p = make_parser();
  // Start mid-turn at packet 20 (192 deg): the first wrap closes a partial turn, which is not published.
  std::vector<std::uint8_t> s;
  for (int k = 20; k < 80; ++k) {
    const auto pk = packet(static_cast<std::uint16_t>((k * 960) % 36000), static_cast<std::uint16_t>((k * 960 + 880) % 36000));
    s.insert(s.end(), pk.begin(), pk.end());
  }
  p->feed(s.data(), s.size(), 0);
  CHECK_EQUAL(1u, p->counters().scans);
  CHECK(p->counters().samples_discarded > 0);
}

TEST(Ld06, ConfigureRejectsBadGrids) {
  Ld06Parser* p = new Ld06Parser;
  Ld06Config c;
  c.bins_per_turn = 0;
  CHECK_FALSE(p->configure(c));
  c.bins_per_turn = kMaxScanPoints + 1;
  CHECK_FALSE(p->configure(c));
  c.bins_per_turn = 360;
  c.point_rate_hz = 0;
  CHECK_FALSE(p->configure(c));
  delete p;
}
