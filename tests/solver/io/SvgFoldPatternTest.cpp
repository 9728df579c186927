#include "devsurf/io/SvgFoldPattern.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace devsurf::io {
namespace {

// --- a minimal XML scanner: enough to check well-formedness of what the writer emits -----------

struct Element {
  std::string name;
  std::map<std::string, std::string> attrs;
  std::string text;
  std::vector<std::unique_ptr<Element>> children;

  /// All descendants (depth first) named `n`.
  void collect(const std::string& n, std::vector<const Element*>& out) const {
    for (const auto& c : children) {
      if (c->name == n) out.push_back(c.get());
      c->collect(n, out);
    }
  }
  std::vector<const Element*> all(const std::string& n) const {
    std::vector<const Element*> out;
    collect(n, out);
    return out;
  }
  const Element* byId(const std::string& id) const {
    for (const auto& c : children) {
      if (auto it = c->attrs.find("id"); it != c->attrs.end() && it->second == id) return c.get();
      if (const Element* e = c->byId(id)) return e;
    }
    return nullptr;
  }
  std::string attr(const std::string& a) const {
    const auto it = attrs.find(a);
    return it == attrs.end() ? std::string() : it->second;
  }
};

/// Parses a document (XML declaration, comments, elements, attributes, character data and the
/// five predefined entities); throws std::runtime_error at the first well-formedness error.
class XmlScanner {
 public:
  explicit XmlScanner(std::string text) : s_(std::move(text)) {}

  std::unique_ptr<Element> parse() {
    skipSpace();
    if (s_.compare(i_, 5, "<?xml") == 0) {
      const auto end = s_.find("?>", i_);
      if (end == std::string::npos) fail("unterminated XML declaration");
      i_ = end + 2;
    }
    skipMisc();
    if (i_ >= s_.size() || s_[i_] != '<') fail("no root element");
    auto root = element();
    skipMisc();
    if (i_ != s_.size()) fail("content after the root element");
    return root;
  }

 private:
  [[noreturn]] void fail(const std::string& what) {
    throw std::runtime_error("XML error at " + std::to_string(i_) + ": " + what);
  }
  void skipSpace() {
    while (i_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[i_]))) ++i_;
  }
  void skipMisc() {
    for (;;) {
      skipSpace();
      if (s_.compare(i_, 4, "<!--") == 0) {
        const auto end = s_.find("-->", i_);
        if (end == std::string::npos) fail("unterminated comment");
        i_ = end + 3;
      } else {
        return;
      }
    }
  }
  static bool nameChar(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == ':' ||
           c == '.';
  }
  std::string name() {
    const std::size_t b = i_;
    if (i_ >= s_.size() || !(std::isalpha(static_cast<unsigned char>(s_[i_])) || s_[i_] == '_'))
      fail("bad name");
    while (i_ < s_.size() && nameChar(s_[i_])) ++i_;
    return s_.substr(b, i_ - b);
  }
  std::string decode(const std::string& raw) {
    std::string out;
    for (std::size_t k = 0; k < raw.size(); ++k) {
      if (raw[k] == '<') fail("'<' in character data");
      if (raw[k] != '&') {
        out += raw[k];
        continue;
      }
      const auto semi = raw.find(';', k);
      if (semi == std::string::npos) fail("unterminated entity");
      const std::string ent = raw.substr(k + 1, semi - k - 1);
      if (ent == "amp") out += '&';
      else if (ent == "lt") out += '<';
      else if (ent == "gt") out += '>';
      else if (ent == "quot") out += '"';
      else if (ent == "apos") out += '\'';
      else fail("unknown entity &" + ent + ";");
      k = semi;
    }
    return out;
  }
  std::unique_ptr<Element> element() {
    ++i_;  // '<'
    auto e = std::make_unique<Element>();
    e->name = name();
    for (;;) {
      const std::size_t before = i_;
      skipSpace();
      if (i_ >= s_.size()) fail("unterminated start tag");
      if (s_.compare(i_, 2, "/>") == 0) {
        i_ += 2;
        return e;
      }
      if (s_[i_] == '>') {
        ++i_;
        break;
      }
      if (i_ == before) fail("attributes must be separated by white space");
      const std::string a = name();
      skipSpace();
      if (i_ >= s_.size() || s_[i_] != '=') fail("attribute without value");
      ++i_;
      skipSpace();
      if (i_ >= s_.size() || (s_[i_] != '"' && s_[i_] != '\'')) fail("unquoted attribute");
      const char q = s_[i_++];
      const auto end = s_.find(q, i_);
      if (end == std::string::npos) fail("unterminated attribute value");
      if (!e->attrs.emplace(a, decode(s_.substr(i_, end - i_))).second)
        fail("duplicate attribute " + a);
      i_ = end + 1;
    }
    for (;;) {  // content
      const auto lt = s_.find('<', i_);
      if (lt == std::string::npos) fail("unclosed element " + e->name);
      e->text += decode(s_.substr(i_, lt - i_));
      i_ = lt;
      if (s_.compare(i_, 4, "<!--") == 0) {
        skipMisc();
      } else if (s_.compare(i_, 2, "</") == 0) {
        i_ += 2;
        const std::string closing = name();
        if (closing != e->name) fail("</" + closing + "> closes <" + e->name + ">");
        skipSpace();
        if (i_ >= s_.size() || s_[i_] != '>') fail("bad end tag");
        ++i_;
        return e;
      } else {
        e->children.push_back(element());
      }
    }
  }

  std::string s_;
  std::size_t i_ = 0;
};

std::unique_ptr<Element> parseXml(const std::string& text) { return XmlScanner(text).parse(); }

std::vector<std::pair<double, double>> points(const std::string& list) {
  std::vector<std::pair<double, double>> out;
  std::istringstream in(list);
  std::string pair;
  while (in >> pair) {
    const auto comma = pair.find(',');
    out.emplace_back(std::stod(pair.substr(0, comma)), std::stod(pair.substr(comma + 1)));
  }
  return out;
}

/// "<number>mm" → number; fails the test on anything else.
double millimetres(const std::string& v) {
  EXPECT_GE(v.size(), 3u);
  EXPECT_EQ(v.substr(v.size() - 2), "mm") << v;
  return std::stod(v.substr(0, v.size() - 2));
}

// --- the pattern ----------------------------------------------------------------------------------

/// A 4×2 sheet whose boundary is split at (0,1) and (4,1); a curved mountain crease (curve 0)
/// runs across it through the top-most crease point (2, 1.3), and a valley crease (curve 1) lies
/// below it. One flat edge and two rulings.
CreasePattern sheet() {
  CreasePattern p;
  p.title = "sheet & crease <test>";
  p.vertices2d.resize(12, 2);
  p.vertices2d << 0, 0, 4, 0, 4, 1, 4, 2, 0, 2, 0, 1,  // boundary 0..5
      1, 1.2, 2, 1.3, 3, 1.2,                         // mountain interior 6..8
      1, 0.3, 2, 0.5, 3, 0.3;                         // valley 9..11
  p.unitToMm = 10.0;
  using A = EdgeAssignment;
  p.edges = {{0, 1, A::Boundary, std::nullopt, -1}, {1, 2, A::Boundary, std::nullopt, -1},
             {2, 3, A::Boundary, std::nullopt, -1}, {3, 4, A::Boundary, std::nullopt, -1},
             {4, 5, A::Boundary, std::nullopt, -1}, {5, 0, A::Boundary, std::nullopt, -1},
             // mountain chain listed out of order and against its direction, to exercise chaining
             {7, 8, A::Mountain, -40.0, 0},         {6, 5, A::Mountain, -40.0, 0},
             {8, 2, A::Mountain, -40.0, 0},         {6, 7, A::Mountain, -40.0, 0},
             {9, 10, A::Valley, 20.0, 1},           {10, 11, A::Valley, 20.0, 1},
             {0, 9, A::Flat, std::nullopt, -1}};
  p.rulings.resize(2, 4);
  p.rulings << 1, 1.2, 1, 2, 3, 1.2, 3, 2;
  return p;
}

TEST(SvgFoldPattern, IsWellFormedSvgSizedInMillimetres) {
  SvgFoldOptions o;
  o.marginMm = 5.0;
  const std::string svg = svgFoldPattern(sheet(), o);
  std::unique_ptr<Element> root;
  ASSERT_NO_THROW(root = parseXml(svg)) << svg;
  EXPECT_EQ(root->name, "svg");
  EXPECT_EQ(root->attr("xmlns"), "http://www.w3.org/2000/svg");
  EXPECT_EQ(root->attr("version"), "1.1");
  // bounding box 4 × 2 units, 10 mm per unit, 5 mm margins
  EXPECT_DOUBLE_EQ(millimetres(root->attr("width")), 4 * 10 + 2 * 5.0);
  EXPECT_DOUBLE_EQ(millimetres(root->attr("height")), 2 * 10 + 2 * 5.0);
  EXPECT_EQ(root->attr("viewBox"), "0 0 50 30");
  // The scanner itself rejects broken documents.
  EXPECT_THROW(parseXml("<svg><g></svg>"), std::runtime_error);
  EXPECT_THROW(parseXml("<svg a=\"1\" a=\"2\"/>"), std::runtime_error);
  EXPECT_THROW(parseXml("<svg>&nbsp;</svg>"), std::runtime_error);

  o.marginMm = 0.0;
  const auto tight = parseXml(svgFoldPattern(sheet(), o));
  EXPECT_DOUBLE_EQ(millimetres(tight->attr("width")), 40.0);
  EXPECT_DOUBLE_EQ(millimetres(tight->attr("height")), 20.0);
  EXPECT_EQ(tight->byId("legend"), nullptr);  // no room for it
}

TEST(SvgFoldPattern, CreasesArePolylinesPerCurveCarryingTheirStyles) {
  const auto root = parseXml(svgFoldPattern(sheet()));
  const Element* mountain = root->byId("curve-0");
  const Element* valley = root->byId("curve-1");
  ASSERT_NE(mountain, nullptr);
  ASSERT_NE(valley, nullptr);
  EXPECT_EQ(mountain->name, "polyline");
  EXPECT_EQ(valley->name, "polyline");
  EXPECT_EQ(root->byId("curve-0-2"), nullptr);  // the four mountain edges form one polyline
  EXPECT_EQ(points(mountain->attr("points")).size(), 5u);
  EXPECT_EQ(points(valley->attr("points")).size(), 3u);

  const SvgLineStyle m = svgEdgeStyle(EdgeAssignment::Mountain);
  const SvgLineStyle v = svgEdgeStyle(EdgeAssignment::Valley);
  EXPECT_EQ(std::string(m.color), "#ff0000");  // red
  EXPECT_EQ(std::string(v.color), "#0000ff");  // blue
  EXPECT_EQ(mountain->attr("class"), "mountain");
  EXPECT_EQ(mountain->attr("stroke"), m.color);
  EXPECT_EQ(mountain->attr("stroke-dasharray"), m.dasharray);
  const std::string mDash = m.dasharray, vDash = v.dasharray;
  EXPECT_EQ(std::count(mDash.begin(), mDash.end(), ' '), 3);  // dash-dot: dash, gap, dot, gap
  EXPECT_EQ(valley->attr("class"), "valley");
  EXPECT_EQ(valley->attr("stroke"), v.color);
  EXPECT_EQ(valley->attr("stroke-dasharray"), v.dasharray);
  EXPECT_EQ(std::count(vDash.begin(), vDash.end(), ' '), 1);  // dashed: dash, gap
  EXPECT_DOUBLE_EQ(std::stod(mountain->attr("stroke-width")), SvgFoldOptions().foldWidthMm);

  // Polylines live in their kind's group; the boundary is one closed black solid polygon.
  ASSERT_NE(root->byId("mountain"), nullptr);
  EXPECT_EQ(root->byId("mountain")->all("polyline").size(), 1u);
  const Element* boundary = root->byId("boundary");
  ASSERT_NE(boundary, nullptr);
  const auto polygons = boundary->all("polygon");
  ASSERT_EQ(polygons.size(), 1u);
  EXPECT_EQ(points(polygons[0]->attr("points")).size(), 6u);
  EXPECT_EQ(polygons[0]->attr("stroke"), "#000000");
  EXPECT_EQ(polygons[0]->attr("stroke-dasharray"), "");
  EXPECT_EQ(root->all("line").size(), 4u);  // only the legend's samples: no single segments

  // The mountain polyline visits the crease in order from (0,1) to (4,1).
  const auto pts = points(mountain->attr("points"));
  const double margin = SvgFoldOptions().marginMm;
  EXPECT_DOUBLE_EQ(pts.front().first, margin + 0.0);
  EXPECT_DOUBLE_EQ(pts.back().first, margin + 40.0);
  for (std::size_t k = 1; k < pts.size(); ++k) EXPECT_GT(pts[k].first, pts[k - 1].first);
}

TEST(SvgFoldPattern, FlipsTheYAxisSoTheDevelopmentIsNotMirrored) {
  SvgFoldOptions o;
  o.marginMm = 5.0;
  const auto root = parseXml(svgFoldPattern(sheet(), o));
  const auto boundary = points(root->byId("boundary")->all("polygon")[0]->attr("points"));
  // vertex 0 (0, 0) is the bottom-left corner, vertex 3 (4, 2) the top-right one
  EXPECT_DOUBLE_EQ(boundary[0].first, 5.0);
  EXPECT_DOUBLE_EQ(boundary[0].second, 25.0);
  EXPECT_DOUBLE_EQ(boundary[3].first, 45.0);
  EXPECT_DOUBLE_EQ(boundary[3].second, 5.0);  // the top of the development is at small SVG y
  // The crease's highest point (2, 1.3) has the smallest y of the mountain polyline.
  const auto crease = points(root->byId("curve-0")->attr("points"));
  EXPECT_DOUBLE_EQ(crease[2].first, 25.0);
  EXPECT_DOUBLE_EQ(crease[2].second, 5.0 + (2.0 - 1.3) * 10.0);
  for (const auto& pt : crease) EXPECT_GE(pt.second, crease[2].second);
  // Counter-clockwise in the development reads clockwise on screen (positive y-down area).
  double area = 0;
  for (std::size_t k = 0; k < boundary.size(); ++k) {
    const auto& a = boundary[k];
    const auto& b = boundary[(k + 1) % boundary.size()];
    area += a.first * b.second - b.first * a.second;
  }
  EXPECT_LT(area, 0.0);
}

TEST(SvgFoldPattern, DocumentsItsConventionsAndTheLegendCanBeSwitchedOff) {
  const std::string svg = svgFoldPattern(sheet());
  const auto root = parseXml(svg);
  ASSERT_EQ(root->all("title").size(), 1u);
  EXPECT_EQ(root->all("title")[0]->text, "sheet & crease <test>");  // escaped and decoded
  const std::string desc = root->all("desc")[0]->text;
  for (const char* phrase : {"millimetres", "mountain folds red dash-dot",
                             "valley folds blue dashed", "boundary and cuts solid black"})
    EXPECT_NE(desc.find(phrase), std::string::npos) << phrase;
  const Element* legend = root->byId("legend");
  ASSERT_NE(legend, nullptr);
  const auto labels = legend->all("text");
  ASSERT_EQ(labels.size(), 4u);  // mountain, valley, boundary / cut, ruling
  EXPECT_EQ(labels[0]->text, "mountain");
  EXPECT_EQ(legend->all("line")[0]->attr("stroke"), "#ff0000");
  // The legend stays inside the bottom margin.
  const double height = millimetres(root->attr("height"));
  for (const Element* line : legend->all("line"))
    EXPECT_GT(std::stod(line->attr("y1")), height - SvgFoldOptions().marginMm);

  SvgFoldOptions off;
  off.legend = false;
  const auto bare = parseXml(svgFoldPattern(sheet(), off));
  EXPECT_EQ(bare->byId("legend"), nullptr);
  EXPECT_EQ(bare->attr("width"), root->attr("width"));
  EXPECT_EQ(bare->attr("height"), root->attr("height"));
}

TEST(SvgFoldPattern, RulingsAndFlatEdgesAreOptional) {
  const auto root = parseXml(svgFoldPattern(sheet()));
  const Element* rulings = root->byId("rulings");
  ASSERT_NE(rulings, nullptr);
  const auto paths = rulings->all("path");
  ASSERT_EQ(paths.size(), 1u);
  EXPECT_EQ(paths[0]->attr("stroke"), svgRulingStyle().color);
  EXPECT_DOUBLE_EQ(std::stod(paths[0]->attr("stroke-width")), SvgFoldOptions().rulingWidthMm);
  const std::string d = paths[0]->attr("d");
  EXPECT_EQ(std::count(d.begin(), d.end(), 'M'), 2);
  EXPECT_EQ(root->byId("flat"), nullptr);  // flat edges are off by default

  SvgFoldOptions o;
  o.drawRulings = false;
  o.drawFlat = true;
  const auto other = parseXml(svgFoldPattern(sheet(), o));
  EXPECT_EQ(other->byId("rulings"), nullptr);
  ASSERT_NE(other->byId("flat"), nullptr);
  EXPECT_EQ(other->byId("flat")->all("polyline").size(), 1u);

  o.marginMm = -1.0;
  EXPECT_THROW(svgFoldPattern(sheet(), o), std::invalid_argument);
}

TEST(SvgFoldPattern, ASmallPatternKeepsItsTrueSizeAndScalesItsLineStylesDown) {
  CreasePattern small = sheet();
  small.unitToMm = 1.0;  // 4 × 2 mm: a tenth of the 40 mm reference size
  const auto root = parseXml(svgFoldPattern(small));
  const SvgFoldOptions o;
  const double k = 4.0 / o.styleReferenceMm;
  EXPECT_DOUBLE_EQ(millimetres(root->attr("width")), 4.0 + 2 * o.marginMm * k);
  EXPECT_DOUBLE_EQ(millimetres(root->attr("height")), 2.0 + 2 * o.marginMm * k);
  const Element* mountain = root->byId("curve-0");
  ASSERT_NE(mountain, nullptr);
  EXPECT_DOUBLE_EQ(std::stod(mountain->attr("stroke-width")), o.foldWidthMm * k);
  EXPECT_EQ(mountain->attr("stroke-dasharray"), "0.4 0.12 0.06 0.12");  // "4 1.2 0.6 1.2" × 0.1
  EXPECT_EQ(root->byId("curve-1")->attr("stroke-dasharray"), "0.25 0.15");
  EXPECT_DOUBLE_EQ(std::stod(root->byId("boundary")->all("polygon")[0]->attr("stroke-width")),
                   o.boundaryWidthMm * k);
  EXPECT_NE(root->byId("legend"), nullptr);  // shrunk with the margin
  EXPECT_NE(root->all("desc")[0]->text.find("scaled by 0.1"), std::string::npos);

  // At the reference size and above, and with scaling off, the styles are as given.
  SvgFoldOptions off;
  off.styleReferenceMm = 0.0;
  const auto unscaled = parseXml(svgFoldPattern(small, off));
  EXPECT_DOUBLE_EQ(millimetres(unscaled->attr("width")), 4.0 + 2 * o.marginMm);
  EXPECT_EQ(unscaled->byId("curve-0")->attr("stroke-dasharray"), svgEdgeStyle(EdgeAssignment::Mountain).dasharray);
  const auto reference = parseXml(svgFoldPattern(sheet()));  // 40 mm wide
  EXPECT_EQ(reference->byId("curve-0")->attr("stroke-dasharray"), svgEdgeStyle(EdgeAssignment::Mountain).dasharray);
  off.styleReferenceMm = -1.0;
  EXPECT_THROW(svgFoldPattern(small, off), std::invalid_argument);
}

TEST(SvgFoldPattern, EdgeChainsBreakAtBranchesAndCloseLoops) {
  CreasePattern p;
  p.vertices2d.resize(5, 2);
  p.vertices2d << 0, 0, 1, 0, 2, 0, 1, 1, 1, -1;
  using A = EdgeAssignment;
  // A "+" of mountain edges meeting at vertex 1, plus a valley triangle loop 0-3-2.
  p.edges = {{0, 1, A::Mountain, std::nullopt, 0}, {1, 2, A::Mountain, std::nullopt, 0},
             {1, 3, A::Mountain, std::nullopt, 0}, {4, 1, A::Mountain, std::nullopt, 0},
             {3, 2, A::Valley, std::nullopt, 1},   {2, 4, A::Valley, std::nullopt, 1},
             {4, 3, A::Valley, std::nullopt, 1}};
  const auto chains = edgeChains(p);
  ASSERT_EQ(chains.size(), 5u);
  for (int k = 0; k < 4; ++k) {
    EXPECT_EQ(chains[k].assignment, A::Mountain);
    EXPECT_EQ(chains[k].edges.size(), 1u);
    EXPECT_FALSE(chains[k].closed);
  }
  EXPECT_EQ(chains[4].assignment, A::Valley);
  EXPECT_TRUE(chains[4].closed);
  EXPECT_EQ(chains[4].vertices, (std::vector<int>{3, 2, 4}));
  EXPECT_EQ(chains[4].edges, (std::vector<int>{4, 5, 6}));

  // The sheet's mountain edges, listed out of order, chain into one polyline 5-6-7-8-2.
  for (const EdgeChain& c : edgeChains(sheet()))
    if (c.assignment == A::Mountain) {
      EXPECT_EQ(c.vertices, (std::vector<int>{5, 6, 7, 8, 2}));
    }
}

TEST(SvgFoldPattern, WritesFiles) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("devsurf_svg_" + std::to_string(::getpid()) + ".svg"))
                               .string();
  writeSvgFoldPattern(sheet(), path);
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), svgFoldPattern(sheet()));
  std::remove(path.c_str());
  EXPECT_THROW(writeSvgFoldPattern(sheet(), "/nonexistent-dir/x.svg"), std::runtime_error);
}

}  // namespace
}  // namespace devsurf::io
