// The simulator's rendered camera: the view chain against core's tag measurement (exact inverse), the region-limited
// render and blur against the whole-image ones, the camera's frames against the truth, and closed-loop dockings on
// rendered frames through the tag detector (seed 003's own success test; `smooth` with the tag fused).
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "dockcore/drivers/apriltag_detector.hpp"
#include "dockcore/perception/tag_measurement.hpp"
#include "docksim/angles.hpp"
#include "docksim/rendered_camera.hpp"
#include "docksim/rng.hpp"
#include "docksim/scenario.hpp"
#include "docksim/sim_run.hpp"
#include "docksim/tag_render.hpp"
#include "real_tolerance.hpp"

#include <CppUTest/TestHarness.h>

using dockcore::Pose2;
using dockcore::Real;

namespace {

// The controller-name list is a function-local static: create it before CppUTest starts counting allocations.
const bool kNamesReady = !docksim::controller_names().empty();

constexpr double kDeg = docksim::kDegD;

std::string repo_file(const std::string& rel) {
  std::string f = __FILE__;  // .../tests/unit/test_rendered_camera.cpp
  for (int i = 0; i < 3; ++i) f = f.substr(0, f.find_last_of('/'));
  return f + "/" + rel;
}

docksim::SimOptions rendered_options() {
  docksim::SimOptions so;
  so.record_trajectory = false;
  so.keep_last_scan = false;
  so.make_frame_camera = [](const docksim::Scenario& sc) -> std::unique_ptr<docksim::FrameCamera> {
    std::string err;
    std::unique_ptr<docksim::FrameCamera> c = docksim::RenderedTagCamera::create(sc, err);
    if (!c) FAIL(err.c_str());
    return c;
  };
  return so;
}

/// The tag observation the view describes (its rotation and translation), stamped 0, margin 100.
dockcore::TagObservation observation_of(const docksim::PinholeView& v) {
  dockcore::TagObservation o;
  o.id = 3;
  o.decision_margin = 100;
  for (int k = 0; k < 9; ++k) o.rotation(k / 3, k % 3) = static_cast<Real>(v.rotation[k]);
  for (int k = 0; k < 3; ++k) o.translation_m(k) = static_cast<Real>(v.translation_m[k]);
  return o;
}

}  // namespace

TEST_GROUP(RenderView){};

TEST(RenderView, PlacedTagMeasuresBackToTheDockPose) {
  // place_tag_in_view is the chain tag_to_dock_measurement inverts: for cameras turned, pitched and raised anywhere
  // and docks anywhere in front, the measurement gives the dock pose back exactly.
  docksim::Rng rng(7);
  for (int i = 0; i < 200; ++i) {
    dockcore::TagFusionParams p;
    p.mount =
        dockcore::CameraMount3{static_cast<Real>(rng.uniform(-0.3, 0.3)), static_cast<Real>(rng.uniform(-0.2, 0.2)),
                               static_cast<Real>(rng.uniform(0.05, 0.5)), static_cast<Real>(rng.uniform(-0.3, 0.3)),
                               static_cast<Real>(rng.uniform(-0.2, 0.2)), static_cast<Real>(rng.uniform(-0.1, 0.1))};
    p.dock_tag.id = 3;
    p.dock_tag.x_m = static_cast<Real>(rng.uniform(-0.05, 0.05));
    p.dock_tag.y_m = static_cast<Real>(rng.uniform(-0.1, 0.1));
    p.dock_tag.z_m = static_cast<Real>(rng.uniform(0.05, 0.4));
    p.dock_tag.yaw_rad = static_cast<Real>(rng.uniform(-0.2, 0.2));
    // The dock ahead of the camera, facing it within ±40°.
    const double d = rng.uniform(0.5, 2.0), b = rng.uniform(-0.3, 0.3);
    const Pose2 dock{static_cast<Real>(static_cast<double>(p.mount.x_m) + d * std::cos(b)),
                     static_cast<Real>(static_cast<double>(p.mount.y_m) + d * std::sin(b)),
                     static_cast<Real>(dockcore::kPi + b + rng.uniform(-40, 40) * kDeg)};
    docksim::PinholeView v;
    docksim::place_tag_in_view(v, p.mount, dock, p.dock_tag);
    dockcore::TagMeasurement m;
    CHECK(dockcore::tag_to_dock_measurement(observation_of(v), p, &m) == dockcore::TagStatus::kFused);
    // Two chains of 3D rotations in Real (the view's, then the measurement's): 64 ulps in the float build.
    const double tol = dockcore_test::real_tol(2.0, 1e-9, 64);
    DOUBLES_EQUAL(static_cast<double>(dock.x_m), static_cast<double>(m.dock_in_robot.x_m), tol);
    DOUBLES_EQUAL(static_cast<double>(dock.y_m), static_cast<double>(m.dock_in_robot.y_m), tol);
    DOUBLES_EQUAL(0, static_cast<double>(dockcore::wrap_angle(dock.yaw_rad - m.dock_in_robot.yaw_rad)), tol);
  }
}

TEST(RenderView, RegionRenderAndBlurMatchTheWholeImageInsideAndLeaveTheRest) {
  docksim::TagPatternImage tag;
  std::string err;
  CHECK_TEXT(docksim::make_tag_pattern("tag36h11", 3, 0.08, tag, err), err.c_str());
  docksim::PinholeView v;
  v.fx_px = v.fy_px = 500;
  v.cx_px = 320;
  v.cy_px = 240;
  docksim::facing_rotation(20 * kDeg, v.rotation);
  v.translation_m[0] = 0.05;
  v.translation_m[2] = 0.6;
  docksim::PixelRect box;
  CHECK(docksim::tag_pixel_bounds(tag.pattern, v, 5, box));
  // Every corner of the pattern projects inside the box (less its margin).
  const double h = 0.5 * tag.pattern.cell_m * tag.pattern.cells;
  for (const double sx : {-h, h}) {
    for (const double sy : {-h, h}) {
      double u = 0, w = 0;
      CHECK(docksim::project_tag_point(v, sx, sy, u, w));
      CHECK(u >= box.col0 + 5 - 1 && u <= box.col1 - 5);
      CHECK(w >= box.row0 + 5 - 1 && w <= box.row1 - 5);
    }
  }
  // Rendering a region leaves every other pixel alone.
  std::vector<std::uint8_t> marked(640 * 480, 77);
  CHECK(docksim::render_tag(tag.pattern, v, marked.data(), 640, &box));
  // Render and blur of the tag's own pixels (no margin) on a background frame give the whole image's render and
  // blur inside that region, to the last bit: the blur reads the background beyond the region's edge.
  CHECK(docksim::tag_pixel_bounds(tag.pattern, v, 0, box));
  std::vector<std::uint8_t> whole(640 * 480, 0), part(640 * 480, v.background);
  CHECK(docksim::render_tag(tag.pattern, v, whole.data(), 640));
  CHECK(docksim::render_tag(tag.pattern, v, part.data(), 640, &box));
  docksim::blur_grey(whole.data(), 640, 480, 640, 0.8);
  docksim::blur_grey(part.data(), 640, 480, 640, 0.8, &box);
  std::size_t inside = 0;
  for (std::uint32_t r = 0; r < 480; ++r) {
    for (std::uint32_t c = 0; c < 640; ++c) {
      const std::size_t i = r * 640 + c;
      if (c >= box.col0 && c < box.col1 && r >= box.row0 && r < box.row1) {
        CHECK_EQUAL(whole[i], part[i]);
        ++inside;
      } else if (c + 5 < box.col0 || c >= box.col1 + 5 || r + 5 < box.row0 || r >= box.row1 + 5) {
        CHECK_EQUAL(77, marked[i]);
      }
    }
  }
  CHECK(inside > 1000);
  // A tag behind the camera, or wholly beside the image, has no pixels.
  v.translation_m[2] = -0.6;
  CHECK_FALSE(docksim::tag_pixel_bounds(tag.pattern, v, 5, box));
  v.translation_m[2] = 0.6;
  v.translation_m[0] = 5;
  CHECK_FALSE(docksim::tag_pixel_bounds(tag.pattern, v, 5, box));
}

TEST_GROUP(RenderedCamera){};

TEST(RenderedCamera, FramesShowTheTagWhereItIsAndNothingWhenHidden) {
  docksim::Scenario sc = docksim::load_scenario_file(repo_file("tools/scenarios/default.toml"));
  sc.camera.render = true;
  std::string err;
  auto cam = docksim::RenderedTagCamera::create(sc, err);
  CHECK_TEXT(cam != nullptr, err.c_str());
  // The default dock at the origin facing +x; robots 0.6–1.4 m out, off the axis, turned.
  dockcore::TagFusionParams p;
  p.mount = dockcore::CameraMount3{sc.camera.model.mount.x_m,
                                   sc.camera.model.mount.y_m,
                                   static_cast<Real>(sc.camera.z_m),
                                   sc.camera.model.mount.yaw_rad,
                                   0,
                                   0};
  p.fx_px = sc.camera.model.fx_px;
  p.tag_size_m = static_cast<Real>(sc.dock_tag.size_m);
  p.dock_tag.id = sc.dock_tag.id;
  p.dock_tag.z_m = static_cast<Real>(sc.camera.z_m);
  docksim::Rng rng(3), hidden_rng(3), reference(3);
  for (const double x : {0.6, 1.0, 1.4}) {
    for (const double y : {-0.15, 0.1}) {
      const Pose2 robot{static_cast<Real>(x), static_cast<Real>(y), static_cast<Real>(dockcore::kPi + 0.1)};
      const docksim::CameraFrameOutput f = cam->capture(robot, true, nullptr, rng);
      CHECK(f.target.valid);
      CHECK(f.has_tag);
      // The centre column where the pinhole puts the tag's centre (the tag at the contacts, camera height).
      const Pose2 camera = robot.compose(Pose2{p.mount.x_m, p.mount.y_m, p.mount.yaw_rad});
      const dockcore::Vec2 q = camera.inverse_transform(dockcore::Vec2(0, 0));
      const double u = static_cast<double>(sc.camera.model.cx_px) -
                       static_cast<double>(sc.camera.model.fx_px) * static_cast<double>(q.y() / q.x());
      DOUBLES_EQUAL(u, static_cast<double>(f.target.u_px), 0.5);
      // The tag's pose gives the dock within a centimetre and a few degrees.
      dockcore::TagMeasurement m;
      CHECK(dockcore::tag_to_dock_measurement(f.tag, p, &m) == dockcore::TagStatus::kFused);
      const Pose2 truth = robot.inverse().compose(sc.dock_pose);
      DOUBLES_EQUAL(static_cast<double>(truth.y_m), static_cast<double>(m.dock_in_robot.y_m), 0.01);
      DOUBLES_EQUAL(static_cast<double>(truth.x_m), static_cast<double>(m.dock_in_robot.x_m), 0.03);
      // Hidden: no frame content, and the noise stream advances the same.
      const docksim::CameraFrameOutput h = cam->capture(robot, false, nullptr, hidden_rng);
      CHECK_FALSE(h.target.valid);
      CHECK_FALSE(h.has_tag);
      reference.uniform();
    }
  }
  DOUBLES_EQUAL(reference.uniform(), hidden_rng.uniform(), 0);
}

TEST(RenderedCamera, APoleInTheLineOfSightHidesTheTagAndOneBesideItDoesNot) {
  docksim::Scenario sc = docksim::load_scenario_file(repo_file("tools/scenarios/default.toml"));
  sc.camera.render = true;
  std::string err;
  auto cam = docksim::RenderedTagCamera::create(sc, err);
  CHECK_TEXT(cam != nullptr, err.c_str());
  const Pose2 robot{1.0, 0.0, static_cast<Real>(dockcore::kPi)};  // 1 m out, facing the dock at the origin
  docksim::Rng rng(5);
  docksim::World in_sight, beside;
  in_sight.add_circle(dockcore::Vec2(static_cast<Real>(0.5), 0), 0.03);
  beside.add_circle(dockcore::Vec2(static_cast<Real>(0.5), static_cast<Real>(0.3)), 0.03);
  CHECK(cam->capture(robot, true, &beside, rng).target.valid);
  CHECK_FALSE(cam->capture(robot, true, &in_sight, rng).target.valid);
  // Half the tag hidden is no detection either: the detector needs the whole border.
  docksim::World half;
  half.add_circle(dockcore::Vec2(static_cast<Real>(0.5), static_cast<Real>(0.02)), 0.015);
  CHECK_FALSE(cam->capture(robot, true, &half, rng).target.valid);
}

TEST(RenderedCamera, ExposureDecidesWhetherTheTagCanBeRead) {
  docksim::Scenario sc = docksim::load_scenario_file(repo_file("tools/scenarios/default.toml"));
  sc.camera.render = true;
  const Pose2 robot{1.0, 0.0, static_cast<Real>(dockcore::kPi)};
  auto detected = [&](double exposure) {
    sc.camera.exposure = exposure;
    std::string err;
    auto cam = docksim::RenderedTagCamera::create(sc, err);
    docksim::Rng rng(5);
    return cam->capture(robot, true, nullptr, rng).target.valid;
  };
  CHECK(detected(1.0));
  CHECK(detected(0.5));
  // Over-exposed, the white ring merges with the saturated wall, but the black border still stands out: read.
  CHECK(detected(4.0));
  // So dark that the tag's contrast is within the sensor noise: lost.
  CHECK_FALSE(detected(0.06));
}

TEST(RenderedCamera, UnknownTagIsRefusedByName) {
  docksim::Scenario sc = docksim::load_scenario_file(repo_file("tools/scenarios/default.toml"));
  sc.dock_tag.family = "tag99h99";
  std::string err;
  CHECK(docksim::RenderedTagCamera::create(sc, err) == nullptr);
  CHECK(err.find("dock.tag") != std::string::npos);
  CHECK(err.find("tag99h99") != std::string::npos);
}

TEST(RenderedCamera, RunWithoutAFactoryIsRefused) {
  docksim::Scenario sc = docksim::load_scenario_file(repo_file("tools/scenarios/default.toml"));
  sc.camera.render = true;
  CHECK_THROWS(docksim::ScenarioError, docksim::run_docking(sc, "smooth", 1));
}

TEST_GROUP(RenderedDocking){};

TEST(RenderedDocking, SmoothDocksWithTheTagFused) {
  docksim::Scenario sc = docksim::load_scenario_file(repo_file("tools/scenarios/default.toml"));
  sc.camera.render = true;
  const docksim::SimRun r = docksim::run_docking(sc, "smooth", docksim::trial_seed(sc.seed, 0), rendered_options());
  CHECK(r.outcome.charging_confirmed);
  CHECK(r.outcome.camera_rendered);
  CHECK(r.outcome.camera_detections > 50);
  CHECK(r.outcome.tags_fused > 50);
  CHECK(std::fabs(r.outcome.lateral_m) < 0.005);
}

TEST(RenderedDocking, Seed003ReachesItsOwnSuccessTestOnRenderedFrames) {
  docksim::Scenario sc = docksim::load_scenario_file(repo_file("tools/scenarios/seed003.toml"));
  sc.camera.render = true;
  sc.max_time_s = 30;  // its success test holds at ~16 s; what follows it is not this test's subject
  const docksim::SimRun r = docksim::run_docking(sc, "seed003", docksim::trial_seed(sc.seed, 0), rendered_options());
  CHECK(r.outcome.camera_detections > 100);
  CHECK_FALSE(std::isnan(r.outcome.seed_success_t_s));
  CHECK(std::fabs(r.outcome.seed_success_z_err_m) < 0.05);
  CHECK(std::fabs(r.outcome.seed_success_x_m) < 0.05);
}
