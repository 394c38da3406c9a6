#pragma once
/// @file The parameter table: every parameter of dockcore's core structs that a file can set — drive limits,
/// obstacle footprint, task manager, estimator, controllers — declared once with its key, unit, bounds and meaning;
/// its default is the core struct's. dockd's config (app/dockd/config.cpp) and dock-sim's scenarios
/// (tools/sim/src/scenario.cpp) both read these keys through the table (param_toml.hpp), so one key accepts the same
/// values in both; the key tables of docs/dockd.md and docs/scenarios.md are generated from it
/// (`dock-sim params`). A scenario adds only its world and the robot's physics.
/// Host-side start-up code: heap and exceptions are fine here (never in core).

#include <cstddef>
#include <cstdint>
#include <string>

#include "dockcore/control/controllers.hpp"
#include "dockcore/control/kinematics.hpp"
#include "dockcore/control/safety.hpp"
#include "dockcore/control/wheel_deadband.hpp"
#include "dockcore/dockcore.hpp"
#include "dockcore/perception/dock_pose_estimator.hpp"
#include "dockcore/perception/tag_measurement.hpp"
#include "dockcore/task/input_watch.hpp"
#include "dockcore/task/task_manager.hpp"

namespace dockcore::params {

/// How a value is written in the file and stored.
enum class ParamType : std::uint8_t {
  kReal,     ///< A number (an integer is accepted), stored as Real.
  kDegrees,  ///< A number in degrees in the file, stored in radians.
  kInteger,  ///< An integer.
  kBool,     ///< true / false.
  kChoice,   ///< One of ParamSpec::choices; the setter gets its index.
};

/// Which files take a parameter (bit set).
enum ParamUse : std::uint8_t {
  kDockd = 1,     ///< dockd's config.
  kScenario = 2,  ///< dock-sim's scenarios.
  kBoth = 3,
};

/// The core parameter structs one file fills. A pointer may be null only for structs no key of that file sets.
struct ParamTargets {
  DriveGeometry* drive = nullptr;
  DriveLimits* limits = nullptr;
  FootprintParams* footprint = nullptr;
  TaskParams* task = nullptr;
  EstimatorParams* estimator = nullptr;
  Seed000Params* seed000 = nullptr;
  Seed004Params* seed004 = nullptr;
  Seed003Params* seed003 = nullptr;
  SmoothParams* smooth = nullptr;
  TagFusionParams* tag_fusion = nullptr;  ///< dockd only: [camera.fusion].
  WatchdogParams* watchdog = nullptr;
  WheelDeadbandParams* deadband = nullptr;
  DockDetector* detector = nullptr;  ///< One dock's detector (dockd: each [[docks]] entry; a scenario: [dock]).
  IntensityCheckParams* intensity = nullptr;  ///< [intensity]: the lidar intensity check.
};

/// One parameter.
struct ParamSpec {
  const char* table;    ///< TOML table it sits in ("task", "robot.limits", "estimator.segments").
  const char* key;      ///< Key within that table.
  const char* unit;     ///< "m", "s", "rad/s", "°", "–", ...
  ParamType type;       ///< How it is written in the file and stored.
  double min;           ///< Smallest accepted value, in file units (kReal, kDegrees, kInteger).
  double max;           ///< Largest accepted value, in file units.
  std::uint8_t use;     ///< ParamUse bits.
  const char* meaning;  ///< One line for the docs (Markdown).
  /// The value in file units (degrees for kDegrees, the choice's index for kChoice). O(1).
  double (*get)(const ParamTargets&);
  /// Stores a checked value given in file units (degrees for kDegrees, the index for kChoice). O(1).
  void (*set)(const ParamTargets&, double);
  const char* choices = nullptr;       ///< kChoice: the words, '|'-separated, in index order.
  const char* dockd_table = nullptr;   ///< dockd's table when it differs from `table` (the range keys: "lidar").
  const char* default_text = nullptr;  ///< The docs' default when it is not the struct's value ("from the footprint").
  /// dock-sim's scenarios start from this value instead of the struct's (NaN: the struct's). The simulated
  /// default robot drives at 0.4 m/s.
  double scenario_default = __builtin_nan("");
};

/// Every parameter, in docs order. `count` receives the number of entries. O(1).
const ParamSpec* param_table(std::size_t& count);

/// The table `s` sits in for `use` (kDockd or kScenario). O(1).
const char* table_of(const ParamSpec& s, ParamUse use);

/// The entry with `table` (as seen by `use`) and `key`, or nullptr. O(table size).
const ParamSpec* find_param(const std::string& table, const std::string& key, ParamUse use);

/// The words of a kChoice entry (empty for other types). O(choices length).
std::string choice_word(const ParamSpec& s, std::size_t index);
/// The number of words of a kChoice entry. O(choices length).
std::size_t choice_count(const ParamSpec& s);

/// Sets every entry of `use` that has a scenario_default (kScenario only) in `t`. O(table size).
void apply_defaults(const ParamTargets& t, ParamUse use);

/// The Markdown table (header, separator, one row per key) of the entries of `table` that `use` takes: key, unit,
/// default (from default-constructed core structs, or the scenario default), accepted range, meaning.
/// Empty when no entry matches. O(table size).
std::string markdown_table(const std::string& table, ParamUse use);

/// Regenerates every marked block of a Markdown document. A block is
///   <!-- params dockd task -->   (or "scenario"; the table name)
///   ...
///   <!-- /params -->
/// and its lines between the markers become markdown_table(table, use). Returns the new text; sets `error` (and
/// returns the text unchanged) for a malformed marker or an unknown table. O(text size + table size).
std::string update_param_blocks(const std::string& text, std::string& error);

/// What the robot's description decides for the parameters, rather than keys of their own. dockd's config reads it
/// from [robot] and [can], a scenario from its chassis and dock; both hand it to derive_from_robot.
struct RobotFacts {
  bool pads_rear = false;        ///< The charging pads are on the robot's rear: it docks backwards.
  bool mecanum = false;          ///< The base moves sideways (a mecanum drive).
  bool charger_switched = true;  ///< The robot switches the dock's charging current (TaskParams::charger_switched).
  double pad_reach_m = -1;       ///< Rotation centre to the pads, m; < 0: each controller keeps its own.
  bool holonomic_given = false;  ///< Seed003Params::holonomic was set by a key: kept.
  bool backwards_given = false;  ///< SmoothParams::backwards was set by a key: kept.
};

/// Writes the facts into the structs of `t` that take them: every controller's pad reach, smooth's `backwards` and
/// seed 003's `holonomic` (unless given), the task manager's pad side and charger, and caps the task manager's
/// final clamps at the drive limits that are set (> 0). Every pointer of `t` it writes must be non-null: task,
/// limits, seed000, seed004, seed003, smooth. O(1).
void derive_from_robot(const RobotFacts& r, const ParamTargets& t);

}  // namespace dockcore::params
