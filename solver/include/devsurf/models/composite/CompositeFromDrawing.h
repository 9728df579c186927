#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/io/CreaseStrokes.h"
#include "devsurf/io/FoldImport.h"
#include "devsurf/models/composite/CompositeDesign.h"

namespace devsurf::models::composite {

/// Sampling of compositeFromDrawing.
struct DrawingOptions {
  /// A curved stroke of at most this many points is sampled along the interpolating spline
  /// through its points to max(curveSegments, 2 × points) segments (a crease drawn by clicks); a
  /// stroke with more points (an SVG curve, already sampled) is taken as its polyline.
  int curveSegments = 16;
  io::CreaseStrokesOptions strokes;  ///< the arrangement's tolerances and limits
};

/// A composite rebuilt from its drawing, and what the rebuilding left out.
struct DrawingComposite {
  CompositeDesign design;  ///< flat (foldAmount 0), design.drawing = the strokes as given
  std::vector<io::ImportNote> notes;
  /// Per stroke: whether some piece of it bounds no face (a free end, a tail beyond the outline,
  /// a stroke apart from the sheet), so the built design does not follow all of it.
  std::vector<bool> strokeLeftOut;
};

/// The points a curved stroke is drawn through, sampled along the centripetal Catmull–Rom spline
/// through them (it passes through every given point, without cusps or self-intersections
/// within a span): `segments` segments in all, spread over the spans by their chord length, at
/// least one per span. A closed stroke wraps around (no repeated first point in the result).
/// @param[in] points  the stroke's points, ≥ 2 (2: the straight segment)
std::vector<Eigen::Vector2d> sampleThroughPoints(const std::vector<Eigen::Vector2d>& points, bool closed, int segments);

/// Builds the composite a flat drawing describes (io::creasePatternFromStrokes, then
/// compositeFromCreasePattern: planar faces between straight creases, curved folds with proposed
/// rulings where a stroke is curved), flat, with the drawing attached so layout edits can change it
/// and build again. Strokes' `element` is set to "drawing.strokes[i]" for the notes.
/// @throws std::invalid_argument when the strokes make no face or no valid composite (the message
///         names the face or stroke); std::length_error past options.strokes.maxSegments
DrawingComposite compositeFromDrawing(std::vector<io::CreaseStroke> drawing, const DrawingOptions& options = {});

/// Strokes of a straight-crease pattern (one per edge, two points, its assignment and fold angle),
/// so a pattern read from a FOLD file becomes a drawing.
std::vector<io::CreaseStroke> drawingOfCreasePattern(const io::CreasePattern& pattern);

}  // namespace devsurf::models::composite
