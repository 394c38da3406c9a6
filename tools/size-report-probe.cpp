// Compiled (never linked or run) by tools/size-report for each target and scalar type: every array below has the
// size of one object, so `nm -S` on the object file reads sizeof() for any target without running target code.
#include "dockcore/control/controllers.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/dock_pose_estimator.hpp"
#include "dockcore/perception/dock_pose_filter.hpp"
#include "dockcore/task/task_manager.hpp"

#define DOCKCORE_SIZE(name, type) extern "C" { char size_of_##name[sizeof(type)]; }
DOCKCORE_SIZE(Dockcore, dockcore::Dockcore)
DOCKCORE_SIZE(Dockcore720, dockcore::DockcoreN<720>)
DOCKCORE_SIZE(Dockcore1440, dockcore::DockcoreN<1440>)
DOCKCORE_SIZE(DockPoseEstimator, dockcore::DockPoseEstimator)
DOCKCORE_SIZE(DockPoseEstimator720, dockcore::DockPoseEstimatorN<720>)
DOCKCORE_SIZE(DockPoseFilter, dockcore::DockPoseFilter)
DOCKCORE_SIZE(TaskManager, dockcore::TaskManager)
DOCKCORE_SIZE(LaserScan, dockcore::LaserScan)
DOCKCORE_SIZE(LaserScan720, dockcore::LaserScanN<720>)
DOCKCORE_SIZE(DockcoreConfig, dockcore::DockcoreConfig)
DOCKCORE_SIZE(SmoothController, dockcore::SmoothController)
