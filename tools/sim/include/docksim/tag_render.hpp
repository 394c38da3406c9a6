#pragma once
// Pinhole rendering of a square fiducial (an AprilTag's code pattern) into an 8-bit grey image at a camera pose,
// so a tag detector can be tested on frames whose truth is known exactly. Host-side, deterministic.
// Camera frame: x right, y down, z along the optical axis. Tag frame: origin at the tag's centre, x along its
// columns, y along its rows (as printed: row 0 at the top), z out of the back of the tag (a tag facing the camera
// has its z along the camera's z).
#include <cstdint>

namespace docksim {

/// The tag's printed pattern: `cells` × `cells` values (row-major, 0 = black, 255 = white), the outermost ring
/// included, and the physical size of one cell.
struct TagPattern {
  const std::uint8_t* cells_grey = nullptr;
  std::uint32_t cells = 0;
  double cell_m = 0.01;
};

struct PinholeView {
  double fx_px = 600, fy_px = 600, cx_px = 319.5, cy_px = 239.5;  ///< Pixel centres at integer coordinates.
  std::uint32_t width_px = 640, height_px = 480;
  double rotation[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< Tag frame → camera frame, row-major.
  double translation_m[3] = {0, 0, 1};               ///< Tag centre in the camera frame.
  std::uint8_t background = 128;                      ///< Grey where the ray misses the tag.
  std::uint32_t supersample = 3;                      ///< Samples per pixel side (anti-aliasing; 1..8).
  /// Samples per pixel side where those `supersample` ones disagree (a pixel on an edge; ≤ 32): an edge is then
  /// placed to 1/(2·this) px rather than 1/(2·supersample), which sub-pixel corner and yaw checks need.
  std::uint32_t edge_supersample = 16;
};

/// Renders the tag into `grey` (width × height, `stride_bytes` per row), replacing every pixel. Pixels whose rays
/// miss the tag or meet it from behind get the background. False (image untouched) for an empty pattern, a zero
/// focal length, supersample outside 1..8 or edge_supersample above 32. O(width · height · supersample² + edge
/// pixels · edge_supersample²).
bool render_tag(const TagPattern& tag, const PinholeView& view, std::uint8_t* grey, std::uint32_t stride_bytes);

/// The rotation (row-major) of a tag facing the camera, turned by `yaw_rad` about the camera's y axis (a tag on a
/// dock seen from a robot off the dock's axis). O(1).
void facing_rotation(double yaw_rad, double rotation[9]);

/// The pixel (u, v) of the tag-frame point (x, y, 0) in `view`; false when it is behind the camera. O(1).
bool project_tag_point(const PinholeView& view, double x_m, double y_m, double& u_px, double& v_px);

}  // namespace docksim
