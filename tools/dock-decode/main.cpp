// dock-decode: candump logs (and dockd's session record) -> readable timeline of dockcore CAN v1 / AgileX V2 frames,
// with counter/checksum/length errors, gaps over twice a frame's period, a summary, JSON and an SVG plot.
// Usage and output: docs/can.md "dock-decode".
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "candump_line.hpp"
#include "dockcore/protocols/can/can_agilex_v2.hpp"
#include "dockcore/protocols/can/can_dockcore_v1.hpp"
#include "dockcore/task/faults.hpp"
#include "dockcore/task/task_manager.hpp"
#include "docksim/svg.hpp"

namespace {

using dockcore::CanFrame;
namespace v1 = dockcore::can_v1;
namespace agx = dockcore::agilex_v2;
using nlohmann::json;

struct Signal {
  std::string name;
  double value;
  std::string unit;
  std::string text;  // enum name etc., optional
};

struct Decoded {
  std::string name;            // frame name, "unknown" for ids of neither profile
  std::vector<Signal> signals;
  std::string error;           // "" or CanV1Error / AgxError name
  std::uint32_t period_ms = 0;
};

struct IdStats {
  std::string name;
  std::uint64_t frames = 0;
  std::uint64_t errors = 0;
  std::uint64_t gaps = 0;
  bool have_last = false;
  std::uint64_t last_us = 0;
};

struct Options {
  std::string profile = "dockcore-v1";
  std::uint32_t chassis_base = v1::kDefaultChassisBaseId;
  std::uint32_t host_base = v1::kDefaultHostBaseId;
};

const char* command_name(unsigned c) {
  switch (c) {
    case 1: return "dock";
    case 2: return "cancel";
    case 3: return "undock";
    case 4: return "test_mode";
    default: return "unknown";
  }
}

class Decoder {
 public:
  explicit Decoder(const Options& o) : opt_(o), ids_{o.chassis_base, o.host_base}, checker_(ids_) {}

  Decoded decode(const CanFrame& f) {
    Decoded d;
    if (opt_.profile == "agilex-v2" && !f.extended && agx::frame_name(f.id) != nullptr) {
      decode_agilex(f, d);
      return d;
    }
    const bool in_range = !f.extended && v1::classify(ids_, f.id) != v1::MessageKind::kUnknown &&
                          (opt_.profile == "dockcore-v1" || v1::classify(ids_, f.id) >= v1::MessageKind::kHostCommand);
    if (!in_range) {
      d.name = "unknown";
      return d;
    }
    v1::MessageKind kind;
    const v1::CanV1Error e = checker_.check(f, kind);
    d.name = v1::to_string(kind);
    d.period_ms = v1::period_ms(kind);
    if (e != v1::CanV1Error::kOk) d.error = v1::to_string(e);
    if (e == v1::CanV1Error::kBadLength || e == v1::CanV1Error::kBadChecksum || e == v1::CanV1Error::kExtendedId)
      return d;  // bytes not trusted: no signals
    const double mps = v1::kWheelMpsPerBit;
    auto add = [&d](const std::string& n, double v, const std::string& u = "", const std::string& t = "") {
      d.signals.push_back({n, v, u, t});
    };
    switch (kind) {
      case v1::MessageKind::kWheelCmdA:
      case v1::MessageKind::kWheelCmdB: {
        v1::WheelCommandFrame m;
        v1::decode(ids_, f, m);
        const int b = m.rear ? 2 : 0;
        add("wheel" + std::to_string(b), m.wheel_mmps[0] * mps, "m/s");
        add("wheel" + std::to_string(b + 1), m.wheel_mmps[1] * mps, "m/s");
        add("enable", m.enable);
        if (m.four_wheel) add("four_wheel", 1);
        add("counter", m.counter);
        break;
      }
      case v1::MessageKind::kChargeRequest: {
        v1::ChargeRequestFrame m;
        v1::decode(ids_, f, m);
        add("charge_enable", m.enable);
        add("counter", m.counter);
        break;
      }
      case v1::MessageKind::kWheelFbA:
      case v1::MessageKind::kWheelFbB: {
        v1::WheelFeedbackFrame m;
        v1::decode(ids_, f, m);
        const int b = m.rear ? 2 : 0;
        add("wheel" + std::to_string(b), m.wheel_mmps[0] * mps, "m/s");
        add("wheel" + std::to_string(b + 1), m.wheel_mmps[1] * mps, "m/s");
        add("counter", m.counter);
        break;
      }
      case v1::MessageKind::kEncoderA:
      case v1::MessageKind::kEncoderB: {
        v1::EncoderFrame m;
        v1::decode(ids_, f, m);
        const int b = m.rear ? 2 : 0;
        add("encoder" + std::to_string(b), m.counts[0], "counts");
        add("encoder" + std::to_string(b + 1), m.counts[1], "counts");
        add("counter", m.counter);
        break;
      }
      case v1::MessageKind::kPower: {
        v1::PowerFrame m;
        v1::decode(ids_, f, m);
        add("voltage", m.voltage_10mv * v1::kVoltsPerBit, "V");
        add("current", m.current_10ma * v1::kAmpsPerBit, "A");
        add("soc", m.soc_pct, "%", m.soc_pct == 255 ? "unknown" : "");
        add("contact", m.contact);
        add("relay", m.charge_relay);
        add("counter", m.counter);
        break;
      }
      case v1::MessageKind::kChassisStatus: {
        v1::ChassisStatusFrame m;
        v1::decode(ids_, f, m);
        static const char* modes[] = {"standby", "can_control", "manual", "fault"};
        add("mode", m.mode, "", m.mode < 4 ? modes[m.mode] : "?");
        add("estop", m.estop);
        add("fault_bits", m.fault_bits);
        add("last_cmd_counter", m.last_cmd_counter);
        add("counter", m.counter);
        break;
      }
      case v1::MessageKind::kHostCommand: {
        v1::HostCommandFrame m;
        v1::decode(ids_, f, m);
        add("command", m.command, "", command_name(m.command));
        add("dock_id", m.dock_id);
        add("sequence", m.sequence);
        add("counter", m.counter);
        break;
      }
      case v1::MessageKind::kDockStatus: {
        v1::DockStatusFrame m;
        v1::decode(ids_, f, m);
        add("state", m.task_state, "", m.task_state <= 9 ? dockcore::to_string(static_cast<dockcore::TaskState>(m.task_state)) : "?");
        add("phase", m.align_phase);
        add("fault", m.fault_code, "",
            m.fault_code == 0 || (m.fault_code >= dockcore::kFirstFaultCode && m.fault_code <= dockcore::kLastFaultCode)
                ? dockcore::to_string(static_cast<dockcore::FaultCode>(m.fault_code))
                : "?");
        add("retries", m.retries);
        add("last_result", m.last_result, "",
            m.last_result <= 6 ? dockcore::to_string(static_cast<dockcore::CommandResult>(m.last_result)) : "?");
        add("last_seq_lo", m.last_seq_lo);
        add("counter", m.counter);
        break;
      }
      case v1::MessageKind::kDockPose: {
        v1::DockPoseFrame m;
        v1::decode(ids_, f, m);
        add("x", m.x_mm * v1::kPoseMetresPerBit, "m");
        add("y", m.y_mm * v1::kPoseMetresPerBit, "m");
        add("yaw", m.yaw_100urad * v1::kYawRadPerBit, "rad");
        add("valid", m.valid);
        add("counter", m.counter);
        break;
      }
      default:
        break;
    }
    return d;
  }

 private:
  void decode_agilex(const CanFrame& f, Decoded& d) {
    d.name = agx::frame_name(f.id);
    d.period_ms = agx::period_ms(f.id);
    auto add = [&d](const std::string& n, double v, const std::string& u = "", const std::string& t = "") {
      d.signals.push_back({n, v, u, t});
    };
    agx::AgxError e = agx::AgxError::kOk;
    switch (f.id) {
      case agx::kIdControlMode: {
        agx::ControlModeFrame m;
        if ((e = agx::decode(f, m)) == agx::AgxError::kOk) add("mode", m.mode, "", m.mode == 1 ? "can_command" : "standby");
        break;
      }
      case agx::kIdMotionCommand:
      case agx::kIdMotionState: {
        agx::MotionCommandFrame m;
        CanFrame g = f;
        g.id = agx::kIdMotionCommand;  // same layout
        if ((e = agx::decode(g, m)) == agx::AgxError::kOk) {
          add("linear", m.linear_mmps * agx::kMpsPerBit, "m/s");
          add("angular", m.angular_mradps * agx::kRadpsPerBit, "rad/s");
          add("lateral", m.lateral_mmps * agx::kMpsPerBit, "m/s");
          add("steering", m.steering_mrad * agx::kRadPerBit, "rad");
        }
        break;
      }
      case agx::kIdSystemState: {
        agx::SystemStateFrame m;
        if ((e = agx::decode(f, m)) == agx::AgxError::kOk) {
          static const char* st[] = {"normal", "estop", "exception"};
          add("state", m.vehicle_state, "", m.vehicle_state < 3 ? st[m.vehicle_state] : "?");
          add("mode", m.control_mode);
          add("voltage", m.voltage_100mv * agx::kVoltsPerBit, "V");
          add("error_code", m.error_code);
          add("count", m.count);
        }
        break;
      }
      case agx::kIdOdometry: {
        agx::OdometryFrame m;
        if ((e = agx::decode(f, m)) == agx::AgxError::kOk) {
          add("left", m.left_mm * agx::kOdomMetresPerBit, "m");
          add("right", m.right_mm * agx::kOdomMetresPerBit, "m");
        }
        break;
      }
      case agx::kIdBms: {
        agx::BmsFrame m;
        if ((e = agx::decode(f, m)) == agx::AgxError::kOk) {
          add("soc", m.soc_pct, "%");
          add("soh", m.soh_pct, "%");
          add("voltage", m.voltage_100mv * agx::kVoltsPerBit, "V");
          add("current", m.current_100ma * agx::kAmpsPerBit, "A");
          add("temperature", m.temperature_100mdegc * agx::kDegCPerBit, "degC");
        }
        break;
      }
      default:
        break;
    }
    if (e != agx::AgxError::kOk) d.error = agx::to_string(e);
  }

  Options opt_;
  v1::Ids ids_;
  v1::FrameChecker checker_;
};

std::string fmt(double v) {
  char b[32];
  if (v == static_cast<double>(static_cast<long long>(v)) && v < 1e15 && v > -1e15)
    std::snprintf(b, sizeof b, "%lld", static_cast<long long>(v));
  else
    std::snprintf(b, sizeof b, "%.3f", v);
  return b;
}

std::uint32_t parse_id(const std::string& s) { return static_cast<std::uint32_t>(std::stoul(s, nullptr, 0)); }

struct Point {
  double t;
  double v;
};

void write_svg(const std::string& path, double t_end, const std::map<std::string, std::vector<Point>>& series) {
  const double dur = std::max(1.0, t_end);
  const double panel = dur * 0.22;  // world height of one panel
  const double gap = dur * 0.05;
  docksim::SvgBounds b;
  b.add(0, 0);
  b.add(dur, 3 * panel + 2 * gap);
  docksim::SvgCanvas c(b, 1000.0 / dur, 40.0);
  c.title("dock-decode: velocities (top), task state (middle), fault code (bottom) over " + fmt(dur) + " s");
  struct Panel {
    double y0;
    std::vector<std::string> keys;
    std::vector<std::string> colours;
    const char* label;
  };
  const std::vector<Panel> panels = {
      {2 * panel + 2 * gap, {"cmd0", "cmd1", "meas0", "meas1"}, {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728"}, "m/s"},
      {panel + gap, {"state"}, {"#9467bd"}, "state"},
      {0, {"fault"}, {"#d62728"}, "fault"}};
  const std::map<std::string, std::string> legend = {
      {"cmd0", "commanded wheel 0 / linear"}, {"cmd1", "commanded wheel 1 / angular"},
      {"meas0", "measured wheel 0 / linear"}, {"meas1", "measured wheel 1 / angular"},
      {"state", "task state (0..9)"},         {"fault", "fault code (0, 177..190)"}};
  for (const Panel& p : panels) {
    double lo = 0, hi = 0;
    bool any = false;
    for (const std::string& k : p.keys) {
      auto it = series.find(k);
      if (it == series.end()) continue;
      for (const Point& q : it->second) {
        lo = any ? std::min(lo, q.v) : q.v;
        hi = any ? std::max(hi, q.v) : q.v;
        any = true;
      }
    }
    if (std::string(p.label) == "state") lo = 0, hi = 9;
    if (std::string(p.label) == "fault") lo = 0, hi = std::max(hi, 190.0);
    if (hi - lo < 1e-9) hi = lo + 1;
    c.line({0, p.y0}, {dur, p.y0}, docksim::SvgStyle::line("#bbbbbb"));
    c.line({0, p.y0 + panel}, {dur, p.y0 + panel}, docksim::SvgStyle::line("#bbbbbb"));
    c.text_px({0, p.y0 + panel}, 4, 12, std::string(p.label) + " " + fmt(lo) + " .. " + fmt(hi), 11, "#555555");
    for (std::size_t i = 0; i < p.keys.size(); ++i) {
      auto it = series.find(p.keys[i]);
      if (it == series.end() || it->second.empty()) continue;
      std::vector<dockcore::Vec2> pts;
      for (const Point& q : it->second)
        pts.emplace_back(static_cast<dockcore::Real>(q.t),
                         static_cast<dockcore::Real>(p.y0 + (q.v - lo) / (hi - lo) * panel));
      c.polyline(pts, docksim::SvgStyle::line(p.colours[i], 1.2));
      c.legend(legend.at(p.keys[i]), docksim::SvgStyle::line(p.colours[i], 2));
    }
  }
  std::string err;
  if (!c.write(path, &err)) throw std::runtime_error("cannot write " + path + ": " + err);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"dock-decode: decode candump logs / dockd session records of dockcore CAN v1 or AgileX V2"};
  std::string log;
  Options opt;
  std::string chassis_base = "0x100", host_base = "0x180";
  bool strict = false, strict_gaps = false, as_json = false, quiet = false;
  std::string svg;
  app.add_option("log", log, "candump -L / -l log or dockd session record ('-' = stdin)")->required();
  app.add_option("--profile", opt.profile, "chassis profile: dockcore-v1 | agilex-v2")
      ->check(CLI::IsMember({"dockcore-v1", "agilex-v2"}));
  app.add_option("--chassis-base", chassis_base, "dockcore v1 chassis base id (default 0x100)");
  app.add_option("--host-base", host_base, "dockcore v1 host base id (default 0x180)");
  app.add_flag("--strict", strict, "exit 1 when any counter/checksum/length error or malformed line was found");
  app.add_flag("--strict-gaps", strict_gaps, "with --strict: gaps count as errors too");
  app.add_flag("--json", as_json, "one JSON document (summary + timeline) instead of text");
  app.add_flag("-q,--quiet", quiet, "summary only, no timeline");
  app.add_option("--svg", svg, "plot commanded/measured velocities, task state and fault code to FILE");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;  // argument errors: CLI11's message, exit 2; --help: 0
  }

  try {
    opt.chassis_base = parse_id(chassis_base);
    opt.host_base = parse_id(host_base);
  } catch (const std::exception&) {
    std::cerr << "dock-decode: base ids must be numbers (e.g. 0x100)\n";
    return 2;
  }
  if (!v1::ids_valid(v1::Ids{opt.chassis_base, opt.host_base})) {
    std::cerr << "dock-decode: base ids overlap or exceed 0x7FF (chassis range base..base+0x15, host base..base+2)\n";
    return 2;
  }
  std::ifstream file;
  std::istream* in = &std::cin;
  if (log != "-") {
    file.open(log);
    if (!file) {
      std::cerr << "dock-decode: cannot open " << log << "\n";
      return 2;
    }
    in = &file;
  }

  Decoder dec(opt);
  std::map<std::uint32_t, IdStats> per_id;
  std::map<std::string, std::uint64_t> errors;
  std::uint64_t lines = 0, frames = 0, rtr = 0, canfd = 0, errframes = 0, blank = 0;
  json malformed = json::array(), gaps = json::array(), timeline = json::array();
  std::map<std::string, std::vector<Point>> series;
  bool have_t0 = false;
  std::uint64_t t0 = 0, t_last = 0;
  std::ostringstream text;
  std::string line;
  while (std::getline(*in, line)) {
    ++lines;
    dockdecode::CandumpLine cl;
    const dockdecode::LineKind k = dockdecode::parse_candump_line(line, cl);
    if (k == dockdecode::LineKind::kBlank) {
      ++blank;
      continue;
    }
    if (k == dockdecode::LineKind::kMalformed) {
      malformed.push_back({{"line", lines}, {"reason", cl.reason}, {"text", line.substr(0, 120)}});
      continue;
    }
    if (k == dockdecode::LineKind::kRtr) { ++rtr; continue; }
    if (k == dockdecode::LineKind::kCanFd) { ++canfd; continue; }
    if (k == dockdecode::LineKind::kErrorFrame) { ++errframes; continue; }
    ++frames;
    if (!have_t0) {
      t0 = cl.stamp_us;
      have_t0 = true;
    }
    const double t = cl.stamp_us >= t0 ? static_cast<double>(cl.stamp_us - t0) * 1e-6 : -static_cast<double>(t0 - cl.stamp_us) * 1e-6;
    t_last = std::max(t_last, cl.stamp_us);
    const Decoded d = dec.decode(cl.frame);
    IdStats& st = per_id[cl.frame.id | (cl.frame.extended ? 0x80000000u : 0u)];
    st.name = d.name;
    ++st.frames;
    std::string gap_note;
    if (st.have_last && d.period_ms > 0 && cl.stamp_us > st.last_us &&
        cl.stamp_us - st.last_us > 2ull * d.period_ms * 1000ull) {
      const double dt_ms = static_cast<double>(cl.stamp_us - st.last_us) * 1e-3;
      ++st.gaps;
      gaps.push_back({{"line", lines}, {"t_s", t}, {"id", cl.frame.id}, {"name", d.name}, {"gap_ms", dt_ms},
                      {"period_ms", d.period_ms}});
      gap_note = " [gap " + fmt(dt_ms) + " ms]";
    }
    st.have_last = true;
    st.last_us = cl.stamp_us;
    if (!d.error.empty()) {
      ++st.errors;
      ++errors[d.error];
    }
    // Plot series.
    auto val = [&d](const char* n, double& v) {
      for (const Signal& s : d.signals)
        if (s.name == n) { v = s.value; return true; }
      return false;
    };
    double v = 0;
    if (d.name == "WheelCmdA" || d.name == "MotionCommand") {
      if (val(d.name == "WheelCmdA" ? "wheel0" : "linear", v)) series["cmd0"].push_back({t, v});
      if (val(d.name == "WheelCmdA" ? "wheel1" : "angular", v)) series["cmd1"].push_back({t, v});
    } else if (d.name == "WheelFbA" || d.name == "MotionState") {
      if (val(d.name == "WheelFbA" ? "wheel0" : "linear", v)) series["meas0"].push_back({t, v});
      if (val(d.name == "WheelFbA" ? "wheel1" : "angular", v)) series["meas1"].push_back({t, v});
    } else if (d.name == "DockStatus") {
      if (val("state", v)) series["state"].push_back({t, v});
      if (val("fault", v)) series["fault"].push_back({t, v});
    }
    char head[96];
    std::snprintf(head, sizeof head, "%12.6f  %s%03X %-14s", t, cl.frame.extended ? "x" : "0x", cl.frame.id, d.name.c_str());
    std::string sig;
    json js = json::object();
    for (const Signal& s : d.signals) {
      sig += " " + s.name + "=" + fmt(s.value) + (s.unit.empty() ? "" : " " + s.unit) + (s.text.empty() ? "" : "(" + s.text + ")");
      js[s.name] = s.value;
    }
    if (d.name == "unknown") {
      sig = " data=";
      for (int i = 0; i < cl.frame.dlc; ++i) {
        char b[4];
        std::snprintf(b, sizeof b, "%02X", cl.frame.data[i]);
        sig += b;
      }
    }
    if (!quiet) text << head << sig << (d.error.empty() ? "" : "  [" + d.error + "]") << gap_note << "\n";
    if (as_json && !quiet) {
      json e = {{"t_s", t}, {"line", lines}, {"id", cl.frame.id}, {"name", d.name}, {"signals", js}};
      if (!d.error.empty()) e["error"] = d.error;
      timeline.push_back(e);
    }
  }

  std::uint64_t total_errors = 0;
  for (const auto& e : errors) total_errors += e.second;
  const std::uint64_t n_gaps = gaps.size();
  const bool fail = strict && (total_errors > 0 || !malformed.empty() || (strict_gaps && n_gaps > 0));

  if (as_json) {
    json ids = json::array();
    for (const auto& [id, st] : per_id)
      ids.push_back({{"id", id & 0x7FFFFFFFu}, {"extended", (id & 0x80000000u) != 0}, {"name", st.name},
                     {"frames", st.frames}, {"errors", st.errors}, {"gaps", st.gaps}});
    json doc = {{"profile", opt.profile},
                {"chassis_base", opt.chassis_base},
                {"host_base", opt.host_base},
                {"lines", lines},
                {"frames", frames},
                {"skipped", {{"rtr", rtr}, {"canfd", canfd}, {"error_frames", errframes}, {"blank", blank}}},
                {"malformed", malformed},
                {"errors", errors},
                {"error_total", total_errors},
                {"gaps", gaps},
                {"per_id", ids},
                {"duration_s", have_t0 ? static_cast<double>(t_last - t0) * 1e-6 : 0.0}};
    if (!quiet) doc["timeline"] = timeline;
    std::cout << doc.dump(1) << "\n";
  } else {
    std::cout << text.str();
    std::cout << "summary: " << lines << " lines, " << frames << " frames, " << (have_t0 ? fmt(static_cast<double>(t_last - t0) * 1e-6) : "0")
              << " s; skipped: " << rtr << " RTR, " << canfd << " CAN FD, " << errframes << " error frames\n";
    std::cout << "  id     name             frames  errors  gaps\n";
    for (const auto& [id, st] : per_id) {
      char b[128];
      std::snprintf(b, sizeof b, "  %s%03X %-16s %7llu %7llu %5llu\n", (id & 0x80000000u) ? "x" : "0x", id & 0x7FFFFFFFu,
                    st.name.c_str(), static_cast<unsigned long long>(st.frames),
                    static_cast<unsigned long long>(st.errors), static_cast<unsigned long long>(st.gaps));
      std::cout << b;
    }
    std::cout << "errors: " << total_errors;
    for (const auto& e : errors) std::cout << "  " << e.first << "=" << e.second;
    std::cout << "\ngaps (> 2x period): " << n_gaps << "\n";
    for (const auto& g : gaps)
      std::cout << "  line " << g["line"].get<std::uint64_t>() << " t=" << fmt(g["t_s"].get<double>()) << " s "
                << g["name"].get<std::string>() << " " << fmt(g["gap_ms"].get<double>()) << " ms (period "
                << g["period_ms"].get<std::uint32_t>() << " ms)\n";
    std::cout << "malformed lines: " << malformed.size() << "\n";
    for (const auto& m : malformed)
      std::cout << "  line " << m["line"].get<std::uint64_t>() << ": " << m["reason"].get<std::string>() << ": "
                << m["text"].get<std::string>() << "\n";
  }
  if (!svg.empty()) {
    try {
      write_svg(svg, have_t0 ? static_cast<double>(t_last - t0) * 1e-6 : 1.0, series);
    } catch (const std::exception& e) {
      std::cerr << "dock-decode: " << e.what() << "\n";
      return 2;
    }
  }
  return fail ? 1 : 0;
}
