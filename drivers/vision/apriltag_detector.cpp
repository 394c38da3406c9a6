// AprilTag detection through libapriltag (see dockcore/drivers/apriltag_detector.hpp).
#include "dockcore/drivers/apriltag_detector.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

extern "C" {
#include <apriltag/apriltag.h>
#include <apriltag/apriltag_pose.h>
#include <apriltag/common/image_u8.h>
#include <apriltag/common/matd.h>
#include <apriltag/common/zarray.h>
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h10.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagCircle21h7.h>
#include <apriltag/tagCircle49h12.h>
#include <apriltag/tagCustom48h12.h>
#include <apriltag/tagStandard41h12.h>
#include <apriltag/tagStandard52h13.h>
}

namespace dockcore::drivers {

namespace {

struct FamilyEntry {
  const char* name;
  apriltag_family_t* (*create)();
  void (*destroy)(apriltag_family_t*);
};

// The same names as kTagFamilyNames (drivers/src/tag_families.cpp, which config parsing uses without libapriltag).
const FamilyEntry kFamilies[] = {
    {"tag16h5", tag16h5_create, tag16h5_destroy},
    {"tag25h9", tag25h9_create, tag25h9_destroy},
    {"tag36h10", tag36h10_create, tag36h10_destroy},
    {"tag36h11", tag36h11_create, tag36h11_destroy},
    {"tagCircle21h7", tagCircle21h7_create, tagCircle21h7_destroy},
    {"tagCircle49h12", tagCircle49h12_create, tagCircle49h12_destroy},
    {"tagCustom48h12", tagCustom48h12_create, tagCustom48h12_destroy},
    {"tagStandard41h12", tagStandard41h12_create, tagStandard41h12_destroy},
    {"tagStandard52h13", tagStandard52h13_create, tagStandard52h13_destroy},
};

const FamilyEntry* find_family(const std::string& name) {
  for (const FamilyEntry& f : kFamilies) {
    if (name == f.name) return &f;
  }
  return nullptr;
}

// Debian's libapriltag 3.3 exports neither matd_create/matd_destroy nor homography_compute. A matd_t is one
// calloc'ed block (header + data, matd.c), so the pose matrices estimate_tag_pose returns are released with free(),
// and the 3×3 homography of corrected corners is made and fitted here.
matd_t* make_mat3() {
  void* m = std::calloc(1, sizeof(matd_t) + 9 * sizeof(double));
  if (m == nullptr) return nullptr;
  matd_t* h = static_cast<matd_t*>(m);
  h->nrows = 3;
  h->ncols = 3;
  return h;
}
void free_mat(matd_t* m) { std::free(m); }

/// (x, y) through H (row-major 3×3).
void project(const matd_t* h, double x, double y, double& ox, double& oy) {
  const double* a = h->data;
  const double w = a[6] * x + a[7] * y + a[8];
  ox = (a[0] * x + a[1] * y + a[2]) / w;
  oy = (a[3] * x + a[4] * y + a[5]) / w;
}

/// The homography (h33 = 1) mapping the four `from` points exactly onto `to`: an 8×8 linear system solved by
/// Gaussian elimination with partial pivoting. False when the points are degenerate.
bool fit_homography4(const double from[4][2], const double to[4][2], matd_t* h) {
  double a[8][9];
  for (int i = 0; i < 4; ++i) {
    const double x = from[i][0], y = from[i][1], u = to[i][0], v = to[i][1];
    const double r0[9] = {x, y, 1, 0, 0, 0, -u * x, -u * y, u};
    const double r1[9] = {0, 0, 0, x, y, 1, -v * x, -v * y, v};
    for (int j = 0; j < 9; ++j) {
      a[2 * i][j] = r0[j];
      a[2 * i + 1][j] = r1[j];
    }
  }
  for (int c = 0; c < 8; ++c) {
    int piv = c;
    for (int r = c + 1; r < 8; ++r) {
      if (std::fabs(a[r][c]) > std::fabs(a[piv][c])) piv = r;
    }
    if (std::fabs(a[piv][c]) < 1e-12) return false;
    if (piv != c) {
      for (int j = 0; j < 9; ++j) std::swap(a[c][j], a[piv][j]);
    }
    for (int r = 0; r < 8; ++r) {
      if (r == c) continue;
      const double f = a[r][c] / a[c][c];
      for (int j = c; j < 9; ++j) a[r][j] -= f * a[c][j];
    }
  }
  for (int i = 0; i < 8; ++i) h->data[i] = a[i][8] / a[i][i];
  h->data[8] = 1;
  return true;
}

/// libapriltag's pixel coordinates minus this are the calibration convention's (pixel centres at integers).
constexpr double kApriltagPixelOffset = 0.5;

/// The tag-frame corner (±1, ±1) that libapriltag's homography maps nearest to each detected corner, so the
/// corrected homography keeps the library's corner order whatever its convention.
void tag_corner_coords(const apriltag_detection_t& d, double tag_xy[4][2]) {
  const double cand[4][2] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
  for (int i = 0; i < 4; ++i) {
    double best = 1e300;
    for (const auto& c : cand) {
      double x = 0, y = 0;
      project(d.H, c[0], c[1], x, y);
      const double e = (x - d.p[i][0]) * (x - d.p[i][0]) + (y - d.p[i][1]) * (y - d.p[i][1]);
      if (e < best) {
        best = e;
        tag_xy[i][0] = c[0];
        tag_xy[i][1] = c[1];
      }
    }
  }
}

/// Bilinear grey value at (x, y) in the calibration convention (pixel centres at integers); false outside the image.
bool sample(const image_u8_t& im, double x, double y, double& out) {
  if (!(x >= 0 && y >= 0 && x < im.width - 1 && y < im.height - 1)) return false;
  const int ix = static_cast<int>(x), iy = static_cast<int>(y);
  const double fx = x - ix, fy = y - iy;
  const std::uint8_t* r0 = im.buf + static_cast<std::ptrdiff_t>(iy) * im.stride + ix;
  const std::uint8_t* r1 = r0 + im.stride;
  out = (1 - fy) * ((1 - fx) * r0[0] + fx * r0[1]) + fy * ((1 - fx) * r1[0] + fx * r1[1]);
  return true;
}

/// A line n·x = c (|n| = 1) fitted by total least squares to points, after dropping those off the first fit by more
/// than 3 median deviations. False with fewer than 6 points.
bool fit_line(const double (*pts)[2], int n, double line[3]) {
  if (n < 6) return false;
  bool keep[256];
  for (int i = 0; i < n; ++i) keep[i] = true;
  for (int pass = 0; pass < 2; ++pass) {
    double mx = 0, my = 0;
    int m = 0;
    for (int i = 0; i < n; ++i) {
      if (!keep[i]) continue;
      mx += pts[i][0];
      my += pts[i][1];
      ++m;
    }
    if (m < 6) return false;
    mx /= m;
    my /= m;
    double sxx = 0, sxy = 0, syy = 0;
    for (int i = 0; i < n; ++i) {
      if (!keep[i]) continue;
      const double dx = pts[i][0] - mx, dy = pts[i][1] - my;
      sxx += dx * dx;
      sxy += dx * dy;
      syy += dy * dy;
    }
    // The normal is the eigenvector of the scatter's smaller eigenvalue.
    const double angle = 0.5 * std::atan2(2 * sxy, sxx - syy);  // direction of the line
    line[0] = -std::sin(angle);
    line[1] = std::cos(angle);
    line[2] = line[0] * mx + line[1] * my;
    if (pass == 1) break;
    double dev[256];
    for (int i = 0; i < n; ++i) dev[i] = std::fabs(line[0] * pts[i][0] + line[1] * pts[i][1] - line[2]);
    double sorted[256];
    std::copy(dev, dev + n, sorted);
    std::nth_element(sorted, sorted + n / 2, sorted + n);
    const double limit = 3 * std::max(sorted[n / 2], 0.01);
    for (int i = 0; i < n; ++i) keep[i] = dev[i] <= limit;
  }
  return true;
}

/// Moves the four corners (calibration convention, in order around the quad) onto the intersections of lines fitted
/// to the black square's edges at sub-pixel precision: along each edge, away from its corners, the grey profile
/// across the edge is sampled and the step's position found from its area (below). The profile reaches half a code
/// cell to either side, so it sees the black border and the white ring only. libapriltag's own edge refinement
/// leaves corner errors of ≈ 0.1 px, which the tag's yaw (a few tenths of a pixel of perspective between its left
/// and right edges) cannot afford. Corners are left alone for tags with code cells under 5 px, when an edge yields
/// too few points or when a refined corner lands more than 1 px from the detected one.
void refine_corners(const image_u8_t& im, int cells_at_border, double p[4][2]) {
  double lines[4][3];
  for (int e = 0; e < 4; ++e) {
    const double* a = p[e];
    const double* b = p[(e + 1) % 4];
    const double len = std::hypot(b[0] - a[0], b[1] - a[1]);
    if (!(len > 8)) return;
    const double dx = (b[0] - a[0]) / len, dy = (b[1] - a[1]) / len;
    const double nx = -dy, ny = dx;
    // Half a code cell, at most 4 px; a step needs ±2.5 px to show both its levels through the blur of a lens.
    const double reach = std::min(0.5 * len / cells_at_border, 4.0);
    if (reach < 2.5) return;
    constexpr double kStep = 0.25;
    const int half = static_cast<int>(reach / kStep);
    double pts[256][2];
    int n = 0;
    const int samples = std::min(256, static_cast<int>(len * 0.7));
    for (int i = 0; i < samples; ++i) {
      const double t = len * (0.15 + 0.7 * (i + 0.5) / samples);
      const double ex = a[0] + dx * t, ey = a[1] + dy * t;  // on the current edge
      double prof[40];
      bool ok = half * 2 + 1 <= 40;
      for (int k = -half; k <= half && ok; ++k)
        ok = sample(im, ex + nx * k * kStep, ey + ny * k * kStep, prof[k + half]);
      if (!ok) continue;
      const double lo = (prof[0] + prof[1] + prof[2]) / 3;
      const double hi = (prof[2 * half] + prof[2 * half - 1] + prof[2 * half - 2]) / 3;
      if (std::fabs(hi - lo) < 20) continue;
      // The step's position is the length of its low side: the integral of (hi − I)/(hi − lo) across the window
      // (trapezoids). Exact for any symmetric blur and for a pixel's area sampling alike, where a half-level
      // crossing interpolated between pixels is off by up to 0.1 px on a sharp edge.
      double low_side = 0;
      for (int k = 0; k < 2 * half; ++k) low_side += 0.5 * ((hi - prof[k]) + (hi - prof[k + 1])) / (hi - lo) * kStep;
      const double best = low_side - half * kStep;
      if (!(std::fabs(best) < reach)) continue;
      pts[n][0] = ex + nx * best;
      pts[n][1] = ey + ny * best;
      ++n;
    }
    if (!fit_line(pts, n, lines[e])) return;
  }
  double q[4][2];
  for (int c = 0; c < 4; ++c) {
    const double* l0 = lines[(c + 3) % 4];  // the edge ending at corner c
    const double* l1 = lines[c];            // the edge starting there
    const double det = l0[0] * l1[1] - l0[1] * l1[0];
    if (std::fabs(det) < 1e-6) return;
    q[c][0] = (l0[2] * l1[1] - l0[1] * l1[2]) / det;
    q[c][1] = (l0[0] * l1[2] - l0[2] * l1[0]) / det;
    // A refined corner far from the detected one means the lines were not the square's edges.
    if (std::hypot(q[c][0] - p[c][0], q[c][1] - p[c][1]) > 1) return;
  }
  std::memcpy(p, q, sizeof q);
}

class AprilTagDetectorImpl final : public TagDetector {
 public:
  AprilTagDetectorImpl(const TagDetectorOptions& o, const FamilyEntry& f) : opt_(o), fam_entry_(f) {
    family_ = f.create();
    td_ = apriltag_detector_create();
    apriltag_detector_add_family_bits(td_, family_, o.max_hamming);
    td_->quad_decimate = static_cast<float>(o.quad_decimate);
    td_->quad_sigma = static_cast<float>(o.quad_sigma);
    td_->nthreads = o.threads;
    td_->refine_edges = o.refine_edges;
    td_->debug = false;
  }
  ~AprilTagDetectorImpl() override {
    apriltag_detector_destroy(td_);
    fam_entry_.destroy(family_);
  }
  AprilTagDetectorImpl(const AprilTagDetectorImpl&) = delete;
  AprilTagDetectorImpl& operator=(const AprilTagDetectorImpl&) = delete;

  std::size_t detect(const std::uint8_t* grey, std::uint32_t width_px, std::uint32_t height_px,
                     std::uint32_t stride_bytes, TagDetection* out, std::size_t max_out,
                     std::size_t* overflow) override {
    if (overflow != nullptr) *overflow = 0;
    if (grey == nullptr || width_px == 0 || height_px == 0 || width_px >= 32768 || height_px >= 32768 ||
        stride_bytes < width_px) {
      return 0;
    }
    // libapriltag reads the input image and never writes it.
    image_u8_t im{static_cast<std::int32_t>(width_px), static_cast<std::int32_t>(height_px),
                  static_cast<std::int32_t>(stride_bytes), const_cast<std::uint8_t*>(grey)};
    zarray_t* dets = apriltag_detector_detect(td_, &im);
    const int n = zarray_size(dets);
    // Strongest first, so a caller keeping max_out keeps the best.
    apriltag_detection_t* sorted[kMaxTagDetections * 4];
    int kept = 0;
    std::size_t skipped = 0;
    for (int i = 0; i < n; ++i) {
      apriltag_detection_t* d = nullptr;
      zarray_get(dets, i, &d);
      if (static_cast<double>(d->decision_margin) < opt_.min_decision_margin) continue;
      if (kept < static_cast<int>(sizeof sorted / sizeof sorted[0])) sorted[kept++] = d;
      else ++skipped;
    }
    std::sort(sorted, sorted + kept, [](const apriltag_detection_t* a, const apriltag_detection_t* b) {
      return a->decision_margin > b->decision_margin;
    });
    std::size_t written = 0;
    for (int i = 0; i < kept; ++i) {
      if (written >= max_out) {
        ++skipped;
        continue;
      }
      fill(*sorted[i], im, out[written++]);
    }
    if (overflow != nullptr) *overflow = skipped;
    apriltag_detections_destroy(dets);
    return written;
  }

  const TagDetectorOptions& options() const override { return opt_; }

 private:
  void fill(apriltag_detection_t& d, const image_u8_t& im, TagDetection& t) const {
    const CameraIntrinsics& k = opt_.intrinsics;
    t = TagDetection{};
    t.id = d.id;
    t.hamming = d.hamming;
    t.decision_margin = static_cast<double>(d.decision_margin);
    // libapriltag puts the centre of the top-left pixel at (0.5, 0.5); calibrations (and so cx, cy) put it at
    // (0, 0). Everything reported and the pose use the calibration's convention.
    apriltag_detection_t ideal = d;
    for (int i = 0; i < 4; ++i) {
      ideal.p[i][0] = d.p[i][0] - kApriltagPixelOffset;
      ideal.p[i][1] = d.p[i][1] - kApriltagPixelOffset;
    }
    if (opt_.refine_corners) refine_corners(im, family_->width_at_border, ideal.p);
    std::memcpy(t.corners_px, ideal.p, sizeof t.corners_px);
    ideal.c[0] = d.c[0] - kApriltagPixelOffset;
    ideal.c[1] = d.c[1] - kApriltagPixelOffset;
    t.u_px = ideal.c[0];
    t.v_px = ideal.c[1];
    matd_t* h = make_mat3();
    if (h == nullptr) return;
    const bool have_intrinsics = k.fx_px > 0 && k.fy_px > 0;
    const bool undistort = have_intrinsics && k.has_distortion();
    if (opt_.refine_corners || undistort) {
      // The centre and the pose from the (refined, corrected) corners and a homography fitted to them.
      double tag_xy[4][2];
      tag_corner_coords(d, tag_xy);
      if (undistort) {
        for (int i = 0; i < 4; ++i) undistort_pixel(k, ideal.p[i][0], ideal.p[i][1], ideal.p[i][0], ideal.p[i][1]);
      }
      if (!fit_homography4(tag_xy, ideal.p, h)) {
        free_mat(h);
        return;
      }
      project(h, 0, 0, ideal.c[0], ideal.c[1]);
      t.u_px = ideal.c[0];
      t.v_px = ideal.c[1];
    } else {
      // The library's homography moved by the same offset: rows 0 and 1 minus offset × row 2.
      const double* a = d.H->data;
      for (int c = 0; c < 3; ++c) {
        h->data[c] = a[c] - kApriltagPixelOffset * a[6 + c];
        h->data[3 + c] = a[3 + c] - kApriltagPixelOffset * a[6 + c];
        h->data[6 + c] = a[6 + c];
      }
    }
    if (!have_intrinsics) {
      free_mat(h);
      return;
    }
    ideal.H = h;
    for (int i = 0; i < 4; ++i) {
      t.corners_unit_focal[i][0] = (ideal.p[i][0] - k.cx_px) / k.fx_px;
      t.corners_unit_focal[i][1] = (ideal.p[i][1] - k.cy_px) / k.fy_px;
    }
    apriltag_detection_info_t info{&ideal, opt_.tag_size_m, k.fx_px, k.fy_px, k.cx_px, k.cy_px};
    apriltag_pose_t pose{nullptr, nullptr};
    t.pose_error = estimate_tag_pose(&info, &pose);
    if (pose.R != nullptr && pose.t != nullptr) {
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) t.rotation[3 * r + c] = MATD_EL(pose.R, r, c);
        t.translation_m[r] = MATD_EL(pose.t, r, 0);
      }
      t.has_pose = std::isfinite(t.translation_m[2]) && t.translation_m[2] > 0;
    }
    free_mat(pose.R);
    free_mat(pose.t);
    free_mat(h);
  }

  TagDetectorOptions opt_;
  const FamilyEntry& fam_entry_;
  apriltag_family_t* family_ = nullptr;
  apriltag_detector_t* td_ = nullptr;
};

}  // namespace

bool draw_tag_upright(const std::string& family, int id, std::uint32_t cell_px, std::uint32_t x0_px,
                      std::uint32_t y0_px, std::uint8_t* grey, std::uint32_t width_px, std::uint32_t height_px,
                      std::uint32_t stride_bytes, std::uint32_t* black_side_px) {
  const FamilyEntry* f = find_family(family);
  if (f == nullptr || cell_px == 0 || grey == nullptr) return false;
  apriltag_family_t* fam = f->create();
  bool ok = id >= 0 && static_cast<std::uint32_t>(id) < fam->ncodes;
  image_u8_t* im = ok ? apriltag_to_image(fam, id) : nullptr;
  ok = im != nullptr;
  if (ok) {
    const std::uint32_t side = static_cast<std::uint32_t>(im->width) * cell_px;
    ok = x0_px + side <= width_px && y0_px + side <= height_px;
    if (ok) {
      for (std::uint32_t r = 0; r < side; ++r) {
        for (std::uint32_t c = 0; c < side; ++c) {
          grey[static_cast<std::size_t>(y0_px + r) * stride_bytes + x0_px + c] =
              im->buf[static_cast<std::size_t>(r / cell_px) * static_cast<std::size_t>(im->stride) + c / cell_px];
        }
      }
      if (black_side_px != nullptr) *black_side_px = static_cast<std::uint32_t>(fam->width_at_border) * cell_px;
    }
    image_u8_destroy(im);
  }
  f->destroy(fam);
  return ok;
}

void distort_pixel(const CameraIntrinsics& k, double u_px, double v_px, double& u_out_px, double& v_out_px) {
  const double x = (u_px - k.cx_px) / k.fx_px, y = (v_px - k.cy_px) / k.fy_px;
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k.k1 + r2 * (k.k2 + r2 * k.k3));
  const double xd = x * radial + 2 * k.p1 * x * y + k.p2 * (r2 + 2 * x * x);
  const double yd = y * radial + k.p1 * (r2 + 2 * y * y) + 2 * k.p2 * x * y;
  u_out_px = k.cx_px + k.fx_px * xd;
  v_out_px = k.cy_px + k.fy_px * yd;
}

void undistort_pixel(const CameraIntrinsics& k, double u_px, double v_px, double& u_out_px, double& v_out_px) {
  const double xd = (u_px - k.cx_px) / k.fx_px, yd = (v_px - k.cy_px) / k.fy_px;
  double x = xd, y = yd;
  for (int i = 0; i < 20; ++i) {
    const double r2 = x * x + y * y;
    const double radial = 1 + r2 * (k.k1 + r2 * (k.k2 + r2 * k.k3));
    const double dx = 2 * k.p1 * x * y + k.p2 * (r2 + 2 * x * x);
    const double dy = k.p1 * (r2 + 2 * y * y) + 2 * k.p2 * x * y;
    x = (xd - dx) / radial;
    y = (yd - dy) / radial;
  }
  u_out_px = k.cx_px + k.fx_px * x;
  v_out_px = k.cy_px + k.fy_px * y;
}

std::unique_ptr<TagDetector> TagDetector::create(const TagDetectorOptions& o, std::string& error) {
  const FamilyEntry* f = find_family(o.family);
  if (f == nullptr) {
    std::string names;
    for (const char* const* n = kTagFamilyNames; *n != nullptr; ++n) names += (names.empty() ? "" : ", ") + std::string(*n);
    error = "tag family '" + o.family + "' is not one libapriltag provides (" + names + ")";
    return nullptr;
  }
  if (!(o.tag_size_m > 0 && o.tag_size_m < 10)) {
    error = "tag size must be in (0, 10) m";
    return nullptr;
  }
  if (!(o.quad_decimate >= 1 && o.quad_decimate <= 8)) {
    error = "quad_decimate must be in [1, 8]";
    return nullptr;
  }
  if (!(o.quad_sigma >= 0 && o.quad_sigma <= 5)) {
    error = "quad_sigma must be in [0, 5] px";
    return nullptr;
  }
  if (o.threads < 1 || o.threads > 16) {
    error = "threads must be in [1, 16]";
    return nullptr;
  }
  if (o.max_hamming < 0 || o.max_hamming > 2) {
    error = "max_hamming must be 0, 1 or 2";
    return nullptr;
  }
  return std::make_unique<AprilTagDetectorImpl>(o, *f);
}

}  // namespace dockcore::drivers
