#pragma once
// The simulator's rendered camera: every frame is a pinhole image of the dock's AprilTag at the camera's true pose
// (docksim/tag_render.hpp), with the optics' blur and pixel noise, run through the detector dockd runs
// (dockcore::drivers::TagDetector, libapriltag) and reduced to what dockd's camera pipeline queues
// (select_target_tag). So `dock-sim run` with `[robot.camera] render = true` docks on detections of images, not on
// a target-level model. Host-side; allocates (images, libapriltag). Deterministic for a given scenario and noise
// stream.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/drivers/apriltag_detector.hpp"
#include "docksim/camera_sim.hpp"
#include "docksim/scenario.hpp"
#include "docksim/tag_render.hpp"

namespace docksim {

/// A tag's printed pattern, one value per code cell, for the renderer: tag `id` of `family` with a black square of
/// side `size_m`. Empty `cells` (and a message in `error`) when the family or id is unknown. Allocates.
struct TagPatternImage {
  std::vector<std::uint8_t> cells;
  TagPattern pattern{};  ///< Points into `cells`: do not copy the struct and keep the pattern.
};
bool make_tag_pattern(const std::string& family, int id, double size_m, TagPatternImage& out, std::string& error);

/// A FrameCamera for one run of a scenario whose camera renders (Scenario::camera.render).
class RenderedTagCamera final : public FrameCamera {
 public:
  /// nullptr + message when the tag cannot be drawn or the detector not made (unknown family, bad size).
  static std::unique_ptr<RenderedTagCamera> create(const Scenario& sc, std::string& error);

  /// Renders the frame (background grey 128; only the tag's pixels are drawn and blurred), paints the image columns
  /// in which an occluder stands between the camera and the tag's plane dark grey (60), scales by the exposure, adds
  /// the noise, detects. A hidden dock, or a tag behind the camera or wholly outside the image, gives an empty frame
  /// without a detection run. Cost: the tag's pixels × 9 samples, a ray per tag column, plus one detection (≈ 2 ms at
  /// 640×480, decimate 2).
  CameraFrameOutput capture(const dockcore::Pose2& robot_world, bool dock_visible, const World* occluders,
                            Rng& rng) override;

 private:
  RenderedTagCamera() = default;
  /// Paints the columns of `box` whose ray from the camera meets an occluder before the tag's plane.
  void occlude_columns(const World& occluders, const dockcore::Pose2& camera_world, const PixelRect& box);

  TagPatternImage tag_;
  PinholeView view_{};
  dockcore::CameraMount3 mount_{};  ///< The camera on the robot (level).
  dockcore::Pose2 dock_world_{};
  dockcore::DockTag dock_tag_{};
  double blur_px_ = 0;
  int exposure_q8_ = 256;  ///< Exposure gain in 1/256.
  std::int32_t tag_id_ = 0;
  std::unique_ptr<dockcore::drivers::TagDetector> detector_;
  std::vector<std::uint8_t> image_;
  std::vector<std::int8_t> noise_;  ///< A table of Gaussian pixel noise; each frame starts at a random offset.
};

}  // namespace docksim
