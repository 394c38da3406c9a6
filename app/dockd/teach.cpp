// dockd: teach — average the dock's detections while the robot sits on the charger and store the docked target.
#include "teach.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>

#include "daemon_internal.hpp"

namespace dockd {

namespace {

using dockcore::kMaxReflectors;

/// A read stripe agrees with a profile's own when each of its edges lies this close to the profile's: a few beam
/// spacings at charger range, far below a readable region's width (docs/docks.md, "Reflectors").
constexpr double kCodeMatchM = 0.010;

}  // namespace

Teacher::Teacher(const DockdConfig& config, TeachHooks& hooks)
    : cfg_(config), hooks_(hooks), samples_(std::make_unique<Pose2[]>(kMaxScans)) {}

Teacher::~Teacher() = default;

void Teacher::start(const HostRequest& r, const TeachConditions& c, std::uint64_t now_us) {
  const std::uint16_t id = r.has_dock_id ? r.dock_id : cfg_.default_dock_id;
  if (cfg_.find_dock(id) == nullptr) {
    char msg[96];
    std::snprintf(msg, sizeof msg, "dock id %u is not in the dock database", id);
    hooks_.reply_error(r, HostErrorCode::kUnknownDockId, msg);
    return;
  }
  if (active_) {
    hooks_.reply_error(r, HostErrorCode::kBusy, "a teach is already running");
    return;
  }
  const TaskState s = c.state;
  if (!(s == TaskState::kNotTasking || s == TaskState::kFinishTasking || s == TaskState::kFault)) {
    hooks_.reply_error(r, HostErrorCode::kTeachFailed, "teach needs an idle robot (stop the running task first)");
    return;
  }
  if (!c.on_charger) {
    hooks_.reply_error(r, HostErrorCode::kTeachFailed, "teach needs the robot on the charger: contacts are not closed");
    return;
  }
  if (!c.lidar_fresh) {
    hooks_.reply_error(r, HostErrorCode::kTeachFailed, "teach needs the lidar: no fresh scans");
    return;
  }
  // Detections against the dock's own profile, without any earlier correction (that is what is being measured).
  if (!hooks_.configure_core(id, true)) {
    hooks_.reply_error(r, HostErrorCode::kTeachFailed, "dock profile refused");
    return;
  }
  active_ = true;
  dock_id_ = id;
  wanted_ = r.scans != 0 ? r.scans : cfg_.teach_scans;
  if (wanted_ > kMaxScans) wanted_ = kMaxScans;  // the parser and the config bound both to 1..kMaxScans already
  have_ = 0;
  sx_ = sy_ = sc_ = ss_ = 0;
  for (PatternVote& v : votes_) v = PatternVote{};
  intensity_unusable_ = 0;
  deadline_us_ = now_us + static_cast<std::uint64_t>(cfg_.teach_timeout_s * 1e6);
  request_ = r;
  EventLine e(now_us, "teach_start");
  e.w.uint("dock_id", id).uint("scans", wanted_);
  hooks_.log_event(e, LogLevel::kInfo);
}

void Teacher::sample(const dockcore::DockEstimate& e, const dockcore::ScanView& scan, bool intensity_usable) {
  if (!active_ || have_ >= wanted_) return;
  samples_[have_++] = e.pose;
  sx_ += static_cast<double>(e.pose.x_m);
  sy_ += static_cast<double>(e.pose.y_m);
  sc_ += std::cos(static_cast<double>(e.pose.yaw_rad));
  ss_ += std::sin(static_cast<double>(e.pose.yaw_rad));
  if (!intensity_usable) {
    ++intensity_unusable_;
    return;
  }
  // The stripes at the detected pose, on the dock's own profile (the one the core was configured with for the teach).
  const DockEntry* d = cfg_.find_dock(dock_id_);
  if (d == nullptr) return;
  const dockcore::StripeRead r =
      dockcore::read_reflector_stripes(scan, cfg_.lidar_mount, d->profile, e.pose, stripe_read_params(cfg_));
  if (r.status != dockcore::StripeReadStatus::kOk) return;  // unread: a vote for no pattern
  PatternVote& v = votes_[r.count];
  for (std::size_t q = 0; q < r.count; ++q) {
    if (v.scans > 0 && v.segments[q] != r.stripes[q].segment) return;
  }
  for (std::size_t q = 0; q < r.count; ++q) {
    v.segments[q] = r.stripes[q].segment;
    const double edge[2] = {static_cast<double>(r.stripes[q].from_m), static_cast<double>(r.stripes[q].to_m)};
    for (int k = 0; k < 2; ++k) {
      v.sum_m[q][k] += edge[k];
      v.min_m[q][k] = v.scans == 0 ? edge[k] : std::fmin(v.min_m[q][k], edge[k]);
      v.max_m[q][k] = v.scans == 0 ? edge[k] : std::fmax(v.max_m[q][k], edge[k]);
    }
  }
  ++v.scans;
}

void Teacher::finish(bool ok, const char* why, std::uint64_t now_us) {
  const HostRequest r = request_;
  const std::uint16_t id = dock_id_;
  active_ = false;
  if (!ok) {
    hooks_.configure_core(hooks_.active_dock_id(), false);
    hooks_.reply_error(r, HostErrorCode::kTeachFailed, why);
    return;
  }
  const double n = have_;
  TaughtTarget t;
  t.dock_id = id;
  t.target = Pose2{static_cast<Real>(sx_ / n), static_cast<Real>(sy_ / n), static_cast<Real>(std::atan2(ss_, sc_))};
  t.scans = have_;
  double spread = 0;
  for (std::uint16_t i = 0; i < have_; ++i) {
    spread = std::fmax(spread, std::hypot(static_cast<double>(samples_[i].x_m - t.target.x_m),
                                          static_cast<double>(samples_[i].y_m - t.target.y_m)));
  }
  t.spread_m = spread;
  t.taught_unix_s = static_cast<std::uint64_t>(std::time(nullptr));
  // The code: the stripe pattern a majority of the scans read, its edges averaged. A profile with its own stripes
  // keeps them; the teach then says whether what it read agrees.
  const DockEntry* dock = cfg_.find_dock(id);
  const bool own_code = dock != nullptr && dock->profile.reflector_count > 0;
  const char* code = "unread";
  int best = -1;
  for (std::size_t c = 0; c <= dockcore::kMaxReflectors; ++c) {
    if (2u * votes_[c].scans > have_) best = static_cast<int>(c);
  }
  dockcore::ReflectorStripe read[dockcore::kMaxReflectors];
  std::size_t read_n = 0;
  double code_spread = 0;
  bool code_matches = false;
  if (2u * intensity_unusable_ >= have_) {
    code = "intensity_unusable";
    best = -1;
  } else if (best >= 0) {
    const PatternVote& v = votes_[best];
    read_n = static_cast<std::size_t>(best);
    for (std::size_t q = 0; q < read_n; ++q) {
      const double from = v.sum_m[q][0] / v.scans;
      const double to = v.sum_m[q][1] / v.scans;
      read[q].segment = v.segments[q];
      read[q].from_m = static_cast<Real>(from);
      read[q].to_m = static_cast<Real>(to);
      code_spread = std::fmax(code_spread, std::fmax(v.max_m[q][0] - from, from - v.min_m[q][0]));
      code_spread = std::fmax(code_spread, std::fmax(v.max_m[q][1] - to, to - v.min_m[q][1]));
    }
    if (own_code) {
      code = "profile";
      code_matches = dockcore::same_stripes(dock->profile.reflectors, dock->profile.reflector_count, read, read_n,
                                            static_cast<Real>(kCodeMatchM));
    } else if (read_n == 0) {
      code = "none";
    } else {
      // The averaged stripes must make a valid profile (on their segments, apart): otherwise no code is stored.
      dockcore::DockProfile check = dock != nullptr ? dock->profile : dockcore::DockProfile{};
      bool valid = dock != nullptr;
      for (std::size_t q = 0; q < read_n && valid; ++q) {
        valid = dockcore::add_reflector(check, read[q]) == dockcore::ProfileError::kOk;
      }
      if (valid) {
        code = "taught";
        for (std::size_t q = 0; q < read_n; ++q) t.stripes[q] = read[q];
        t.stripe_count = static_cast<std::uint8_t>(read_n);
        t.code_scans = v.scans;
        t.code_spread_m = code_spread;
      } else {
        code = "invalid";
      }
    }
  }
  // A moving robot or a detection flipping between two fits would teach garbage: 2 cm is far beyond lidar noise
  // averaged over a still robot.
  if (spread > 0.02) {
    hooks_.configure_core(id, false);
    char msg[128];
    std::snprintf(msg, sizeof msg, "detections spread %.1f mm (> 20 mm): robot moving or dock ambiguous", spread * 1e3);
    hooks_.reply_error(r, HostErrorCode::kTeachFailed, msg);
    return;
  }
  std::string err;
  if (!hooks_.store_target(t, err)) {
    hooks_.configure_core(id, false);
    hooks_.reply_error(r, HostErrorCode::kTeachFailed, ("state file: " + err).c_str());
    return;
  }
  hooks_.configure_core(id, false);
  const Pose2 nom = nominal_docked_target(cfg_);
  // The taught target, once for the event and once inside the reply.
  char tb[640];
  JsonWriter target(tb, sizeof tb);
  target.uint("dock_id", id)
      .uint("scans", t.scans)
      .real("target_x_m", static_cast<double>(t.target.x_m), 4)
      .real("target_y_m", static_cast<double>(t.target.y_m), 4)
      .real("target_yaw_deg", deg(t.target.yaw_rad), 3)
      .str("code", code);
  if (best >= 0) {
    // [[segment, from_m, to_m], ...]
    char arr[kMaxReflectors * 32 + 4];
    std::size_t len = 0;
    arr[len++] = '[';
    for (std::size_t q = 0; q < read_n; ++q) {
      const int w = std::snprintf(arr + len, sizeof arr - len, "%s[%u,%.4f,%.4f]", q > 0 ? "," : "", read[q].segment,
                                  static_cast<double>(read[q].from_m), static_cast<double>(read[q].to_m));
      if (w > 0) len += static_cast<std::size_t>(w);
    }
    arr[len++] = ']';
    target.raw("stripes", arr, len).uint("code_scans", votes_[best].scans).real("code_spread_mm", code_spread * 1e3, 1);
    if (own_code) target.boolean("code_matches", code_matches);
  }
  char buf[1024];
  JsonWriter reply(buf, sizeof buf);
  reply.boolean("ok", true)
      .str("cmd", "teach")
      .uint("seq", r.seq)
      .fields(target.body(), target.body_len())
      .real("spread_mm", spread * 1e3, 2)
      .real("offset_x_mm", static_cast<double>(t.target.x_m - nom.x_m) * 1e3, 1)
      .real("offset_y_mm", static_cast<double>(t.target.y_m - nom.y_m) * 1e3, 1)
      .real("offset_yaw_deg", deg(dockcore::wrap_angle(t.target.yaw_rad - nom.yaw_rad)), 3);
  hooks_.reply(r, buf, reply.finish());
  EventLine e(now_us, "teach_done");
  e.w.fields(target.body(), target.body_len());
  hooks_.log_event(e, LogLevel::kInfo);
}

void Teacher::cancel(std::uint64_t now_us) {
  if (active_) finish(false, "cancelled by stop", now_us);
}

void Teacher::progress(std::uint64_t now_us) {
  if (!active_) return;
  if (have_ >= wanted_) {
    finish(true, "", now_us);
  } else if (now_us >= deadline_us_) {
    char msg[128];
    std::snprintf(msg, sizeof msg, "only %u of %u scans saw the dock within %.0f s", have_, wanted_,
                  cfg_.teach_timeout_s);
    finish(false, msg, now_us);
  }
}

}  // namespace dockd
