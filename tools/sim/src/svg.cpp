#include "docksim/svg.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

namespace docksim {
namespace {

using dockcore::Vec2;

constexpr double kTitlePx = 28.0;        // height reserved for a title
constexpr double kLegendFontPx = 13.0;
constexpr double kLegendRowPx = 19.0;
constexpr double kLegendMarkPx = 28.0;   // width of the mark column
constexpr double kLegendPadPx = 10.0;

const char* anchor_name(SvgAnchor a) {
  switch (a) {
    case SvgAnchor::kMiddle: return "middle";
    case SvgAnchor::kEnd: return "end";
    default: return "start";
  }
}

}  // namespace

void SvgBounds::add(double x, double y) {
  if (empty) {
    x_min = x_max = x;
    y_min = y_max = y;
    empty = false;
    return;
  }
  x_min = std::min(x_min, x);
  x_max = std::max(x_max, x);
  y_min = std::min(y_min, y);
  y_max = std::max(y_max, y);
}

void SvgBounds::add(const Vec2& p) { add(static_cast<double>(p.x()), static_cast<double>(p.y())); }

void SvgBounds::pad(double pad_m) {
  x_min -= pad_m;
  y_min -= pad_m;
  x_max += pad_m;
  y_max += pad_m;
}

SvgCanvas::SvgCanvas(const SvgBounds& world, double px_per_m, double margin_px)
    : world_(world), px_per_m_(px_per_m > 0 ? px_per_m : 100.0), margin_px_(margin_px >= 0 ? margin_px : 0) {
  if (world_.empty) {
    world_.add(0, 0);
  }
  if (!(world_.x_max > world_.x_min)) {
    world_.x_min -= 0.5;
    world_.x_max += 0.5;
  }
  if (!(world_.y_max > world_.y_min)) {
    world_.y_min -= 0.5;
    world_.y_max += 0.5;
  }
}

Vec2 SvgCanvas::to_px(const Vec2& w) const {
  const double x = margin_px_ + (static_cast<double>(w.x()) - world_.x_min) * px_per_m_;
  const double y = margin_px_ + (world_.y_max - static_cast<double>(w.y())) * px_per_m_;
  return Vec2(static_cast<dockcore::Real>(x), static_cast<dockcore::Real>(y));
}

Vec2 SvgCanvas::to_world(const Vec2& px) const {
  const double x = world_.x_min + (static_cast<double>(px.x()) - margin_px_) / px_per_m_;
  const double y = world_.y_max - (static_cast<double>(px.y()) - margin_px_) / px_per_m_;
  return Vec2(static_cast<dockcore::Real>(x), static_cast<dockcore::Real>(y));
}

double SvgCanvas::top_px() const { return title_.empty() ? 0.0 : kTitlePx; }

double SvgCanvas::width_px() const {
  double w = 2 * margin_px_ + (world_.x_max - world_.x_min) * px_per_m_;
  if (!legend_.empty()) {
    std::size_t longest = 0;
    for (const auto& e : legend_) longest = std::max(longest, e.label.size());
    w += 2 * kLegendPadPx + kLegendMarkPx + 0.62 * kLegendFontPx * static_cast<double>(longest) + margin_px_;
  }
  return std::ceil(w);
}

double SvgCanvas::height_px() const {
  const double plot = 2 * margin_px_ + (world_.y_max - world_.y_min) * px_per_m_;
  const double legend =
      legend_.empty() ? 0.0 : 2 * margin_px_ + 2 * kLegendPadPx + kLegendRowPx * static_cast<double>(legend_.size());
  return std::ceil(top_px() + std::max(plot, legend));
}

std::string SvgCanvas::num(double v) {
  if (!std::isfinite(v)) v = 0;
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.2f", v);
  std::string s(buf);
  if (s == "-0.00") s = "0.00";
  return s;
}

std::string SvgCanvas::escape(const std::string& s) {
  std::string o;
  o.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '&': o += "&amp;"; break;
      case '<': o += "&lt;"; break;
      case '>': o += "&gt;"; break;
      case '"': o += "&quot;"; break;
      case '\'': o += "&apos;"; break;
      default: o += c;
    }
  }
  return o;
}

std::string SvgCanvas::style_attr(const SvgStyle& s) const {
  std::string a = "stroke=\"" + escape(s.stroke) + "\" fill=\"" + escape(s.fill) + "\" stroke-width=\"" +
                  num(s.stroke_width_px) + "\"";
  if (!s.dash.empty()) a += " stroke-dasharray=\"" + escape(s.dash) + "\"";
  if (s.opacity < 1.0) a += " opacity=\"" + num(s.opacity) + "\"";
  return a;
}

void SvgCanvas::line(const Vec2& a_m, const Vec2& b_m, const SvgStyle& style) {
  const Vec2 a = to_px(a_m);
  const Vec2 b = to_px(b_m);
  body_.push_back("<line x1=\"" + num(a.x()) + "\" y1=\"" + num(a.y()) + "\" x2=\"" + num(b.x()) + "\" y2=\"" +
                  num(b.y()) + "\" " + style_attr(style) + " stroke-linecap=\"round\"/>");
}

void SvgCanvas::polyline(const std::vector<Vec2>& pts_m, const SvgStyle& style, bool closed) {
  if (pts_m.empty()) return;
  std::string pts;
  for (const Vec2& p : pts_m) {
    const Vec2 q = to_px(p);
    if (!pts.empty()) pts += ' ';
    pts += num(q.x()) + "," + num(q.y());
  }
  body_.push_back(std::string(closed ? "<polygon" : "<polyline") + " points=\"" + pts + "\" " + style_attr(style) +
                  " stroke-linejoin=\"round\"/>");
}

void SvgCanvas::circle(const Vec2& centre_m, double radius_m, const SvgStyle& style) {
  const Vec2 c = to_px(centre_m);
  body_.push_back("<circle cx=\"" + num(c.x()) + "\" cy=\"" + num(c.y()) + "\" r=\"" + num(radius_m * px_per_m_) +
                  "\" " + style_attr(style) + "/>");
}

void SvgCanvas::dots(const std::vector<Vec2>& pts_m, double radius_px, const SvgStyle& style) {
  if (pts_m.empty()) return;
  std::string g = "<g " + style_attr(style) + ">";
  for (const Vec2& p : pts_m) {
    const Vec2 c = to_px(p);
    g += "<circle cx=\"" + num(c.x()) + "\" cy=\"" + num(c.y()) + "\" r=\"" + num(radius_px) + "\"/>";
  }
  g += "</g>";
  body_.push_back(g);
}

void SvgCanvas::arrow(const Vec2& a_m, const Vec2& b_m, const SvgStyle& style, double head_px) {
  const Vec2 a = to_px(a_m);
  const Vec2 b = to_px(b_m);
  const Vec2 d = b - a;
  const double len = static_cast<double>(d.norm());
  if (len <= 1e-9) return;
  const Vec2 u = d / static_cast<dockcore::Real>(len);
  const Vec2 n(-u.y(), u.x());
  const double h = std::min(head_px, len);
  const auto r = [](double v) { return static_cast<dockcore::Real>(v); };
  const Vec2 base = b - u * r(h);
  const Vec2 l = base + n * r(h * 0.45);
  const Vec2 rr = base - n * r(h * 0.45);
  SvgStyle shaft = style;
  shaft.fill = "none";
  body_.push_back("<line x1=\"" + num(a.x()) + "\" y1=\"" + num(a.y()) + "\" x2=\"" + num(base.x()) + "\" y2=\"" +
                  num(base.y()) + "\" " + style_attr(shaft) + " stroke-linecap=\"round\"/>");
  SvgStyle head = style;
  head.fill = style.stroke;
  head.dash.clear();
  head.stroke_width_px = 1.0;
  body_.push_back("<polygon points=\"" + num(b.x()) + "," + num(b.y()) + " " + num(l.x()) + "," + num(l.y()) + " " +
                  num(rr.x()) + "," + num(rr.y()) + "\" " + style_attr(head) + "/>");
}

void SvgCanvas::pose(const dockcore::Pose2& p, double length_m, const SvgStyle& style) {
  const Vec2 o(p.x_m, p.y_m);
  const Vec2 tip = p.transform(Vec2(static_cast<dockcore::Real>(length_m), 0));
  arrow(o, tip, style);
  SvgStyle dot = style;
  dot.fill = "none";
  dot.dash.clear();
  const Vec2 c = to_px(o);
  body_.push_back("<circle cx=\"" + num(c.x()) + "\" cy=\"" + num(c.y()) + "\" r=\"3.00\" " + style_attr(dot) + "/>");
}

void SvgCanvas::outline(const std::vector<Vec2>& body_pts_m, const dockcore::Pose2& p, const SvgStyle& style,
                        bool closed) {
  std::vector<Vec2> w;
  w.reserve(body_pts_m.size());
  for (const Vec2& q : body_pts_m) w.push_back(p.transform(q));
  polyline(w, style, closed);
}

void SvgCanvas::text_px(const Vec2& at_m, double dx_px, double dy_px, const std::string& s, double size_px,
                        const std::string& colour, SvgAnchor anchor) {
  const Vec2 a = to_px(at_m);
  body_.push_back("<text x=\"" + num(static_cast<double>(a.x()) + dx_px) + "\" y=\"" +
                  num(static_cast<double>(a.y()) + dy_px) + "\" font-size=\"" + num(size_px) + "\" fill=\"" +
                  escape(colour) + "\" text-anchor=\"" + anchor_name(anchor) + "\">" + escape(s) + "</text>");
}

void SvgCanvas::text(const Vec2& at_m, const std::string& s, double size_px, const std::string& colour,
                     SvgAnchor anchor) {
  text_px(at_m, 0, 0, s, size_px, colour, anchor);
}

void SvgCanvas::grid(double step_m, const std::string& colour) {
  if (!(step_m > 0)) return;
  const SvgStyle st = SvgStyle::line(colour, 1.0);
  using dockcore::Real;
  for (double x = std::ceil(world_.x_min / step_m) * step_m; x <= world_.x_max + 1e-9; x += step_m) {
    line(Vec2(static_cast<Real>(x), static_cast<Real>(world_.y_min)),
         Vec2(static_cast<Real>(x), static_cast<Real>(world_.y_max)), st);
  }
  for (double y = std::ceil(world_.y_min / step_m) * step_m; y <= world_.y_max + 1e-9; y += step_m) {
    line(Vec2(static_cast<Real>(world_.x_min), static_cast<Real>(y)),
         Vec2(static_cast<Real>(world_.x_max), static_cast<Real>(y)), st);
  }
}

void SvgCanvas::scale_bar(double length_m) {
  if (!(length_m > 0)) return;
  const double x0 = margin_px_ + 10;
  const double y0 = margin_px_ + (world_.y_max - world_.y_min) * px_per_m_ - 10;
  const double x1 = x0 + length_m * px_per_m_;
  char label[32];
  if (length_m >= 1.0) {
    std::snprintf(label, sizeof(label), "%g m", length_m);
  } else {
    std::snprintf(label, sizeof(label), "%g cm", length_m * 100.0);
  }
  body_.push_back("<g stroke=\"black\" stroke-width=\"2.00\"><line x1=\"" + num(x0) + "\" y1=\"" + num(y0) +
                  "\" x2=\"" + num(x1) + "\" y2=\"" + num(y0) + "\"/><line x1=\"" + num(x0) + "\" y1=\"" +
                  num(y0 - 4) + "\" x2=\"" + num(x0) + "\" y2=\"" + num(y0 + 4) + "\"/><line x1=\"" + num(x1) +
                  "\" y1=\"" + num(y0 - 4) + "\" x2=\"" + num(x1) + "\" y2=\"" + num(y0 + 4) + "\"/></g>");
  body_.push_back("<text x=\"" + num((x0 + x1) / 2) + "\" y=\"" + num(y0 - 6) +
                  "\" font-size=\"11.00\" fill=\"black\" text-anchor=\"middle\">" + escape(label) + "</text>");
}

void SvgCanvas::title(const std::string& s) { title_ = s; }

void SvgCanvas::legend(const std::string& label, const SvgStyle& style, SvgLegendMark mark) {
  legend_.push_back(LegendEntry{label, style, mark});
}

void SvgCanvas::legend_text(const std::string& label) {
  legend_.push_back(LegendEntry{label, SvgStyle{}, SvgLegendMark::kNone});
}

std::string SvgCanvas::str() const {
  const double w = width_px();
  const double h = height_px();
  std::string s = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  s += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + num(w) + "\" height=\"" + num(h) + "\" viewBox=\"0 0 " +
       num(w) + " " + num(h) + "\" font-family=\"sans-serif\">\n";
  s += "<rect x=\"0.00\" y=\"0.00\" width=\"" + num(w) + "\" height=\"" + num(h) + "\" fill=\"white\"/>\n";
  if (!title_.empty()) {
    s += "<text x=\"" + num(margin_px_) + "\" y=\"" + num(kTitlePx - 6) + "\" font-size=\"16.00\" fill=\"black\">" +
         escape(title_) + "</text>\n";
  }
  // Shapes are stored in plot coordinates (to_px); the group shifts them below the title, and the clip keeps shapes
  // reaching past the shown world rectangle out of the margins and the legend.
  const double pw = (world_.x_max - world_.x_min) * px_per_m_;
  const double ph = (world_.y_max - world_.y_min) * px_per_m_;
  s += "<defs><clipPath id=\"plot-area\"><rect x=\"" + num(margin_px_) + "\" y=\"" + num(margin_px_) + "\" width=\"" +
       num(pw) + "\" height=\"" + num(ph) + "\"/></clipPath></defs>\n";
  s += "<g transform=\"translate(0," + num(top_px()) + ")\">\n<g clip-path=\"url(#plot-area)\">\n";
  for (const std::string& e : body_) s += e + "\n";
  s += "</g>\n<rect x=\"" + num(margin_px_) + "\" y=\"" + num(margin_px_) + "\" width=\"" + num(pw) + "\" height=\"" +
       num(ph) + "\" fill=\"none\" stroke=\"#bbbbbb\" stroke-width=\"1.00\"/>\n</g>\n";
  if (!legend_.empty()) {
    const double x0 = 2 * margin_px_ + (world_.x_max - world_.x_min) * px_per_m_;
    const double y0 = top_px() + margin_px_;
    const double lw = w - x0 - margin_px_;
    const double lh = 2 * kLegendPadPx + kLegendRowPx * static_cast<double>(legend_.size());
    s += "<g font-size=\"" + num(kLegendFontPx) + "\">\n";
    s += "<rect x=\"" + num(x0) + "\" y=\"" + num(y0) + "\" width=\"" + num(lw) + "\" height=\"" + num(lh) +
         "\" fill=\"#fafafa\" stroke=\"#bbbbbb\" stroke-width=\"1.00\"/>\n";
    for (std::size_t i = 0; i < legend_.size(); ++i) {
      const LegendEntry& e = legend_[i];
      const double cy = y0 + kLegendPadPx + kLegendRowPx * (static_cast<double>(i) + 0.5);
      const double mx0 = x0 + kLegendPadPx;
      const double mx1 = mx0 + kLegendMarkPx - 6;
      SvgStyle st = e.style;
      switch (e.mark) {
        case SvgLegendMark::kLine:
          st.fill = "none";
          s += "<line x1=\"" + num(mx0) + "\" y1=\"" + num(cy) + "\" x2=\"" + num(mx1) + "\" y2=\"" + num(cy) + "\" " +
               style_attr(st) + "/>\n";
          break;
        case SvgLegendMark::kDot:
          s += "<circle cx=\"" + num((mx0 + mx1) / 2) + "\" cy=\"" + num(cy) + "\" r=\"3.00\" " + style_attr(st) +
               "/>\n";
          break;
        case SvgLegendMark::kArrow: {
          SvgStyle head = st;
          head.fill = st.stroke;
          head.dash.clear();
          head.stroke_width_px = 1.0;
          st.fill = "none";
          s += "<line x1=\"" + num(mx0) + "\" y1=\"" + num(cy) + "\" x2=\"" + num(mx1 - 6) + "\" y2=\"" + num(cy) +
               "\" " + style_attr(st) + "/>\n";
          s += "<polygon points=\"" + num(mx1) + "," + num(cy) + " " + num(mx1 - 7) + "," + num(cy - 3.5) + " " +
               num(mx1 - 7) + "," + num(cy + 3.5) + "\" " + style_attr(head) + "/>\n";
          break;
        }
        case SvgLegendMark::kNone:
          break;
      }
      const double tx = e.mark == SvgLegendMark::kNone ? mx0 : x0 + kLegendPadPx + kLegendMarkPx;
      // Free text rows are usually aligned figures: monospace keeps their columns.
      s += "<text x=\"" + num(tx) + "\" y=\"" + num(cy + 4.5) + "\" fill=\"black\"" +
           (e.mark == SvgLegendMark::kNone ? " font-family=\"monospace\" xml:space=\"preserve\"" : "") + ">" +
           escape(e.label) + "</text>\n";
    }
    s += "</g>\n";
  }
  s += "</svg>\n";
  return s;
}

bool SvgCanvas::write(const std::string& path, std::string* error) const {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) {
    if (error) *error = "cannot open " + path + " for writing";
    return false;
  }
  out << str();
  out.flush();
  if (!out) {
    if (error) *error = "error writing " + path;
    return false;
  }
  return true;
}

}  // namespace docksim
