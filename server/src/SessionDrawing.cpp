// Layout edits of a composite made from a drawing (issue 16 item 3): draw, erase, relabel and
// reshape creases on the flat sheet. Each changes model.drawing and rebuilds the composite from it
// (models::composite::compositeFromDrawing), flat; refused edits change nothing.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "devsurf/models/composite/CompositeFromDrawing.h"
#include "devsurf/server/Session.h"

namespace devsurf::server {

namespace {

using nlohmann::json;
namespace composite = models::composite;

/// Snap tolerance of a drawn crease's ends, as a fraction of the sheet's diagonal.
constexpr double kDrawingSnapFraction = 0.01;

/// Edit messages this file handles.
bool isDrawingEditType(const std::string& type) {
  return type == "draw_crease" || type == "erase_crease" || type == "relabel_crease" || type == "reshape_crease";
}

/// The polyline a stroke draws (a curved one of few points sampled as compositeFromDrawing does).
std::vector<Eigen::Vector2d> drawnPolyline(const io::CreaseStroke& s) {
  const composite::DrawingOptions defaults;
  const int count = static_cast<int>(s.points.size());
  if (s.curved && count >= 2 && count <= defaults.curveSegments)
    return composite::sampleThroughPoints(s.points, s.closed, std::max(defaults.curveSegments, 2 * count));
  std::vector<Eigen::Vector2d> line = s.points;
  if (s.closed && !line.empty()) line.push_back(line.front());
  return line;
}

/// Bounding box of the sheet: its outline strokes (every stroke when none is marked B).
void sheetBox(const std::vector<io::CreaseStroke>& strokes, Eigen::Vector2d& lo, Eigen::Vector2d& hi) {
  lo.setConstant(std::numeric_limits<double>::infinity());
  hi.setConstant(-std::numeric_limits<double>::infinity());
  const bool anyOutline = std::any_of(strokes.begin(), strokes.end(),
                                      [](const io::CreaseStroke& s) { return s.assignment == io::EdgeAssignment::Boundary; });
  for (const io::CreaseStroke& s : strokes) {
    if (anyOutline && s.assignment != io::EdgeAssignment::Boundary) continue;
    for (const Eigen::Vector2d& p : drawnPolyline(s)) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
}

/// `p` moved onto the nearest stroke other than `skip` when within `tolerance`: onto one of its
/// points when one is that near, else onto the nearest point of its polyline.
Eigen::Vector2d snappedToStrokes(const Eigen::Vector2d& p, const std::vector<io::CreaseStroke>& strokes, int skip,
                                 double tolerance) {
  double bestPoint = tolerance, bestLine = tolerance;
  Eigen::Vector2d atPoint = p, atLine = p;
  bool onPoint = false, onLine = false;
  for (std::size_t i = 0; i < strokes.size(); ++i) {
    if (static_cast<int>(i) == skip) continue;
    const std::vector<Eigen::Vector2d> line = drawnPolyline(strokes[i]);
    for (const Eigen::Vector2d& q : strokes[i].points)
      if ((q - p).norm() <= bestPoint) {
        bestPoint = (q - p).norm();
        atPoint = q;
        onPoint = true;
      }
    for (std::size_t k = 0; k + 1 < line.size(); ++k) {
      const Eigen::Vector2d a = line[k], d = line[k + 1] - line[k];
      const double t = d.squaredNorm() > 0.0 ? std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
      const Eigen::Vector2d q = a + t * d;
      if ((q - p).norm() <= bestLine) {
        bestLine = (q - p).norm();
        atLine = q;
        onLine = true;
      }
    }
  }
  return onPoint ? atPoint : onLine ? atLine : p;
}

std::string pointText(const Eigen::Vector2d& p) {
  std::ostringstream s;
  s.precision(4);
  s << "(" << p.x() << ", " << p.y() << ")";
  return s.str();
}

}  // namespace

bool Session::isDrawingEdit(const std::string& type) { return isDrawingEditType(type); }

bool Session::applyDrawingEdit(int participant, const json& edit, bool replaying) {
  const std::string type = edit.at("type").get<std::string>();
  auto reject = refuser(participant, edit, replaying);
  const proto::Scene before = persistentScene();
  const auto* design = std::get_if<composite::CompositeDesign>(&before.model);
  if (design == nullptr)
    return reject("invalid", std::string("applies to composite sessions drawn on a sheet; this session edits a ") +
                                 proto::modelKind(before.model),
                  "type");
  if (design->drawing.empty())
    return reject("invalid",
                  "this composite has no drawing (it was not made from a crease pattern); import an SVG or FOLD crease "
                  "pattern or start from a blank sheet to draw creases",
                  "type");
  std::vector<io::CreaseStroke> strokes = design->drawing;
  Eigen::Vector2d lo, hi;
  sheetBox(strokes, lo, hi);
  const double diagonal = (hi - lo).norm();
  const double tolerance = kDrawingSnapFraction * diagonal;

  // The stroke a message addresses: it exists and is not the outline.
  int crease = -1;
  if (edit.contains("crease")) {
    crease = edit["crease"].get<int>();
    if (crease >= static_cast<int>(strokes.size()))
      return reject("invalid", "no crease " + std::to_string(crease) + " (the drawing has " + std::to_string(strokes.size()) + " strokes)",
                    "crease");
    if (strokes[static_cast<std::size_t>(crease)].assignment == io::EdgeAssignment::Boundary)
      return reject("invalid", "stroke " + std::to_string(crease) + " is the sheet's outline; only creases and cuts are edited",
                    "crease");
  }
  // What the schema says (the daemon checks it; a session fed directly, as in tests and replays,
  // checks it here too).
  if (edit.contains("assignment")) {
    const json& a = edit["assignment"];
    if (!a.is_string() || (a != "M" && a != "V" && a != "F" && a != "C"))
      return reject("invalid", "expected M, V, F or C (the outline is not drawn)", "assignment");
  }
  if (edit.contains("fold_angle")) {
    const json& a = edit["fold_angle"];
    if (!a.is_number() || !(a.get<double>() > 0.0 && a.get<double>() <= 180.0))
      return reject("invalid", "expected degrees in (0, 180]", "fold_angle");
  }
  auto assignmentOf = [&edit](io::CreaseStroke& s) {
    s.assignment = io::parseFoldAssignment(edit.at("assignment").get<std::string>());
    s.foldAngle.reset();
    const double magnitude = edit.value("fold_angle", 180.0);
    if (s.assignment == io::EdgeAssignment::Mountain) s.foldAngle = -magnitude;
    if (s.assignment == io::EdgeAssignment::Valley) s.foldAngle = magnitude;
  };
  // Points on the sheet, the ends snapped onto the strokes they are meant to meet.
  std::vector<Eigen::Vector2d> points;
  if (edit.contains("points")) {
    for (const json& p : edit["points"]) points.emplace_back(p[0].get<double>(), p[1].get<double>());
    for (std::size_t k = 0; k < points.size(); ++k) {
      const Eigen::Vector2d& p = points[k];
      if (!p.allFinite() || (p.array() < (lo.array() - tolerance)).any() || (p.array() > (hi.array() + tolerance)).any())
        return reject("invalid", "point " + pointText(p) + " is outside the sheet", "points[" + std::to_string(k) + "]");
    }
    points.front() = snappedToStrokes(points.front(), strokes, crease, tolerance);
    points.back() = snappedToStrokes(points.back(), strokes, crease, tolerance);
    for (std::size_t k = 1; k < points.size(); ++k)
      if ((points[k] - points[k - 1]).norm() <= 1e-9 * diagonal)
        return reject("invalid", "points " + std::to_string(k - 1) + " and " + std::to_string(k) + " coincide",
                      "points[" + std::to_string(k) + "]");
  }
  // A straight crease given a third point (a point inserted into it) bends: curved unless told.
  const bool curved = edit.value("curved", crease >= 0 ? strokes[static_cast<std::size_t>(crease)].curved || points.size() > 2 : false);
  if (edit.contains("points")) {
    if (!curved && points.size() != 2)
      return reject("invalid", "a straight crease has 2 points, got " + std::to_string(points.size()) +
                                   " (send curved: true for a spline through them)",
                    "points");
    if (curved && points.size() < 3)
      return reject("invalid", "a curved crease passes through at least 3 points, got " + std::to_string(points.size()),
                    "points");
  }

  int edited = crease;
  if (type == "draw_crease") {
    io::CreaseStroke s;
    s.points = points;
    s.curved = curved;
    assignmentOf(s);
    strokes.push_back(std::move(s));
    edited = static_cast<int>(strokes.size()) - 1;
  } else if (type == "erase_crease") {
    strokes.erase(strokes.begin() + crease);
    edited = -1;
  } else if (type == "relabel_crease") {
    assignmentOf(strokes[static_cast<std::size_t>(crease)]);
  } else {  // reshape_crease
    strokes[static_cast<std::size_t>(crease)].points = points;
    strokes[static_cast<std::size_t>(crease)].curved = curved;
  }

  composite::DrawingComposite built;
  try {
    built = composite::compositeFromDrawing(strokes);
  } catch (const std::length_error& e) {
    return reject("limit", e.what(), edit.contains("points") ? "points" : "crease");
  } catch (const std::invalid_argument& e) {
    return reject("invalid", std::string("the sheet does not make a valid composite with this change: ") + e.what(),
                  edit.contains("points") ? "points" : "crease");
  }
  if (edited >= 0 && built.strokeLeftOut[static_cast<std::size_t>(edited)]) {
    const Eigen::Vector2d a = strokes[static_cast<std::size_t>(edited)].points.front();
    const Eigen::Vector2d b = strokes[static_cast<std::size_t>(edited)].points.back();
    return reject("invalid",
                  "a crease runs from the sheet's outline or another crease to the outline or another crease; this one "
                  "(from " + pointText(a) + " to " + pointText(b) + ") has a free end or leaves the sheet",
                  "points");
  }
  // Another stroke that loses its hold (a crease ending on the one erased or reshaped).
  const bool othersLeftOut = std::any_of(built.strokeLeftOut.begin(), built.strokeLeftOut.end(), [](bool b) { return b; });
  if (othersLeftOut) {
    std::vector<bool> beforeLeftOut;
    try {
      beforeLeftOut = composite::compositeFromDrawing(design->drawing).strokeLeftOut;
    } catch (const std::exception&) {
      beforeLeftOut.assign(design->drawing.size(), false);
    }
    for (std::size_t i = 0; i < strokes.size(); ++i) {
      // Stroke i of the new drawing is stroke j of the old one (erase shifts the later ones down).
      const std::size_t j = type == "erase_crease" && static_cast<int>(i) >= crease ? i + 1 : i;
      const bool wasLeftOut = j < beforeLeftOut.size() && beforeLeftOut[j];
      if (built.strokeLeftOut[i] && !wasLeftOut && static_cast<int>(i) != edited)
        return reject("conflict",
                      "crease " + std::to_string(j) + " ends on this one and would be left with a free end; erase or "
                      "reshape it first",
                      "crease");
    }
  }
  proto::Scene next = before;
  next.model = std::move(built.design);
  return rebuildForEdit(participant, edit, replaying, before, next, edit.contains("points") ? "points" : "crease");
}

}  // namespace devsurf::server
