// dockd's status object at its longest: every string at the longest name it can take, every counter at the largest
// value of its type, every real at its widest printed form — written by the real status writer and sent by the real
// host protocol, so the reply measured is the datagram dockd sends. It must fit one datagram (hal::kMaxHostReply, the
// newline the link appends included) and parse as JSON.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "daemon.hpp"
#include "dockcore/control/controllers.hpp"
#include "fake_host_link.hpp"
#include "host_protocol.hpp"
#include "status.hpp"

#include "CppUTest/TestHarness.h"

namespace {

using dockcore::hal::kMaxHostReply;
using dockd::CameraValues;
using dockd::StatusValues;

using dockd_test::FakeRequestLink;

/// The daemon's side: the status as write_status writes `status` (and the camera groups that fit, as the daemon
/// does); `extra_bytes` > 0 adds a field of that many bytes, a status that cannot fit.
struct FakeActions final : dockd::HostActions {
  dockd::DockdConfig cfg;
  StatusValues status;
  CameraValues camera;
  std::size_t extra_bytes = 0;

  void status_fields(dockd::JsonWriter& w, std::uint64_t) const override {
    dockd::write_status(w, status);
    if (extra_bytes > 0) w.str("extra", std::string(extra_bytes, 'x').c_str());
    dockd::write_camera_groups(w, camera, true);
  }
  void camera_fields(dockd::JsonWriter& w) const override { dockd::write_camera_groups(w, camera, false); }
  void counter_fields(dockd::JsonWriter& w, std::uint64_t) const override { dockd::write_counters_part(w, status); }
  const dockd::DockdConfig& config() const override { return cfg; }
  std::uint16_t active_dock_id() const override { return 0; }
  dockcore::SubmitResult submit(dockcore::HostCommandType, std::uint16_t, std::uint32_t, std::uint32_t&) override {
    return dockcore::SubmitResult::kQueued;
  }
  void start_teach(const dockd::HostRequest&, std::uint64_t) override {}
  void cancel_teach(std::uint64_t) override {}
  void log_event(dockd::EventLine&, dockd::LogLevel) override {}
};

/// The longest of `name(i)` for every value i of an enum whose underlying type is `U` (out-of-range values included:
/// whatever the name function answers for them is what the status would carry).
template <class U, class F>
const char* longest_name(F name) {
  const char* best = "";
  for (std::uint32_t i = 0; i <= std::numeric_limits<U>::max(); ++i) {
    const char* n = name(static_cast<U>(i));
    if (n != nullptr && std::strlen(n) > std::strlen(best)) best = n;
  }
  return best;
}

template <class T>
T max_of(const T&) {
  return std::numeric_limits<T>::max();
}

/// The widest a status real prints: negative, just under kStatusRealLimit (rounds to -1000000.0000 at 4 decimals).
double widest_real() {
  return -std::nextafter(dockd::kStatusRealLimit, 0.0);
}

/// The longest phase name of every controller dockd can run, over every phase code.
const char* longest_phase_name() {
  dockcore::ControllerSet set(dockcore::Seed000Params{}, dockcore::Seed004Params{}, dockcore::Seed003Params{},
                              dockcore::SmoothParams{});
  const char* best = "";  // phase names are static strings
  for (const dockcore::DockingController* c : {static_cast<const dockcore::DockingController*>(&set.seed000),
                                               static_cast<const dockcore::DockingController*>(&set.seed004),
                                               static_cast<const dockcore::DockingController*>(&set.seed003),
                                               static_cast<const dockcore::DockingController*>(&set.smooth)}) {
    for (unsigned p = 0; p <= 255; ++p) {
      const char* n = c->phase_name(static_cast<std::uint8_t>(p));
      if (n != nullptr && std::strlen(n) > std::strlen(best)) best = n;
    }
  }
  return best;
}

/// The longest status dockd can write.
StatusValues worst_status() {
  StatusValues v;
  const double r = widest_real();
  v.stamp_us = max_of(v.stamp_us);
  v.state = longest_name<std::uint8_t>(
      [](std::uint8_t i) { return dockcore::to_string(static_cast<dockcore::TaskState>(i)); });
  v.state_code = max_of(v.state_code);
  v.phase = max_of(v.phase);
  v.phase_name = longest_phase_name();
  v.fault = max_of(v.fault);
  v.fault_name = longest_name<std::uint16_t>(
      [](std::uint16_t i) { return dockcore::to_string(static_cast<dockcore::FaultCode>(i)); });
  v.watchdog_fault = max_of(v.watchdog_fault);
  v.retries = max_of(v.retries);
  v.dock_id = max_of(v.dock_id);
  v.dock_x_m = v.dock_y_m = v.dock_yaw_deg = r;
  v.last_command = longest_name<std::uint8_t>(
      [](std::uint8_t i) { return dockcore::to_string(static_cast<dockcore::CommandResult>(i)); });
  v.last_result = longest_name<std::uint8_t>(
      [](std::uint8_t i) { return dockd::to_string_result(static_cast<dockcore::TaskResult>(i)); });
  v.charge_current_a = v.battery_v = v.soc = r;
  v.odom_x_m = v.odom_y_m = v.odom_yaw_deg = r;
  v.cmd_vx_mps = v.cmd_wz_radps = r;
  v.wheels = dockcore::kMaxDriveWheels;
  for (std::size_t i = 0; i < dockcore::kMaxDriveWheels; ++i) v.deadband_fwd_radps[i] = v.deadband_rev_radps[i] = r;
  v.deadband_raises = max_of(v.deadband_raises);
  v.mount_swings = max_of(v.mount_swings);
  v.mount_calibration = longest_name<std::uint8_t>(
      [](std::uint8_t i) { return dockcore::to_string(static_cast<dockcore::MountCalibrationStatus>(i)); });
  v.mount_x_m = v.mount_y_m = r;
  v.ticks = v.tick_worst_us = v.tick_overruns = v.tick_work_worst_us = max_of(v.ticks);
  v.scans = v.detections = max_of(v.scans);
  v.lidar_crc_errors = v.lidar_resyncs = v.lidar_dropped_bytes = v.lidar_foreign_datagrams = max_of(v.scans);
  v.lidar_reconnects = v.lidar_late_scans = max_of(v.scans);
  v.lidar_intensity = longest_name<std::uint8_t>(
      [](std::uint8_t i) { return dockcore::to_string(static_cast<dockcore::IntensityVerdict>(i)); });
  v.can_bad_frames = v.can_send_failures = max_of(v.can_bad_frames);
  v.commands = v.commands_rejected = v.resumes = v.can_host_rejected = v.udp_not_allowed = max_of(v.commands);
  v.replies_too_long = max_of(v.replies_too_long);
  v.config_reloads = v.config_reloads_rejected = max_of(v.config_reloads);
  v.learned_saves = v.learned_save_failures = max_of(v.learned_saves);
  v.det_evidence_nats = r;
  for (double& c : v.det_cues_nats) c = r;
  const char* reject = longest_name<std::uint8_t>(
      [](std::uint8_t i) { return dockcore::to_string(static_cast<dockcore::RejectReason>(i)); });
  v.det_reject = std::strlen(reject) > 4 ? reject : "none";
  // Daemon's code reading: none, not_read, read, wrong, unread, no_dock.
  v.det_code = "not_read";
  v.det_code_dock = std::numeric_limits<decltype(v.det_code_dock)>::min();
  v.dock_evidence_nats = r;
  // Booleans at their longer spelling.
  v.dock_valid = v.charge_enable = v.contact = v.estop = v.lidar_stale = v.chassis_stale = false;
  v.teaching = v.taught = v.config_reload_pending = v.det_found = v.dock_confirmed = false;
  return v;
}

/// Every camera group present, at its longest.
CameraValues worst_camera() {
  CameraValues v;
  v.has_tags = v.has_stall_watch = v.has_camera = true;
  for (std::uint32_t& t : v.tags) t = max_of(t);
  v.stalled = false;
  v.camera.connected = false;
  v.camera.capture.frames = v.camera.capture.dropped = v.camera.capture.late = max_of(v.camera.capture.frames);
  v.camera.capture.corrupt = max_of(v.camera.capture.corrupt);
  v.camera.capture.reconnects = max_of(v.camera.capture.reconnects);
  v.camera.tag_id = std::numeric_limits<decltype(v.camera.tag_id)>::min();
  return v;
}

/// The datagram the UDP link sends for `json`: the object and its newline.
std::size_t datagram_bytes(const std::string& json) {
  return json.size() + 1;
}

}  // namespace

TEST_GROUP(DockdStatus) {
  FakeRequestLink link;
  FakeActions actions;
  dockd::DaemonCounters counters;

  void setup() override {
    link.subscribers = 1;
  }  // the stream goes out only with a subscriber
};

TEST(DockdStatus, TheLongestStatusFitsADatagramWithItsTaskDockAndDetection) {
  actions.status = worst_status();
  actions.camera = worst_camera();
  // The longest status reply as it would be without a datagram's limit: the prefix handle_udp writes, the main
  // fields and the counters, no camera group (those are dropped before the counters are).
  std::vector<char> big(8192);
  dockd::JsonWriter m(big.data(), big.size());
  m.boolean("ok", true).str("cmd", "status").uint("seq", 4294967295u);
  dockd::write_status(m, actions.status);
  const std::size_t whole = m.finish() + 1;  // + the newline the link appends
  CHECK(whole > 1);
  CHECK(nlohmann::json::parse(std::string(big.data(), whole - 1), nullptr, false).is_object());
  std::printf("\nlongest status reply with its counters: %zu bytes (one datagram: %zu)\n", whole, kMaxHostReply);

  dockd::HostProtocol p(&link, nullptr, actions, counters);
  link.pending.push_back("{\"cmd\":\"status\",\"seq\":4294967295}");
  p.poll(1000);
  CHECK_EQUAL(1u, link.replies.size());
  const std::string& reply = link.replies[0];
  std::printf("longest status reply sent: %zu bytes\n", datagram_bytes(reply));
  CHECK(datagram_bytes(reply) <= kMaxHostReply);
  const nlohmann::json j = nlohmann::json::parse(reply, nullptr, false);
  CHECK(!j.is_discarded());
  CHECK(j.is_object());
  // Whatever the values, the task, the dock and the detection go; the counters go whole or not at all.
  CHECK(j.at("ok").get<bool>());
  CHECK_EQUAL(4294967295u, j.at("seq").get<std::uint32_t>());
  CHECK(j.contains("state") && j.contains("fault_name") && j.contains("dock_x_m") && j.contains("det_code_dock"));
  CHECK(j.at("dock_confirmed").is_boolean());
  CHECK_EQUAL(dockcore::kEvidenceCueCount, j.at("det_cues_nats").size());
  CHECK_EQUAL(whole <= kMaxHostReply, j.contains("ticks"));
  CHECK_EQUAL(j.contains("ticks"), j.contains("config_reloads_rejected"));
  CHECK(!j.contains("tag_fused") || j.at("tag_refused").size() == dockcore::kTagStatusCount - 1);
  CHECK(!j.contains("camera_connected") || j.contains("camera_tag_id"));
  CHECK_EQUAL(0u, counters.replies_too_long);
}

TEST(DockdStatus, TheLongestCountersPartFitsWhole) {
  actions.status = worst_status();
  dockd::HostProtocol p(&link, nullptr, actions, counters);
  link.pending.push_back("{\"cmd\":\"status\",\"seq\":4294967295,\"part\":\"counters\"}");
  p.poll(1000);
  CHECK_EQUAL(1u, link.replies.size());
  const std::string& reply = link.replies[0];
  std::printf("\nworst-case counters part reply: %zu bytes\n", datagram_bytes(reply));
  CHECK(datagram_bytes(reply) <= kMaxHostReply);
  const nlohmann::json j = nlohmann::json::parse(reply, nullptr, false);
  CHECK(!j.is_discarded());
  CHECK(j.at("ok").get<bool>());
  STRCMP_EQUAL("counters", j.at("part").get<std::string>().c_str());
  CHECK_EQUAL(actions.status.ticks, j.at("ticks").get<std::uint64_t>());
  CHECK_EQUAL(actions.status.config_reloads_rejected, j.at("config_reloads_rejected").get<std::uint32_t>());
  CHECK_EQUAL(actions.status.learned_save_failures, j.at("learned_save_failures").get<std::uint32_t>());
  CHECK_FALSE(j.contains("state"));
}

TEST(DockdStatus, TheLongestCameraPartFitsWhole) {
  actions.camera = worst_camera();
  dockd::HostProtocol p(&link, nullptr, actions, counters);
  link.pending.push_back("{\"cmd\":\"status\",\"seq\":4294967295,\"part\":\"camera\"}");
  p.poll(1000);
  CHECK_EQUAL(1u, link.replies.size());
  const std::string& reply = link.replies[0];
  std::printf("\nworst-case camera part reply: %zu bytes\n", datagram_bytes(reply));
  CHECK(datagram_bytes(reply) <= kMaxHostReply);
  const nlohmann::json j = nlohmann::json::parse(reply, nullptr, false);
  CHECK(!j.is_discarded());
  CHECK(j.contains("tag_refused") && j.contains("camera_stalled") && j.contains("camera_tag_id"));
}

TEST(DockdStatus, TheLongestStreamObjectFitsAndParses) {
  actions.status = worst_status();
  actions.camera = worst_camera();
  dockd::HostProtocol p(&link, nullptr, actions, counters);
  p.publish_status(dockcore::hal::StatusMessage{}, 1000);
  CHECK_EQUAL(1u, link.published.size());
  std::printf("\nlongest status stream object sent: %zu bytes\n", datagram_bytes(link.published[0]));
  CHECK(datagram_bytes(link.published[0]) <= kMaxHostReply);
  const nlohmann::json j = nlohmann::json::parse(link.published[0], nullptr, false);
  CHECK(!j.is_discarded());
  CHECK(j.contains("type") && j.contains("state") && j.contains("det_found"));
}

TEST(DockdStatus, ARealBeyondTheLimitIsNull) {
  StatusValues v;
  v.dock_x_m = -dockd::kStatusRealLimit;
  v.odom_y_m = 1e300;
  v.det_cues_nats[0] = std::numeric_limits<double>::infinity();
  v.battery_v = 24.5;
  char buf[kMaxHostReply];
  dockd::JsonWriter w(buf, sizeof buf);
  dockd::write_status(w, v);
  const std::size_t n = w.finish();
  CHECK(n > 0);
  const nlohmann::json j = nlohmann::json::parse(std::string(buf, n));
  CHECK(j.at("dock_x_m").is_null());
  CHECK(j.at("odom_y_m").is_null());
  CHECK(j.at("det_cues_nats")[0].is_null());
  CHECK_EQUAL(24.5, j.at("battery_v").get<double>());
}

TEST(DockdStatus, AStatusThatDoesNotFitIsAnsweredWithAnErrorAndCounted) {
  actions.extra_bytes = 2 * kMaxHostReply;
  dockd::HostProtocol p(&link, nullptr, actions, counters);
  link.pending.push_back("{\"cmd\":\"status\",\"seq\":5}");
  p.poll(1000);
  CHECK_EQUAL(1u, link.replies.size());
  const nlohmann::json j = nlohmann::json::parse(link.replies[0], nullptr, false);
  CHECK(!j.is_discarded());
  CHECK(!j.at("ok").get<bool>());
  CHECK_EQUAL(5u, j.at("seq").get<std::uint32_t>());
  CHECK_EQUAL(10, j.at("code").get<int>());
  STRCMP_EQUAL("reply_too_long", j.at("error").get<std::string>().c_str());
  CHECK_EQUAL(1u, counters.replies_too_long);
  CHECK_EQUAL(0u, counters.commands_rejected);  // the request was good: not a refusal

  // The stream's subscribers get the error object too, counted the same.
  p.publish_status(dockcore::hal::StatusMessage{}, 2000);
  CHECK_EQUAL(1u, link.published.size());
  const nlohmann::json s = nlohmann::json::parse(link.published[0], nullptr, false);
  CHECK(!s.is_discarded());
  STRCMP_EQUAL("status", s.at("type").get<std::string>().c_str());  // a stream object, not a reply
  CHECK(!s.at("ok").get<bool>());
  CHECK_EQUAL(10, s.at("code").get<int>());
  STRCMP_EQUAL("reply_too_long", s.at("error").get<std::string>().c_str());
  CHECK(!s.contains("seq"));
  CHECK_EQUAL(2u, counters.replies_too_long);
}
