// Example bare-metal firmware: dockcore's whole docking stack (estimator, filter, task manager, smooth controller)
// on a Cortex-M7 with no OS, no heap and no exceptions.
//
// The "lidar" is a canned scene: a `plate-v` dock at the world origin against a 4 m wall, rendered every 100 ms into a
// 720-beam scan (LD06-like, 0.5 degree steps) by core's own ray caster (PlacedProfile::raycast) from wherever the robot
// is, plus a fixed pseudo-random ±3 mm range noise. The "chassis" moves the robot by the twist Dockcore sends the drive
// (after its limits) exactly, reports the wheel speeds it ran at (Dockcore integrates them into its odometry, as on a
// robot) and closes the contacts when the pads reach the dock face within ±10 mm / ±2 degrees; current flows 0.5 s
// later. The main loop runs the 50 Hz control tick. With DOCKCORE_FW_SEMIHOSTING the firmware prints its timeline
// through Arm semihosting (qemu-system-arm -semihosting, or a debug probe) and exits with status 0 when charging was
// confirmed; without it the result is left in g_result for a debugger and the core sleeps.
#include <cstddef>
#include <cstdint>

#include "dockcore/control/controllers.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "dockcore/perception/profile_geometry.hpp"
#include "dockcore/task/task_manager.hpp"

using namespace dockcore;

namespace {

constexpr std::size_t kBeams = 720;
constexpr std::uint64_t kTickUs = 20000;  // 50 Hz control tick
constexpr unsigned kTicksPerScan = 5;     // 10 Hz lidar
constexpr unsigned kMaxTicks = 50 * 60;   // give up after 60 s
const Real kWallX_m = static_cast<Real>(-0.08);        // wall behind the dock, world x = -0.08 m
const Real kWallHalfLength_m = static_cast<Real>(2.0);  // ... from y = -2 m to +2 m
const Vec2 kPadsBody(static_cast<Real>(0.37), 0);  // charging pads: centre of the front edge (default footprint)

// Everything large is static: even sized for 720 beams Dockcore is tens of KiB (docs/architecture.md), beyond any stack.
SmoothController g_controller;
DockcoreN<kBeams> g_core(g_controller);  // sized for the 720-beam lidar, not core's largest
LaserScanN<kBeams> g_scan;
DockProfile g_profile;
PlacedProfile g_placed;

#if DOCKCORE_FW_SEMIHOSTING
// Arm semihosting (ARM DUI 0471): operation in r0, argument in r1, trap with BKPT 0xAB on M-profile.
int semihost(int op, const void* arg) {
  register int r0 __asm("r0") = op;
  register const void* r1 __asm("r1") = arg;
  __asm volatile("bkpt 0xAB" : "+r"(r0) : "r"(r1) : "memory");
  return r0;
}
void put(const char* s) { semihost(0x04, s); }  // SYS_WRITE0
// Prints v with `decimals` digits after the point (rounded), no printf (which would bring newlib's stdio and heap).
void put_fixed(Real v, int decimals) {
  char buf[24];
  int n = 0;
  bool neg = v < 0;
  if (neg) v = -v;
  std::uint32_t scale = 1;
  for (int i = 0; i < decimals; ++i) scale *= 10;
  const auto fixed = static_cast<std::uint32_t>(v * static_cast<Real>(scale) + static_cast<Real>(0.5));
  std::uint32_t ip = fixed / scale, fp = fixed % scale;
  char tmp[24];
  int t = 0;
  for (int i = 0; i < decimals; ++i, fp /= 10) tmp[t++] = static_cast<char>('0' + fp % 10);
  if (decimals > 0) tmp[t++] = '.';
  do { tmp[t++] = static_cast<char>('0' + ip % 10); ip /= 10; } while (ip != 0);
  if (neg) buf[n++] = '-';
  while (t > 0) buf[n++] = tmp[--t];
  buf[n] = '\0';
  put(buf);
}
void put_uint(std::uint64_t v) {  // exact for any count (put_fixed goes through Real)
  char tmp[24];
  int t = 23;
  tmp[t] = '\0';
  do { tmp[--t] = static_cast<char>('0' + v % 10); v /= 10; } while (v != 0);
  put(tmp + t);
}
[[noreturn]] void exit_with(bool ok) {
  // SYS_EXIT with ADP_Stopped_ApplicationExit (qemu: status 0) or ADP_Stopped_RunTimeErrorUnknown (status 1).
  semihost(0x18, reinterpret_cast<const void*>(ok ? 0x20026u : 0x20023u));
  for (;;) __asm volatile("wfi");
}
#else
void put(const char*) {}
void put_fixed(Real, int) {}
#endif

#if DOCKCORE_FW_SEMIHOSTING
// Cost of each on_scan() and tick(), counted with SysTick (24-bit, processor clock, extended by its wrap interrupt)
// and converted with a calibration loop of a known instruction count. Under qemu -icount (run-qemu.sh) virtual time
// advances by the same amount for every instruction, so the result is the number of instructions executed; on
// silicon SysTick counts cycles and the same figures are cycles in units of that loop's cost.
volatile std::uint32_t& syst(std::uint32_t off) { return *reinterpret_cast<volatile std::uint32_t*>(0xE000E010u + off); }
volatile std::uint32_t g_systick_wraps = 0;
std::uint64_t systick_now() {  // ticks since start, monotonic
  for (;;) {
    const std::uint32_t w = g_systick_wraps;
    const std::uint32_t v = syst(8) & 0xFFFFFFu;  // SYST_CVR counts down
    if (w == g_systick_wraps) return (static_cast<std::uint64_t>(w) << 24) + (0xFFFFFFu - v);
  }
}
void systick_start() {
  syst(4) = 0xFFFFFFu;  // SYST_RVR
  syst(8) = 0;          // SYST_CVR: any write clears it
  syst(0) = 7;          // SYST_CSR: enable, wrap interrupt, processor clock
}
// Ticks of `iterations` turns of a 2-instruction loop (subs + bne), bracketed by the same reads as a measurement.
std::uint64_t loop_ticks(std::uint32_t iterations) {
  const std::uint64_t t0 = systick_now();
  __asm volatile("1: subs %0, %0, #1\n\tbne 1b" : "+r"(iterations) : : "cc");
  return systick_now() - t0;
}
struct Cost {
  std::uint64_t max = 0, sum = 0;
  std::uint32_t n = 0, at = 0;  // calls, and which call was the worst (1-based)
  void add(std::uint64_t v) {
    ++n;
    sum += v;
    if (v > max) { max = v; at = n; }
  }
};
#endif

std::uint32_t g_rng = 0x2545F491u;
// xorshift32: a fixed noise sequence, so every run of the firmware sees the same scans.
Real noise_m() {
  g_rng ^= g_rng << 13;
  g_rng ^= g_rng >> 17;
  g_rng ^= g_rng << 5;
  return (static_cast<Real>(g_rng >> 8) / static_cast<Real>(1u << 24) - static_cast<Real>(0.5)) * static_cast<Real>(0.006);
}

// The dock (world = dock frame) as the lidar at `robot` sees it; lidar at the robot centre, facing forward.
void render_scan(const Pose2& robot, std::uint64_t stamp_us) {
  g_placed.place(g_profile, robot.inverse());
  const Real inc = kTwoPi / static_cast<Real>(kBeams);
  g_scan.reset(kBeams, -kPi, inc, stamp_us);
  for (std::size_t i = 0; i < kBeams; ++i) {
    const Real a = g_scan.view().angle_rad(i);
    Real r = 0;
    std::size_t seg = 0;
    if (!g_placed.raycast(Vec2(std::cos(a), std::sin(a)), &r, &seg)) r = 0;
    // The wall the dock stands against (the estimator requires one behind the dock's ends by default).
    const Real dx = std::cos(a + robot.yaw_rad);
    if (dx < 0) {
      const Real t = (kWallX_m - robot.x_m) / dx;
      const Real y = robot.y_m + t * std::sin(a + robot.yaw_rad);
      if (std::fabs(y) <= kWallHalfLength_m && (r == 0 || t < r)) r = t;
    }
    if (r > 0) g_scan.ranges_m[i] = r + noise_m();
  }
}

}  // namespace

#if DOCKCORE_FW_SEMIHOSTING
extern "C" void SysTick_Handler() { g_systick_wraps = g_systick_wraps + 1; }
extern "C" std::uint32_t __stack_limit__;
extern "C" std::uint32_t __stack_top__;
#endif

// For a debugger when there is no semihosting: final state, fault, pads' errors at the end.
struct FirmwareResult {
  std::uint8_t state;
  std::uint16_t fault;
  std::uint32_t ticks;
  float pad_lateral_m;
  float pad_yaw_rad;
};
volatile FirmwareResult g_result;

int main() {
  builtin_profile("plate-v", g_profile);
  DockcoreConfig cfg;
  cfg.control_period_s = static_cast<Real>(kTickUs) * static_cast<Real>(1e-6);
  if (!g_core.configure(g_profile, cfg)) return 1;

  // Start 1.3 m out, 0.2 m to the side, 12 degrees off the dock's axis, facing roughly towards it.
  Pose2 robot{static_cast<Real>(1.3), static_cast<Real>(0.2), kPi - static_cast<Real>(0.21)};
  WheelSpeeds wheels_ran{};  // what the drive reports: the wheel speeds of the previous tick's command
  TaskState last_state = TaskState::kNotTasking;
  std::uint64_t now_us = 0;
  std::uint64_t contact_since_us = 0;
  bool contact = false;
  bool charged = false;
  put("firmware-example: dockcore on bare metal, smooth controller, plate-v dock\n");
#if DOCKCORE_FW_SEMIHOSTING
  // Stack high-water mark: paint the unused stack below this frame, find the lowest overwritten word at the end.
  constexpr std::uint32_t kPaint = 0xA5C3E187u;
  std::uint32_t* const stack_limit = &__stack_limit__;
  for (std::uint32_t* w = stack_limit; w < static_cast<std::uint32_t*>(__builtin_frame_address(0)) - 16; ++w) *w = kPaint;
  systick_start();
  // Calibration: the difference of two loop lengths cancels the reads' own cost.
  constexpr std::uint32_t kCalIterations = 100000;
  const std::uint64_t cal_ticks = loop_ticks(kCalIterations + 1000) - loop_ticks(1000);  // 2 * kCalIterations insns
  const std::uint64_t overhead = loop_ticks(1000) * 2 * kCalIterations / cal_ticks - 2000;  // reads' own cost
  auto instructions = [&](std::uint64_t ticks) {
    const std::uint64_t i = (ticks * 2 * kCalIterations + cal_ticks / 2) / cal_ticks;
    return i > overhead ? i - overhead : 0;
  };
  Cost scan_cost, tick_cost;
#endif
  unsigned k = 0;
  for (; k < kMaxTicks; ++k, now_us += kTickUs) {
    g_core.on_wheels(wheels_ran, now_us);
    if (k % kTicksPerScan == 0) {
      render_scan(robot, now_us);
#if DOCKCORE_FW_SEMIHOSTING
      const std::uint64_t t0 = systick_now();
      g_core.on_scan(g_scan.view(), now_us, now_us);
      scan_cost.add(instructions(systick_now() - t0));
#else
      g_core.on_scan(g_scan.view(), now_us, now_us);
#endif
    }

    const Vec2 pads = robot.transform(kPadsBody);
    const Real yaw_err = wrap_angle(robot.yaw_rad - kPi);  // docked head-on = facing -x
    const bool at_face = pads.x() <= 0 && std::fabs(pads.y()) < static_cast<Real>(0.15);
    const bool closed = at_face && std::fabs(pads.y()) <= static_cast<Real>(0.010) &&
                        std::fabs(yaw_err) <= deg_to_rad(static_cast<Real>(2));
    if (closed && !contact) contact_since_us = now_us;
    contact = closed;

    TickInput in;
    in.now_us = now_us;
    if (k == 1) {
      QueuedCommand dock;
      dock.command = HostCommand{HostCommandType::kDock, 0};
      g_core.submit(dock);
    }
    in.contact = contact;
    in.charge_current_a = contact && now_us - contact_since_us >= 500000 ? static_cast<Real>(5) : 0;
#if DOCKCORE_FW_SEMIHOSTING
    const std::uint64_t t0 = systick_now();
    const TickOutput out = g_core.tick(in);
    tick_cost.add(instructions(systick_now() - t0));
#else
    const TickOutput out = g_core.tick(in);
#endif

    const bool progress = out.status.state == TaskState::kAlign && k % 50 == 0;  // once a second while driving
    if (out.status.state != last_state || progress) {
      put("t=");
      put_fixed(static_cast<Real>(now_us) * static_cast<Real>(1e-6), 2);
      put(progress && out.status.state == last_state ? " s       " : " s state ");
      put(to_string(out.status.state));
      put(" dock ");
      put_fixed(out.status.dock_pose.x_m, 3);
      put(" ");
      put_fixed(out.status.dock_pose.y_m, 3);
      put(" m cmd vx ");
      put_fixed(out.drive_cmd.vx_mps, 3);
      put(" m/s wz ");
      put_fixed(out.drive_cmd.wz_radps, 3);
      put(" rad/s\n");
      last_state = out.status.state;
    }
    if (out.status.state == TaskState::kFinishTasking) {
      charged = true;
      break;
    }
    if (out.status.state == TaskState::kFault) break;
    wheels_ran = out.wheels;

    // Ideal unicycle over one tick; the dock face stops the pads (no pressing through it).
    const Real dt = static_cast<Real>(kTickUs) * static_cast<Real>(1e-6);
    Pose2 next = robot.compose(Pose2{out.drive_cmd.vx_mps * dt, 0, out.drive_cmd.wz_radps * dt});
    if (!(at_face && next.transform(kPadsBody).x() < pads.x())) robot = next;
  }

  const Vec2 pads = robot.transform(kPadsBody);
  g_result.state = static_cast<std::uint8_t>(g_core.task_manager().state());
  g_result.fault = static_cast<std::uint16_t>(g_core.task_manager().fault());
  g_result.ticks = k;
  g_result.pad_lateral_m = static_cast<float>(pads.y());
  g_result.pad_yaw_rad = static_cast<float>(wrap_angle(robot.yaw_rad - kPi));
  put(charged ? "outcome: CHARGING" : "outcome: NOT DOCKED, fault ");
  if (!charged) put(to_string(g_core.task_manager().fault()));
  put(" after ");
  put_fixed(static_cast<Real>(now_us) * static_cast<Real>(1e-6), 2);
  put(" s; pads lateral ");
  put_fixed(pads.y() * static_cast<Real>(1000), 1);
  put(" mm, yaw ");
  put_fixed(rad_to_deg(wrap_angle(robot.yaw_rad - kPi)), 2);
  put(" deg; last estimate ");
  put(to_string(g_core.last_estimate().status));
  put("\n");
  const EstimatorCounters& ec = g_core.estimator().counters();
  for (std::size_t r = 1; r < static_cast<std::size_t>(RejectReason::kCount); ++r) {
    if (ec.rejected_by[r] == 0) continue;
    put("  candidates rejected: ");
    put(to_string(static_cast<RejectReason>(r)));
    put(" x");
    put_fixed(static_cast<Real>(ec.rejected_by[r]), 0);
    put("\n");
  }
#if DOCKCORE_FW_SEMIHOSTING
  // One line each, parsed by tools/size-report: worst and mean instructions per call, and which call was the worst.
  const Cost* costs[2] = {&scan_cost, &tick_cost};
  const char* names[2] = {"cost: on_scan instructions max ", "cost: tick instructions max "};
  for (int c = 0; c < 2; ++c) {
    put(names[c]);
    put_uint(costs[c]->max);
    put(" (call ");
    put_uint(costs[c]->at);
    put(") mean ");
    put_uint(costs[c]->n ? costs[c]->sum / costs[c]->n : 0);
    put(" calls ");
    put_uint(costs[c]->n);
    put("\n");
  }
  put("cost: calibration SysTick ticks per 1000 instructions ");
  put_fixed(static_cast<Real>(cal_ticks) * static_cast<Real>(1000) / static_cast<Real>(2 * kCalIterations), 1);
  put("\n");
  std::uint32_t* w = stack_limit;
  while (*w == kPaint) ++w;
  put("stack: high-water ");
  put_uint(reinterpret_cast<std::uintptr_t>(&__stack_top__) - reinterpret_cast<std::uintptr_t>(w));
  put(" bytes of ");
  put_uint(reinterpret_cast<std::uintptr_t>(&__stack_top__) - reinterpret_cast<std::uintptr_t>(stack_limit));
  put(" reserved\n");
  exit_with(charged);
#endif
  return charged ? 0 : 1;
}
