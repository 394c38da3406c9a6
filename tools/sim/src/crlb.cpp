#include "docksim/crlb.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <cmath>

#include "dockcore/perception/profile_geometry.hpp"

namespace docksim {

Crlb dock_pose_crlb(const dockcore::DockProfile& profile, const dockcore::Pose2& dock_in_sensor, double angle_min_rad,
                    double angle_increment_rad, std::size_t beams, double sigma_const_m, double sigma_prop) {
  using dockcore::Mat3;
  using dockcore::Vec2;
  using dockcore::Vec3;
  Crlb out;
  dockcore::PlacedProfile placed;
  placed.place(profile, dock_in_sensor);
  const Vec2 t(dock_in_sensor.x_m, dock_in_sensor.y_m);
  Mat3 info = Mat3::Zero();
  for (std::size_t i = 0; i < beams; ++i) {
    const double a = angle_min_rad + static_cast<double>(i) * angle_increment_rad;
    const Vec2 u(std::cos(a), std::sin(a));
    dockcore::Real r = 0;
    std::size_t seg = 0;
    if (!placed.raycast(u, &r, &seg)) continue;
    const Vec2& n = placed.n[seg];
    const double nu = n.dot(u);
    const Vec2 x = r * u;
    // r = (n·a + n·t)/(n·u) for the line through the placed segment; differentiate w.r.t. t and the dock's yaw.
    const Vec3 j(n.x() / nu, n.y() / nu, -Vec2(-n.y(), n.x()).dot(x - t) / nu);
    const double sigma = sigma_const_m + sigma_prop * r;
    info += j * j.transpose() / (sigma * sigma);
    ++out.beams;
  }
  if (out.beams < 3) return out;
  // A direction with (numerically) no information means the pose is unobservable from this view, e.g. sliding a
  // flat plate along itself; report that rather than a meaningless inverse.
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(info);
  if (eig.info() != Eigen::Success || !(eig.eigenvalues()(0) > 1e-9 * eig.eigenvalues()(2))) return out;
  out.cov = info.inverse();
  if (!out.cov.allFinite() || out.cov(2, 2) <= 0) return out;
  const Vec2 ex(std::cos(dock_in_sensor.yaw_rad), std::sin(dock_in_sensor.yaw_rad));
  const Vec2 ey(-ex.y(), ex.x());
  const dockcore::Mat2 cxy = out.cov.topLeftCorner<2, 2>();
  out.sigma_longitudinal_m = std::sqrt(ex.dot(cxy * ex));
  out.sigma_lateral_m = std::sqrt(ey.dot(cxy * ey));
  out.sigma_yaw_rad = std::sqrt(out.cov(2, 2));
  out.ok = true;
  return out;
}

}  // namespace docksim
