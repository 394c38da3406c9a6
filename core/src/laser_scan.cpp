#include "dockcore/laser_scan.hpp"

namespace dockcore {

std::size_t scan_to_points(const ScanView& scan, const Pose2& lidar_mount, Real min_range_m, Real max_range_m,
                           ScanPointBuffer& out, std::size_t* truncated) {
  out.clear();
  std::size_t dropped = 0;
  const Real c = std::cos(lidar_mount.yaw_rad);
  const Real s = std::sin(lidar_mount.yaw_rad);
  for (std::size_t i = 0; i < scan.count; ++i) {
    const Real r = scan.ranges_m[i];
    if (!is_valid_range(r) || r < min_range_m || r > max_range_m) continue;
    const Real a = scan.angle_rad(i);
    const Real lx = r * std::cos(a);
    const Real ly = r * std::sin(a);
    ScanPoint sp;
    sp.p_m = Vec2(lidar_mount.x_m + c * lx - s * ly, lidar_mount.y_m + s * lx + c * ly);
    sp.range_m = r;
    sp.angle_rad = a;
    sp.index = static_cast<std::uint32_t>(i);
    if (!out.push_back(sp)) ++dropped;
  }
  if (truncated != nullptr) *truncated = dropped;
  return out.size();
}

}  // namespace dockcore
