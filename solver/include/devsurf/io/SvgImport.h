#pragma once

#include <string>
#include <vector>

#include "devsurf/io/CreasePattern.h"
#include "devsurf/io/CreaseStrokes.h"
#include "devsurf/io/FoldImport.h"

namespace devsurf::io {

/// Limits and sampling of importSvgText.
struct SvgImportOptions {
  /// Points per curved path segment (cubic, quadratic Bézier; arcs get this many per half turn).
  int samplesPerCurve = 16;
  /// Pieces each straight stroke is cut into when the drawing has curved creases, so rulings can be
  /// proposed to points along it (a drawing of straight creases only keeps one edge per stroke).
  int straightPieces = 6;
  /// Refused (std::length_error) above this many segments after sampling.
  int maxSegments = 20000;
  /// Points closer than this fraction of the drawing's diagonal are one point, and a stroke ending
  /// this close to another meets it (hand-drawn end points rarely land exactly).
  double mergeFraction = 5e-4;
  /// An open stroke's end farther than the merge tolerance but within this fraction of the
  /// drawing's diagonal from another stroke is moved onto it, with a note (snapNearlyMeetingEnds).
  double snapFraction = 0.01;
};

/// A crease pattern read from an SVG drawing, and what the reading changed or left out.
struct SvgImport {
  /// Development in millimetres (pattern.unitToMm = 1), y up (the SVG's y axis points down, so
  /// the drawing is mirrored in y: faces stay counter-clockwise seen from the viewer of the
  /// drawing, which is the front of the sheet). Edges of one stroke share CreaseEdge::curve when
  /// the drawing has curved creases (−1 otherwise); faces from the planar arrangement.
  CreasePattern pattern;
  std::vector<ImportNote> notes;  ///< by element: "path[2]", "path#crease-a", "svg"
  int curvedStrokes = 0;          ///< strokes that are not straight (curved creases or outline)
  int strokes = 0;                ///< strokes read (after splitting paths at corners)
  /// The strokes themselves (millimetres, y up; `curved` set), the drawing a composite made from
  /// this pattern keeps (CompositeDesign::drawing).
  std::vector<CreaseStroke> drawing;
  /// Whether the drawing states its size (a width or height in a unit, px included): else one user
  /// unit was read as one px (1/96 in), `mmPerUserUnit`.
  bool sizeStated = false;
  double mmPerUserUnit = 25.4 / 96.0;  ///< the scale the drawing was read at (x, when uneven)
};

/// Reads a crease pattern drawn as SVG, with Origami Simulator's conventions
/// (origamisimulator.org, "File import tips"): stroke colour per assignment — black boundary, red
/// mountain, blue valley, green cut, yellow facet (flat), magenta undriven (flat) — and the
/// stroke's opacity as the fold angle (opacity × 180°; 1 when absent).
///  * Elements: line, polyline, polygon, rect, circle, ellipse and path (M L H V C S Q T A Z,
///    absolute and relative); transforms of the element and its groups; stroke and opacity from
///    attributes, inline style, class rules of <style> elements and inherited from groups. Hidden
///    elements, <defs>, <use>, <text> and <image> are left out (noted).
///  * Paths are split into strokes at corners (tangent turning by more than 10°; in a path of 8
///    or more pieces — closed, with at most a quarter of its joins turning 10°–25° — such a join is
///    no corner when a neighbouring join turns the same way by a third as much: a sampled curve
///    bending hard is not cut, a polygon keeps its corners); pieces of no length are passed over; a polyline bent slightly where other strokes end on it is split into its
///    straight lines (splitIntoStraightRuns); Bézier pieces
///    and arcs are sampled (options.samplesPerCurve) into edges sharing one curve id.
///  * Units: the root's width/height with viewBox; px at 96 per inch when unitless. Everything is
///    converted to millimetres.
///  * Faces: spatial::planarArrangement of all strokes (crossings split, dangling strokes left
///    out, noted; islands — closed strokes touching nothing — joined to what surrounds them by two
///    straight bridges each, proposed rulings of the composite, noted). Faces enclosed by black
///    strokes inside the sheet are holes, cut out (noted). Edges on the outline become boundary
///    edges whatever their colour (noted when coloured as a crease); other black lines inside the
///    sheet become cuts (noted).
/// @throws std::invalid_argument "SVG: …" for malformed XML, a root other than <svg>, malformed
///         path data (naming the element) or a drawing enclosing no face
/// @throws std::length_error past options.maxSegments
SvgImport importSvgText(const std::string& text, const SvgImportOptions& options = {});

}  // namespace devsurf::io
