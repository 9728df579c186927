// SVG path data, transforms and number lists (issue 16 item 1), read for crease patterns.
#include "devsurf/io/SvgPathData.h"

#include <cctype>
#include <cmath>
#include <optional>
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace devsurf::io::svg {

void refuseSvg(const std::string& message) { throw std::invalid_argument("SVG: " + message); }

namespace {
std::string trimmedText(const std::string& s) {
  std::size_t b = 0, e = s.size();
  while (b < e && std::isspace(static_cast<unsigned char>(s[b]))) ++b;
  while (e > b && std::isspace(static_cast<unsigned char>(s[e - 1]))) --e;
  return s.substr(b, e - b);
}
}  // namespace

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

namespace {
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
}  // namespace

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
    const std::string name = trimmedText(text.substr(pos, open - pos));
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



namespace {
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
}  // namespace

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


}  // namespace devsurf::io::svg
