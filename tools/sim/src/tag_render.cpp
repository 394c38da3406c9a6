// Pinhole rendering of a tag pattern (see docksim/tag_render.hpp).
#include "docksim/tag_render.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

namespace docksim {

void facing_rotation(double yaw_rad, double r[9]) {
  const double c = std::cos(yaw_rad), s = std::sin(yaw_rad);
  // Rotation about the camera's y axis (down): tag x (columns) turns towards the optical axis.
  const double m[9] = {c, 0, s, 0, 1, 0, -s, 0, c};
  for (int i = 0; i < 9; ++i) r[i] = m[i];
}

bool project_tag_point(const PinholeView& v, double x_m, double y_m, double& u_px, double& v_px) {
  const double* R = v.rotation;
  const double X = R[0] * x_m + R[1] * y_m + v.translation_m[0];
  const double Y = R[3] * x_m + R[4] * y_m + v.translation_m[1];
  const double Z = R[6] * x_m + R[7] * y_m + v.translation_m[2];
  if (Z <= 0) return false;
  u_px = v.cx_px + v.fx_px * X / Z;
  v_px = v.cy_px + v.fy_px * Y / Z;
  return true;
}

bool render_tag(const TagPattern& tag, const PinholeView& v, std::uint8_t* grey, std::uint32_t stride_bytes,
                const PixelRect* region) {
  if (tag.cells_grey == nullptr || tag.cells == 0 || !(tag.cell_m > 0) || !(v.fx_px > 0) || !(v.fy_px > 0) ||
      v.supersample < 1 || v.supersample > 8 || v.edge_supersample > 32 || grey == nullptr ||
      stride_bytes < v.width_px) {
    return false;
  }
  PixelRect rect{0, 0, v.width_px, v.height_px};
  if (region != nullptr) {
    rect = PixelRect{std::min(region->col0, v.width_px), std::min(region->row0, v.height_px),
                     std::min(region->col1, v.width_px), std::min(region->row1, v.height_px)};
  }
  if (rect.col0 >= rect.col1 || rect.row0 >= rect.row1) return true;
  const double* R = v.rotation;
  const double* t = v.translation_m;
  const double n[3] = {R[2], R[5], R[8]};  // the tag's z axis in the camera frame
  const double nt = n[0] * t[0] + n[1] * t[1] + n[2] * t[2];
  const double half = 0.5 * tag.cell_m * tag.cells;
  // The grey of the scene along the ray through image point (u, w).
  auto scene = [&](double u, double w) {
    const double d[3] = {(u - v.cx_px) / v.fx_px, (w - v.cy_px) / v.fy_px, 1.0};
    const double nd = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
    // The plane n·(P − t) = 0 along the ray P = λ·d, met in front of the camera and from the tag's front.
    if (!(nd > 1e-12 && nt > 0)) return static_cast<double>(v.background);
    const double lambda = nt / nd;
    const double p[3] = {lambda * d[0] - t[0], lambda * d[1] - t[1], lambda * d[2] - t[2]};
    const double x = R[0] * p[0] + R[3] * p[1] + R[6] * p[2];  // Rᵀ(P − t)
    const double y = R[1] * p[0] + R[4] * p[1] + R[7] * p[2];
    if (!(x >= -half && x < half && y >= -half && y < half)) return static_cast<double>(v.background);
    const auto c = static_cast<std::uint32_t>((x + half) / tag.cell_m);
    const auto r = static_cast<std::uint32_t>((y + half) / tag.cell_m);
    return c < tag.cells && r < tag.cells ? static_cast<double>(tag.cells_grey[r * tag.cells + c])
                                          : static_cast<double>(v.background);
  };
  // The mean of n × n sub-samples spread over the pixel [col − ½, col + ½] × [row − ½, row + ½]; `uniform` tells
  // whether they all agreed.
  auto pixel = [&](std::uint32_t col, std::uint32_t row, std::uint32_t n_side, bool* uniform) {
    double sum = 0, first = -1;
    bool same = true;
    for (std::uint32_t sy = 0; sy < n_side; ++sy) {
      for (std::uint32_t sx = 0; sx < n_side; ++sx) {
        const double g = scene(col - 0.5 + (sx + 0.5) / n_side, row - 0.5 + (sy + 0.5) / n_side);
        if (first < 0) first = g;
        same = same && g == first;
        sum += g;
      }
    }
    if (uniform != nullptr) *uniform = same;
    return sum / (n_side * n_side);
  };
  // Coarse pass; then every pixel whose samples disagree or whose coarse value differs from a neighbour's is
  // integrated on the fine grid: an edge can cross a pixel between its coarse samples, and only a neighbour shows it.
  // Indices are within the rendered rectangle; its edge stands in for the image's.
  const std::uint32_t w_px = rect.col1 - rect.col0, h_px = rect.row1 - rect.row0;
  std::vector<std::uint8_t> coarse(static_cast<std::size_t>(w_px) * h_px);
  std::vector<std::uint8_t> mixed(coarse.size());
  for (std::uint32_t row = 0; row < h_px; ++row) {
    for (std::uint32_t col = 0; col < w_px; ++col) {
      bool uniform = true;
      const std::size_t i = static_cast<std::size_t>(row) * w_px + col;
      coarse[i] =
          static_cast<std::uint8_t>(std::lround(pixel(rect.col0 + col, rect.row0 + row, v.supersample, &uniform)));
      mixed[i] = uniform ? 0 : 1;
    }
  }
  for (std::uint32_t row = 0; row < h_px; ++row) {
    for (std::uint32_t col = 0; col < w_px; ++col) {
      const std::size_t i = static_cast<std::size_t>(row) * w_px + col;
      bool edge = mixed[i] != 0;
      edge = edge || (col > 0 && coarse[i - 1] != coarse[i]) || (col + 1 < w_px && coarse[i + 1] != coarse[i]);
      edge = edge || (row > 0 && coarse[i - w_px] != coarse[i]) || (row + 1 < h_px && coarse[i + w_px] != coarse[i]);
      std::uint8_t g = coarse[i];
      if (edge && v.edge_supersample > v.supersample) {
        g = static_cast<std::uint8_t>(
            std::lround(pixel(rect.col0 + col, rect.row0 + row, v.edge_supersample, nullptr)));
      }
      grey[static_cast<std::size_t>(rect.row0 + row) * stride_bytes + rect.col0 + col] = g;
    }
  }
  return true;
}

bool tag_pixel_bounds(const TagPattern& tag, const PinholeView& v, std::uint32_t margin_px, PixelRect& out) {
  const double half = 0.5 * tag.cell_m * tag.cells;
  double u_min = 1e300, u_max = -1e300, v_min = 1e300, v_max = -1e300;
  for (int k = 0; k < 4; ++k) {
    double u = 0, w = 0;
    if (!project_tag_point(v, (k & 1) != 0 ? half : -half, (k & 2) != 0 ? half : -half, u, w)) return false;
    u_min = std::min(u_min, u);
    u_max = std::max(u_max, u);
    v_min = std::min(v_min, w);
    v_max = std::max(v_max, w);
  }
  const double m = margin_px;
  if (u_max + m < 0 || v_max + m < 0 || u_min - m >= v.width_px || v_min - m >= v.height_px) return false;
  auto clip = [](double x, std::uint32_t hi) {
    return static_cast<std::uint32_t>(std::clamp(x, 0.0, static_cast<double>(hi)));
  };
  out = PixelRect{clip(std::floor(u_min - m), v.width_px), clip(std::floor(v_min - m), v.height_px),
                  clip(std::ceil(u_max + m) + 1, v.width_px), clip(std::ceil(v_max + m) + 1, v.height_px)};
  return true;
}

void blur_grey(std::uint8_t* img, std::uint32_t w, std::uint32_t h, std::uint32_t stride, double sigma,
               const PixelRect* region) {
  if (!(sigma > 0) || w == 0 || h == 0) return;
  PixelRect r{0, 0, w, h};
  if (region != nullptr) {
    r = PixelRect{std::min(region->col0, w), std::min(region->row0, h), std::min(region->col1, w),
                  std::min(region->row1, h)};
  }
  if (r.col0 >= r.col1 || r.row0 >= r.row1) return;
  const int k_r = std::max(1, static_cast<int>(std::ceil(3 * sigma)));
  std::vector<double> k(static_cast<std::size_t>(2 * k_r + 1));
  double sum = 0;
  for (int i = -k_r; i <= k_r; ++i)
    sum += k[static_cast<std::size_t>(i + k_r)] = std::exp(-0.5 * i * i / (sigma * sigma));
  for (double& x : k) x /= sum;
  const int c0 = static_cast<int>(r.col0), c1 = static_cast<int>(r.col1);
  const int r0 = static_cast<int>(r.row0), r1 = static_cast<int>(r.row1);
  const int rw = c1 - c0;
  const int iw = static_cast<int>(w), ih = static_cast<int>(h);
  auto at = [&](int x, int y) -> std::uint8_t& {
    return img[static_cast<std::size_t>(y) * stride + static_cast<std::size_t>(x)];
  };
  // Rows first over every row the column pass reads (the region grown by the kernel, within the image).
  const int g0 = std::max(0, r0 - k_r), g1 = std::min(ih, r1 + k_r);
  std::vector<double> tmp(static_cast<std::size_t>(rw) * static_cast<std::size_t>(g1 - g0));
  for (int y = g0; y < g1; ++y) {
    for (int x = c0; x < c1; ++x) {
      double a = 0;
      for (int i = -k_r; i <= k_r; ++i) a += k[static_cast<std::size_t>(i + k_r)] * at(std::clamp(x + i, 0, iw - 1), y);
      tmp[static_cast<std::size_t>((y - g0) * rw + (x - c0))] = a;
    }
  }
  for (int y = r0; y < r1; ++y) {
    for (int x = c0; x < c1; ++x) {
      double a = 0;
      for (int i = -k_r; i <= k_r; ++i) {
        a += k[static_cast<std::size_t>(i + k_r)] *
             tmp[static_cast<std::size_t>((std::clamp(y + i, g0, g1 - 1) - g0) * rw + (x - c0))];
      }
      at(x, y) = static_cast<std::uint8_t>(std::clamp(std::lround(a), 0L, 255L));
    }
  }
}

void place_tag_in_view(PinholeView& view, const dockcore::CameraMount3& camera, const dockcore::Pose2& dock,
                       const dockcore::DockTag& tag) {
  using dockcore::Mat3;
  using dockcore::Vec3;
  // The tag's axes in the dock frame when it hangs upright on the face: columns along the dock's +y, rows down,
  // its back into the dock.
  Mat3 upright = Mat3::Zero();
  upright(1, 0) = 1;
  upright(2, 1) = -1;
  upright(0, 2) = -1;
  const Mat3 r_fd = dockcore::axis_rotation(2, dock.yaw_rad);
  const Mat3 r_ft = r_fd * dockcore::axis_rotation(2, tag.yaw_rad) * upright;
  const Vec3 p_ft = Vec3(dock.x_m, dock.y_m, 0) + r_fd * Vec3(tag.x_m, tag.y_m, tag.z_m);
  const Mat3 r_fo = dockcore::camera_rotation(camera);
  const Mat3 r_ot = r_fo.transpose() * r_ft;
  const Vec3 t_ot = r_fo.transpose() * (p_ft - Vec3(camera.x_m, camera.y_m, camera.z_m));
  for (int k = 0; k < 9; ++k) view.rotation[k] = static_cast<double>(r_ot(k / 3, k % 3));
  for (int k = 0; k < 3; ++k) view.translation_m[k] = static_cast<double>(t_ot(k));
}

}  // namespace docksim
