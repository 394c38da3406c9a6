#pragma once
// Pinhole rendering of a square fiducial (an AprilTag's code pattern) into an 8-bit grey image at a camera pose,
// so a tag detector can be tested on frames whose truth is known exactly. Host-side, deterministic.
// Camera frame: x right, y down, z along the optical axis. Tag frame: origin at the tag's centre, x along its
// columns, y along its rows (as printed: row 0 at the top), z out of the back of the tag (a tag facing the camera
// has its z along the camera's z).
#include <cstdint>

#include "dockcore/geometry.hpp"
#include "dockcore/perception/tag_measurement.hpp"

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
  std::uint8_t background = 128;                     ///< Grey where the ray misses the tag.
  std::uint32_t supersample = 3;                     ///< Samples per pixel side (anti-aliasing; 1..8).
  /// Samples per pixel side where those `supersample` ones disagree (a pixel on an edge; ≤ 32): an edge is then
  /// placed to 1/(2·this) px rather than 1/(2·supersample), which sub-pixel corner and yaw checks need.
  std::uint32_t edge_supersample = 16;
};

/// A rectangle of pixels: columns [col0, col1), rows [row0, row1).
struct PixelRect {
  std::uint32_t col0 = 0, row0 = 0, col1 = 0, row1 = 0;
};

/// Renders the tag into `grey` (width × height, `stride_bytes` per row), replacing every pixel (or only those in
/// `region`, clipped to the image, when given). Pixels whose rays miss the tag or meet it from behind get the
/// background. False (image untouched) for an empty pattern, a zero focal length, supersample outside 1..8 or
/// edge_supersample above 32. O(pixels rendered · supersample² + edge pixels · edge_supersample²).
bool render_tag(const TagPattern& tag, const PinholeView& view, std::uint8_t* grey, std::uint32_t stride_bytes,
                const PixelRect* region = nullptr);

/// The pixels the tag's pattern covers in `view`, grown by `margin_px` and clipped to the image; false when a
/// corner is behind the camera or the tag lies wholly outside the image. O(1).
bool tag_pixel_bounds(const TagPattern& tag, const PinholeView& view, std::uint32_t margin_px, PixelRect& out);

/// Separable Gaussian blur of σ `sigma_px` (kernel ±3σ, edges clamped) over `region` of a grey image (the whole
/// image without one), in place; σ ≤ 0 leaves it alone. O(region pixels · σ).
void blur_grey(std::uint8_t* grey, std::uint32_t width_px, std::uint32_t height_px, std::uint32_t stride_bytes,
               double sigma_px, const PixelRect* region = nullptr);

/// Places the dock's tag in `view` (its rotation and translation): the camera at `camera` and the dock at `dock`,
/// both in one frame (the robot's, or the world's), the tag on the dock at `tag` — the chain
/// dockcore::tag_to_dock_measurement inverts. O(1).
void place_tag_in_view(PinholeView& view, const dockcore::CameraMount3& camera, const dockcore::Pose2& dock,
                       const dockcore::DockTag& tag);

/// The rotation (row-major) of a tag facing the camera, turned by `yaw_rad` about the camera's y axis (a tag on a
/// dock seen from a robot off the dock's axis). O(1).
void facing_rotation(double yaw_rad, double rotation[9]);

/// The pixel (u, v) of the tag-frame point (x, y, 0) in `view`; false when it is behind the camera. O(1).
bool project_tag_point(const PinholeView& view, double x_m, double y_m, double& u_px, double& v_px);

}  // namespace docksim
