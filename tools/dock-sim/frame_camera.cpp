// The rendered camera of scenarios with `[robot.camera] render = true` (docs/scenarios.md): dock-sim's factory for
// docksim::SimOptions::make_frame_camera, present when dock-sim is built with the tag detector (libapriltag).
#include "frame_camera.hpp"

#include <string>

#ifdef DOCKSIM_HAVE_RENDERED_CAMERA
#include "docksim/rendered_camera.hpp"
#endif

namespace docksim_cli {

bool use_rendered_camera(docksim::Scenario& sc, bool render, docksim::SimOptions& so, std::string& error) {
  if (render) {
    if (!sc.camera.enabled) {
      error = "--camera-render: the scenario has no camera ([robot.camera] enabled = true)";
      return false;
    }
    sc.camera.render = true;
  }
  if (!sc.camera.enabled || !sc.camera.render) return true;
#ifdef DOCKSIM_HAVE_RENDERED_CAMERA
  // Made once here so a bad tag or detector setting is refused before any run starts (a worker thread must not
  // throw); each run then makes its own camera (a detector is not shared between threads).
  if (!docksim::RenderedTagCamera::create(sc, error)) return false;
  so.make_frame_camera = [](const docksim::Scenario& s) -> std::unique_ptr<docksim::FrameCamera> {
    std::string e;
    std::unique_ptr<docksim::FrameCamera> c = docksim::RenderedTagCamera::create(s, e);
    if (!c) throw docksim::ScenarioError(e);
    return c;
  };
  return true;
#else
  (void)so;
  error = "robot.camera.render needs a tag detector: this dock-sim was built without libapriltag";
  return false;
#endif
}

}  // namespace docksim_cli
