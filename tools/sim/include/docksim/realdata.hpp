#pragma once
// Real lidar recordings for evaluation (../shared/realdata, see its README.md): where they are, what each one is
// (noise, resolution, sensor mount, where its robot poses come from), and loading a recording with its poses.
// The data are never copied into the project; code reads them where they lie and skips cleanly when they are absent.
// Host-side (tools/): std::vector and strings; gzip'ed CARMEN logs are read through zlib.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "dockcore/geometry.hpp"
#include "docksim/scan_io.hpp"

namespace docksim {

/// Where the real-data folder was looked for, and whether it was found.
struct RealDataLocation {
  std::string dir;                  ///< The folder found (holds README.md); empty when none was.
  std::string source;               ///< "--realdata", "$DOCKCORE_REALDATA" or "<repo>/../shared/realdata".
  std::vector<std::string> looked;  ///< Every folder tried, in order.

  bool found() const { return !dir.empty(); }
  /// One line for the user: "real data: DIR (from SOURCE)" or "real data: not found (looked in A, B); skipped".
  std::string describe() const;
};

/// Looks for the real-data folder: `override_dir` when not empty (only it: a wrong --realdata is not papered over by
/// the defaults), else $DOCKCORE_REALDATA when set and not empty (only it), else <repo root>/../shared/realdata with
/// the repository root fixed at build time. A folder counts when it holds README.md. O(1) file-system probes.
RealDataLocation locate_realdata(const std::string& override_dir = std::string());

/// Where a recording's robot poses come from.
enum class PoseSource : std::uint8_t {
  kNone = 0,          ///< No poses: only single-scan figures.
  kCarmenFlaser,      ///< CARMEN FLASER messages of a *-corrected log: the laser's corrected pose in the map.
  kCarmenRobotLaser,  ///< CARMEN ROBOTLASER1 messages: the laser pose the log gives.
  kStatic,            ///< The sensor stands still between scans less than a second apart (identity poses).
};

/// Name of a PoseSource ("none", "carmen-flaser", "carmen-robotlaser", "static"). Never null.
const char* to_string(PoseSource p);

/// One recording of the real-data folder and what the benchmarks assume about it.
struct RealRecording {
  const char* name;  ///< Short name, e.g. "intel-lab".
  const char* file;  ///< JSON-lines scan file, relative to the real-data folder.
  /// Range noise 1-σ used to configure the detector (estimator_params_for_noise) and for pasted docks: the README's
  /// p25 of the straight-window residual at 1-2 m (p10-p25 is close to the sensor's noise on flat walls; p50 counts
  /// curved and cluttered surfaces too).
  double sigma_m;
  /// Step the log's ranges are quantised to (0: finer than 0.25 mm, not modelled): 1 cm for the CARMEN and MRPT logs,
  /// 5 cm for the acapulco / edmonton / fhw logs (68-84 % of their values are 5 cm multiples), 1 mm for the rest.
  double resolution_m;
  PoseSource poses;
  const char* pose_log;    ///< CARMEN log relative to the folder (kCarmen*), else null.
  std::size_t pose_every;  ///< The JSON lines keep every n-th laser message of the log (fr079: every 2nd).
  /// The conversion wrote 0 for log ranges at or above this (the log's no-return code); used to verify the match.
  double noreturn_m;
  const char* environment;  ///< A few words from the README.
};

/// The lidar sits at the origin of every recording's scans (the README's convention): the mount is the identity.
inline dockcore::Pose2 real_lidar_mount() {
  return dockcore::Pose2{};
}

/// The recordings of the folder, in the README's order (a static table: iterate it, or index it up to size()).
struct RealRecordingTable {
  const RealRecording* first = nullptr;
  std::size_t count = 0;
  const RealRecording* begin() const { return first; }
  const RealRecording* end() const { return first + count; }
  std::size_t size() const { return count; }
};

/// Every recording of the folder. O(1).
RealRecordingTable real_recordings();

/// Finds a recording by name; null when there is none. O(recordings).
const RealRecording* find_real_recording(const std::string& name);

/// How the poses of a log were matched to the JSON lines: JSON line j is laser message j * pose_every of the log
/// (the conversion kept them in order); each pair is verified by comparing every range (the log's value, or 0 where
/// it is a no-return code, against the line's to 0.1 mm). Poses are used only when every scan matched.
struct PoseMatch {
  std::size_t log_messages = 0;  ///< Laser messages read from the log.
  std::size_t matched = 0;       ///< Scans whose ranges equal their log message's.
  std::size_t mismatched = 0;    ///< Scans whose log message differs (beam count or a range) or is missing.
  std::size_t log_errors = 0;    ///< Malformed laser lines in the log (skipped, counted).
  std::string first_problem;     ///< The first mismatch or log error, "" when none.
  bool ok() const { return mismatched == 0 && log_errors == 0 && matched > 0; }
};

/// A loaded recording.
struct LoadedRecording {
  const RealRecording* info = nullptr;
  std::vector<RecordedScan> scans;
  ScanReadSummary read;  ///< Lines skipped as malformed (scan_io).
  PoseMatch match;       ///< Filled for kCarmen* recordings.
  /// Sensor pose in the world for each scan when the recording has usable poses (kStatic: identity), else empty.
  std::vector<dockcore::Pose2> sensor_in_world;
  bool has_poses() const { return !sensor_in_world.empty() && sensor_in_world.size() == scans.size(); }
};

/// Loads `rec` from `dir`: its scans (malformed lines skipped and counted) and, for kCarmen*, the log's poses matched
/// and verified as PoseMatch says (a failed match leaves sensor_in_world empty and says why in match). `max_scans`
/// (0 = all) keeps the first scans only. Returns false with *error when the scan file cannot be read.
/// Cost O(bytes of the scan file + bytes of the log up to the last scan kept).
bool load_real_recording(const std::string& dir, const RealRecording& rec, std::size_t max_scans, LoadedRecording* out,
                         std::string* error);

/// One laser message of a CARMEN log.
struct CarmenLaser {
  std::size_t line = 0;            ///< 1-based line in the log.
  std::vector<double> ranges_m;    ///< As in the log (no-return codes kept).
  dockcore::Pose2 laser_in_world;  ///< FLASER: x y theta; ROBOTLASER1: laser_x laser_y laser_theta.
  dockcore::Pose2 robot_in_world;  ///< FLASER: odom_x odom_y odom_theta; ROBOTLASER1: robot_x robot_y robot_theta.
  double timestamp_s = 0;          ///< ipc_timestamp.
};

/// Byte-at-a-time reader of CARMEN log lines. Fields are whitespace-separated; a line is interpreted at its end.
/// FLASER: `FLASER n r_1..r_n x y theta odom_x odom_y odom_theta ipc_timestamp ipc_hostname logger_timestamp`.
/// ROBOTLASER1: `ROBOTLASER1 type start_angle fov resolution max_range accuracy remission_mode n r_1..r_n k
/// rem_1..rem_k laser_x laser_y laser_theta robot_x robot_y robot_theta tv rv fwd_safety side_safety turn_axis
/// ipc_timestamp ipc_hostname logger_timestamp`. Other messages (ODOM, PARAM, comments ...) are skipped and counted.
class CarmenLogParser {
 public:
  enum class Event { kNone, kLaser, kError };
  /// Feeds one byte. kLaser: laser() holds the message just completed; kError: error() says "line N: what" and the
  /// line was skipped. O(1) per byte (amortised).
  Event feed(char c);
  /// End of input: interprets a last line that had no newline. Same events as feed().
  Event finish();
  const CarmenLaser& laser() const { return laser_; }
  const std::string& error() const { return error_; }
  std::size_t lines() const { return line_; }
  std::size_t other_messages() const { return other_; }

  /// Longest field accepted (bytes) and most fields per line: longer ones make the line an error.
  static constexpr std::size_t kMaxFieldBytes = 64;
  static constexpr std::size_t kMaxFields = 8192;

 private:
  enum class State { kLineStart, kType, kBetween, kField, kSkipLine, kOverflow };
  Event end_line();
  Event interpret();
  State state_ = State::kLineStart;
  std::string type_;
  std::string field_;
  std::vector<std::string> fields_;  // after the type
  std::size_t line_ = 0;             // lines completed
  std::size_t other_ = 0;
  std::string overflow_what_;
  CarmenLaser laser_;
  std::string error_;
};

/// Reads the laser messages of a CARMEN log, gzip'ed or not (zlib reads both), stopping after `max_messages`
/// (0 = all). Malformed laser lines are skipped; their count goes to *errors and the first message to *first_error.
/// Returns false with *first_error = "cannot open <path>" / "read error on <path>" when the file cannot be read.
bool read_carmen_log(const std::string& path, std::size_t max_messages, std::vector<CarmenLaser>* out,
                     std::size_t* errors, std::string* first_error);

}  // namespace docksim
