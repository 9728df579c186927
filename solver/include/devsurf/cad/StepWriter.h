#pragma once

#include <string>
#include <vector>

#include "devsurf/io/IgesWriter.h"

namespace devsurf::cad {

/// What stepDocument writes; defaults as documented.
struct StepOptions {
  /// Model units: "mm", "cm", "m" or "in" (the scene's; written as the file's length unit).
  std::string units = "mm";
  /// Join the faces along common edges into shells (BRepBuilderAPI_Sewing) so that patches which
  /// share a boundary curve share one topological edge in the file: a watertight model reads back
  /// as one shell. Without sewing the faces are independent members of a compound.
  bool sew = false;
  /// Sewing tolerance in model units (edges closer than this are merged).
  double sewingTolerance = 1e-6;
};

/// A STEP AP214 file (ISO 10303-21 text, OpenCascade's STEPControl_Writer) holding each surface
/// as a face bounded by its natural boundary: the surfaces are the same B-spline records the IGES
/// writer takes (degrees, clamped or unclamped knots, control points with u fastest, optional
/// weights), written as B_SPLINE_SURFACE_WITH_KNOTS (RATIONAL_… with weights).
/// @throws std::invalid_argument naming the surface ("surfaces[1].knotsU: …") when sizes disagree
///         or a value is not finite
/// @throws std::runtime_error if OpenCascade cannot build or write the model
std::string stepDocument(const std::vector<io::IgesSurface>& surfaces, const StepOptions& options = {});

}  // namespace devsurf::cad
