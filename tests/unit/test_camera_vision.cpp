// The AprilTag wrapper and the detection thread on tags drawn by libapriltag's own tag images (upright, sharp):
// centre, id and pose against the drawing's geometry, the lens-distortion model, families, and the pipeline's
// bounded queue (target id filter, newest wins, full queue counted, stale refused) with a fake frame source.
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include <time.h>

#include "dockcore/drivers/apriltag_detector.hpp"
#include "dockcore/drivers/camera_pipeline.hpp"

#include <CppUTest/TestHarness.h>

using namespace dockcore;
using namespace dockcore::drivers;

namespace {

constexpr std::uint32_t kW = 640, kH = 480;

std::uint64_t mono_us() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000u + static_cast<std::uint64_t>(ts.tv_nsec) / 1000u;
}

/// A 640×480 mid-grey frame with tag36h11 `id` drawn at 12 px per cell (black square 96 px) from (x0, y0).
std::vector<std::uint8_t> drawn_frame(int id, std::uint32_t x0, std::uint32_t y0, std::uint32_t* black_px = nullptr) {
  std::vector<std::uint8_t> img(kW * kH, 128);
  CHECK(draw_tag_upright("tag36h11", id, 12, x0, y0, img.data(), kW, kH, kW, black_px));
  return img;
}

CameraIntrinsics pinhole() { return CameraIntrinsics{600, 600, 319.5, 239.5}; }

/// Serves one image over and over, stamped `age_us` before now, at most every `period_ms`.
class FakeFrames final : public hal::CameraFrameSource {
 public:
  FakeFrames(std::vector<std::uint8_t> img, std::uint64_t age_us, int period_ms)
      : img_(std::move(img)), age_us_(age_us), period_ms_(period_ms) {}
  hal::CameraFrameStatus next_frame(hal::CameraFrame& out, int) override {
    std::this_thread::sleep_for(std::chrono::milliseconds(period_ms_));
    out.grey = img_.data();
    out.width_px = kW;
    out.height_px = kH;
    out.stride_bytes = kW;
    out.stamp_us = mono_us() - age_us_;
    out.sequence = seq_++;
    ++c_.frames;
    served_.store(c_.frames);
    return hal::CameraFrameStatus::kFrame;
  }
  bool connected() const override { return true; }
  const hal::CameraFrameCounters& counters() const override { return c_; }
  const char* last_error() const override { return ""; }
  std::atomic<std::uint64_t> served_{0};

 private:
  std::vector<std::uint8_t> img_;
  std::uint64_t age_us_;
  int period_ms_;
  std::uint32_t seq_ = 0;
  hal::CameraFrameCounters c_{};
};

bool wait_for(const std::function<bool()>& cond, int timeout_ms) {
  for (int i = 0; i < timeout_ms / 5; ++i) {
    if (cond()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return cond();
}

}  // namespace

TEST_GROUP(TagDetector){};

TEST(TagDetector, DrawnTagCentreIdAndPoseMatchTheDrawing) {
  std::uint32_t black = 0;
  const auto img = drawn_frame(7, 200, 150, &black);
  CHECK_EQUAL(96u, black);
  TagDetectorOptions o;
  o.tag_size_m = 0.10;
  o.intrinsics = pinhole();
  std::string err;
  auto det = TagDetector::create(o, err);
  CHECK_TEXT(det != nullptr, err.c_str());
  TagDetection d[kMaxTagDetections];
  CHECK_EQUAL(1u, det->detect(img.data(), kW, kH, kW, d, kMaxTagDetections));
  CHECK_EQUAL(7, d[0].id);
  CHECK_EQUAL(0, d[0].hamming);
  CHECK(d[0].decision_margin > 50);
  // The ring is 10 cells (120 px, pixels 200..319): its centre lies between pixels 259 and 260, at 259.5 in the
  // calibration convention (pixel centres at integers) that the wrapper reports in.
  DOUBLES_EQUAL(259.5, d[0].u_px, 0.2);
  DOUBLES_EQUAL(209.5, d[0].v_px, 0.2);
  // Fronto-parallel at Z = fx · size / side = 600 · 0.10 / 96 = 0.625 m; X, Y from the offset to the principal point.
  CHECK(d[0].has_pose);
  DOUBLES_EQUAL(0.625, d[0].translation_m[2], 0.625 * 0.02);
  DOUBLES_EQUAL((259.5 - 319.5) * 0.625 / 600, d[0].translation_m[0], 0.003);
  DOUBLES_EQUAL((209.5 - 239.5) * 0.625 / 600, d[0].translation_m[1], 0.003);
  // Tag z axis points into the image (away from the camera) for libapriltag's convention: R's third column ≈ ±z.
  DOUBLES_EQUAL(1.0, std::fabs(d[0].rotation[8]), 0.02);
}

TEST(TagDetector, WithoutIntrinsicsThereIsNoPose) {
  const auto img = drawn_frame(3, 100, 100);
  std::string err;
  auto det = TagDetector::create(TagDetectorOptions{}, err);
  TagDetection d[4];
  CHECK_EQUAL(1u, det->detect(img.data(), kW, kH, kW, d, 4));
  CHECK_FALSE(d[0].has_pose);
}

TEST(TagDetector, MaxOutKeepsTheStrongestAndCountsTheRest) {
  std::vector<std::uint8_t> img(kW * kH, 128);
  CHECK(draw_tag_upright("tag36h11", 1, 8, 20, 20, img.data(), kW, kH, kW));
  CHECK(draw_tag_upright("tag36h11", 2, 12, 300, 200, img.data(), kW, kH, kW));
  std::string err;
  auto det = TagDetector::create(TagDetectorOptions{}, err);
  TagDetection d[1];
  std::size_t overflow = 0;
  CHECK_EQUAL(1u, det->detect(img.data(), kW, kH, kW, d, 1, &overflow));
  CHECK_EQUAL(1u, overflow);
}

TEST(TagDetector, UnknownFamilyIsRefusedListingTheKnownOnes) {
  TagDetectorOptions o;
  o.family = "tag37h11";
  std::string err;
  POINTERS_EQUAL(nullptr, TagDetector::create(o, err).get());
  STRCMP_CONTAINS("tag family 'tag37h11' is not one libapriltag provides", err.c_str());
  STRCMP_CONTAINS("tag36h11", err.c_str());
  CHECK_TRUE(is_tag_family("tagStandard41h12"));
  CHECK_FALSE(is_tag_family("aruco4x4"));
  o.family = "tag36h11";
  o.tag_size_m = 0;
  POINTERS_EQUAL(nullptr, TagDetector::create(o, err).get());
}

TEST(TagDetector, OtherFamiliesDetectTheirOwnTags) {
  std::vector<std::uint8_t> img(kW * kH, 128);
  CHECK(draw_tag_upright("tag25h9", 4, 12, 100, 100, img.data(), kW, kH, kW));
  TagDetectorOptions o;
  std::string err;
  auto det36 = TagDetector::create(o, err);
  TagDetection d[4];
  CHECK_EQUAL(0u, det36->detect(img.data(), kW, kH, kW, d, 4));
  o.family = "tag25h9";
  auto det25 = TagDetector::create(o, err);
  CHECK_EQUAL(1u, det25->detect(img.data(), kW, kH, kW, d, 4));
  CHECK_EQUAL(4, d[0].id);
}

TEST(TagDetector, DistortionModelRoundTripsAndCorrectsTheCentre) {
  CameraIntrinsics k = pinhole();
  k.k1 = -0.25;
  k.k2 = 0.08;
  k.p1 = 0.001;
  k.p2 = -0.0015;
  for (double u = 20; u < 640; u += 150) {
    for (double v = 20; v < 480; v += 110) {
      double ud = 0, vd = 0, uu = 0, vu = 0;
      distort_pixel(k, u, v, ud, vd);
      undistort_pixel(k, ud, vd, uu, vu);
      DOUBLES_EQUAL(u, uu, 1e-6);
      DOUBLES_EQUAL(v, vu, 1e-6);
    }
  }
  // A detection off-centre: the reported centre is the corrected one, the corners stay raw.
  const auto img = drawn_frame(5, 60, 40);
  TagDetectorOptions o;
  o.intrinsics = k;
  std::string err;
  auto det = TagDetector::create(o, err);
  TagDetection d[2];
  CHECK_EQUAL(1u, det->detect(img.data(), kW, kH, kW, d, 2));
  double want_u = 0, want_v = 0;
  undistort_pixel(k, 119.5, 99.5, want_u, want_v);
  DOUBLES_EQUAL(want_u, d[0].u_px, 1.0);
  DOUBLES_EQUAL(want_v, d[0].v_px, 1.0);
  CHECK(std::fabs(d[0].u_px - 119.5) > 3);  // the correction is not nothing
  CHECK(d[0].has_pose);
}

TEST_GROUP(CameraPipeline){};

TEST(CameraPipeline, TargetReachesThePollWithTheFrameStamp) {
  FakeFrames src(drawn_frame(7, 200, 150), 0, 5);
  TagDetectorOptions o;
  o.intrinsics = pinhole();
  std::string err;
  auto det = TagDetector::create(o, err);
  CameraPipelineOptions po;
  po.target_id = 7;
  auto p = CameraPipeline::start(src, *det, po, err);
  CHECK_TEXT(p != nullptr, err.c_str());
  CHECK(p->fd() >= 0);
  CameraTarget t;
  CHECK(wait_for([&] { return p->poll_target(t); }, 3000));
  CHECK(t.valid);
  DOUBLES_EQUAL(259.5, static_cast<double>(t.u_px), 0.5);
  DOUBLES_EQUAL(209.5, static_cast<double>(t.v_px), 0.5);
  CHECK(t.confidence > 0 && t.confidence <= 1);
  CHECK(t.stamp_us <= mono_us() && mono_us() - t.stamp_us < 2000000u);
  const CameraPipelineStats s = p->stats();
  CHECK(s.frames_processed >= 1);
  CHECK(s.target_frames >= 1);
  CHECK_EQUAL(7, s.last_tag.id);
  CHECK(s.detect_last_ms > 0);
  p->stop();
}

TEST(CameraPipeline, TagPosesComeInFrameOrderWithTheirStampsBesideTheTarget) {
  FakeFrames src(drawn_frame(7, 200, 150), 0, 5);
  TagDetectorOptions o;
  o.intrinsics = pinhole();
  std::string err;
  auto det = TagDetector::create(o, err);
  CameraPipelineOptions po;
  po.target_id = 7;
  auto p = CameraPipeline::start(src, *det, po, err);
  CHECK_TEXT(p != nullptr, err.c_str());
  CHECK(wait_for([&] { return p->stats().target_frames >= 3; }, 3000));
  p->stop();
  // Draining for the poses leaves the newest target for poll_target.
  TagObservation a, b;
  CHECK(p->poll_tag(a));
  CHECK(p->poll_tag(b));
  CHECK_EQUAL(7, a.id);
  CHECK(b.stamp_us > a.stamp_us);
  CHECK(a.translation_m.z() > 0);
  CHECK(a.decision_margin > 0);
  // The corners for the core's corner fit: around the tag's centre, in unit-focal coordinates.
  CHECK(a.has_corners);
  const dockcore::Vec2 mean = (a.corners[0] + a.corners[1] + a.corners[2] + a.corners[3]) / 4;
  DOUBLES_EQUAL(a.translation_m.x() / a.translation_m.z(), mean.x(), 1e-3);
  DOUBLES_EQUAL(a.translation_m.y() / a.translation_m.z(), mean.y(), 1e-3);
  CameraTarget t;
  CHECK(p->poll_target(t));
  CHECK(t.stamp_us >= b.stamp_us);
  while (p->poll_tag(a)) {
  }
  CHECK_FALSE(p->poll_tag(a));
}

TEST(CameraPipeline, OtherIdsAreNoTarget) {
  FakeFrames src(drawn_frame(7, 200, 150), 0, 5);
  std::string err;
  auto det = TagDetector::create(TagDetectorOptions{}, err);
  CameraPipelineOptions po;
  po.target_id = 8;
  auto p = CameraPipeline::start(src, *det, po, err);
  CHECK(wait_for([&] { return p->stats().frames_processed >= 3; }, 3000));
  CameraTarget t;
  CHECK_FALSE(p->poll_target(t));
  CHECK_EQUAL(0u, p->stats().target_frames);
}

TEST(CameraPipeline, AFullQueueDropsAndCountsAndThePollTakesTheNewest) {
  FakeFrames src(drawn_frame(7, 200, 150), 0, 1);
  std::string err;
  auto det = TagDetector::create(TagDetectorOptions{}, err);
  auto p = CameraPipeline::start(src, *det, CameraPipelineOptions{}, err);
  // Nobody polls: after more than a queue of results the thread drops and counts.
  CHECK(wait_for([&] { return p->stats().queue_full >= 2; }, 5000));
  const std::uint64_t before = mono_us();
  CameraTarget t;
  CHECK(p->poll_target(t));
  const std::uint64_t took = mono_us() - before;
  CHECK_TEXT(took < 5000u, "poll_target must not wait for the thread");
  CHECK(t.valid);
  // Drained: nothing more until the thread pushes again.
  CameraTarget t2;
  if (p->poll_target(t2)) CHECK(t2.stamp_us >= t.stamp_us);
}

TEST(CameraPipeline, StaleTargetsAreRefusedAndCounted) {
  FakeFrames src(drawn_frame(7, 200, 150), 2000000u, 5);  // every frame 2 s old
  std::string err;
  auto det = TagDetector::create(TagDetectorOptions{}, err);
  CameraPipelineOptions po;
  po.max_age_ms = 500;
  auto p = CameraPipeline::start(src, *det, po, err);
  CHECK(wait_for([&] { return p->stats().target_frames >= 2; }, 3000));
  CameraTarget t;
  CHECK_FALSE(p->poll_target(t));
  CHECK(p->stats().stale >= 1);
}

// The simulator's pinhole tag renderer (docksim/tag_render.hpp) and the detector together: a tag36h11 at a known
// pose in front of a known camera is found where the projection puts it, with that pose.
#include "docksim/tag_render.hpp"

namespace {

struct RenderedTag {
  std::vector<std::uint8_t> image = std::vector<std::uint8_t>(kW * kH, 0);
  docksim::PinholeView view{};
  double black_side_m = 0;
};

RenderedTag render(int id, double x_m, double y_m, double z_m, double yaw_rad, double black_side_m) {
  // The pattern, one pixel per cell: 10 × 10 for tag36h11 (white ring, black border, 6 × 6 data).
  std::uint8_t cells[10 * 10] = {};
  std::uint32_t black_cells = 0;
  CHECK(draw_tag_upright("tag36h11", id, 1, 0, 0, cells, 10, 10, 10, &black_cells));
  CHECK_EQUAL(8u, black_cells);
  RenderedTag r;
  r.black_side_m = black_side_m;
  docksim::TagPattern p{cells, 10, black_side_m / black_cells};
  r.view.translation_m[0] = x_m;
  r.view.translation_m[1] = y_m;
  r.view.translation_m[2] = z_m;
  docksim::facing_rotation(yaw_rad, r.view.rotation);
  CHECK(docksim::render_tag(p, r.view, r.image.data(), kW));
  return r;
}

}  // namespace

TEST_GROUP(RenderedTag){};

TEST(RenderedTag, DetectedWhereTheProjectionPutsItWithItsPose) {
  struct Case {
    double x, y, z, yaw_deg;
  };
  const Case cases[] = {{0, 0, 0.8, 0}, {0.12, -0.05, 1.0, 25}, {-0.2, 0.04, 1.5, -35}, {0.05, 0.02, 0.5, 10}};
  for (const Case& c : cases) {
    const RenderedTag r = render(3, c.x, c.y, c.z, c.yaw_deg * 3.14159265358979 / 180, 0.10);
    TagDetectorOptions o;
    o.tag_size_m = r.black_side_m;
    o.intrinsics = CameraIntrinsics{r.view.fx_px, r.view.fy_px, r.view.cx_px, r.view.cy_px};
    std::string err;
    auto det = TagDetector::create(o, err);
    TagDetection d[4];
    char msg[160];
    std::snprintf(msg, sizeof msg, "tag at (%.2f, %.2f, %.2f) m, yaw %.0f deg", c.x, c.y, c.z, c.yaw_deg);
    CHECK_EQUAL_TEXT(1u, det->detect(r.image.data(), kW, kH, kW, d, 4), msg);
    CHECK_EQUAL_TEXT(3, d[0].id, msg);
    double u = 0, v = 0;
    CHECK(docksim::project_tag_point(r.view, 0, 0, u, v));
    DOUBLES_EQUAL_TEXT(u, d[0].u_px, 0.25, msg);
    DOUBLES_EQUAL_TEXT(v, d[0].v_px, 0.25, msg);
    // Every detected corner is within 0.5 px of a projected corner of the black square.
    const double h = r.black_side_m / 2;
    for (const auto& corner : d[0].corners_px) {
      double best = 1e9;
      for (const double sx : {-h, h}) {
        for (const double sy : {-h, h}) {
          double cu = 0, cv = 0;
          docksim::project_tag_point(r.view, sx, sy, cu, cv);
          best = std::fmin(best, std::hypot(corner[0] - cu, corner[1] - cv));
        }
      }
      CHECK_TEXT(best < 0.5, msg);
    }
    CHECK_TEXT(d[0].has_pose, msg);
    DOUBLES_EQUAL_TEXT(c.x, d[0].translation_m[0], 0.01 * c.z, msg);
    DOUBLES_EQUAL_TEXT(c.y, d[0].translation_m[1], 0.01 * c.z, msg);
    DOUBLES_EQUAL_TEXT(c.z, d[0].translation_m[2], 0.01 * c.z, msg);
  }
}

TEST(RenderedTag, RefinedCornersAreWithinAFewHundredthsOfAPixel) {
  // The tag's yaw rests on tenths of a pixel of perspective between its left and right edges: the refined corners
  // must be far better than that, at any pose.
  struct Case {
    double x, y, z, yaw_deg, side_m;
  };
  const Case cases[] = {{0, 0, 1.0, 4, 0.15}, {0.05, 0.01, 1.0, -9, 0.08}, {-0.12, 0.03, 0.8, 25, 0.10}};
  for (const Case& c : cases) {
    const RenderedTag r = render(3, c.x, c.y, c.z, c.yaw_deg * 3.14159265358979 / 180, c.side_m);
    TagDetectorOptions o;
    o.tag_size_m = r.black_side_m;
    o.intrinsics = CameraIntrinsics{r.view.fx_px, r.view.fy_px, r.view.cx_px, r.view.cy_px};
    std::string err;
    auto det = TagDetector::create(o, err);
    TagDetection d[4];
    CHECK_EQUAL(1u, det->detect(r.image.data(), kW, kH, kW, d, 4));
    char msg[160];
    const double h = r.black_side_m / 2;
    for (int k = 0; k < 4; ++k) {
      double u = 0, v = 0;
      CHECK(docksim::project_tag_point(r.view, dockcore::kTagCornerX[k] * h, dockcore::kTagCornerY[k] * h, u, v));
      const double e = std::hypot(d[0].corners_px[k][0] - u, d[0].corners_px[k][1] - v);
      std::snprintf(msg, sizeof msg, "yaw %.0f deg, corner %d off by %.3f px", c.yaw_deg, k, e);
      CHECK_TEXT(e < 0.04, msg);
      // The unit-focal corners are the same points for the core's corner fit.
      DOUBLES_EQUAL_TEXT((d[0].corners_px[k][0] - r.view.cx_px) / r.view.fx_px, d[0].corners_unit_focal[k][0], 1e-9,
                         msg);
      DOUBLES_EQUAL_TEXT((d[0].corners_px[k][1] - r.view.cy_px) / r.view.fy_px, d[0].corners_unit_focal[k][1], 1e-9,
                         msg);
    }
  }
}

TEST(RenderedTag, RendererPlacesEdgesBetweenItsCoarseSamples) {
  // A tag turned a little about the vertical: its bottom edge slants by a fraction of a pixel across the tag. The
  // rendered grey along that edge must follow the slant (an edge crossing a pixel between its coarse samples is
  // integrated on the fine grid), or sub-pixel corner checks measure the renderer.
  const RenderedTag r = render(3, 0.0186, 0, 1.0, 0.0692, 0.15);
  double u0 = 0, v0 = 0, u1 = 0, v1 = 0;
  CHECK(docksim::project_tag_point(r.view, -0.05, 0.075, u0, v0));
  CHECK(docksim::project_tag_point(r.view, 0.05, 0.075, u1, v1));
  CHECK(std::fabs(v0 - v1) > 0.2);  // the edge slants
  // The black fraction of the pixel row the edge crosses, at both ends, tracks the edge's position.
  auto edge_row_v = [&](double u, double v) {
    const auto col = static_cast<std::size_t>(std::lround(u));
    const auto row = static_cast<std::size_t>(std::lround(v));
    // Pixels above the edge are black (0), below white (255): the edge sits where the column turns white.
    const double above = r.image[(row - 1) * kW + col] / 255.0, at = r.image[row * kW + col] / 255.0,
                 below = r.image[(row + 1) * kW + col] / 255.0;
    return static_cast<double>(row) - 1.5 + (1 - above) + (1 - at) + (1 - below);
  };
  DOUBLES_EQUAL(v0, edge_row_v(u0, v0), 0.05);
  DOUBLES_EQUAL(v1, edge_row_v(u1, v1), 0.05);
}

TEST(RenderedTag, RendererRefusesBadInput) {
  std::vector<std::uint8_t> img(kW * kH, 7);
  docksim::PinholeView v;
  docksim::TagPattern empty{};
  CHECK_FALSE(docksim::render_tag(empty, v, img.data(), kW));
  const std::uint8_t cells[4] = {0, 255, 255, 0};
  docksim::TagPattern p{cells, 2, 0.05};
  v.supersample = 0;
  CHECK_FALSE(docksim::render_tag(p, v, img.data(), kW));
  CHECK_EQUAL(7, img[0]);  // untouched
  v.supersample = 2;
  v.translation_m[2] = -1;  // behind the camera: nothing but background
  CHECK(docksim::render_tag(p, v, img.data(), kW));
  CHECK_EQUAL(128, img[kW * (kH / 2) + kW / 2]);
}
