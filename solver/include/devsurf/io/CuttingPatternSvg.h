#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/io/PolygonMesh.h"

namespace devsurf::io {

/// Options of the cutting pattern. All lengths are millimetres on paper.
struct CuttingPatternOptions {
  double marginMm = 10.0;      ///< blank border around the unfolding's bounding box (≥ 0)
  double cutWidthMm = 0.3;     ///< cut lines (boundary edges that are not glued)
  double glueWidthMm = 0.3;    ///< glue edges
  double meshWidthMm = 0.05;   ///< faint interior mesh lines (when drawn)
  bool drawMesh = true;        ///< draw the interior edges as faint lines
  double labelSizeMm = 3.0;    ///< font size of the seam numbers (> 0)
  std::string title;           ///< <title>; "devsurf cutting pattern" when empty
  /// What the drawing is, the first sentence of <desc> (units and line styles follow); "Cutting
  /// pattern of a quad mesh's unfolding, exported by devsurf." when empty.
  std::string what;
  int decimals = 4;            ///< decimals of the coordinates, in [0, 12]
};

/// The paper model of a quad mesh's unfolding M′ as an SVG 1.1 document at true size.
///
/// Size: width/height are "<W>mm"/"<H>mm" with W = (xmax − xmin)·mmPerUnit + 2·margin over all
/// vertices of M′ (H likewise from y) and viewBox "0 0 W H": one user unit is one millimetre.
/// The y axis is flipped (SVG's y points down): a point (x, y) of M′ is drawn at
/// (margin + (x − xmin)·mmPerUnit, margin + (ymax − y)·mmPerUnit), so the drawing is not
/// mirrored. Pieces (connected components) stay where M′ puts them.
///
/// Every edge is one <line> with data-v0/data-v1 (its vertex indices), in three groups, bottom to
/// top: <g id="mesh"> interior edges (class "mesh", faint grey; only with drawMesh), <g id="cuts">
/// boundary edges that are not glued (class "cut", solid black), <g id="glue"> glued boundary
/// edges (class "glue", blue dashed, data-seam="k"); then <g id="labels">: per seam k = 1, 2, …
/// two <text class="glue-label" data-seam="k" data-side="0|1">k</text>, one beside the middle of
/// each side's edges, inside the piece (towards the edge's face). Glue pairs, glue edges and seams
/// are those of findGlueSeams (with the unfolding's corner rule); both edges of a glued pair carry the same seam number.
///
/// @param unfolding V×2 (or V×3: z is ignored) vertices of M′ in design units
/// @param faces counter-clockwise in M′ (a triangle has [3] = -1)
/// @param gluePairs vertex pairs (i, j) glued together on the 3D mesh
/// @param mmPerUnit millimetres per design unit (> 0)
/// @throws std::invalid_argument for bad faces, glue pairs, non-finite coordinates, mmPerUnit or
///         option lengths.
std::string cuttingPatternSvg(const Eigen::MatrixXd& unfolding, const std::vector<PolygonFace>& faces,
                              const std::vector<std::array<int, 2>>& gluePairs, double mmPerUnit,
                              const CuttingPatternOptions& options = {});

/// Writes cuttingPatternSvg to `path`.
/// @throws std::invalid_argument as above, std::runtime_error naming the file when writing fails.
void writeCuttingPatternSvg(const Eigen::MatrixXd& unfolding, const std::vector<PolygonFace>& faces,
                            const std::vector<std::array<int, 2>>& gluePairs, double mmPerUnit,
                            const std::string& path, const CuttingPatternOptions& options = {});

}  // namespace devsurf::io
