// Pinhole rendering of a tag pattern (see docksim/tag_render.hpp).
#include "docksim/tag_render.hpp"

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

bool render_tag(const TagPattern& tag, const PinholeView& v, std::uint8_t* grey, std::uint32_t stride_bytes) {
  if (tag.cells_grey == nullptr || tag.cells == 0 || !(tag.cell_m > 0) || !(v.fx_px > 0) || !(v.fy_px > 0) ||
      v.supersample < 1 || v.supersample > 8 || v.edge_supersample > 32 || grey == nullptr ||
      stride_bytes < v.width_px) {
    return false;
  }
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
  const std::uint32_t w_px = v.width_px, h_px = v.height_px;
  std::vector<std::uint8_t> coarse(static_cast<std::size_t>(w_px) * h_px);
  std::vector<std::uint8_t> mixed(coarse.size());
  for (std::uint32_t row = 0; row < h_px; ++row) {
    for (std::uint32_t col = 0; col < w_px; ++col) {
      bool uniform = true;
      const std::size_t i = static_cast<std::size_t>(row) * w_px + col;
      coarse[i] = static_cast<std::uint8_t>(std::lround(pixel(col, row, v.supersample, &uniform)));
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
        g = static_cast<std::uint8_t>(std::lround(pixel(col, row, v.edge_supersample, nullptr)));
      }
      grey[static_cast<std::size_t>(row) * stride_bytes + col] = g;
    }
  }
  return true;
}

}  // namespace docksim
