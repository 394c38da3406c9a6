#pragma once
// A small SVG writer for plots in world coordinates: scenes, scans, poses, robot outlines, trajectories, maps.
//
// The canvas shows the world rectangle [x_min, x_max] x [y_min, y_max] (metres) at px_per_m pixels per metre with a
// margin around it; world y points up (SVG's y points down, the writer flips it). Shapes are buffered in call order
// (later shapes draw on top) and rendered by str(), clipped to the world rectangle, inside a thin frame. An optional
// legend panel is drawn to the right of the plot.
// Host-side; no dependencies beyond the standard library and dockcore's geometry types.
#include <string>
#include <vector>

#include "dockcore/geometry.hpp"

namespace docksim {

/// How a shape is painted. Colours are any SVG colour ("#1f77b4", "grey", "none").
struct SvgStyle {
  std::string stroke = "black";
  std::string fill = "none";
  double stroke_width_px = 1.0;
  std::string dash;          ///< SVG stroke-dasharray in pixels, e.g. "6,3"; empty = solid.
  double opacity = 1.0;      ///< Applies to stroke and fill.

  static SvgStyle line(const std::string& colour, double width_px = 1.0, const std::string& dash = "") {
    SvgStyle s;
    s.stroke = colour;
    s.stroke_width_px = width_px;
    s.dash = dash;
    return s;
  }
  static SvgStyle filled(const std::string& colour, double opacity = 1.0) {
    SvgStyle s;
    s.stroke = "none";
    s.fill = colour;
    s.opacity = opacity;
    return s;
  }
};

/// Text anchoring (horizontal), as SVG's text-anchor.
enum class SvgAnchor { kStart, kMiddle, kEnd };

/// What a legend entry shows next to its label.
enum class SvgLegendMark { kLine, kDot, kArrow, kNone };

/// An axis-aligned world rectangle, grown point by point.
struct SvgBounds {
  double x_min = 0, y_min = 0, x_max = 0, y_max = 0;
  bool empty = true;
  void add(const dockcore::Vec2& p);
  void add(double x, double y);
  /// Grows every side by pad_m.
  void pad(double pad_m);
};

class SvgCanvas {
 public:
  /// Canvas showing `world` (must be non-empty with positive extent; a degenerate side is widened to 1 m) at
  /// px_per_m (> 0), with margin_px of blank border.
  SvgCanvas(const SvgBounds& world, double px_per_m, double margin_px = 20.0);

  /// World (metres, y up) -> pixel (x right, y down) in the plot area.
  dockcore::Vec2 to_px(const dockcore::Vec2& world_m) const;
  /// Pixel -> world, the inverse of to_px.
  dockcore::Vec2 to_world(const dockcore::Vec2& px) const;
  double px_per_m() const { return px_per_m_; }
  /// Size of the whole picture in pixels (plot plus margin plus the legend panel, if any entries).
  double width_px() const;
  double height_px() const;

  // --- Shapes in world coordinates ---
  void line(const dockcore::Vec2& a_m, const dockcore::Vec2& b_m, const SvgStyle& style);
  /// Open polyline, or polygon when `closed` (fill applies).
  void polyline(const std::vector<dockcore::Vec2>& pts_m, const SvgStyle& style, bool closed = false);
  /// Circle of radius in metres.
  void circle(const dockcore::Vec2& centre_m, double radius_m, const SvgStyle& style);
  /// Dots of a fixed pixel radius (scan points): one <circle> each, grouped.
  void dots(const std::vector<dockcore::Vec2>& pts_m, double radius_px, const SvgStyle& style);
  /// An arrow from a_m to b_m with a head of head_px pixels (stroke colour fills the head).
  void arrow(const dockcore::Vec2& a_m, const dockcore::Vec2& b_m, const SvgStyle& style, double head_px = 8.0);
  /// A pose: an arrow of length_m along the pose's heading from its position, plus a small circle at the position.
  void pose(const dockcore::Pose2& pose, double length_m, const SvgStyle& style);
  /// A polygon given in a body frame (robot footprint, dock outline), placed at `pose`.
  void outline(const std::vector<dockcore::Vec2>& body_pts_m, const dockcore::Pose2& pose, const SvgStyle& style,
               bool closed = true);
  /// Text at a world position (baseline), size in pixels. The text is escaped.
  void text(const dockcore::Vec2& at_m, const std::string& s, double size_px = 12.0, const std::string& colour = "black",
            SvgAnchor anchor = SvgAnchor::kStart);
  /// Text offset by (dx_px, dy_px) pixels (dy down) from a world position.
  void text_px(const dockcore::Vec2& at_m, double dx_px, double dy_px, const std::string& s, double size_px = 12.0,
               const std::string& colour = "black", SvgAnchor anchor = SvgAnchor::kStart);

  // --- Decorations ---
  /// Light grid lines every step_m inside the plot (drawn where called; call first to keep it underneath).
  void grid(double step_m, const std::string& colour = "#eeeeee");
  /// A scale bar of length_m at the plot's bottom-left, labelled.
  void scale_bar(double length_m);
  /// A title above the plot (top margin grows to fit it).
  void title(const std::string& s);
  /// Legend entries in the right-hand panel, in call order.
  void legend(const std::string& label, const SvgStyle& style, SvgLegendMark mark = SvgLegendMark::kLine);
  /// A plain text line in the legend panel (e.g. error figures).
  void legend_text(const std::string& label);

  /// The complete SVG document.
  std::string str() const;
  /// Writes str() to `path`; false with *error set on failure.
  bool write(const std::string& path, std::string* error) const;

  /// Formats a number for SVG attributes: fixed with 2 decimals, no "-0.00". Exposed for tests.
  static std::string num(double v);
  /// Escapes &, <, >, " and ' for text content and attributes.
  static std::string escape(const std::string& s);

 private:
  std::string style_attr(const SvgStyle& s) const;
  double top_px() const;  // margin plus title height

  SvgBounds world_;
  double px_per_m_;
  double margin_px_;
  std::string title_;
  std::vector<std::string> body_;  // rendered shape elements, in order
  struct LegendEntry {
    std::string label;
    SvgStyle style;
    SvgLegendMark mark;
  };
  std::vector<LegendEntry> legend_;
};

}  // namespace docksim
