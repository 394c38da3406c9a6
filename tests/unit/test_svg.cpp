// SVG writer: the world -> pixel map (metres to pixels, y up), tag balance of the document, numbers written where
// the geometry says they should be, text escaping.
#include <cstdlib>
#include <regex>
#include <string>
#include <vector>

#include "dockcore/geometry.hpp"
#include "docksim/svg.hpp"

#include <CppUTest/TestHarness.h>

using dockcore::Pose2;
using dockcore::Vec2;
using docksim::SvgBounds;
using docksim::SvgCanvas;
using docksim::SvgStyle;

namespace {

/// Checks XML-ish tag balance: every <x ...> is closed by </x> in LIFO order or self-closed; returns false otherwise.
/// Skips the <?xml ...?> declaration. Attribute values contain no '>' (the writer escapes it).
bool tags_balanced(const std::string& s, int* elements) {
  std::vector<std::string> stack;
  *elements = 0;
  std::size_t i = 0;
  while ((i = s.find('<', i)) != std::string::npos) {
    const std::size_t j = s.find('>', i);
    if (j == std::string::npos) return false;
    const std::string tag = s.substr(i + 1, j - i - 1);
    i = j + 1;
    if (tag.empty()) return false;
    if (tag[0] == '?') continue;
    if (tag[0] == '/') {
      if (stack.empty() || stack.back() != tag.substr(1)) return false;
      stack.pop_back();
      continue;
    }
    ++*elements;
    if (tag.back() == '/') continue;
    stack.push_back(tag.substr(0, tag.find(' ')));
  }
  return stack.empty();
}

/// Value of attribute `name` of the first element matching `element_regex` (e.g. "<line[^>]*"), as a double.
double attr(const std::string& doc, const std::string& element_regex, const std::string& name) {
  std::smatch m;
  const std::regex re(element_regex);
  if (!std::regex_search(doc, m, re)) return NAN;
  const std::string el = m.str();
  const std::regex are(" " + name + "=\"([-0-9.]+)\"");
  std::smatch am;
  if (!std::regex_search(el, am, are)) return NAN;
  return std::atof(am[1].str().c_str());
}

SvgBounds box(double x0, double y0, double x1, double y1) {
  SvgBounds b;
  b.add(x0, y0);
  b.add(x1, y1);
  return b;
}

}  // namespace

TEST_GROUP(Svg){};

TEST(Svg, WorldToPixelMapsMetresWithYUp) {
  // World x in [-1, 3], y in [-2, 1] at 50 px/m with a 10 px margin: 220 x 170 px.
  const SvgCanvas c(box(-1, -2, 3, 1), 50, 10);
  DOUBLES_EQUAL(220, c.width_px(), 1e-9);
  DOUBLES_EQUAL(170, c.height_px(), 1e-9);
  // Top-left world corner (-1, 1) is at the margin.
  const Vec2 tl = c.to_px(Vec2(-1, 1));
  DOUBLES_EQUAL(10, tl.x(), 1e-9);
  DOUBLES_EQUAL(10, tl.y(), 1e-9);
  // Origin: 1 m right of the left edge, 1 m below the top edge.
  const Vec2 o = c.to_px(Vec2(0, 0));
  DOUBLES_EQUAL(60, o.x(), 1e-9);
  DOUBLES_EQUAL(60, o.y(), 1e-9);
  // Going up in the world goes up (smaller y) on screen.
  CHECK(c.to_px(Vec2(0, 0.5)).y() < o.y());
  const Vec2 back = c.to_world(c.to_px(Vec2(2.25, -1.5)));
  DOUBLES_EQUAL(2.25, back.x(), 1e-12);
  DOUBLES_EQUAL(-1.5, back.y(), 1e-12);
}

TEST(Svg, ShapesWriteTheMappedNumbers) {
  SvgCanvas c(box(0, 0, 2, 2), 100, 0);
  c.line(Vec2(0, 0), Vec2(2, 1), SvgStyle::line("grey", 1.5, "4,2"));
  c.circle(Vec2(1, 1), 0.25, SvgStyle::filled("red", 0.5));
  const std::string doc = c.str();
  DOUBLES_EQUAL(0, attr(doc, "<line[^>]*", "x1"), 1e-9);
  DOUBLES_EQUAL(200, attr(doc, "<line[^>]*", "y1"), 1e-9);  // world y 0 is the bottom
  DOUBLES_EQUAL(200, attr(doc, "<line[^>]*", "x2"), 1e-9);
  DOUBLES_EQUAL(100, attr(doc, "<line[^>]*", "y2"), 1e-9);
  DOUBLES_EQUAL(1.5, attr(doc, "<line[^>]*", "stroke-width"), 1e-9);
  CHECK(doc.find("stroke-dasharray=\"4,2\"") != std::string::npos);
  DOUBLES_EQUAL(100, attr(doc, "<circle[^>]*", "cx"), 1e-9);
  DOUBLES_EQUAL(100, attr(doc, "<circle[^>]*", "cy"), 1e-9);
  DOUBLES_EQUAL(25, attr(doc, "<circle[^>]*", "r"), 1e-9);
  DOUBLES_EQUAL(0.5, attr(doc, "<circle[^>]*", "opacity"), 1e-9);
  int n = 0;
  CHECK(tags_balanced(doc, &n));
}

TEST(Svg, PoseArrowPointsAlongHeading) {
  SvgCanvas c(box(-1, -1, 1, 1), 100, 0);
  // Heading +90° (world +y): the arrow tip is straight up on screen, 50 px above the origin's pixel (100, 100).
  c.pose(Pose2{0, 0, dockcore::kPi / 2}, 0.5, SvgStyle::line("red", 2));
  const std::string doc = c.str();
  std::smatch m;
  const std::regex re("<polygon points=\"([-0-9.]+),([-0-9.]+) ");
  CHECK(std::regex_search(doc, m, re));
  DOUBLES_EQUAL(100, std::atof(m[1].str().c_str()), 1e-9);
  DOUBLES_EQUAL(50, std::atof(m[2].str().c_str()), 1e-9);
  // The shaft starts at the pose's position.
  DOUBLES_EQUAL(100, attr(doc, "<line[^>]*", "x1"), 1e-9);
  DOUBLES_EQUAL(100, attr(doc, "<line[^>]*", "y1"), 1e-9);
}

TEST(Svg, OutlinePlacesBodyPointsAtPose) {
  SvgCanvas c(box(0, 0, 4, 4), 10, 0);
  // Body square corner (0.5, 0) at pose (2, 2, 90°) lands at world (2, 2.5) -> pixel (20, 15).
  c.outline({Vec2(0.5, 0), Vec2(0, 0.5), Vec2(-0.5, 0)}, Pose2{2, 2, dockcore::kPi / 2}, SvgStyle::line("black"));
  const std::string doc = c.str();
  CHECK(doc.find("<polygon points=\"20.00,15.00 15.00,20.00 20.00,25.00\"") != std::string::npos);
}

TEST(Svg, DocumentIsBalancedWithLegendTitleAndEscapedText) {
  SvgCanvas c(box(-1, -1, 1, 1), 80, 20);
  c.grid(0.5);
  c.polyline({Vec2(-1, -1), Vec2(0, 0.5), Vec2(1, -1)}, SvgStyle::line("blue"));
  c.dots({Vec2(0, 0), Vec2(0.1, 0.1)}, 1.5, SvgStyle::filled("#1f77b4"));
  c.arrow(Vec2(0, 0), Vec2(0.5, 0.5), SvgStyle::line("green"));
  c.text(Vec2(0, 0), "a < b & \"c\"");
  c.scale_bar(0.5);
  c.title("Title <1>");
  c.legend("scan", SvgStyle::filled("#1f77b4"), docksim::SvgLegendMark::kDot);
  c.legend("estimate", SvgStyle::line("red", 2), docksim::SvgLegendMark::kArrow);
  c.legend_text("err x 1.2 mm");
  const std::string doc = c.str();
  int elements = 0;
  CHECK(tags_balanced(doc, &elements));
  CHECK(elements > 20);
  CHECK(doc.find("a &lt; b &amp; &quot;c&quot;") != std::string::npos);
  CHECK(doc.find("Title &lt;1&gt;") != std::string::npos);
  CHECK(doc.find("<svg xmlns=\"http://www.w3.org/2000/svg\"") != std::string::npos);
  // The legend widens the picture beyond the plot (160 + 40 px) and the title adds to the height.
  CHECK(c.width_px() > 200);
  CHECK(c.height_px() > 200);
  DOUBLES_EQUAL(c.width_px(), attr(doc, "<svg[^>]*", "width"), 1e-9);
  // Shapes sit in a group shifted below the title.
  CHECK(doc.find("<g transform=\"translate(0,28.00)\">") != std::string::npos);
}

TEST(Svg, NumberFormatting) {
  STRCMP_EQUAL("0.00", SvgCanvas::num(-0.001).c_str());
  STRCMP_EQUAL("-1.25", SvgCanvas::num(-1.25).c_str());
  STRCMP_EQUAL("0.00", SvgCanvas::num(NAN).c_str());
}
