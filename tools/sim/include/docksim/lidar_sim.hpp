#pragma once
// 2D lidar simulator: raycasts a world of polylines from a lidar pose and applies a lidar model's sampling and noise.
// Host-side (tools/), not core: uses std::vector freely. Deterministic for a given Rng seed.
#include <cstdint>
#include <string>
#include <vector>

#include "dockcore/geometry.hpp"
#include "dockcore/laser_scan.hpp"
#include "dockcore/perception/dock_profile.hpp"
#include "docksim/rng.hpp"

namespace docksim {

using dockcore::Pose2;
using dockcore::Real;
using dockcore::Vec2;

/// One straight wall piece in world coordinates. Two-sided unless one_sided (then only hit from the side its
/// outward normal (dy, -dx) faces, like a dock profile segment).
struct Segment {
  Vec2 a;
  Vec2 b;
  double reflectivity = 0.5;  ///< 0..1, scales the simulated intensity.
  bool one_sided = false;
  bool retro = false;  ///< Retro-reflective tape: bright up to LidarModel::retro_cutoff_rad of incidence.
  /// A retro segment's own cut-off incidence, rad (0: LidarModel::retro_cutoff_rad). Chrome is retro with a small
  /// one: a mirror-like surface returns the beam only when met near its normal.
  double retro_cutoff_rad = 0;
};

/// A 2D world: a bag of segments. Helpers add common objects.
struct World {
  std::vector<Segment> segments;

  /// Adds the profile's polyline placed at dock_pose (dock frame -> world); segments are two-sided so the dock's
  /// back and sides block rays like a solid object. The profile's reflector stripes become retro segments of their
  /// own (the surface split at their ends, so the outline stays one continuous surface).
  void add_dock(const dockcore::DockProfile& profile, const Pose2& dock_pose, double reflectivity = 0.8);
  /// Some segment is retro-reflective (simulate_scan then blends the intensity over the beam's footprint).
  bool has_retro() const;
  void add_polyline(const std::vector<Vec2>& pts, bool closed = false, double reflectivity = 0.5);
  /// Axis-aligned in its own frame, rotated by yaw about its centre.
  void add_box(const Vec2& centre, double size_x, double size_y, double yaw_rad, double reflectivity = 0.5);
  /// A table leg / pole: a regular polygon approximating a circle.
  void add_circle(const Vec2& centre, double radius, int sides = 12, double reflectivity = 0.5);

  /// Nearest hit of the ray origin + t*dir (dir unit), t in (0, max_range]; returns false when nothing is hit.
  /// One-sided segments are skipped when the ray meets them from behind (dot(dir, outward normal) >= 0).
  /// Cost O(segments) with a two-cross-product rejection per segment.
  bool raycast(const Vec2& origin, const Vec2& dir, double max_range, double* range_out,
               double* reflectivity_out = nullptr) const;
  /// As raycast, also reporting the hit segment's index (into segments) when segment_out is not null.
  bool raycast_segment(const Vec2& origin, const Vec2& dir, double max_range, double* range_out,
                       std::size_t* segment_out) const;
};

/// What a lidar reports as a return's intensity (the surface model's value, `raw`, turned into the sensor's own).
enum class IntensityOutput : std::uint8_t {
  kRaw = 0,         ///< The model's value as a real number (0..intensity_scale).
  kLd06,            ///< LD06/LD19: rounded and clamped to 0..255.
  kRplidarQuality,  ///< RPLIDAR standard scan as a real A1 reports it: 6-bit quality saturating at 15 (below
                    ///< rplidar_saturation of the raw value it falls in proportion; grazing and far returns).
  kConstant,        ///< RPLIDAR express / dense modes: 47 for every return.
  kNone,            ///< 0 for every return (a driver that gives no intensity).
};
/// "raw", "ld06", "rplidar-quality", "constant", "none". Never null.
const char* to_string(IntensityOutput o);
/// The output named `name` (as to_string writes it); false for an unknown name.
bool intensity_output(const std::string& name, IntensityOutput* out);
/// Every output's name, in enum order (the scenario key's choices).
std::vector<std::string> intensity_output_names();

/// How a lidar samples and what its errors look like.
struct LidarModel {
  std::string name = "ld06";
  double rate_hz = 10.0;                 ///< Scan rate.
  double angle_min_rad = -dockcore::kPi; ///< First beam.
  double angle_increment_rad = 0.8 * dockcore::kPi / 180.0;
  std::size_t beams = 450;               ///< Samples per scan (<= dockcore::kMaxScanPoints).
  double min_range_m = 0.02;             ///< Blind zone: closer hits read as "no return" (0).
  double max_range_m = 12.0;             ///< Farther hits read as 0.
  double sigma_const_m = 0.010;          ///< Range noise, constant part (1 sigma).
  double sigma_prop = 0.0;               ///< Range noise proportional to range (1 sigma per metre).
  double dropout_prob = 0.0;             ///< Chance a valid return is lost.
  double angular_jitter_rad = 0.0;       ///< 1-sigma error of the true beam angle (the reported angle stays nominal).
  bool mixed_pixels = true;              ///< Beams straddling a depth edge may return a range between the two.
  double beam_divergence_rad = 0.3 * dockcore::kPi / 180.0;  ///< Footprint width used for mixed pixels.
  /// Mixed pixels: three sub-rays at -div/2, 0, +div/2 around the true beam angle. When all three hit, their
  /// ranges span more than mixed_pixel_threshold_m and they straddle a depth discontinuity (two of them hit
  /// segments that are neither the same nor share an endpoint, so an oblique wall or a corner does not count), then
  /// with probability mixed_pixel_prob the beam returns near + u*(far - near), u uniform in [0,1); otherwise (and
  /// always when a sub-ray misses) the centre ray's range.
  double mixed_pixel_threshold_m = 0.03;
  double mixed_pixel_prob = 0.5;          ///< See mixed_pixel_threshold_m.
  /// Intensity = intensity_scale * reflectivity * |cos(incidence)| / (1 + (range / intensity_ref_range_m)^2),
  /// 0 for no return. A plain falloff model: detectors should only rely on "brighter surface -> larger value".
  /// Retro-reflective tape (Segment::retro) returns intensity_scale * retro_gain / (1 + (range / ref)^2) whatever
  /// the incidence up to retro_cutoff_rad (so it saturates an LD06 at every docking range), and beyond it behaves as
  /// a diffuse surface of reflectivity 0.5. In a world with tape, a beam's intensity is the mean over its footprint
  /// (three sub-rays at -div/2, 0, +div/2; a miss adds 0): a beam straddling a tape edge reads in between.
  double intensity_scale = 255.0;
  double intensity_ref_range_m = 4.0;     ///< Range at which the intensity falls to half its near value.
  IntensityOutput intensity_output = IntensityOutput::kRaw;  ///< What the sensor reports of that value.
  double retro_gain = 4.0;  ///< Tape's brightness over a white diffuse surface's, head on.
  double retro_cutoff_rad = 60.0 * 3.14159265358979323846 / 180.0;  ///< Incidence beyond which tape is diffuse.
  /// kRplidarQuality: the raw value (0..intensity_scale) at and above which the quality reads 15. A real A1 reads 15
  /// on 87–96 % of its valid returns in a room (the realdata README); 30 of 255 gives the simulated rooms that share.
  double rplidar_saturation = 30.0;
};

/// The model's intensity of a return from `s` at `range_m` met at |cos(incidence)| `cos_incidence` (the formula of
/// LidarModel::intensity_scale's comment), before the sensor's own scale (sensor_intensity). O(1).
double surface_intensity(const LidarModel& m, const Segment& s, double range_m, double cos_incidence);
/// What the sensor reports of a model intensity `raw` (LidarModel::intensity_output). O(1).
double sensor_intensity(const LidarModel& m, double raw);

/// Built-in models: "ld06" (LD06/LD19: 4500 pts/s, 10 Hz, 0.8°, intensity 0..255), "rplidar-a1" (~1°, 5.5 Hz, 360
/// pts, standard-scan quality), "rplidar-a2" (A2M8: 0.45°, 10 Hz, 800 pts, quality), "industrial" (0.25°, 25 Hz, 270°
/// field of view, raw intensity). Returns false for an unknown name.
bool lidar_model(const std::string& name, LidarModel* out);
/// Names of the built-in models.
std::vector<std::string> lidar_model_names();

/// Simulates one scan of `world` from `lidar_pose` (lidar frame in world). Beam i has nominal angle
/// angle_min + i*increment in the lidar frame. Ranges outside [min,max] or dropped are 0.
/// Per beam, in this order: true angle = nominal + angular_jitter * N(0,1); ray cast (with mixed pixels, see
/// LidarModel); range noise N(0, sqrt(sigma_const^2 + (sigma_prop*range)^2)) (independent sources add in
/// quadrature); the noisy range is then 0 when < min_range_m or > max_range_m; then dropout. Intensities as
/// documented on LidarModel. model.beams above dockcore::kMaxScanPoints are truncated to it.
/// Cost O(beams * segments near each beam): segments are transformed once per scan and bucketed by bearing.
void simulate_scan(const World& world, const Pose2& lidar_pose, const LidarModel& model, Rng& rng,
                   dockcore::LaserScan* out, std::uint64_t stamp_us = 0);

}  // namespace docksim
