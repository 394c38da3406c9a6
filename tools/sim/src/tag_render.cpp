// Pinhole rendering of a tag pattern (see docksim/tag_render.hpp).
#include "docksim/tag_render.hpp"

#include <cmath>

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
      v.supersample < 1 || v.supersample > 8 || grey == nullptr || stride_bytes < v.width_px) {
    return false;
  }
  const double* R = v.rotation;
  const double* t = v.translation_m;
  const double n[3] = {R[2], R[5], R[8]};  // the tag's z axis in the camera frame
  const double nt = n[0] * t[0] + n[1] * t[1] + n[2] * t[2];
  const double half = 0.5 * tag.cell_m * tag.cells;
  const std::uint32_t ss = v.supersample;
  for (std::uint32_t row = 0; row < v.height_px; ++row) {
    for (std::uint32_t col = 0; col < v.width_px; ++col) {
      double sum = 0;
      for (std::uint32_t sy = 0; sy < ss; ++sy) {
        for (std::uint32_t sx = 0; sx < ss; ++sx) {
          // Sub-sample positions spread over the pixel [col − ½, col + ½] × [row − ½, row + ½].
          const double u = col - 0.5 + (sx + 0.5) / ss;
          const double w = row - 0.5 + (sy + 0.5) / ss;
          const double d[3] = {(u - v.cx_px) / v.fx_px, (w - v.cy_px) / v.fy_px, 1.0};
          const double nd = n[0] * d[0] + n[1] * d[1] + n[2] * d[2];
          double value = v.background;
          // The plane n·(P − t) = 0 along the ray P = λ·d, met in front of the camera and from the tag's front.
          if (nd > 1e-12 && nt > 0) {
            const double lambda = nt / nd;
            const double p[3] = {lambda * d[0] - t[0], lambda * d[1] - t[1], lambda * d[2] - t[2]};
            const double x = R[0] * p[0] + R[3] * p[1] + R[6] * p[2];  // Rᵀ(P − t)
            const double y = R[1] * p[0] + R[4] * p[1] + R[7] * p[2];
            if (x >= -half && x < half && y >= -half && y < half) {
              const auto c = static_cast<std::uint32_t>((x + half) / tag.cell_m);
              const auto r = static_cast<std::uint32_t>((y + half) / tag.cell_m);
              if (c < tag.cells && r < tag.cells) value = tag.cells_grey[r * tag.cells + c];
            }
          }
          sum += value;
        }
      }
      grey[static_cast<std::size_t>(row) * stride_bytes + col] =
          static_cast<std::uint8_t>(std::lround(sum / (ss * ss)));
    }
  }
  return true;
}

}  // namespace docksim
