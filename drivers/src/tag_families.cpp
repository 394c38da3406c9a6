// The AprilTag family names (see dockcore/drivers/apriltag_detector.hpp). Here, not in drivers/vision, so dockd's
// config check names a wrong family in a build without libapriltag too.
#include <string>

#include "dockcore/drivers/apriltag_detector.hpp"

namespace dockcore::drivers {

const char* const kTagFamilyNames[] = {"tag16h5",        "tag25h9",          "tag36h10",
                                       "tag36h11",       "tagCircle21h7",    "tagCircle49h12",
                                       "tagCustom48h12", "tagStandard41h12", "tagStandard52h13",
                                       nullptr};

bool is_tag_family(const std::string& name) {
  for (const char* const* n = kTagFamilyNames; *n != nullptr; ++n) {
    if (name == *n) return true;
  }
  return false;
}

}  // namespace dockcore::drivers
