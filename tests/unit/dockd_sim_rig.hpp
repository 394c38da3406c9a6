#pragma once
// In-memory HAL fakes that close dockd's loop through dockcore_sim (the simulated chassis behind hal::ChassisLink,
// the lidar simulator behind hal::LidarSource, a CAN host, a simulated clock), and the default scenario's robot as
// a dockd config. Shared by test_dockd_daemon.cpp and test_dockd_heap.cpp. Test code: heap allowed.
#include <cstdint>
#include <memory>
#include <string>

#include "config.hpp"
#include "daemon.hpp"
#include "docksim/chassis.hpp"
#include "docksim/lidar_sim.hpp"
#include "docksim/scenario.hpp"
#include "docksim/sim_run.hpp"

namespace dockd_test {

inline std::string default_scenario_path() { return std::string(DOCKCORE_SOURCE_DIR) + "/tools/scenarios/default.toml"; }

struct SimClock final : dockcore::hal::Clock {
  std::uint64_t t = 1000000;
  std::uint64_t now_us() const override { return t; }
};

struct SimChassis final : dockcore::hal::ChassisLink {
  docksim::Chassis* ch = nullptr;
  const SimClock* clock = nullptr;
  bool silent = false;  // feedback stops (the base or the bus died)
  dockcore::hal::ChassisFeedback fb{};
  dockcore::hal::ChassisCounters c{};
  dockcore::hal::WheelCommand last{};
  int sends = 0;
  bool send_wheels(const dockcore::hal::WheelCommand& w) override {
    last = w;
    ++sends;
    docksim::WheelRadps r{};
    for (std::size_t i = 0; i < w.count && i < 4; ++i) r[i] = static_cast<double>(w.radps[i]);
    ch->command_wheels(r);
    return true;
  }
  bool relay_broken = false;  ///< The base's charger relay never closes (the charger delivers no current).
  bool request_charging(bool on) override {
    ch->set_charging_inhibited(!on || relay_broken);  // the base's charger relay
    return true;
  }
  const dockcore::hal::ChassisFeedback& poll() override {
    const docksim::ChassisState& s = ch->state();
    if (!silent && s.responding) {
      for (std::size_t i = 0; i < 4; ++i) fb.wheel_radps[i] = static_cast<dockcore::Real>(s.wheel_measured_radps[i]);
      fb.wheels_stamp_us = clock->t;
      fb.charging_contact = s.contact;
      fb.battery_current_a = static_cast<dockcore::Real>(s.charge_current_a);
      fb.battery_voltage_v = static_cast<dockcore::Real>(s.battery_voltage_v);
      fb.soc = static_cast<dockcore::Real>(s.battery_soc);
      fb.power_stamp_us = fb.status_stamp_us = clock->t;
    }
    return fb;
  }
  int fd() const override { return -1; }
  const dockcore::hal::ChassisCounters& counters() const override { return c; }
};

struct SimLidar final : dockcore::hal::LidarSource {
  std::unique_ptr<dockcore::LaserScan> scan = std::make_unique<dockcore::LaserScan>();
  bool pending = false;
  dockcore::hal::LidarCounters c{};
  const dockcore::LaserScan* poll_scan() override {
    if (!pending) return nullptr;
    pending = false;
    return scan.get();
  }
  int fd() const override { return -1; }
  const dockcore::hal::LidarCounters& counters() const override { return c; }
};

struct FakeHost final : dockcore::hal::HostLink {
  bool has = false;
  dockcore::hal::HostCommandMessage next{};
  dockcore::hal::StatusMessage last{};
  int statuses = 0;
  void command(std::uint8_t cmd, std::uint16_t dock) {
    next.command = cmd;
    next.dock_id = dock;
    ++next.sequence;
    has = true;
  }
  bool poll_command(dockcore::hal::HostCommandMessage& out) override {
    if (!has) return false;
    out = next;
    has = false;
    return true;
  }
  bool send_status(const dockcore::hal::StatusMessage& s) override {
    last = s;
    ++statuses;
    return true;
  }
  int fd() const override { return -1; }
  std::uint32_t host_commands_rejected() const override { return 0; }
};

/// dockd's config for the scenario's robot (drive, limits, footprint, lidar mount, estimator, task, smooth
/// controller) with dock 0 of the scenario's profile; the caller sets files and further docks.
inline dockd::DockdConfig scenario_config(const docksim::Scenario& sc) {
  dockd::DockdConfig cfg;
  cfg.drive = docksim::core_drive_geometry(sc.chassis.geometry);
  cfg.limits = sc.limits;
  cfg.footprint = sc.safety;
  cfg.lidar_mount = sc.lidar_mount;
  cfg.estimator = sc.estimator;
  cfg.task = sc.task;
  cfg.smooth = sc.smooth;
  cfg.pad_reach_m = static_cast<double>(sc.smooth.common.pad_reach_m);
  cfg.pads_rear = sc.smooth.backwards;
  dockd::DockEntry d0;
  d0.id = 0;
  d0.profile = sc.profile;
  cfg.docks = {d0};
  cfg.task.accepted_dock_ids = 1u;
  return cfg;
}

/// The scenario's chassis (seed 11) with its dock placed, wired to `link` on `clock`.
inline std::unique_ptr<docksim::Chassis> scenario_chassis(const docksim::Scenario& sc, SimChassis& link,
                                                          const SimClock& clock) {
  auto chassis = std::make_unique<docksim::Chassis>(sc.chassis, 11);
  docksim::DockPlacement dp;
  dp.pose_world = sc.dock_pose;
  dp.face_half_width_m = sc.dock_face_half_width_m;
  chassis->set_dock(dp);
  link.ch = chassis.get();
  link.clock = &clock;
  return chassis;
}

}  // namespace dockd_test
