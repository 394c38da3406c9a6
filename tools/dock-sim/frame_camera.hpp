#pragma once
// dock-sim's rendered camera factory (frame_camera.cpp).
#include <string>

#include "docksim/scenario.hpp"
#include "docksim/sim_run.hpp"

namespace docksim_cli {

/// For a scenario whose camera renders frames (or any scenario with a camera when `render` is set: the
/// `--camera-render` flag, which sets robot.camera.render), sets `so.make_frame_camera` to the AprilTag renderer and
/// detector; false + message when the scenario has no camera to render, the tag or the detector settings are
/// unusable, or this dock-sim has no detector. Does nothing (true) for other scenarios. Cost: one detector made and
/// dropped.
bool use_rendered_camera(docksim::Scenario& sc, bool render, docksim::SimOptions& so, std::string& error);

}  // namespace docksim_cli
