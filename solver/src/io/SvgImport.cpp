#include "devsurf/io/SvgImport.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>

#include <pugixml.hpp>

#include "devsurf/spatial/PlanarArrangement.h"

namespace devsurf::io {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kMmPerPx = 25.4 / 96.0;
constexpr double kCornerTurnDeg = 10.0;  ///< a path turning more than this starts a new stroke
constexpr int kMaxNesting = 64;          ///< groups deeper than this are refused (the reader recurses)

[[noreturn]] void refuseSvg(const std::string& message) { throw std::invalid_argument("SVG: " + message); }

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

/// Class and type rules of the document's <style> elements (simple selectors only: ".a", "path",
/// "path.a" and comma lists of them), in document order.
struct StyleSheet {
  struct Rule {
    std::string tag;        ///< empty = any
    std::string className;  ///< empty = any
    std::map<std::string, std::string> declarations;
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
        if (selector.empty() || selector.find_first_of(" >+~[:#*") != std::string::npos) continue;
        Rule rule;
        const std::size_t dot = selector.find('.');
        rule.tag = lowered(selector.substr(0, dot));
        if (dot != std::string::npos) rule.className = selector.substr(dot + 1);
        rule.declarations = declarations;
        rules.push_back(std::move(rule));
      }
      pos = close + 1;
    }
  }

  /// Declarations for an element: rules in order, later ones winning.
  void apply(const std::string& tag, const std::string& classAttribute, std::map<std::string, std::string>& into) const {
    std::set<std::string> classes;
    std::size_t s = 0;
    while (s < classAttribute.size()) {
      while (s < classAttribute.size() && std::isspace(static_cast<unsigned char>(classAttribute[s]))) ++s;
      std::size_t e = s;
      while (e < classAttribute.size() && !std::isspace(static_cast<unsigned char>(classAttribute[e]))) ++e;
      if (e > s) classes.insert(classAttribute.substr(s, e - s));
      s = e;
    }
    for (const Rule& r : rules) {
      if (!r.tag.empty() && r.tag != tag) continue;
      if (!r.className.empty() && !classes.count(r.className)) continue;
      for (const auto& [k, v] : r.declarations) into[k] = v;
    }
  }
};

/// 2D affine map [a c e; b d f].
using Affine = Eigen::Matrix<double, 2, 3>;

Affine identityAffine() {
  Affine m;
  m << 1, 0, 0, 0, 1, 0;
  return m;
}

Affine compose(const Affine& outer, const Affine& inner) {
  Affine r;
  r.leftCols<2>() = outer.leftCols<2>() * inner.leftCols<2>();
  r.col(2) = outer.leftCols<2>() * inner.col(2) + outer.col(2);
  return r;
}

Eigen::Vector2d applyAffine(const Affine& m, const Eigen::Vector2d& p) { return m.leftCols<2>() * p + m.col(2); }

/// Reads the numbers of SVG attribute values: separators are white space and commas; "1.5.5"
/// is 1.5 and .5, "1-2" is 1 and −2.
class NumberScanner {
 public:
  explicit NumberScanner(const std::string& text) : s_(text) {}

  void skipSeparators() {
    while (i_ < s_.size() && (std::isspace(static_cast<unsigned char>(s_[i_])) || s_[i_] == ',')) ++i_;
  }
  bool atEnd() {
    skipSeparators();
    return i_ >= s_.size();
  }
  bool startsNumber() {
    skipSeparators();
    if (i_ >= s_.size()) return false;
    const char c = s_[i_];
    return std::isdigit(static_cast<unsigned char>(c)) || c == '-' || c == '+' || c == '.';
  }
  std::optional<double> number() {
    skipSeparators();
    const std::size_t begin = i_;
    if (i_ < s_.size() && (s_[i_] == '-' || s_[i_] == '+')) ++i_;
    bool digits = false, dot = false;
    while (i_ < s_.size()) {
      const char c = s_[i_];
      if (std::isdigit(static_cast<unsigned char>(c))) {
        digits = true;
      } else if (c == '.' && !dot) {
        dot = true;
      } else {
        break;
      }
      ++i_;
    }
    if (!digits) {
      i_ = begin;
      return std::nullopt;
    }
    if (i_ < s_.size() && (s_[i_] == 'e' || s_[i_] == 'E')) {
      std::size_t j = i_ + 1;
      if (j < s_.size() && (s_[j] == '-' || s_[j] == '+')) ++j;
      if (j < s_.size() && std::isdigit(static_cast<unsigned char>(s_[j]))) {
        while (j < s_.size() && std::isdigit(static_cast<unsigned char>(s_[j]))) ++j;
        i_ = j;
      }
    }
    const double v = std::strtod(s_.substr(begin, i_ - begin).c_str(), nullptr);
    if (!std::isfinite(v)) return std::nullopt;
    return v;
  }
  /// An arc flag: a single 0 or 1, separators optional ("a1 1 0 011 1").
  std::optional<int> flag() {
    skipSeparators();
    if (i_ < s_.size() && (s_[i_] == '0' || s_[i_] == '1')) return s_[i_++] - '0';
    return std::nullopt;
  }
  std::optional<char> command() {
    skipSeparators();
    if (i_ < s_.size() && std::isalpha(static_cast<unsigned char>(s_[i_]))) return s_[i_++];
    return std::nullopt;
  }
  std::size_t position() const { return i_; }

 private:
  const std::string& s_;
  std::size_t i_ = 0;
};

/// The transform attribute: a list of matrix, translate, scale, rotate, skewX, skewY.
Affine parseTransform(const std::string& text, const std::string& element) {
  Affine total = identityAffine();
  std::size_t pos = 0;
  while (true) {
    while (pos < text.size() && (std::isspace(static_cast<unsigned char>(text[pos])) || text[pos] == ',')) ++pos;
    if (pos >= text.size()) break;
    const std::size_t open = text.find('(', pos), close = text.find(')', pos);
    if (open == std::string::npos || close == std::string::npos || close < open)
      refuseSvg(element + ": transform \"" + text + "\" is not a transform list");
    const std::string name = trimmed(text.substr(pos, open - pos));
    const std::string inside = text.substr(open + 1, close - open - 1);
    NumberScanner scan(inside);
    std::vector<double> v;
    while (!scan.atEnd()) {
      const auto x = scan.number();
      if (!x) refuseSvg(element + ": transform " + name + "(" + inside + ") has something other than numbers");
      v.push_back(*x);
    }
    Affine m = identityAffine();
    const auto need = [&element, &name, &v](std::size_t a, std::size_t b) {
      if (v.size() < a || v.size() > b)
        refuseSvg(element + ": transform " + name + " takes " + std::to_string(a) +
                  (a == b ? "" : "–" + std::to_string(b)) + " numbers, got " + std::to_string(v.size()));
    };
    if (name == "matrix") {
      need(6, 6);
      m << v[0], v[2], v[4], v[1], v[3], v[5];
    } else if (name == "translate") {
      need(1, 2);
      m(0, 2) = v[0];
      m(1, 2) = v.size() > 1 ? v[1] : 0.0;
    } else if (name == "scale") {
      need(1, 2);
      m(0, 0) = v[0];
      m(1, 1) = v.size() > 1 ? v[1] : v[0];
    } else if (name == "rotate") {
      if (v.size() != 1 && v.size() != 3) need(1, 1);
      const double a = v[0] * kPi / 180.0;
      m << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0;
      if (v.size() == 3) {
        const Eigen::Vector2d c(v[1], v[2]);
        m.col(2) = c - m.leftCols<2>() * c;
      }
    } else if (name == "skewX") {
      need(1, 1);
      m(0, 1) = std::tan(v[0] * kPi / 180.0);
    } else if (name == "skewY") {
      need(1, 1);
      m(1, 0) = std::tan(v[0] * kPi / 180.0);
    } else {
      refuseSvg(element + ": unknown transform \"" + name + "\"");
    }
    total = compose(total, m);
    pos = close + 1;
  }
  return total;
}

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
std::optional<EdgeAssignment> assignmentOfColour(const std::string& raw) {
  const std::string c = lowered(trimmed(raw));
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

/// One drawn piece: a straight segment (2 points) or a sampled curve.
struct Piece {
  std::vector<Eigen::Vector2d> points;
  bool curved = false;
};
struct Subpath {
  std::vector<Piece> pieces;
  bool closed = false;
};

void sampleCubic(const Eigen::Vector2d& p0, const Eigen::Vector2d& p1, const Eigen::Vector2d& p2,
                 const Eigen::Vector2d& p3, int n, Piece& piece) {
  piece.curved = true;
  piece.points.push_back(p0);
  for (int k = 1; k <= n; ++k) {
    const double t = static_cast<double>(k) / n, s = 1.0 - t;
    piece.points.push_back(s * s * s * p0 + 3 * s * s * t * p1 + 3 * s * t * t * p2 + t * t * t * p3);
  }
  piece.points.back() = p3;
}

/// SVG 1.1 F.6.5: an elliptical arc from its end points to centre form, sampled.
void sampleArc(const Eigen::Vector2d& p0, const Eigen::Vector2d& p1, double rx, double ry, double phiDeg, int largeArc,
               int sweep, int perHalfTurn, Piece& piece) {
  rx = std::abs(rx);
  ry = std::abs(ry);
  if (rx == 0.0 || ry == 0.0 || (p1 - p0).norm() == 0.0) {
    piece.points = {p0, p1};
    return;
  }
  const double phi = phiDeg * kPi / 180.0, cp = std::cos(phi), sp = std::sin(phi);
  const Eigen::Vector2d d = (p0 - p1) / 2.0;
  const double x1 = cp * d.x() + sp * d.y(), y1 = -sp * d.x() + cp * d.y();
  const double lambda = x1 * x1 / (rx * rx) + y1 * y1 / (ry * ry);
  if (lambda > 1.0) {
    rx *= std::sqrt(lambda);
    ry *= std::sqrt(lambda);
  }
  const double num = rx * rx * ry * ry - rx * rx * y1 * y1 - ry * ry * x1 * x1;
  const double den = rx * rx * y1 * y1 + ry * ry * x1 * x1;
  const double coef = (largeArc != sweep ? 1.0 : -1.0) * std::sqrt(std::max(0.0, num / den));
  const double cxp = coef * rx * y1 / ry, cyp = -coef * ry * x1 / rx;
  const Eigen::Vector2d centre(cp * cxp - sp * cyp + (p0.x() + p1.x()) / 2.0, sp * cxp + cp * cyp + (p0.y() + p1.y()) / 2.0);
  const auto angleOf = [](double ux, double uy) { return std::atan2(uy, ux); };
  const double theta1 = angleOf((x1 - cxp) / rx, (y1 - cyp) / ry);
  double dtheta = angleOf((-x1 - cxp) / rx, (-y1 - cyp) / ry) - theta1;
  while (dtheta > kPi) dtheta -= 2 * kPi;
  while (dtheta < -kPi) dtheta += 2 * kPi;
  if (!sweep && dtheta > 0) dtheta -= 2 * kPi;
  if (sweep && dtheta < 0) dtheta += 2 * kPi;
  const int n = std::max(4, static_cast<int>(std::ceil(std::abs(dtheta) / kPi * perHalfTurn)));
  piece.curved = true;
  piece.points.push_back(p0);
  for (int k = 1; k <= n; ++k) {
    const double t = theta1 + dtheta * k / n;
    piece.points.emplace_back(centre.x() + rx * cp * std::cos(t) - ry * sp * std::sin(t),
                              centre.y() + rx * sp * std::cos(t) + ry * cp * std::sin(t));
  }
  piece.points.back() = p1;
}

/// Path data (SVG 1.1 §8.3) as subpaths of pieces, in user units.
std::vector<Subpath> parsePathData(const std::string& d, const std::string& element, int samples) {
  std::vector<Subpath> out;
  NumberScanner scan(d);
  Eigen::Vector2d current = Eigen::Vector2d::Zero(), start = Eigen::Vector2d::Zero(), lastControl = current;
  char previous = 0;
  char cmd = 0;
  const auto fail = [&element, &scan](const std::string& what) {
    refuseSvg(element + ": d, at character " + std::to_string(scan.position()) + ": " + what);
  };
  while (!scan.atEnd()) {
    if (const auto c = scan.command()) {
      cmd = *c;
      if (std::string("MmLlHhVvCcSsQqTtAaZz").find(cmd) == std::string::npos)
        fail(std::string("unknown command '") + cmd + "'");
    } else if (cmd == 0) {
      fail("path data must start with a command (M)");
    } else if (cmd == 'Z' || cmd == 'z') {
      fail("numbers after Z");
    }
    const bool rel = std::islower(static_cast<unsigned char>(cmd)) != 0;
    const char up = static_cast<char>(std::toupper(static_cast<unsigned char>(cmd)));
    const auto num = [&scan, &fail, up]() {
      const auto v = scan.number();
      if (!v) fail(std::string("expected a number for ") + up);
      return *v;
    };
    const auto point = [&num, &current, rel]() {
      const double x = num(), y = num();
      return rel ? Eigen::Vector2d(current.x() + x, current.y() + y) : Eigen::Vector2d(x, y);
    };
    if (up != 'M' && out.empty()) fail("a drawing command before the first M");
    switch (up) {
      case 'M': {
        current = point();
        start = current;
        out.push_back({});
        cmd = rel ? 'l' : 'L';  // further pairs are line-tos
        break;
      }
      case 'Z': {
        if ((current - start).norm() > 0.0) out.back().pieces.push_back({{current, start}, false});
        out.back().closed = true;
        current = start;
        // A command after Z without M starts a new subpath at the same point.
        out.push_back({});
        break;
      }
      case 'L': {
        const Eigen::Vector2d p = point();
        out.back().pieces.push_back({{current, p}, false});
        current = p;
        break;
      }
      case 'H': case 'V': {
        const double v = num();
        Eigen::Vector2d p = current;
        (up == 'H' ? p.x() : p.y()) = rel ? (up == 'H' ? current.x() : current.y()) + v : v;
        out.back().pieces.push_back({{current, p}, false});
        current = p;
        break;
      }
      case 'C': case 'S': {
        Eigen::Vector2d c1;
        const char prevUp = static_cast<char>(std::toupper(static_cast<unsigned char>(previous)));
        if (up == 'C') c1 = point();
        else c1 = (prevUp == 'C' || prevUp == 'S') ? Eigen::Vector2d(2 * current - lastControl) : current;
        const Eigen::Vector2d c2 = point(), p = point();
        Piece piece;
        sampleCubic(current, c1, c2, p, samples, piece);
        out.back().pieces.push_back(std::move(piece));
        lastControl = c2;
        current = p;
        break;
      }
      case 'Q': case 'T': {
        Eigen::Vector2d q;
        const char prevUp = static_cast<char>(std::toupper(static_cast<unsigned char>(previous)));
        if (up == 'Q') q = point();
        else q = (prevUp == 'Q' || prevUp == 'T') ? Eigen::Vector2d(2 * current - lastControl) : current;
        const Eigen::Vector2d p = point();
        Piece piece;
        sampleCubic(current, current + 2.0 / 3.0 * (q - current), p + 2.0 / 3.0 * (q - p), p, samples, piece);
        out.back().pieces.push_back(std::move(piece));
        lastControl = q;
        current = p;
        break;
      }
      case 'A': {
        const double rx = num(), ry = num(), rotation = num();
        const auto large = scan.flag();
        const auto sweep = scan.flag();
        if (!large || !sweep) fail("an arc needs flags 0 or 1");
        const Eigen::Vector2d p = point();
        Piece piece;
        sampleArc(current, p, rx, ry, rotation, *large, *sweep, samples, piece);
        out.back().pieces.push_back(std::move(piece));
        current = p;
        break;
      }
      default: break;
    }
    previous = cmd;
    if (up == 'M') previous = 'M';
  }
  out.erase(std::remove_if(out.begin(), out.end(), [](const Subpath& s) { return s.pieces.empty(); }), out.end());
  return out;
}

std::vector<double> numbersOf(const std::string& text, const std::string& element, const std::string& attribute) {
  NumberScanner scan(text);
  std::vector<double> v;
  while (!scan.atEnd()) {
    const auto x = scan.number();
    if (!x) refuseSvg(element + ": " + attribute + " has something other than numbers");
    v.push_back(*x);
  }
  return v;
}

/// A stroke of the drawing: consecutive pieces without a corner between them.
struct Stroke {
  std::vector<Eigen::Vector2d> points;  ///< user units after transforms
  bool closed = false;
  bool curved = false;
  EdgeAssignment assignment = EdgeAssignment::Flat;
  std::optional<double> foldAngle;
  std::string element;
};

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
bool smoothJoin(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a.dot(b) >= std::cos(kCornerTurnDeg * kPi / 180.0);
}

struct Reader {
  const SvgImportOptions& options;
  StyleSheet sheet;
  SvgImport& result;
  std::vector<Stroke> strokes;
  std::map<std::string, int> tagCount;
  std::set<std::string> reportedColours;

  struct Inherited {
    Affine ctm = identityAffine();
    std::optional<std::string> stroke;
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
      for (const char* name : {"stroke", "opacity", "stroke-opacity", "display", "visibility", "transform"})
        if (const pugi::xml_attribute a = child.attribute(name)) props[name] = a.value();
      sheet.apply(tag, child.attribute("class").value(), props);
      for (const auto& [k, v] : cssDeclarations(child.attribute("style").value())) props[k] = v;
      Inherited here = inherited;
      if (props.count("transform")) here.ctm = compose(inherited.ctm, parseTransform(props["transform"], element));
      if (props.count("stroke")) here.stroke = props["stroke"];
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
      const double amount = here.opacity * here.strokeOpacity;
      std::optional<double> angle;
      if (*assignment == EdgeAssignment::Mountain) angle = -180.0 * amount;
      if (*assignment == EdgeAssignment::Valley) angle = 180.0 * amount;
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
    std::vector<std::vector<Eigen::Vector2d>> runs;
    for (const Piece& piece : sub.pieces) {
      if (piece.points.size() < 2) continue;
      if (!runs.empty() && smoothJoin(endTangent(runs.back()), startTangent(piece.points))) {
        runs.back().insert(runs.back().end(), piece.points.begin() + 1, piece.points.end());
      } else {
        runs.push_back(piece.points);
      }
    }
    if (runs.empty()) return;
    bool closedLoop = false;
    if (sub.closed && (runs.back().back() - runs.front().front()).norm() == 0.0 &&
        smoothJoin(endTangent(runs.back()), startTangent(runs.front()))) {
      if (runs.size() == 1) {
        closedLoop = true;
      } else {
        runs.back().insert(runs.back().end(), runs.front().begin() + 1, runs.front().end());
        runs.front() = std::move(runs.back());
        runs.pop_back();
      }
    }
    for (auto& run : runs) {
      Stroke s;
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

  SvgImport result;
  Reader reader{options, {}, result, {}, {}, {}};
  for (const pugi::xpath_node& style : doc.select_nodes("//*[local-name()='style']"))
    reader.sheet.add(style.node().child_value());
  if (const pugi::xml_node title = root.child("title")) result.pattern.title = trimmed(title.child_value());

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
  if (!viewBox.empty()) {
    if (widthMm) sx = *widthMm / viewBox[2];
    if (heightMm) sy = *heightMm / viewBox[3];
    if (widthMm && !heightMm) sy = sx;
    if (heightMm && !widthMm) sx = sy;
    if (!widthMm && !heightMm)
      result.notes.push_back({"svg", "no width or height: one user unit is read as one px (1/96 in)"});
  }
  if (std::abs(sx - sy) > 1e-9 * std::max(sx, sy))
    result.notes.push_back({"svg", "width and height scale the viewBox unequally; the drawing is stretched as a viewer shows it"});

  Reader::Inherited top;
  reader.visit(doc, top);
  std::vector<Stroke>& strokes = reader.strokes;
  if (strokes.empty()) refuseSvg("no strokes in a crease colour (black, red, blue, green, yellow, magenta)");

  // Millimetres, y up.
  const double originY = !viewBox.empty() ? viewBox[1] + viewBox[3] : 0.0;
  const double originX = !viewBox.empty() ? viewBox[0] : 0.0;
  for (Stroke& s : strokes)
    for (Eigen::Vector2d& p : s.points) p = Eigen::Vector2d((p.x() - originX) * sx, (originY - p.y()) * sy);

  Eigen::Vector2d lo = strokes[0].points[0], hi = lo;
  for (const Stroke& s : strokes)
    for (const Eigen::Vector2d& p : s.points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  const double diagonal = (hi - lo).norm();
  if (!(diagonal > 0.0)) refuseSvg("the drawing has no extent");
  for (Stroke& s : strokes) {
    if (s.closed) {
      s.curved = true;
      continue;
    }
    const Eigen::Vector2d a = s.points.front(), b = s.points.back();
    const Eigen::Vector2d axis = (b - a).norm() > 0 ? Eigen::Vector2d((b - a).normalized()) : Eigen::Vector2d::UnitX();
    double deviation = 0.0;
    for (const Eigen::Vector2d& p : s.points) deviation = std::max(deviation, std::abs(axis.x() * (p - a).y() - axis.y() * (p - a).x()));
    s.curved = deviation > 1e-6 * diagonal || (b - a).norm() == 0.0;
  }
  const bool anyCurved = std::any_of(strokes.begin(), strokes.end(), [](const Stroke& s) { return s.curved; });
  result.strokes = static_cast<int>(strokes.size());
  result.curvedStrokes = static_cast<int>(std::count_if(strokes.begin(), strokes.end(), [](const Stroke& s) { return s.curved; }));

  // Segments of every stroke; straight strokes cut into pieces where rulings may need points.
  std::vector<Eigen::Vector2d> points;
  std::vector<std::array<int, 2>> segments;
  std::vector<int> strokeOfSegment;
  for (std::size_t s = 0; s < strokes.size(); ++s) {
    const Stroke& stroke = strokes[s];
    std::vector<Eigen::Vector2d> pts = stroke.points;
    if (!stroke.curved && anyCurved && options.straightPieces > 1) {
      pts.clear();
      for (int k = 0; k <= options.straightPieces; ++k)
        pts.push_back(stroke.points.front() + (stroke.points.back() - stroke.points.front()) * k / options.straightPieces);
    } else if (!stroke.curved) {
      pts = {stroke.points.front(), stroke.points.back()};
    }
    const int first = static_cast<int>(points.size());
    points.insert(points.end(), pts.begin(), pts.end());
    const int count = static_cast<int>(pts.size());
    for (int k = 0; k + 1 < count; ++k) {
      segments.push_back({first + k, first + k + 1});
      strokeOfSegment.push_back(static_cast<int>(s));
    }
    if (stroke.closed && count >= 3) {
      segments.push_back({first + count - 1, first});
      strokeOfSegment.push_back(static_cast<int>(s));
    }
    if (static_cast<int>(segments.size()) > options.maxSegments)
      throw std::length_error("SVG: more than " + std::to_string(options.maxSegments) + " segments after sampling the curves");
  }
  Eigen::MatrixX2d pointMatrix(static_cast<Eigen::Index>(points.size()), 2);
  for (std::size_t k = 0; k < points.size(); ++k) pointMatrix.row(static_cast<Eigen::Index>(k)) = points[k].transpose();
  const spatial::PlanarArrangement arrangement =
      spatial::planarArrangement(pointMatrix, segments, options.mergeFraction * diagonal);

  std::set<int> leftOut;
  for (int s : arrangement.unusedSegments) leftOut.insert(strokeOfSegment[static_cast<std::size_t>(s)]);
  std::set<int> usedStrokes;
  for (int source : arrangement.sourceOfSegment) usedStrokes.insert(strokeOfSegment[static_cast<std::size_t>(source)]);
  for (int s : leftOut)
    if (!usedStrokes.count(s))
      result.notes.push_back({strokes[static_cast<std::size_t>(s)].element,
                              "a stroke with a free end, or apart from the sheet; left out"});
  if (arrangement.islands > 0)
    result.notes.push_back({"svg", std::to_string(arrangement.islands) + " island(s) inside the sheet (a face with a hole); left out"});
  if (arrangement.faces.empty()) refuseSvg("the strokes enclose no face (draw the sheet's outline in black)");

  CreasePattern& p = result.pattern;
  p.unitToMm = 1.0;
  p.vertices2d = arrangement.points;
  p.faces = arrangement.faces;
  std::map<std::pair<int, int>, int> facesOfPair;
  for (const auto& f : p.faces)
    for (std::size_t k = 0; k < f.size(); ++k) ++facesOfPair[std::minmax(f[k], f[(k + 1) % f.size()])];
  std::set<int> outlineCreases, innerBoundaries;
  for (std::size_t s = 0; s < arrangement.segments.size(); ++s) {
    const auto key = std::minmax(arrangement.segments[s][0], arrangement.segments[s][1]);
    const auto count = facesOfPair.find(key);
    if (count == facesOfPair.end()) continue;
    const int strokeId = strokeOfSegment[static_cast<std::size_t>(arrangement.sourceOfSegment[s])];
    const Stroke& stroke = strokes[static_cast<std::size_t>(strokeId)];
    CreaseEdge edge;
    edge.v0 = key.first;
    edge.v1 = key.second;
    edge.curve = anyCurved ? strokeId : -1;
    if (count->second == 1) {
      edge.assignment = EdgeAssignment::Boundary;
      if (stroke.assignment != EdgeAssignment::Boundary && stroke.assignment != EdgeAssignment::Cut) outlineCreases.insert(strokeId);
    } else if (stroke.assignment == EdgeAssignment::Boundary) {
      edge.assignment = EdgeAssignment::Cut;
      innerBoundaries.insert(strokeId);
    } else {
      edge.assignment = stroke.assignment;
      if (stroke.foldAngle && *stroke.foldAngle != 0.0) edge.foldAngle = stroke.foldAngle;
    }
    p.edges.push_back(edge);
  }
  for (int s : outlineCreases)
    result.notes.push_back({strokes[static_cast<std::size_t>(s)].element, "a crease colour on the sheet's outline; read as boundary"});
  for (int s : innerBoundaries)
    result.notes.push_back({strokes[static_cast<std::size_t>(s)].element, "a boundary (black) line inside the sheet; read as a cut"});
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    refuseSvg(e.what());
  }
  return result;
}

}  // namespace devsurf::io
