#include "devsurf/io/SvgImport.h"

#include "devsurf/io/SvgPathData.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <limits>
#include <sstream>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

#include <pugixml.hpp>


namespace devsurf::io {

namespace {

using svg::Affine;
using svg::applyAffine;
using svg::compose;
using svg::identityAffine;
using svg::parsePathData;
using svg::parseTransform;
using svg::sampleArc;
using svg::Piece;
using svg::Subpath;
using svg::kPi;
using svg::numbersOf;
using svg::refuseSvg;

constexpr double kMmPerPx = 25.4 / 96.0;
constexpr double kCornerTurnDeg = 10.0;  ///< a path turning more than this starts a new stroke…
/// …unless it turns by at most this much and a neighbouring join turns the same way by at least a
/// third as much: a sampled curve bending hard (a development's outline near its ends, drawn as a
/// polyline by devsurf's own export, turns by 18°, 16°, 8° over its first three points), not a
/// corner between straight lines (a lone turn, or a zigzag's turns of alternating sign).
constexpr double kSampledCurveTurnDeg = 25.0;
/// …and only in a path of at least this many pieces, and, when it is closed, at most a quarter of
/// whose joins turn so hard (a 16-sided polygon turns 22.5° at every join: its corners stay).
constexpr std::size_t kSampledCurvePieces = 8;
constexpr int kMaxNesting = 64;          ///< groups deeper than this are refused (the reader recurses)


std::string trimmed(const std::string& s) {
  std::size_t b = 0, e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return s.substr(b, e - b);
}

std::string lowered(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

/// "a: b; c: d" → {a: b, c: d} (names lower-cased).
std::map<std::string, std::string> cssDeclarations(const std::string& text) {
  std::map<std::string, std::string> out;
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find(';', start);
    if (end == std::string::npos) end = text.size();
    const std::string decl = text.substr(start, end - start);
    const std::size_t colon = decl.find(':');
    if (colon != std::string::npos) {
      std::string value = trimmed(decl.substr(colon + 1));
      if (const std::size_t bang = value.find("!important"); bang != std::string::npos) value = trimmed(value.substr(0, bang));
      out[lowered(trimmed(decl.substr(0, colon)))] = value;
    }
    start = end + 1;
  }
  return out;
}

/// Id, class and type rules of the document's <style> elements (simple selectors only: ".a",
/// "path", "path.a", "#a", "path#a" and comma lists of them), applied by specificity (id over class
/// over type), then in document order.
struct StyleSheet {
  struct Rule {
    std::string tag;        ///< empty = any
    std::string className;  ///< empty = any
    std::string id;         ///< empty = any
    std::map<std::string, std::string> declarations;
    int specificity() const { return (id.empty() ? 0 : 100) + (className.empty() ? 0 : 10) + (tag.empty() ? 0 : 1); }
  };
  std::vector<Rule> rules;

  void add(std::string css) {
    for (std::size_t c = css.find("/*"); c != std::string::npos; c = css.find("/*")) {
      const std::size_t e = css.find("*/", c + 2);
      css.erase(c, e == std::string::npos ? std::string::npos : e + 2 - c);
    }
    std::size_t pos = 0;
    while (true) {
      const std::size_t open = css.find('{', pos);
      if (open == std::string::npos) break;
      const std::size_t close = css.find('}', open);
      if (close == std::string::npos) break;
      const auto declarations = cssDeclarations(css.substr(open + 1, close - open - 1));
      std::string selectors = css.substr(pos, open - pos);
      std::size_t s = 0;
      while (s <= selectors.size()) {
        std::size_t comma = selectors.find(',', s);
        if (comma == std::string::npos) comma = selectors.size();
        const std::string selector = trimmed(selectors.substr(s, comma - s));
        s = comma + 1;
        if (selector.empty() || selector.find_first_of(" >+~[:*") != std::string::npos) continue;
        Rule rule;
        const std::size_t mark = selector.find_first_of(".#");
        rule.tag = lowered(selector.substr(0, mark));
        if (mark != std::string::npos) {
          const std::string rest = selector.substr(mark + 1);
          if (rest.find_first_of(".#") != std::string::npos) continue;  // compound: not read
          (selector[mark] == '.' ? rule.className : rule.id) = rest;
        }
        rule.declarations = declarations;
        rules.push_back(std::move(rule));
      }
      pos = close + 1;
    }
  }

  /// Declarations for an element: rules in order, later ones winning.
  void apply(const std::string& tag, const std::string& classAttribute, const std::string& id,
             std::map<std::string, std::string>& into) const {
    std::set<std::string> classes;
    std::size_t s = 0;
    while (s < classAttribute.size()) {
      while (s < classAttribute.size() && std::isspace(static_cast<unsigned char>(classAttribute[s]))) ++s;
      std::size_t e = s;
      while (e < classAttribute.size() && !std::isspace(static_cast<unsigned char>(classAttribute[e]))) ++e;
      if (e > s) classes.insert(classAttribute.substr(s, e - s));
      s = e;
    }
    std::vector<const Rule*> matching;
    for (const Rule& r : rules) {
      if (!r.tag.empty() && r.tag != tag) continue;
      if (!r.className.empty() && !classes.count(r.className)) continue;
      if (!r.id.empty() && r.id != id) continue;
      matching.push_back(&r);
    }
    std::stable_sort(matching.begin(), matching.end(),
                     [](const Rule* a, const Rule* b) { return a->specificity() < b->specificity(); });
    for (const Rule* r : matching)
      for (const auto& [k, v] : r->declarations) into[k] = v;
  }
};

/// A length in millimetres ("210mm", "8.5in", "600" = px); nullopt for percentages or nonsense.
std::optional<double> lengthMm(const std::string& text) {
  const std::string t = trimmed(text);
  if (t.empty()) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(t.c_str(), &end);
  if (end == t.c_str() || !std::isfinite(v) || v <= 0.0) return std::nullopt;
  const std::string unit = lowered(trimmed(std::string(end)));
  if (unit.empty() || unit == "px") return v * kMmPerPx;
  if (unit == "mm") return v;
  if (unit == "cm") return v * 10.0;
  if (unit == "in") return v * 25.4;
  if (unit == "pt") return v * 25.4 / 72.0;
  if (unit == "pc") return v * 25.4 / 6.0;
  if (unit == "m") return v * 1000.0;
  return std::nullopt;
}

/// Origami Simulator's colours. nullopt: not a crease colour.
/// The alpha of a colour with one (#rgba, #rrggbbaa, rgba(r, g, b, a)), else 1: it multiplies the
/// stroke's opacity, which is the fold angle.
double alphaOfColour(const std::string& raw) {
  const std::string c = lowered(trimmed(raw));
  double alpha = 1.0;
  if (c.size() == 5 && c[0] == '#') alpha = static_cast<double>(std::strtol(std::string(2, c[4]).c_str(), nullptr, 16)) / 255.0;
  if (c.size() == 9 && c[0] == '#') alpha = static_cast<double>(std::strtol(c.substr(7, 2).c_str(), nullptr, 16)) / 255.0;
  if (c.rfind("rgba(", 0) == 0 && c.back() == ')') {
    const std::size_t comma = c.rfind(',');
    if (comma != std::string::npos) {
      const std::string part = trimmed(c.substr(comma + 1, c.size() - comma - 2));
      alpha = std::strtod(part.c_str(), nullptr);
      if (!part.empty() && part.back() == '%') alpha /= 100.0;
    }
  }
  return std::isfinite(alpha) ? std::clamp(alpha, 0.0, 1.0) : 1.0;
}

std::optional<EdgeAssignment> assignmentOfColour(const std::string& raw) {
  std::string c = lowered(trimmed(raw));
  // With an alpha (read by alphaOfColour): the colour without it.
  if (c.size() == 5 && c[0] == '#') c = c.substr(0, 4);
  if (c.size() == 9 && c[0] == '#') c = c.substr(0, 7);
  if (c.rfind("rgba(", 0) == 0 && c.back() == ')') c = "rgb(" + c.substr(5, c.rfind(',') - 5) + ")";
  static const std::map<std::string, EdgeAssignment> named{
      {"black", EdgeAssignment::Boundary}, {"red", EdgeAssignment::Mountain},  {"blue", EdgeAssignment::Valley},
      {"green", EdgeAssignment::Cut},      {"lime", EdgeAssignment::Cut},      {"yellow", EdgeAssignment::Flat},
      {"magenta", EdgeAssignment::Flat},   {"fuchsia", EdgeAssignment::Flat}};
  if (const auto it = named.find(c); it != named.end()) return it->second;
  std::array<double, 3> rgb{};
  if (c.size() == 4 && c[0] == '#') {
    for (int k = 0; k < 3; ++k) {
      const std::string h(2, c[1 + k]);
      rgb[k] = static_cast<double>(std::strtol(h.c_str(), nullptr, 16));
    }
  } else if (c.size() == 7 && c[0] == '#') {
    for (int k = 0; k < 3; ++k) rgb[k] = static_cast<double>(std::strtol(c.substr(1 + 2 * k, 2).c_str(), nullptr, 16));
  } else if (c.rfind("rgb(", 0) == 0 && c.back() == ')') {
    std::string inside = c.substr(4, c.size() - 5);
    for (int k = 0; k < 3; ++k) {
      const std::size_t comma = inside.find(',');
      const std::string part = trimmed(inside.substr(0, comma));
      double v = std::strtod(part.c_str(), nullptr);
      if (!part.empty() && part.back() == '%') v *= 2.55;
      rgb[k] = v;
      if (comma == std::string::npos) {
        if (k < 2) return std::nullopt;
        break;
      }
      inside = inside.substr(comma + 1);
    }
  } else {
    return std::nullopt;
  }
  static const std::array<std::pair<std::array<double, 3>, EdgeAssignment>, 6> references{{
      {{0, 0, 0}, EdgeAssignment::Boundary},
      {{255, 0, 0}, EdgeAssignment::Mountain},
      {{0, 0, 255}, EdgeAssignment::Valley},
      {{0, 255, 0}, EdgeAssignment::Cut},
      {{255, 255, 0}, EdgeAssignment::Flat},
      {{255, 0, 255}, EdgeAssignment::Flat},
  }};
  double best = 1e300;
  std::optional<EdgeAssignment> result;
  for (const auto& [ref, a] : references) {
    const double d = std::hypot(rgb[0] - ref[0], rgb[1] - ref[1], rgb[2] - ref[2]);
    if (d < best) {
      best = d;
      result = a;
    }
  }
  return best <= 100.0 ? result : std::nullopt;
}

Eigen::Vector2d startTangent(const std::vector<Eigen::Vector2d>& p) {
  for (std::size_t k = 1; k < p.size(); ++k)
    if ((p[k] - p[0]).norm() > 0.0) return (p[k] - p[0]).normalized();
  return Eigen::Vector2d::Zero();
}
Eigen::Vector2d endTangent(const std::vector<Eigen::Vector2d>& p) {
  for (std::size_t k = p.size() - 1; k-- > 0;)
    if ((p.back() - p[k]).norm() > 0.0) return (p.back() - p[k]).normalized();
  return Eigen::Vector2d::Zero();
}

struct Reader {
  const SvgImportOptions& options;
  StyleSheet sheet;
  SvgImport& result;
  std::vector<CreaseStroke> strokes;
  std::map<std::string, int> tagCount;
  std::set<std::string> reportedColours;

  struct Inherited {
    Affine ctm = identityAffine();
    std::optional<std::string> stroke;
    std::optional<std::string> color;  // the `color` property, what currentColor names
    double opacity = 1.0;
    double strokeOpacity = 1.0;
    bool hidden = false;
  };

  void visit(const pugi::xml_node& node, Inherited inherited, int depth = 0) {
    if (depth > kMaxNesting) refuseSvg("groups nested more than " + std::to_string(kMaxNesting) + " deep");
    for (const pugi::xml_node& child : node.children()) {
      if (child.type() != pugi::node_element) continue;
      const std::string tag = child.name();
      if (tag.find(':') != std::string::npos) continue;  // editor metadata (sodipodi:, inkscape:)
      const std::string id = child.attribute("id").value();
      const int index = tagCount[tag]++;
      const std::string element = id.empty() ? tag + "[" + std::to_string(index) + "]" : tag + "#" + id;
      static const std::set<std::string> quiet{"defs", "metadata", "title", "desc", "style", "symbol", "clipPath",
                                               "mask", "marker", "pattern", "linearGradient", "radialGradient", "filter"};
      if (quiet.count(tag)) continue;
      if (tag == "use" || tag == "text" || tag == "image" || tag == "foreignObject") {
        result.notes.push_back({element, "<" + tag + "> is not read; left out"});
        continue;
      }
      std::map<std::string, std::string> props;
      for (const char* name : {"stroke", "color", "opacity", "stroke-opacity", "display", "visibility", "transform"})
        if (const pugi::xml_attribute a = child.attribute(name)) props[name] = a.value();
      sheet.apply(tag, child.attribute("class").value(), id, props);
      for (const auto& [k, v] : cssDeclarations(child.attribute("style").value())) props[k] = v;
      Inherited here = inherited;
      if (props.count("transform")) here.ctm = compose(inherited.ctm, parseTransform(props["transform"], element));
      if (props.count("color")) here.color = props["color"];
      if (props.count("stroke")) {
        // currentColor: the element's (inherited) color, as a viewer draws it.
        here.stroke = lowered(trimmed(props["stroke"])) == "currentcolor" ? (here.color ? here.color : std::optional<std::string>("black"))
                                                                           : std::optional<std::string>(props["stroke"]);
      }
      const auto fraction = [&props](const char* name) {
        if (!props.count(name)) return 1.0;
        const std::string v = trimmed(props[name]);
        double x = std::strtod(v.c_str(), nullptr);
        if (!v.empty() && v.back() == '%') x /= 100.0;
        return std::isfinite(x) ? std::clamp(x, 0.0, 1.0) : 1.0;
      };
      here.opacity *= fraction("opacity");
      if (props.count("stroke-opacity")) here.strokeOpacity = fraction("stroke-opacity");
      if (props.count("visibility")) here.hidden = trimmed(props["visibility"]) == "hidden";
      if (props.count("display") && trimmed(props["display"]) == "none") {
        result.notes.push_back({element, "hidden (display: none); left out"});
        continue;
      }
      if (tag == "g" && id == "legend") {
        // The key that devsurf's own fold patterns draw in their margin (line samples in the
        // crease colours): not creases.
        result.notes.push_back({element, "a legend (g#legend); left out"});
        continue;
      }
      if (tag == "g" && id == "rulings") {
        // The rulings devsurf's fold patterns draw (thin grey lines, no crease colour): the import
        // proposes its own.
        result.notes.push_back({element, "rulings (g#rulings); left out: the import lays out its own"});
        continue;
      }
      if (tag == "g" || tag == "svg" || tag == "a") {
        visit(child, here, depth + 1);
        continue;
      }
      std::vector<Subpath> geometry = shapeOf(child, tag, element);
      if (geometry.empty()) continue;
      if (here.hidden) {
        result.notes.push_back({element, "hidden (visibility: hidden); left out"});
        continue;
      }
      if (!here.stroke || lowered(trimmed(*here.stroke)) == "none") {
        result.notes.push_back({element, "has no stroke colour; left out (a crease pattern is drawn with strokes)"});
        continue;
      }
      const auto assignment = assignmentOfColour(*here.stroke);
      if (!assignment) {
        if (reportedColours.insert(lowered(trimmed(*here.stroke))).second)
          result.notes.push_back({element, "stroke " + trimmed(*here.stroke) +
                                               " is none of the crease colours (black boundary, red mountain, blue "
                                               "valley, green cut, yellow or magenta flat); such strokes are left out"});
        continue;
      }
      const double amount = here.opacity * here.strokeOpacity * alphaOfColour(*here.stroke);
      std::optional<double> angle;
      if (*assignment == EdgeAssignment::Mountain) angle = -180.0 * amount;
      if (*assignment == EdgeAssignment::Valley) angle = 180.0 * amount;
      // devsurf's own fold patterns write the angle itself (their strokes stay opaque to print);
      // the colour says mountain or valley.
      if (angle) {
        if (const pugi::xml_attribute written = child.attribute("data-fold-angle")) {
          const double degrees = std::strtod(written.value(), nullptr);
          if (std::isfinite(degrees) && std::abs(degrees) <= 180.0) angle = std::copysign(std::abs(degrees), *angle);
        }
      }
      for (Subpath& sub : geometry) {
        for (Piece& piece : sub.pieces)
          for (Eigen::Vector2d& p : piece.points) p = applyAffine(here.ctm, p);
        addStrokes(sub, *assignment, angle, element);
      }
    }
  }

  std::vector<Subpath> shapeOf(const pugi::xml_node& node, const std::string& tag, const std::string& element) {
    const auto attr = [&node, &element](const char* name, bool required) {
      const pugi::xml_attribute a = node.attribute(name);
      if (!a) {
        if (required) refuseSvg(element + ": " + name + " is missing");
        return 0.0;
      }
      char* end = nullptr;
      const double v = std::strtod(a.value(), &end);
      if (end == a.value() || !std::isfinite(v)) refuseSvg(element + ": " + name + " is not a number");
      return v;
    };
    const auto segment = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return Piece{{a, b}, false}; };
    if (tag == "line") {
      Subpath s;
      s.pieces.push_back(segment({attr("x1", false), attr("y1", false)}, {attr("x2", false), attr("y2", false)}));
      return {s};
    }
    if (tag == "polyline" || tag == "polygon") {
      const std::vector<double> v = numbersOf(node.attribute("points").value(), element, "points");
      if (v.size() % 2 != 0) refuseSvg(element + ": points has an odd count of numbers");
      Subpath s;
      for (std::size_t k = 2; k + 1 < v.size(); k += 2) s.pieces.push_back(segment({v[k - 2], v[k - 1]}, {v[k], v[k + 1]}));
      if (tag == "polygon" && v.size() >= 6) {
        s.pieces.push_back(segment({v[v.size() - 2], v.back()}, {v[0], v[1]}));
        s.closed = true;
      }
      return {s};
    }
    if (tag == "rect") {
      const double x = attr("x", false), y = attr("y", false), w = attr("width", true), h = attr("height", true);
      if (w <= 0 || h <= 0) return {};
      if (attr("rx", false) > 0 || attr("ry", false) > 0)
        result.notes.push_back({element, "rounded corners (rx, ry) read as sharp corners"});
      Subpath s;
      const Eigen::Vector2d a(x, y), b(x + w, y), c(x + w, y + h), d(x, y + h);
      s.pieces = {segment(a, b), segment(b, c), segment(c, d), segment(d, a)};
      s.closed = true;
      return {s};
    }
    if (tag == "circle" || tag == "ellipse") {
      const double cx = attr("cx", false), cy = attr("cy", false);
      const double rx = tag == "circle" ? attr("r", true) : attr("rx", true);
      const double ry = tag == "circle" ? rx : attr("ry", true);
      if (rx <= 0 || ry <= 0) return {};
      Subpath s;
      const Eigen::Vector2d p0(cx + rx, cy), p1(cx - rx, cy);
      Piece upper, lower;
      sampleArc(p0, p1, rx, ry, 0, 0, 1, options.samplesPerCurve, upper);
      sampleArc(p1, p0, rx, ry, 0, 0, 1, options.samplesPerCurve, lower);
      s.pieces = {upper, lower};
      s.closed = true;
      return {s};
    }
    if (tag == "path") return parsePathData(node.attribute("d").value(), element, options.samplesPerCurve);
    result.notes.push_back({element, "<" + tag + "> is not a shape devsurf reads; left out"});
    return {};
  }

  /// Splits a subpath at its corners into strokes.
  void addStrokes(const Subpath& sub, EdgeAssignment assignment, std::optional<double> angle, const std::string& element) {
    // Pieces of no length (a repeated point, an L to where the path is) have no direction: left
    // out, so the turn across them is measured between their neighbours (a corner stays one).
    const auto hasLength = [](const Piece& piece) {
      return std::any_of(piece.points.begin(), piece.points.end(), [&piece](const Eigen::Vector2d& p) { return p != piece.points.front(); });
    };
    const bool anyLength = std::any_of(sub.pieces.begin(), sub.pieces.end(), hasLength);
    std::vector<const Piece*> pieces;
    for (const Piece& piece : sub.pieces)
      if (piece.points.size() >= 2 && (!anyLength || hasLength(piece))) pieces.push_back(&piece);
    // Signed turn (degrees) from one piece to the next.
    const auto turnBetween = [](const Piece& from, const Piece& to) {
      const Eigen::Vector2d a = endTangent(from.points), b = startTangent(to.points);
      return std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b)) * 180.0 / kPi;
    };
    std::vector<double> turns(pieces.size(), 0.0);  // turns[k]: at the join before pieces[k], k ≥ 1
    for (std::size_t k = 1; k < pieces.size(); ++k) turns[k] = turnBetween(*pieces[k - 1], *pieces[k]);
    // A sampled curve (many pieces, most joins gentle) may bend hard at a few joins; a polygon or a
    // polyline of a few straight lines turns at every join and keeps its corners.
    std::size_t hardJoins = 0;
    for (std::size_t k = 1; k < pieces.size(); ++k)
      hardJoins += std::abs(turns[k]) > kCornerTurnDeg && std::abs(turns[k]) <= kSampledCurveTurnDeg;
    // A closed path turning hard at most joins is a polygon (a 16-gon turns 22.5° at each); an
    // open one of enough pieces is a sampled curve (a 90° arc in 8 pieces turns 11.25° at each).
    const bool sampledCurve = pieces.size() >= kSampledCurvePieces && (!sub.closed || 4 * hardJoins <= pieces.size() - 1);
    const auto smoothTurn = [sampledCurve](double t, std::optional<double> before, std::optional<double> after) {
      if (std::abs(t) <= kCornerTurnDeg) return true;
      if (!sampledCurve || std::abs(t) > kSampledCurveTurnDeg) return false;
      const auto alike = [t](std::optional<double> u) {
        return u && *u * t > 0.0 && std::abs(*u) >= std::abs(t) / 3.0 && std::abs(*u) <= kSampledCurveTurnDeg;
      };
      return alike(before) || alike(after);
    };
    const auto smoothAt = [&turns, &pieces, &smoothTurn](std::size_t k) {
      return smoothTurn(turns[k], k >= 2 ? std::optional<double>(turns[k - 1]) : std::nullopt,
                        k + 1 < pieces.size() ? std::optional<double>(turns[k + 1]) : std::nullopt);
    };
    std::vector<std::vector<Eigen::Vector2d>> runs;
    for (std::size_t k = 0; k < pieces.size(); ++k) {
      const Piece& piece = *pieces[k];
      if (!runs.empty() && smoothAt(k)) {
        runs.back().insert(runs.back().end(), piece.points.begin() + 1, piece.points.end());
      } else {
        runs.push_back(piece.points);
      }
    }
    if (runs.empty()) return;
    bool closedLoop = false;
    const auto closingSmooth = [&]() {
      const double t = turnBetween(*pieces.back(), *pieces.front());
      return smoothTurn(t, pieces.size() >= 2 ? std::optional<double>(turns.back()) : std::nullopt,
                        pieces.size() >= 2 ? std::optional<double>(turns[1]) : std::nullopt);
    };
    if (sub.closed && (runs.back().back() - runs.front().front()).norm() == 0.0 && closingSmooth()) {
      if (runs.size() == 1) {
        closedLoop = true;
      } else {
        runs.back().insert(runs.back().end(), runs.front().begin() + 1, runs.front().end());
        runs.front() = std::move(runs.back());
        runs.pop_back();
      }
    }
    for (auto& run : runs) {
      CreaseStroke s;
      s.points = std::move(run);
      s.closed = closedLoop;
      if (s.closed) s.points.pop_back();  // the first point again
      s.assignment = assignment;
      s.foldAngle = angle;
      s.element = element;
      strokes.push_back(std::move(s));
    }
  }
};

}  // namespace

SvgImport importSvgText(const std::string& text, const SvgImportOptions& options) {
  pugi::xml_document doc;
  const pugi::xml_parse_result parsed = doc.load_buffer(text.data(), text.size());
  if (!parsed) refuseSvg(std::string("not XML: ") + parsed.description() + " at byte " + std::to_string(parsed.offset));
  const pugi::xml_node root = doc.document_element();
  if (std::string(root.name()) != "svg") refuseSvg(std::string("the root element is <") + root.name() + ">, not <svg>");

  // devsurf's cutting pattern of a covering (pieces to cut out and glue edge to edge): its glue
  // lines are blue, and read as a crease pattern it became 700 valleys with free ends.
  if (doc.select_node("//*[local-name()='g'][@id='cuts']") && doc.select_node("//*[local-name()='g'][@id='glue']"))
    refuseSvg("a cutting pattern (pieces to cut out, g#cuts, and glue lines, g#glue), not a crease pattern: its pieces "
              "are glued, not folded; open the scene it was exported from instead");
  SvgImport result;
  Reader reader{options, {}, result, {}, {}, {}};
  for (const pugi::xpath_node& style : doc.select_nodes("//*[local-name()='style']"))
    reader.sheet.add(style.node().child_value());

  // Units: user units → millimetres.
  std::vector<double> viewBox;
  if (const pugi::xml_attribute vb = root.attribute("viewBox")) {
    viewBox = numbersOf(vb.value(), "svg", "viewBox");
    if (viewBox.size() != 4 || viewBox[2] <= 0 || viewBox[3] <= 0) {
      result.notes.push_back({"svg", "viewBox \"" + std::string(vb.value()) + "\" is not four numbers with a positive size; ignored"});
      viewBox.clear();
    }
  }
  const std::optional<double> widthMm = lengthMm(root.attribute("width").value());
  const std::optional<double> heightMm = lengthMm(root.attribute("height").value());
  double sx = kMmPerPx, sy = kMmPerPx;
  double shiftX = 0.0, shiftY = 0.0;  // where the viewBox lands in the page (millimetres, y up)
  if (!viewBox.empty()) {
    if (widthMm) sx = *widthMm / viewBox[2];
    if (heightMm) sy = *heightMm / viewBox[3];
    if (widthMm && !heightMm) sy = sx;
    if (heightMm && !widthMm) sx = sy;
    if (!widthMm && !heightMm)
      result.notes.push_back({"svg", "no width or height: one user unit is read as one px (1/96 in)"});
    if (std::abs(sx - sy) > 1e-9 * std::max(sx, sy)) {
      // A page whose shape differs from the viewBox's: preserveAspectRatio says how a viewer fits
      // it — by default ("xMidYMid meet") uniformly, the smaller scale, centred; "none" stretches.
      std::istringstream aspect(root.attribute("preserveAspectRatio").as_string("xMidYMid meet"));
      std::string align = "xMidYMid", fit = "meet";
      aspect >> align >> fit;
      if (align == "none") {
        result.notes.push_back({"svg", "preserveAspectRatio=\"none\": the drawing is stretched to the page, as a viewer shows it"});
      } else {
        const double scale = fit == "slice" ? std::max(sx, sy) : std::min(sx, sy);
        auto fraction = [&align](const char* axis) {  // where the viewBox sits along the axis: 0, ½ or 1
          if (align.find(std::string(axis) + "Min") != std::string::npos) return 0.0;
          if (align.find(std::string(axis) + "Max") != std::string::npos) return 1.0;
          return 0.5;
        };
        shiftX = (viewBox[2] * sx - viewBox[2] * scale) * fraction("x");
        shiftY = (viewBox[3] * sy - viewBox[3] * scale) * (1.0 - fraction("Y"));  // y up: the bottom margin
        sx = sy = scale;
        result.notes.push_back({"svg", "the page's shape differs from the viewBox's: the drawing is scaled uniformly "
                                       "and placed as preserveAspectRatio says, as a viewer shows it"});
      }
    }
  }

  Reader::Inherited top;
  reader.visit(doc, top);
  std::vector<CreaseStroke>& strokes = reader.strokes;
  if (strokes.empty()) refuseSvg("no strokes in a crease colour (black, red, blue, green, yellow, magenta)");

  // Millimetres, y up, the page's bottom left corner at the origin. Without a viewBox the page is
  // the width and height in px from (0, 0) (without a height, the drawing's own lowest point).
  double originY = 0.0;
  if (!viewBox.empty()) {
    originY = viewBox[1] + viewBox[3];
  } else if (heightMm) {
    originY = *heightMm / kMmPerPx;
  } else {
    originY = -std::numeric_limits<double>::infinity();
    for (const CreaseStroke& s : strokes)
      for (const Eigen::Vector2d& p : s.points) originY = std::max(originY, p.y());
  }
  const double originX = !viewBox.empty() ? viewBox[0] : 0.0;
  for (CreaseStroke& s : strokes)
    for (Eigen::Vector2d& p : s.points)
      p = Eigen::Vector2d((p.x() - originX) * sx + shiftX, (originY - p.y()) * sy + shiftY);

  // Hand-drawn ends that stop short of the stroke they are meant to meet (or run a little past
  // it) meet it, within 1 % of the drawing's diagonal as the editor's drawing tool snaps — in the
  // kept drawing too, so layout edits rebuild the same pattern.
  for (ImportNote& note : absorbEndJogs(strokes, options.snapFraction)) result.notes.push_back(std::move(note));
  for (ImportNote& note : snapNearlyMeetingEnds(strokes, options.mergeFraction, options.snapFraction))
    result.notes.push_back(std::move(note));
  for (ImportNote& note : splitIntoStraightRuns(strokes, options.mergeFraction)) result.notes.push_back(std::move(note));
  CreaseStrokesOptions strokeOptions;
  strokeOptions.straightPieces = options.straightPieces;
  strokeOptions.maxSegments = options.maxSegments;
  strokeOptions.mergeFraction = options.mergeFraction;
  StrokePattern made = creasePatternFromStrokes(strokes, strokeOptions);
  for (std::size_t i = 0; i < strokes.size(); ++i) strokes[i].curved = made.strokeCurved[i];
  result.drawing = std::move(strokes);
  result.pattern = std::move(made.pattern);
  result.sizeStated = widthMm.has_value() || heightMm.has_value();
  result.mmPerUserUnit = sx;
  if (const pugi::xml_node title = root.child("title")) result.pattern.title = trimmed(title.child_value());
  result.notes.insert(result.notes.end(), made.notes.begin(), made.notes.end());
  result.strokes = made.strokes;
  result.curvedStrokes = made.curvedStrokes;
  return result;
}

}  // namespace devsurf::io
