#pragma once

#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/io/CreasePattern.h"
#include "devsurf/io/FoldImport.h"

namespace devsurf::io {

/// A stroke whose points all lie within this fraction of the drawing's diagonal of its chord is
/// straight: a tenth of the import's merge tolerance, so a straight line written with a few
/// decimals (devsurf's own SVG export of a 4 mm pattern at 0.1 µm, a tool's rounded px) is not
/// read as a curve, while any curve a designer means bends far more.
inline constexpr double kStraightStrokeFraction = 5e-5;

/// One stroke of a drawn crease pattern: a polyline without corners (a straight line, a sampled
/// curve, or a closed curve), in millimetres with y up (the front of the sheet faces the viewer).
struct CreaseStroke {
  std::vector<Eigen::Vector2d> points;  ///< ≥ 2 points; a closed stroke does not repeat its first
  bool closed = false;
  /// Not straight (set by creasePatternFromStrokes: deviation from the chord above
  /// kStraightStrokeFraction × the drawing's diagonal, or closed).
  bool curved = false;
  EdgeAssignment assignment = EdgeAssignment::Flat;
  std::optional<double> foldAngle;  ///< degrees, FOLD convention (+ valley, − mountain)
  std::string element;              ///< where it came from, for notes ("path#crease-a")
};

/// Sampling and limits of creasePatternFromStrokes.
struct CreaseStrokesOptions {
  /// Pieces each straight stroke is cut into when the drawing has curved strokes, so rulings can be
  /// proposed to points along it (a drawing of straight creases keeps one edge per stroke).
  int straightPieces = 6;
  int maxSegments = 20000;      ///< std::length_error beyond
  /// Points where the strokes end or meet (on other than two pieces of the arrangement):
  /// std::length_error beyond (a
  /// scene's development holds at most 10 000 corners; a 150 × 150 grid of lines, 23 104 points,
  /// took 5–14 s to be refused by the scene's schema once the whole composite was built).
  int maxPoints = 10000;
  double mergeFraction = 5e-4;  ///< merge tolerance as a fraction of the drawing's diagonal
  /// The kind of file the strokes come from, named in messages and notes: "SVG" (strokes in
  /// colours) or "FOLD" (lines of edges, foldCurvedCreases).
  std::string source = "SVG";
  /// The strokes' `curved` flags are already decided (foldCurvedCreases: with the file's rounding
  /// and devsurf's curve marks): kept instead of measured again.
  bool curvedDecided = false;
};

/// Moves the open ends of strokes that nearly meet another stroke onto it, as a hand-drawn end
/// meant to: an end farther from every other stroke than `mergeFraction` × the drawing's diagonal
/// (the arrangement joins those itself) but within `snapFraction` × the diagonal of one goes onto
/// the nearest point of that stroke's polyline (onto its vertex when the foot is within the merge
/// tolerance of one). One note per moved end, naming both strokes and the gap. Strokes of no
/// length, strokes no longer than twice the snap distance and closed strokes keep their points.
/// @param[in,out] strokes  in the drawing's units (millimetres for an SVG)
/// @return the notes, by the moved stroke's element
std::vector<ImportNote> snapNearlyMeetingEnds(std::vector<CreaseStroke>& strokes, double mergeFraction = 5e-4,
                                              double snapFraction = 0.01);

/// Absorbs the jogs of hand-drawn paths: a piece of a path (strokes of one `element`, cut where
/// the path turns) no longer than `jogFraction` × the drawing's diagonal at the path's start or end
/// is dropped, and the piece it joins runs on to the jog's far end instead — a 1 mm kink where a
/// crease leaves the outline made a sliver face that no fold could hinge on. One note per jog.
/// @param[in,out] strokes  in the drawing's units (millimetres for an SVG)
/// @return the notes, by element
std::vector<ImportNote> absorbEndJogs(std::vector<CreaseStroke>& strokes, double jogFraction = 0.01);

/// Splits a slightly kinked polyline into the straight lines it is made of: an open stroke of three
/// or more points that is not straight (kStraightStrokeFraction) is cut at its inner points where
/// another stroke ends (within `mergeFraction` × the drawing's diagonal) when every part is
/// straight. A development's side drawn through the ends of its creases (devsurf's own SVG export:
/// rulings of neighbouring strips meet there at a small angle) is three straight sides, not one
/// curve with no straight end — read as a curve, the faces beside it had no layout. A curve a
/// crease ends on keeps its points. One note per split stroke.
/// @param[in,out] strokes  in the drawing's units; split strokes keep their element and assignment
/// @return the notes, by element
std::vector<ImportNote> splitIntoStraightRuns(std::vector<CreaseStroke>& strokes, double mergeFraction = 5e-4);

/// A crease pattern made from strokes, with what the making changed or left out.
struct StrokePattern {
  CreasePattern pattern;
  std::vector<ImportNote> notes;
  int strokes = 0;
  int curvedStrokes = 0;
  /// Per stroke: some piece of it bounds no face (a free end, a tail beyond the outline, a stroke
  /// apart from the sheet), so the pattern does not follow all of it.
  std::vector<bool> strokeLeftOut;
  std::vector<bool> strokeCurved;  ///< per stroke: CreaseStroke::curved as decided here
};

/// The crease pattern a set of strokes draws: every stroke cut into segments (its pieces keep the
/// stroke's index as CreaseEdge::curve when any stroke is curved, else −1), faces from
/// spatial::planarArrangement (crossings split, dangling strokes left out, islands bridged, faces
/// walled off by black strokes cut out as holes, noted by element; a bridge is a CreaseEdge with
/// `proposed` set). Edges on the outline become boundary edges whatever their stroke (noted when a crease
/// colour), boundary strokes inside the sheet cuts (noted); fold angles from the strokes.
/// Development in millimetres (unitToMm = 1), no folded state.
/// @throws std::invalid_argument "SVG: …" for no strokes, no extent or no face
/// @throws std::length_error past options.maxSegments or options.maxPoints
StrokePattern creasePatternFromStrokes(std::vector<CreaseStroke> strokes, const CreaseStrokesOptions& options = {});

}  // namespace devsurf::io
