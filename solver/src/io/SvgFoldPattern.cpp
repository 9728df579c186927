#include "devsurf/io/SvgFoldPattern.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "devsurf/io/SvgWriting.h"

namespace devsurf::io {
namespace {

void checkFoldLength(double v, const char* name, bool allowZero) {
  checkSvgLength(v, "SvgFoldOptions", name, allowZero);
}

/// Presentation attributes of a line style; `scale` multiplies its dash pattern.
std::string strokeAttributes(const SvgLineStyle& st, const std::string& width, double scale,
                             const SvgNumberFormat& num) {
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
  checkFoldLength(o.marginMm, "marginMm", true);
  checkFoldLength(o.boundaryWidthMm, "boundaryWidthMm", false);
  checkFoldLength(o.foldWidthMm, "foldWidthMm", false);
  checkFoldLength(o.flatWidthMm, "flatWidthMm", false);
  checkFoldLength(o.rulingWidthMm, "rulingWidthMm", false);
  checkFoldLength(o.styleReferenceMm, "styleReferenceMm", true);
  if (o.decimals < 0 || o.decimals > 12)
    throw std::invalid_argument("SvgFoldOptions: decimals must lie in [0, 12]");

  const SvgNumberFormat num(o.decimals);
  const double s = p.unitToMm;
  const SvgBounds bounds = svgBounds(p.vertices2d);
  // Style lengths, scaled down for a pattern smaller than the reference size.
  const double side = std::max(bounds.xmax - bounds.xmin, bounds.ymax - bounds.ymin) * s;
  const double style = o.styleReferenceMm > 0.0 && side > 0.0 && side < o.styleReferenceMm
                           ? side / o.styleReferenceMm : 1.0;
  const double m = o.marginMm * style, boundaryWidth = o.boundaryWidthMm * style,
               foldWidth = o.foldWidthMm * style, flatWidth = o.flatWidthMm * style,
               rulingWidth = o.rulingWidthMm * style;
  const SvgPage page{bounds, s, m};
  const double W = page.widthMm(), H = page.heightMm();
  auto X = [&num, &page](double x) { return num(page.x(x)); };
  auto Y = [&num, &page](double y) { return num(page.y(y)); };  // SVG's y points down

  const std::string title = !o.title.empty() ? o.title
                            : !p.title.empty() ? p.title
                                               : std::string("devsurf fold pattern");
  const std::string description =
      "Fold pattern (development) exported by devsurf. Units: millimetres, one user unit = 1 mm; "
      "scale: 1 model unit = " + num(s) + " mm; margin " + num(m) +
      " mm. Lines: boundary and cuts solid black; mountain folds red dash-dot; "
      "valley folds blue dashed; flat creases light grey dotted; rulings thin grey. "
      "The development's y axis points up (the drawing is not mirrored): the front "
      "side of the sheet faces the viewer and valley folds close towards it." +
      (style < 1.0 ? " Line widths, dashes and margin are scaled by " + num(style) + " for this small pattern."
                   : std::string());
  std::string out = svgDocumentHead(W, H, num, title, description);

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
    el += strokeAttributes(svgEdgeStyle(c.assignment), num(w), style, num);
    if (c.assignment == EdgeAssignment::Mountain || c.assignment == EdgeAssignment::Valley) {
      // The fold angle (the mean along the chain, FOLD's sign), for devsurf's own import: Origami
      // Simulator's convention, the stroke's opacity, would print a 30° score line nearly white.
      double sum = 0.0;
      for (int e : c.edges) sum += p.edges[static_cast<std::size_t>(e)].foldAngle.value_or(c.assignment == EdgeAssignment::Valley ? 180.0 : -180.0);
      if (!c.edges.empty()) el += " data-fold-angle=\"" + num(sum / static_cast<double>(c.edges.size())) + "\"";
    }
    el += " points=\"" + points + "\"/>\n";
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
  writeSvgFile(path, svgFoldPattern(pattern, options));
}

}  // namespace devsurf::io
