#pragma once

#include <string>

#include "devsurf/io/CreasePattern.h"

namespace devsurf::io {

/// Line style of one kind of edge in the SVG fold pattern. Colours and dash patterns follow the
/// common origami-software convention: boundary and cuts solid black, mountain folds red
/// dash-dot, valley folds blue dashed; flat (unfolded) edges light grey dotted, rulings thin grey.
/// Dash lengths are in millimetres.
struct SvgLineStyle {
  const char* cssClass;
  const char* color;
  const char* dasharray;  ///< "none" for a solid line
};
SvgLineStyle svgEdgeStyle(EdgeAssignment assignment);
SvgLineStyle svgRulingStyle();

/// Options of the SVG fold pattern. All lengths are millimetres on paper.
struct SvgFoldOptions {
  double marginMm = 10.0;          ///< blank border around the development's bounding box
  double boundaryWidthMm = 0.3;    ///< boundary and cut lines
  double foldWidthMm = 0.25;       ///< mountain and valley lines
  double flatWidthMm = 0.1;        ///< flat interior edges (when drawn)
  double rulingWidthMm = 0.1;      ///< rulings (when drawn)
  bool drawFlat = false;           ///< draw flat (unfolded interior) edges
  bool drawRulings = true;         ///< draw the pattern's rulings
  bool legend = true;              ///< legend group id="legend" in the bottom margin (needs ≥ 2 mm)
  std::string title;               ///< <title>; the pattern title, or a default, when empty
  int decimals = 4;                ///< decimals of the coordinates (0.1 µm)
  /// A development whose larger side is below this many millimetres has every style length —
  /// margin, line widths, dash patterns, legend — scaled by side / styleReferenceMm, so that a
  /// small pattern reads like one of the reference size (at 40 mm the mountain dash-dot repeats
  /// about six times across; a 2 mm pattern would otherwise drown under 0.3 mm lines and 4 mm
  /// dashes). Its size stays true. 0: never scale.
  double styleReferenceMm = 40.0;
};

/// The development as an SVG 1.1 document in millimetres.
///
/// width/height are "<W>mm"/"<H>mm" with W = (xmax − xmin)·unitToMm + 2·margin (likewise H from
/// y) over the development's vertices, and viewBox "0 0 W H", so one user unit is one millimetre
/// (margin and the other style lengths scaled down for small patterns, see styleReferenceMm).
/// The y axis is flipped (SVG's y points down): a development point (x, y) is drawn at
/// (margin + (x − xmin)·unitToMm, margin + (ymax − y)·unitToMm), so the drawing is not mirrored.
/// Edges are grouped into chains (edgeChains) and each chain drawn as one <polyline> (<polygon>
/// when closed) carrying its style as presentation attributes (stroke, stroke-width,
/// stroke-dasharray, class) and, for a crease curve, id "curve-<id>" (then "curve-<id>-2", …).
/// Groups, bottom to top: rulings, flat, valley, mountain, cut, boundary, legend.
/// The conventions are written out in the document's <title> and <desc>.
/// @throws std::invalid_argument for a bad pattern or negative / non-finite option lengths.
std::string svgFoldPattern(const CreasePattern& pattern, const SvgFoldOptions& options = {});

/// Writes svgFoldPattern to `path`.
/// @throws std::invalid_argument as above, std::runtime_error naming the file when writing fails.
void writeSvgFoldPattern(const CreasePattern& pattern, const std::string& path,
                         const SvgFoldOptions& options = {});

}  // namespace devsurf::io
