#pragma once
/// @file AprilTag detection on grey frames (docs/camera.md), a thin wrapper of libapriltag (Debian's
/// libapriltag-dev): family by name, the detector's tuning, and per tag the centre (u, v), id, decision margin,
/// corners and the tag's pose in the camera frame from its printed size and the camera intrinsics
/// (estimate_tag_pose). With lens distortion given, the centre, the corners used for the pose and the pose itself
/// are corrected to the ideal pinhole image; `corners_px` stay as detected in the raw image.
/// Pixel coordinates follow the camera-calibration convention (OpenCV, ROS): the centre of the top-left pixel is
/// (0, 0), so they agree with cx, cy. libapriltag's own coordinates put it at (0.5, 0.5); they are shifted by −0.5 px.
/// libapriltag allocates on every detect() call (its own images, lists and worker pool): run it off the control
/// tick (CameraPipeline does).

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace dockcore::drivers {

/// Pinhole intrinsics of the camera plus OpenCV's radial-tangential ("plumb bob") distortion k1 k2 p1 p2 k3.
struct CameraIntrinsics {
  double fx_px = 0;
  double fy_px = 0;
  double cx_px = 0;
  double cy_px = 0;
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
  bool has_distortion() const { return k1 != 0 || k2 != 0 || p1 != 0 || p2 != 0 || k3 != 0; }
};

/// The ideal (undistorted) pixel of raw pixel (u, v), by fixed-point iteration of the distortion model (20
/// iterations; converges for the distortion of ordinary lenses within the image). O(1).
void undistort_pixel(const CameraIntrinsics& k, double u_px, double v_px, double& u_out_px, double& v_out_px);
/// The raw pixel an ideal pixel is imaged at (the forward model). O(1).
void distort_pixel(const CameraIntrinsics& k, double u_px, double v_px, double& u_out_px, double& v_out_px);

/// The tag families libapriltag 3.3 provides, null-terminated: tag16h5, tag25h9, tag36h10, tag36h11, tagCircle21h7,
/// tagCircle49h12, tagCustom48h12, tagStandard41h12, tagStandard52h13.
extern const char* const kTagFamilyNames[];
/// True when `name` is one of kTagFamilyNames.
bool is_tag_family(const std::string& name);

struct TagDetectorOptions {
  std::string family = "tag36h11";
  double tag_size_m = 0.10;          ///< Side of the tag's black square (the outer edge of its border), m.
  CameraIntrinsics intrinsics{};     ///< Required for the pose (fx, fy > 0); without it has_pose is false.
  double quad_decimate = 2.0;        ///< libapriltag quad_decimate: quads found on an image this many times smaller.
  double quad_sigma = 0.0;           ///< Gaussian blur before quad detection, px (0 = none).
  int threads = 1;                   ///< libapriltag worker threads.
  bool refine_edges = true;          ///< Snap quad edges to the full-resolution gradients.
  /// Then move the corners onto lines fitted to the black square's edges at sub-pixel precision (the step position
  /// of the grey profile across each edge): the tag's yaw rests on tenths of a pixel between its edges.
  bool refine_corners = true;
  double min_decision_margin = 0.0;  ///< Detections with a smaller decision margin are dropped.
  int max_hamming = 2;               ///< Bit errors corrected (0..2; libapriltag's default for tag36h11 is 2).
};

/// Draws tag `id` of `family` upright (no perspective) into a grey image, for tests and the benchmark: `cell_px`
/// pixels per code cell, the top-left corner of its outer white ring at (x0_px, y0_px). `black_side_px` (optional)
/// gets the side of the black square in pixels (the tag size the pose uses). False when the family or id is unknown
/// or the tag does not fit. O(tag pixels); allocates (libapriltag's tag image).
bool draw_tag_upright(const std::string& family, int id, std::uint32_t cell_px, std::uint32_t x0_px,
                      std::uint32_t y0_px, std::uint8_t* grey, std::uint32_t width_px, std::uint32_t height_px,
                      std::uint32_t stride_bytes, std::uint32_t* black_side_px = nullptr);

/// One tag in one frame.
struct TagDetection {
  int id = 0;
  int hamming = 0;                ///< Bits corrected.
  double decision_margin = 0;     ///< libapriltag's decode quality (higher = more certain; small for a blurred tag).
  double u_px = 0, v_px = 0;      ///< Centre of the tag (ideal pinhole image when distortion is given).
  double corners_px[4][2] = {};   ///< Corners in the raw image (refined when refine_corners), counter-clockwise.
  bool has_pose = false;
  double rotation[9] = {};        ///< Tag frame → camera frame rotation, row-major (camera: x right, y down, z out).
  double translation_m[3] = {};   ///< Tag centre in the camera frame, m.
  double pose_error = 0;          ///< estimate_tag_pose's object-space error (smaller is better).
  /// With the pose: the corners in the ideal pinhole image in unit-focal coordinates ((u − cx)/fx, (v − cy)/fy,
  /// distortion removed), in `corners_px`'s order, which is the tag-frame order of dockcore::kTagCornerX/Y.
  double corners_unit_focal[4][2] = {};
};

/// Most detections reported per frame (more are counted in `overflow` of detect()).
constexpr std::size_t kMaxTagDetections = 32;

class TagDetector {
 public:
  /// nullptr + message when the family is unknown (the message lists the known ones), the size is not > 0 or a
  /// tuning value is out of range.
  static std::unique_ptr<TagDetector> create(const TagDetectorOptions& options, std::string& error);
  virtual ~TagDetector() = default;
  /// Detects tags in a grey image (`stride_bytes` per row, width/height < 32768). Writes at most `max_out`
  /// detections, strongest decision margin first, and returns how many were written; `overflow` (optional) gets
  /// those left out. Allocates inside libapriltag.
  virtual std::size_t detect(const std::uint8_t* grey, std::uint32_t width_px, std::uint32_t height_px,
                             std::uint32_t stride_bytes, TagDetection* out, std::size_t max_out,
                             std::size_t* overflow = nullptr) = 0;
  virtual const TagDetectorOptions& options() const = 0;
};

}  // namespace dockcore::drivers
