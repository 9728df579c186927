#include "devsurf/io/CuttingPatternSvg.h"

#include <cmath>
#include <limits>
#include <stdexcept>

#include "devsurf/io/GlueSeams.h"
#include "devsurf/io/SvgWriting.h"

namespace devsurf::io {
namespace {

void checkLength(double v, const char* name, bool allowZero) {
  checkSvgLength(v, "CuttingPatternOptions", name, allowZero);
}

/// The cutting pattern's established escaping: apostrophes as they are, carriage returns dropped.
constexpr XmlEscapeOptions kEscape{/*escapeApostrophe=*/false, /*keepCarriageReturn=*/false};

}  // namespace

std::string cuttingPatternSvg(const Eigen::MatrixXd& V, const std::vector<PolygonFace>& faces,
                              const std::vector<std::array<int, 2>>& gluePairs, double mmPerUnit,
                              const CuttingPatternOptions& o) {
  if (V.cols() != 2 && V.cols() != 3)
    throw std::invalid_argument("cutting pattern: the unfolding must have 2 or 3 columns");
  if (!V.allFinite()) throw std::invalid_argument("cutting pattern: the unfolding must be finite");
  if (!(std::isfinite(mmPerUnit) && mmPerUnit > 0.0))
    throw std::invalid_argument("cutting pattern: mmPerUnit must be finite and > 0");
  checkLength(o.marginMm, "marginMm", true);
  checkLength(o.cutWidthMm, "cutWidthMm", false);
  checkLength(o.glueWidthMm, "glueWidthMm", false);
  checkLength(o.meshWidthMm, "meshWidthMm", false);
  checkLength(o.labelSizeMm, "labelSizeMm", false);
  if (o.decimals < 0 || o.decimals > 12)
    throw std::invalid_argument("CuttingPatternOptions: decimals must lie in [0, 12]");
  const GlueSeams seams = findGlueSeams(static_cast<int>(V.rows()), faces, gluePairs, V);

  const double s = mmPerUnit, m = o.marginMm;
  const SvgPage page{svgBounds(V), s, m};
  const double W = page.widthMm(), H = page.heightMm();
  const SvgNumberFormat num(o.decimals);
  auto X = [&num, &page](double x) { return num(page.x(x)); };
  auto Y = [&num, &page](double y) { return num(page.y(y)); };  // SVG's y points down

  auto line = [&V, &X, &Y](const PolygonEdge& e, const char* cls, const std::string& extra) {
    return std::string("    <line class=\"") + cls + "\" data-v0=\"" + std::to_string(e.v0) +
           "\" data-v1=\"" + std::to_string(e.v1) + "\"" + extra + " x1=\"" + X(V(e.v0, 0)) +
           "\" y1=\"" + Y(V(e.v0, 1)) + "\" x2=\"" + X(V(e.v1, 0)) + "\" y2=\"" + Y(V(e.v1, 1)) +
           "\"/>\n";
  };
  std::string mesh, cuts, glue;
  for (const PolygonEdge& e : seams.edges) {
    if (e.faceCount == 2) {
      if (o.drawMesh) mesh += line(e, "mesh", "");
    } else if (e.gluedTo < 0) {
      cuts += line(e, "cut", "");
    } else {
      glue += line(e, "glue", " data-seam=\"" + std::to_string(e.seam + 1) + "\"");
    }
  }

  // Seam numbers inside the piece, so they stay on it when it is cut out.
  std::string labels;
  for (const SeamLabel& label : seamLabelPositions(seams, faces, V, 0.7 * o.labelSizeMm / s))
    labels += "    <text class=\"glue-label\" data-seam=\"" + std::to_string(label.seam + 1) + "\" data-side=\"" +
              std::to_string(label.side) + "\" x=\"" + X(label.position.x()) + "\" y=\"" + Y(label.position.y()) + "\">" +
              std::to_string(label.seam + 1) + "</text>\n";

  const std::string title = o.title.empty() ? std::string("devsurf cutting pattern") : o.title;
  const std::string description =
      (o.what.empty() ? std::string("Cutting pattern of a quad mesh's unfolding, exported by devsurf.") : o.what) +
      " Units: millimetres, one "
      "user unit = 1 mm; scale: 1 design unit = " + num(s) + " mm; margin " + num(m) +
      " mm. Cut along the solid black lines. Blue dashed edges are glued: edges with the same "
      "number are glued to each other, running in the same direction along the seam. Faint grey "
      "lines are mesh edges (no folds). The unfolding's y axis points up (not mirrored).";
  std::string out = svgDocumentHead(W, H, num, title, description, kEscape);
  if (!mesh.empty())
    out += "  <g id=\"mesh\" fill=\"none\" stroke=\"#c8c8c8\" stroke-width=\"" + num(o.meshWidthMm) +
           "\" stroke-linecap=\"round\">\n" + mesh + "  </g>\n";
  out += "  <g id=\"cuts\" fill=\"none\" stroke=\"#000000\" stroke-width=\"" + num(o.cutWidthMm) +
         "\" stroke-linecap=\"round\">\n" + cuts + "  </g>\n";
  out += "  <g id=\"glue\" fill=\"none\" stroke=\"#0050c8\" stroke-width=\"" + num(o.glueWidthMm) +
         "\" stroke-dasharray=\"" + num(2.0 * o.glueWidthMm / 0.3) + " " + num(1.0 * o.glueWidthMm / 0.3) +
         "\" stroke-linecap=\"butt\">\n" + glue + "  </g>\n";
  out += "  <g id=\"labels\" fill=\"#0050c8\" font-family=\"sans-serif\" font-size=\"" +
         num(o.labelSizeMm) + "\" text-anchor=\"middle\" dominant-baseline=\"central\">\n" + labels +
         "  </g>\n";
  out += "</svg>\n";
  return out;
}

void writeCuttingPatternSvg(const Eigen::MatrixXd& unfolding, const std::vector<PolygonFace>& faces,
                            const std::vector<std::array<int, 2>>& gluePairs, double mmPerUnit,
                            const std::string& path, const CuttingPatternOptions& options) {
  writeSvgFile(path, cuttingPatternSvg(unfolding, faces, gluePairs, mmPerUnit, options));
}

}  // namespace devsurf::io
