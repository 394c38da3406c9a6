// Lakibeam1 datagrams: layout, azimuth interpolation, turn split at the wrap, rejection of wrong sizes / markers,
// LD06 packets over UDP, round trip, the recorded capture.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/protocols/lidar/lidar_lakibeam.hpp"
#include "dockcore/protocols/lidar/lidar_ld06.hpp"

#include "lidar_capture.hpp"
#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using lidar_test::capture_dist_mm;
using lidar_test::read_capture;

namespace {

std::unique_ptr<LakibeamParser> make_parser() {
  auto p = std::make_unique<LakibeamParser>();
  CHECK(p->configure(LakibeamConfig{}));
  return p;
}

// One datagram: block b azimuth az0 + b * 16 * step (0.01 deg), range 2000 + point index mm.
std::vector<std::uint8_t> datagram(std::uint32_t az0, std::uint32_t step) {
  std::vector<std::uint8_t> d(kLakibeamDatagramBytes, 0);
  for (std::size_t b = 0; b < 12; ++b) {
    std::uint8_t* blk = d.data() + 100 * b;
    blk[0] = 0xFF;
    blk[1] = 0xEE;
    const std::uint32_t az = (az0 + static_cast<std::uint32_t>(b) * 16 * step) % 36000;
    blk[2] = static_cast<std::uint8_t>(az & 0xFF);
    blk[3] = static_cast<std::uint8_t>(az >> 8);
    for (std::size_t k = 0; k < 16; ++k) {
      const auto mm = static_cast<std::uint16_t>(2000 + 16 * b + k);
      blk[4 + 6 * k] = static_cast<std::uint8_t>(mm & 0xFF);
      blk[5 + 6 * k] = static_cast<std::uint8_t>(mm >> 8);
      blk[6 + 6 * k] = 77;
    }
  }
  d[1200] = 0x78;
  d[1201] = 0x56;
  d[1202] = 0x34;
  d[1203] = 0x12;
  d[1204] = 0x40;
  d[1205] = 0x37;
  return d;
}

}  // namespace

TEST_GROUP(Lakibeam){};

TEST(Lakibeam, InterpolatesAzimuthAndSplitsAtTheWrap) {
  auto p = make_parser();
  // 0.25 deg steps: 1440 points per turn = 7.5 datagrams; 16 datagrams = 2 turns + 192 points.
  std::size_t scans = 0;
  for (std::uint32_t g = 0; g < 16; ++g) scans += p->feed_datagram(datagram(g * 192 * 25, 25).data(), kLakibeamDatagramBytes, 100 + g);
  CHECK_EQUAL(2u, scans);
  const auto& c = p->counters();
  CHECK_EQUAL(16u, c.packets);
  CHECK_EQUAL(0u, c.bad_packets);
  CHECK_EQUAL(0u, c.bin_collisions);
  CHECK_EQUAL(0x12345678u, p->last_timestamp());
  LaserScan s;
  CHECK(p->take_scan(s));
  CHECK_EQUAL(1440u, s.count);
  CHECK_EQUAL(107u, s.stamp_us);  // turn 2 starts at point 1440 = datagram 7, point 96
  // Counter-clockwise, sensor 0 deg = core -180 deg: sensor azimuth a -> core a - 180 deg.
  // Point 1440 + 10 (datagram 7, block 6, k 10 -> 2000 + 106 mm) sits at sensor 2.5 deg.
  Real r = 0, i = 0;
  CHECK(scan_lookup(s.view(), deg_to_rad(2.5 - 180), &r, &i));
  REAL_EQUAL(2.106, r, 1e-9);
  REAL_EQUAL(77.0, i, 1e-9);
}

TEST(Lakibeam, LastBlockReusesThePreviousStep) {
  auto p = make_parser();
  const auto d = datagram(100, 25);
  p->feed_datagram(d.data(), d.size(), 0);
  // Feed the turn's end and a wrap so the scan is published.
  auto w = datagram(36000 - 192 * 25 / 2, 25);
  p->feed_datagram(w.data(), w.size(), 0);
  p->reset();
  CHECK_EQUAL(0u, p->counters().bin_collisions);
  CHECK(p->counters().samples_discarded > 0);  // the first (partial, started at 1 deg) turn
}

TEST(Lakibeam, WrongSizeOrMarkersRejectedWhole) {
  auto p = make_parser();
  auto d = datagram(0, 25);
  CHECK_EQUAL(0u, p->feed_datagram(d.data(), 1205, 0));
  CHECK_EQUAL(1u, p->counters().bad_packets);
  std::vector<std::uint8_t> big(d);
  big.push_back(0);
  p->feed_datagram(big.data(), big.size(), 0);
  CHECK_EQUAL(2u, p->counters().bad_packets);
  auto m = d;
  m[500] = 0xFE;  // block 5 marker
  p->feed_datagram(m.data(), m.size(), 0);
  auto t = d;
  t[1205] = 0x38;
  p->feed_datagram(t.data(), t.size(), 0);
  auto a = d;
  a[302] = 0xFF;
  a[303] = 0xFF;  // azimuth 655.35 deg
  p->feed_datagram(a.data(), a.size(), 0);
  p->feed_datagram(nullptr, 0, 0);
  const auto& c = p->counters();
  CHECK_EQUAL(6u, c.bad_packets);
  CHECK_EQUAL(0u, c.packets);
  CHECK_EQUAL(0u, c.samples);
  CHECK_EQUAL(1205u + 1207u + 3u * 1206u, c.dropped_bytes);
  CHECK_EQUAL(c.bytes, c.bytes_accepted + c.dropped_bytes);
}

TEST(Lakibeam, EncoderRoundTrip) {
  LaserScan in;
  in.reset(1080, -deg_to_rad(135), deg_to_rad(0.25), 0);  // 270 deg industrial field of view
  for (std::size_t i = 0; i < in.count; ++i) {
    in.ranges_m[i] = (i % 23 == 0) ? 0.0 : 0.5 + 0.007 * static_cast<double>(i);
    in.intensities[i] = static_cast<double>(i % 256);
  }
  struct Sink {
    std::unique_ptr<LakibeamParser> p;
    std::size_t datagrams = 0;
  } sink{make_parser(), 0};
  LakibeamEncoder enc;
  enc.configure(LidarAngleConvention{false, -kPi});
  auto emit = [](const std::uint8_t* d, std::size_t n, void* u) {
    auto* s = static_cast<Sink*>(u);
    s->p->feed_datagram(d, n, 0);
    ++s->datagrams;
  };
  for (int t = 0; t < 3; ++t) enc.encode_scan(in.view(), 0, emit, &sink);
  CHECK_EQUAL(22u, sink.datagrams);  // 3 * 1440 / 192 = 22.5
  CHECK_EQUAL(2u, sink.p->counters().scans);
  LaserScan out;
  CHECK(sink.p->take_scan(out));
  CHECK_EQUAL(1440u, out.count);
  for (std::size_t i = 0; i < in.count; ++i) {
    Real r = -1, it = -1;
    CHECK(scan_lookup(out.view(), in.view().angle_rad(i), &r, &it));
    REAL_EQUAL(in.ranges_m[i], r, 0.0005 + 1e-12);
    REAL_EQUAL(in.ranges_m[i] > 0 ? in.intensities[i] : 0.0, it, 1e-9);
  }
  // Outside the 270 deg field of view: no return.
  Real r = -1, it = -1;
  CHECK(scan_lookup(out.view(), kPi, &r, &it));
  REAL_EQUAL(0.0, r, 0.0);
}

TEST(Lakibeam, Ld06PacketsOverUdpFeedTheLd06Parser) {
  auto p = std::make_unique<Ld06Parser>();
  CHECK(p->configure(Ld06Config{}));
  // Two datagrams each carrying several packets, the second starting mid-packet.
  std::vector<std::uint8_t> all;
  for (int k = 0; k < 40; ++k) {
    Ld06Packet pk;
    pk.speed_dps = 3600;
    pk.start_cdeg = static_cast<std::uint16_t>((k * 960) % 36000);
    pk.end_cdeg = static_cast<std::uint16_t>((k * 960 + 880) % 36000);
    std::uint8_t b[47];
    ld06_encode_packet(pk, b);
    all.insert(all.end(), b, b + 47);
  }
  p->feed(all.data(), 1000, 0);
  p->feed(all.data() + 1000, all.size() - 1000, 0);
  CHECK_EQUAL(40u, p->counters().packets);
  CHECK_EQUAL(1u, p->counters().scans);
}

TEST(Lakibeam, RecordedCaptureGivesExactCounters) {
  const auto cap = read_capture("lakibeam_capture.bin");
  CHECK_EQUAL(20u * 1206u, cap.size());
  auto p = make_parser();
  std::vector<LaserScan> scans;
  for (std::size_t off = 0; off < cap.size(); off += 1206) {
    if (p->feed_datagram(cap.data() + off, 1206, off) > 0) {
      scans.emplace_back();
      CHECK(p->take_scan(scans.back()));
    }
  }
  const auto& c = p->counters();
  CHECK_EQUAL(2u, c.scans);
  CHECK_EQUAL(1u, c.bad_packets);
  CHECK_EQUAL(19u, c.packets);
  CHECK_EQUAL(1206u, c.dropped_bytes);
  CHECK_EQUAL(2u, scans.size());
  for (int j = 0; j < 1440; ++j) {
    Real r = -1, i = -1;
    CHECK(scan_lookup(scans[0].view(), deg_to_rad(0.25 * j - 180), &r, &i));
    REAL_EQUAL(capture_dist_mm(j) / 1000.0, r, 1e-9);
  }
}
