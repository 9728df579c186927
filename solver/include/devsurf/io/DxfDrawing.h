#pragma once

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/io/CreasePattern.h"
#include "devsurf/io/PolygonMesh.h"

namespace devsurf::io {

/// A layer of a fabrication drawing. Cutters and CAD programs assign tools by layer.
struct DxfLayer {
  std::string name;        ///< upper case letters, digits and '_'
  int colour = 7;          ///< AutoCAD Color Index 1 … 255 (1 red, 3 green, 5 blue, 7 black/white, 8 grey)
  bool visible = true;     ///< false: the layer is off (written with a negative colour)
  std::string lineType = "CONTINUOUS";  ///< CONTINUOUS, DASHED or DASHDOT
  std::string description; ///< what the layer holds (a comment in the file's header section)
};

/// A polyline on a layer, in millimetres, y up.
struct DxfPolyline {
  std::string layer;
  std::vector<Eigen::Vector2d> points;  ///< ≥ 2
  bool closed = false;
};

/// A single line of text on a layer (seam numbers), centred on `position`, in millimetres.
struct DxfText {
  std::string layer;
  Eigen::Vector2d position = Eigen::Vector2d::Zero();
  double height = 3.0;
  std::string text;
};

/// A 2D drawing in millimetres for cutters and CAD programs.
struct DxfDrawing {
  std::string title;
  std::vector<DxfLayer> layers;
  std::vector<DxfPolyline> polylines;
  std::vector<DxfText> texts;
};

/// The drawing as an ASCII DXF (AutoCAD 2000, AC1015) written through dxflib: a header with
/// $INSUNITS = 4 (millimetres) and $MEASUREMENT = 1 (metric), the line types CONTINUOUS, DASHED
/// and DASHDOT, the layers (layer "0" first, then the drawing's in order; an invisible layer has
/// a negative colour), LWPOLYLINE entities (closed flag 1 when closed) and TEXT entities, each on
/// its layer with colour BYLAYER. Each layer's description is a comment (group 999) at the top.
/// @throws std::invalid_argument naming the entity for an unknown layer, a polyline of fewer than
///         two points, a non-finite coordinate or a bad layer name, colour or line type.
std::string dxfDocument(const DxfDrawing& drawing);

/// Layers of the fabrication drawings below (ACI colour, line type):
///   CUT      7, continuous   outline of the sheet and slits: cut through
///   MOUNTAIN 1, DASHDOT      mountain folds: score on the back (or half-cut)
///   VALLEY   5, DASHED       valley folds: score on the front
///   GLUE     3, continuous   boundary edges glued to another after cutting: cut through as well
///   LABEL    3               seam numbers: engrave or draw, do not cut
///   RULINGS  8, continuous   rulings of the developable (reference only; off)
///   MESH     8, continuous   interior edges of the pattern's mesh (reference only; off)
/// Crease patterns of composites use CUT, MOUNTAIN, VALLEY and RULINGS; cutting patterns (pieces,
/// unfoldings of quad meshes and strips) CUT, GLUE, LABEL and, when asked, MESH. A drawing
/// declares only the layers its entities are on.
std::vector<DxfLayer> fabricationLayers();

/// The crease pattern of a composite's development at true size: boundary and cut edges on CUT,
/// mountain and valley creases on MOUNTAIN and VALLEY (one polyline per chain of edgeChains), the
/// pattern's rulings on RULINGS; flat edges are left out. Coordinates are the development's times
/// unitToMm (y up, as in the FOLD file).
/// @throws std::invalid_argument as CreasePattern::validate.
DxfDrawing creasePatternDrawing(const CreasePattern& pattern);

/// The cutting pattern of pieces with glue pairs (a quad mesh's unfolding, a composite's pieces cut
/// along seams) at true size: boundary edges that are not glued on CUT, glued ones on GLUE, each
/// side of seam k numbered k on LABEL (findGlueSeams' seams, seamLabelPositions' places), interior
/// edges on MESH when asked. Cuts are chained into outlines, glue edges per side of a seam.
/// @param unfolding V×2 (or V×3: z ignored) in design units
/// @param faces counter-clockwise in the unfolding
/// @param gluePairs vertex pairs glued together in 3D
/// @param mmPerUnit millimetres per design unit (> 0)
/// @param labelHeightMm height of the seam numbers (> 0)
/// @param drawMesh also the interior edges, one line each (a layer that is off)
/// @throws std::invalid_argument as findGlueSeams, or for non-finite coordinates or scale.
DxfDrawing cuttingPatternDrawing(const Eigen::MatrixXd& unfolding, const std::vector<PolygonFace>& faces,
                                 const std::vector<std::array<int, 2>>& gluePairs, double mmPerUnit,
                                 double labelHeightMm = 3.0, bool drawMesh = false);

}  // namespace devsurf::io
