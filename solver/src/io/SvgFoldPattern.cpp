#include "devsurf/io/SvgFoldPattern.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace devsurf::io {
namespace {

/// Locale-independent fixed-point number with trailing zeros removed.
class NumberFormat {
 public:
  explicit NumberFormat(int decimals) : decimals_(decimals) {}
  std::string operator()(double v) const {
    char buf[64];
    const auto res = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, decimals_);
    std::string s = res.ec == std::errc() ? std::string(buf, res.ptr) : std::string("0");
    if (s.find('.') != std::string::npos) {
      while (s.back() == '0') s.pop_back();
      if (s.back() == '.') s.pop_back();
    }
    if (s == "-0") s = "0";
    return s;
  }

 private:
  int decimals_;
};

/// Text or attribute value for XML 1.0: escapes markup, drops disallowed control characters.
std::string xmlEscape(const std::string& in) {
  std::string out;
  out.reserve(in.size());
  for (char ch : in) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default:
        if (static_cast<unsigned char>(ch) < 0x20 && ch != '\t' && ch != '\n' && ch != '\r')
          break;
        out += ch;
    }
  }
  return out;
}

void checkLength(double v, const char* name, bool allowZero) {
  if (!std::isfinite(v) || v < 0.0 || (!allowZero && v == 0.0))
    throw std::invalid_argument(std::string("SvgFoldOptions: ") + name +
                                (allowZero ? " must be finite and >= 0" : " must be finite and > 0"));
}

/// Presentation attributes of a line style; `scale` multiplies its dash pattern.
std::string strokeAttributes(const SvgLineStyle& st, const std::string& width, double scale,
                             const NumberFormat& num) {
  std::string a = " class=\"" + std::string(st.cssClass) + "\" stroke=\"" + st.color +
                  "\" stroke-width=\"" + width + "\"";
  if (std::string(st.dasharray) == "none") return a;
  std::string dashes = st.dasharray;
  if (scale != 1.0) {
    std::istringstream in(st.dasharray);
    dashes.clear();
    for (double d; in >> d;) dashes += (dashes.empty() ? "" : " ") + num(d * scale);
  }
  return a + " stroke-dasharray=\"" + dashes + "\"";
}

}  // namespace

SvgLineStyle svgEdgeStyle(EdgeAssignment a) {
  switch (a) {
    case EdgeAssignment::Boundary: return {"boundary", "#000000", "none"};
    case EdgeAssignment::Cut: return {"cut", "#000000", "none"};
    case EdgeAssignment::Mountain: return {"mountain", "#ff0000", "4 1.2 0.6 1.2"};
    case EdgeAssignment::Valley: return {"valley", "#0000ff", "2.5 1.5"};
    case EdgeAssignment::Flat: return {"flat", "#b0b0b0", "0.5 1"};
  }
  return {"flat", "#b0b0b0", "0.5 1"};
}

SvgLineStyle svgRulingStyle() { return {"ruling", "#999999", "none"}; }

std::string svgFoldPattern(const CreasePattern& p, const SvgFoldOptions& o) {
  p.validate();
  checkLength(o.marginMm, "marginMm", true);
  checkLength(o.boundaryWidthMm, "boundaryWidthMm", false);
  checkLength(o.foldWidthMm, "foldWidthMm", false);
  checkLength(o.flatWidthMm, "flatWidthMm", false);
  checkLength(o.rulingWidthMm, "rulingWidthMm", false);
  checkLength(o.styleReferenceMm, "styleReferenceMm", true);
  if (o.decimals < 0 || o.decimals > 12)
    throw std::invalid_argument("SvgFoldOptions: decimals must lie in [0, 12]");

  const NumberFormat num(o.decimals);
  const double s = p.unitToMm;
  double xmin = 0, xmax = 0, ymin = 0, ymax = 0;
  if (p.numVertices() > 0) {
    xmin = p.vertices2d.col(0).minCoeff();
    xmax = p.vertices2d.col(0).maxCoeff();
    ymin = p.vertices2d.col(1).minCoeff();
    ymax = p.vertices2d.col(1).maxCoeff();
  }
  // Style lengths, scaled down for a pattern smaller than the reference size.
  const double side = std::max(xmax - xmin, ymax - ymin) * s;
  const double style = o.styleReferenceMm > 0.0 && side > 0.0 && side < o.styleReferenceMm
                           ? side / o.styleReferenceMm : 1.0;
  const double m = o.marginMm * style, boundaryWidth = o.boundaryWidthMm * style,
               foldWidth = o.foldWidthMm * style, flatWidth = o.flatWidthMm * style,
               rulingWidth = o.rulingWidthMm * style;
  const double W = (xmax - xmin) * s + 2 * m, H = (ymax - ymin) * s + 2 * m;
  auto X = [&](double x) { return num(m + (x - xmin) * s); };
  auto Y = [&](double y) { return num(m + (ymax - y) * s); };  // SVG's y points down

  const std::string title = !o.title.empty() ? o.title
                            : !p.title.empty() ? p.title
                                               : std::string("devsurf fold pattern");
  std::string out;
  out += "<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"no\"?>\n";
  out += "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" + num(W) +
         "mm\" height=\"" + num(H) + "mm\" viewBox=\"0 0 " + num(W) + " " + num(H) + "\">\n";
  out += "  <title>" + xmlEscape(title) + "</title>\n";
  out += "  <desc>" +
         xmlEscape("Fold pattern (development) exported by devsurf. Units: millimetres, one user "
                   "unit = 1 mm; scale: 1 model unit = " + num(s) + " mm; margin " + num(m) +
                   " mm. Lines: boundary and cuts solid black; mountain folds red dash-dot; "
                   "valley folds blue dashed; flat creases light grey dotted; rulings thin grey. "
                   "The development's y axis points up (the drawing is not mirrored): the front "
                   "side of the sheet faces the viewer and valley folds close towards it." +
                   (style < 1.0 ? " Line widths, dashes and margin are scaled by " + num(style) +
                                  " for this small pattern."
                            : std::string())) +
         "</desc>\n";

  // Rulings.
  if (o.drawRulings && p.rulings.rows() > 0) {
    std::string d;
    for (Eigen::Index r = 0; r < p.rulings.rows(); ++r) {
      if (!d.empty()) d += ' ';
      d += "M" + X(p.rulings(r, 0)) + " " + Y(p.rulings(r, 1)) + " L" + X(p.rulings(r, 2)) + " " +
           Y(p.rulings(r, 3));
    }
    out += "  <g id=\"rulings\" fill=\"none\" stroke-linecap=\"round\">\n";
    out += "    <path" + strokeAttributes(svgRulingStyle(), num(rulingWidth), style, num) + " d=\"" + d +
           "\"/>\n";
    out += "  </g>\n";
  }

  // Edge chains, one group per kind.
  const std::vector<EdgeChain> chains = edgeChains(p);
  std::map<int, int> curveUses;
  std::map<EdgeAssignment, std::string> body;
  for (const EdgeChain& c : chains) {
    if (c.assignment == EdgeAssignment::Flat && !o.drawFlat) continue;
    const double w = c.assignment == EdgeAssignment::Boundary || c.assignment == EdgeAssignment::Cut
                         ? boundaryWidth
                     : c.assignment == EdgeAssignment::Flat ? flatWidth
                                                            : foldWidth;
    std::string points;
    for (int v : c.vertices) {
      if (!points.empty()) points += ' ';
      points += X(p.vertices2d(v, 0)) + "," + Y(p.vertices2d(v, 1));
    }
    std::string el = c.closed ? "    <polygon" : "    <polyline";
    if (c.curve >= 0) {
      const int k = ++curveUses[c.curve];
      el += " id=\"curve-" + std::to_string(c.curve) + (k > 1 ? "-" + std::to_string(k) : "") + "\"";
    }
    el += strokeAttributes(svgEdgeStyle(c.assignment), num(w), style, num) + " points=\"" + points + "\"/>\n";
    body[c.assignment] += el;
  }
  for (EdgeAssignment a : {EdgeAssignment::Flat, EdgeAssignment::Valley, EdgeAssignment::Mountain,
                           EdgeAssignment::Cut, EdgeAssignment::Boundary}) {
    const auto it = body.find(a);
    if (it == body.end()) continue;
    out += "  <g id=\"" + std::string(assignmentName(a)) +
           "\" fill=\"none\" stroke-linejoin=\"round\" stroke-linecap=\"butt\">\n" + it->second +
           "  </g>\n";
  }

  // Legend: line samples with labels in the bottom margin, shrunk to fit.
  if (o.legend && m >= 2.0 * style) {
    struct Item {
      SvgLineStyle style;
      std::string label;
      double width;
    };
    std::vector<Item> items = {
        {svgEdgeStyle(EdgeAssignment::Mountain), "mountain", foldWidth},
        {svgEdgeStyle(EdgeAssignment::Valley), "valley", foldWidth},
        {svgEdgeStyle(EdgeAssignment::Boundary), "boundary / cut", boundaryWidth}};
    if (o.drawFlat) items.push_back({svgEdgeStyle(EdgeAssignment::Flat), "flat", flatWidth});
    if (o.drawRulings && p.rulings.rows() > 0)
      items.push_back({svgRulingStyle(), "ruling", rulingWidth});
    // Layout at scale 1: a grid of cells (8 mm sample, label) with 4 mm rows and a 2.5 mm font;
    // the number of rows is the one that lets the grid fit the bottom margin at the largest size.
    const double row = 4.0, font = 2.5, sample = 8.0, gap = 1.5, spacing = 4.0, charW = 0.6 * font;
    double cellW = 0.0;
    for (const Item& it : items)
      cellW = std::max(cellW, sample + gap + charW * static_cast<double>(it.label.size()));
    const double availW = W - 2 * m;
    const int n = static_cast<int>(items.size());
    double k = 0.0;
    int cols = n;
    for (int rows = 1; rows <= n; ++rows) {
      const int c = (n + rows - 1) / rows;
      const double kr = std::min({1.0, 0.8 * m / (row * rows), availW / (c * cellW + (c - 1) * spacing)});
      if (kr > k + 1e-12) {
        k = kr;
        cols = c;
      }
    }
    if (k > 0.0) {
      const int rows = (n + cols - 1) / cols;
      const double top = H - m + (m - row * rows * k) / 2;
      out += "  <g id=\"legend\" fill=\"none\">\n";
      for (int i = 0; i < n; ++i) {
        const Item& it = items[static_cast<std::size_t>(i)];
        const double x = m + (i % cols) * (cellW + spacing) * k;
        const double mid = top + ((i / cols) + 0.5) * row * k;
        // Dashes at the legend's own scale, so that every sample shows a whole dash period.
        out += "    <line" + strokeAttributes(it.style, num(it.width), k, num) + " x1=\"" + num(x) +
               "\" y1=\"" + num(mid) + "\" x2=\"" + num(x + sample * k) + "\" y2=\"" + num(mid) +
               "\"/>\n";
        out += "    <text x=\"" + num(x + (sample + gap) * k) + "\" y=\"" +
               num(mid + 0.35 * font * k) + "\" font-family=\"sans-serif\" font-size=\"" +
               num(font * k) + "\" fill=\"#000000\" stroke=\"none\">" + xmlEscape(it.label) +
               "</text>\n";
      }
      out += "  </g>\n";
    }
  }
  out += "</svg>\n";
  return out;
}

void writeSvgFoldPattern(const CreasePattern& pattern, const std::string& path,
                         const SvgFoldOptions& options) {
  const std::string text = svgFoldPattern(pattern, options);
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot write SVG file " + path);
  out << text;
  out.flush();
  if (!out) throw std::runtime_error("cannot write SVG file " + path);
}

}  // namespace devsurf::io
