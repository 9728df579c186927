#include "devsurf/models/conical_strip/ConicalStripModel.h"

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Geometry>

#include "devsurf/models/CurvePairWidth.h"

namespace devsurf::models::conical_strip {

namespace {

using Clock = std::chrono::steady_clock;

constexpr double kPi = 3.14159265358979323846;
constexpr double kRightAngle = 0.5 * kPi;  ///< a fold-back, as counted and as the quality holds it

double millisecondsSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

[[noreturn]] void failConical(const std::string& message) { throw std::invalid_argument(message); }

/// Angle between two unit vectors, accurate for tiny angles.
double angleBetween(const Eigen::Vector3d& n0, const Eigen::Vector3d& n1) {
  return std::atan2(n0.cross(n1).norm(), n0.dot(n1));
}

ArcLengthCurve makeCurve(const spline::BSplineCurve& curve, const char* field,
                         int intervalsPerSpan) {
  try {
    return ArcLengthCurve(curve, intervalsPerSpan);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string(field) + ": " + e.what());
  }
}

const ConicalStripDesign& validated(const ConicalStripDesign& d, const ConicalStripOptions& o) {
  if (d.np < 2) failConical("np: need at least 2 samples on P, got " + std::to_string(d.np));
  if (d.nq < 2) failConical("nq: need at least 2 samples on Q, got " + std::to_string(d.nq));
  if (!(std::isfinite(d.h3) && d.h3 > 0.0)) failConical("h3: must be finite and positive");
  if (!(std::isfinite(d.h4) && d.h4 > 0.0)) failConical("h4: must be finite and positive");
  if (!(std::isfinite(d.ra) && d.ra >= 1.0)) failConical("ra: must be finite and >= 1");
  if (o.arcLengthIntervalsPerSpan < 1) failConical("options.arcLengthIntervalsPerSpan: must be >= 1");
  if (o.intersectionScanSteps < 1) failConical("options.intersectionScanSteps: must be >= 1");
  if (o.outlineSamples < 1) failConical("options.outlineSamples: must be >= 1");
  if (!(o.foldBackAngle > 0.0)) failConical("options.foldBackAngle: must be positive (π or more: off)");
  if (!(o.tangentLengthMin > 0.0 && o.tangentLengthMax >= o.tangentLengthMin)) {
    failConical("options.tangentLengthMin/tangentLengthMax: need 0 < min <= max");
  }
  return d;
}

/// One side of the strip during the greedy march.
struct SideState {
  const ArcLengthCurve* curve = nullptr;
  const std::vector<double>* params = nullptr;  ///< sample parameters
  const Eigen::MatrixX3d* samples = nullptr;
  int index = 0;                                ///< the sample the current corner stands for
  Eigen::Vector3d corner = Eigen::Vector3d::Zero();
  double param = 0.0;                           ///< nearest curve parameter of the corner

  int last() const { return static_cast<int>(params->size()) - 1; }
  Eigen::Vector3d sample(int k) const { return samples->row(k).transpose(); }
  double sampleParam(int k) const { return (*params)[k]; }
};

struct Candidate {
  ConicalPatch patch;
  double criterion = 0.0;
  Eigen::Vector3d newCornerX = Eigen::Vector3d::Zero();  ///< corner on the patch's base side
  Eigen::Vector3d newCornerY = Eigen::Vector3d::Zero();  ///< corner on the scaled side
  double newParamY = 0.0;
  double newRulingLength = 0.0;  ///< |newCornerX − newCornerY|: the ruling the patch ends on
  /// A quadrilateral: the sample of the scaled side its end corner replaces (the sample nearest to
  /// the plane/curve crossing; samples between the start and it are skipped). -1 for triangles.
  int newIndexY = -1;
};

/// The base boundary from the current corner of `x` to its next sample (§3.1 heuristic).
Eigen::MatrixX3d quadraticBase(const SideState& x) {
  const ArcLengthCurve& c = *x.curve;
  const int next = x.index + 1;
  const double u0 = x.param, u1 = x.sampleParam(next);
  const double middle = c.parameterAt(0.5 * (c.arcLength(u0) + c.arcLength(u1)));
  Eigen::MatrixX3d base(3, 3);
  base.row(0) = x.corner.transpose();
  base.row(1) = quadraticMiddleControl(x.corner, c.unitTangent(u0), x.sample(next),
                                       c.unitTangent(u1), c.point(middle))
                    .transpose();
  base.row(2) = x.sample(next).transpose();
  return base;
}

void setRulingRecords(ConicalPatch& patch, const SideState& p, const SideState& q) {
  patch.pBegin = p.index;
  patch.qBegin = q.index;
  patch.pParamBegin = p.param;
  patch.qParamBegin = q.param;
}

/// Triangle with apex at the current corner of `apexSide`, advancing `x` to its next sample.
Candidate triangle(const SideState& x, const SideState& apexSide, StripSide baseSide,
                   const SideState& p, const SideState& q) {
  Candidate c;
  c.patch.type = PatchType::Triangular;
  c.patch.baseSide = baseSide;
  setConicalForm(c.patch, quadraticBase(x), apexSide.corner, 1.0);
  setRulingRecords(c.patch, p, q);
  c.newCornerX = x.sample(x.index + 1);
  c.newCornerY = apexSide.corner;
  c.newParamY = apexSide.param;
  c.newRulingLength = (c.newCornerX - c.newCornerY).norm();
  return c;
}

/// The sides after `c` is taken: its base side at its next sample, and for a quadrilateral the
/// scaled side at the corner it replaces.
void advanceSides(const Candidate& c, SideState& p, SideState& q) {
  const bool baseIsP = c.patch.baseSide == StripSide::P;
  SideState& x = baseIsP ? p : q;
  SideState& y = baseIsP ? q : p;
  x.index += 1;
  x.corner = c.newCornerX;
  x.param = x.sampleParam(x.index);
  if (c.patch.type == PatchType::Quadrilateral) {
    y.index = c.newIndexY;
    y.corner = c.newCornerY;
    y.param = c.newParamY;
  }
}

struct QuadOutcome {
  bool sideTestPassed = false;
  std::optional<Candidate> candidate;
  enum class Rejection { None, NoCrossing, Distance, Ratio, Corner } rejection = Rejection::None;
};

/// Quadrilateral driven by `x` (its next sample kept), Step 2 side test and Step 3 (1)/(2).
QuadOutcome quadrilateral(const SideState& x, const SideState& y, StripSide baseSide,
                          const SideState& p, const SideState& q, const ConicalStripDesign& design,
                          const ConicalStripOptions& options) {
  QuadOutcome out;
  const ArcLengthCurve& cx = *x.curve;
  const ArcLengthCurve& cy = *y.curve;
  const Eigen::Vector3d xNext = x.sample(x.index + 1);
  const Eigen::Vector3d yNext = y.sample(y.index + 1);
  const Eigen::Vector3d d = y.corner - x.corner;
  Eigen::Vector3d n = (xNext - x.corner).cross(d);
  const double scale = std::max(d.norm(), (xNext - x.corner).norm());
  if (!(n.norm() > 1e-14 * scale * scale)) return out;  // degenerate triangle
  n.normalize();
  // Step 2: the curve tangents at the ruling's ends on the same side of the triangle.
  const double sx = cx.unitTangent(x.param).dot(n), sy = cy.unitTangent(y.param).dot(n);
  const bool coplanarAlready = std::abs(n.dot(yNext - x.corner)) <= 1e-12 * scale;
  if (!(sx * sy > 0.0) && !coplanarAlready) return out;
  out.sideTestPassed = true;
  // Step 3: intersect the plane (x.corner, xNext, y.corner) with curve y near its next sample.
  double root = y.sampleParam(y.index + 1);
  if (!coplanarAlready) {
    const double s0 = cy.arcLength(y.param), s1 = cy.arcLength(y.sampleParam(y.index + 1));
    // Up to h4 beyond the next sample, but short of the last sample (which no quadrilateral may
    // replace: the strip ends on the ruling p_m q_n).
    const double sBeforeLast = cy.arcLength(y.sampleParam(y.last() - 1));
    const double sLast = cy.arcLength(y.sampleParam(y.last()));
    const double uBegin = cy.parameterAt(s0 + 0.1 * (s1 - s0));
    const double uEnd =
        cy.parameterAt(std::min(s1 + design.h4, sBeforeLast + 0.5 * (sLast - sBeforeLast)));
    const std::vector<double> roots =
        cy.planeCrossings(x.corner, n, uBegin, uEnd, options.intersectionScanSteps);
    if (roots.empty()) {
      out.rejection = QuadOutcome::Rejection::NoCrossing;
      return out;
    }
    double best = std::numeric_limits<double>::infinity();
    for (double u : roots) {
      const double dist = (cy.point(u) - yNext).norm();
      if (dist < best) {
        best = dist;
        root = u;
      }
    }
  }
  const Eigen::Vector3d yNew = cy.point(root);
  // The sample the crossing replaces: the nearest one after the current corner.
  int replaced = y.index + 1;
  for (int k = y.index + 2; k < y.last(); ++k) {
    if ((y.sample(k) - yNew).norm() < (y.sample(replaced) - yNew).norm()) replaced = k;
  }
  if (!((yNew - yNext).norm() <= design.h4 && (yNew - y.sample(replaced)).norm() <= design.h4)) {
    out.rejection = QuadOutcome::Rejection::Distance;
    return out;
  }
  // Projection point: O = x.corner + s d on the start ruling, meeting the line xNext → yNew.
  const Eigen::Vector3d e = yNew - xNext, w = x.corner - xNext;
  const double aa = d.dot(d), bb = d.dot(e), cc = e.dot(e), dd = d.dot(w), ee = e.dot(w);
  const double den = aa * cc - bb * bb, sNumerator = bb * ee - cc * dd;
  if (sNumerator == 0.0) return out;  // the rulings meet at x.corner
  const double f = den / sNumerator;  // eq. 3 scaling factor; 1 − f is the boundary length ratio
  const double ratio = 1.0 - f;
  if (!(ratio >= 1.0 / design.ra && ratio <= design.ra)) {
    out.rejection = QuadOutcome::Rejection::Ratio;
    return out;
  }

  Candidate c;
  c.patch.type = PatchType::Quadrilateral;
  c.patch.baseSide = baseSide;
  setConicalForm(c.patch, quadraticBase(x), y.corner, f);
  setRulingRecords(c.patch, p, q);
  const Eigen::Vector3d scaledEnd = c.patch.scaled().row(2).transpose();
  if (!((scaledEnd - yNew).norm() <= design.h4)) {
    out.rejection = QuadOutcome::Rejection::Corner;
    return out;
  }
  c.newCornerX = xNext;
  c.newCornerY = scaledEnd;
  c.newParamY = root;
  c.newIndexY = replaced;
  out.candidate = std::move(c);
  return out;
}

/// Step 4 criterion of a candidate following `previous` (or, for the first patch, the candidate's
/// own change from its start to its end ruling).
double criterion(const ConicalPatch& candidate, const ConicalPatch* previous, Objective objective) {
  const ConicalPatch& before = previous != nullptr ? *previous : candidate;
  const double uBefore = previous != nullptr ? 1.0 : 0.0;
  const Eigen::Vector3d n0 = before.normal(uBefore);
  const Eigen::Vector3d n1 = previous != nullptr ? candidate.normal(0.0) : candidate.normal(1.0);
  if (objective == Objective::NormalVariation) return 1.0 - n0.dot(n1);
  const double sin2 = n0.cross(n1).squaredNorm();
  const double arm = before.momentArm(before.pointA(uBefore), before.pointB(uBefore));
  return arm > 0.0 ? candidate.area() * sin2 / (arm * arm) : 0.0;
}

/// The candidate with the smallest `key` (the first of equals).
template <class Key>
const Candidate* smallest(const std::vector<Candidate*>& candidates, Key key) {
  const Candidate* chosen = nullptr;
  for (const Candidate* c : candidates) {
    if (chosen == nullptr || key(*c) < key(*chosen)) chosen = c;
  }
  return chosen;
}

/// Unit normal of the G1 tangent plane along the ruling a b: the plane spanned by the ruling and
/// the average of the curves' unit tangents at its ends (§4.2), or `fallback` where that average
/// is (nearly) along the ruling.
Eigen::Vector3d rulingPlaneNormal(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                  const Eigen::Vector3d& tangentP, const Eigen::Vector3d& tangentQ,
                                  const Eigen::Vector3d& fallback) {
  const Eigen::Vector3d r = (b - a).normalized();
  Eigen::Vector3d n = (tangentP + tangentQ).cross(r);
  if (!(n.norm() > 1e-6 * (tangentP + tangentQ).norm())) n = fallback.cross(r);
  return n.normalized();
}

/// The boundary direction at a ruling for the G1 adjustment: the curve tangent projected into the
/// ruling's tangent plane (normal `planeNormal`), oriented along the strip.
Eigen::Vector3d tangentInPlane(const Eigen::Vector3d& curveTangent,
                               const Eigen::Vector3d& planeNormal, const Eigen::Vector3d& ruling) {
  Eigen::Vector3d t = curveTangent - curveTangent.dot(planeNormal) * planeNormal;
  // Forward means (t × ruling) · n > 0, the orientation every patch's normal has.
  if (!(t.norm() > 1e-6) || t.cross(ruling).dot(planeNormal) <= 0.0) {
    t = ruling.cross(planeNormal);  // in the plane, orthogonal to the ruling, forward
  }
  return t.normalized();
}

}  // namespace

const char* objectiveName(Objective objective) {
  return objective == Objective::NormalVariation ? "normal_variation" : "bending_energy";
}

spline::BSplineCurve ConicalStripDesign::polyline(const Eigen::MatrixX3d& points) {
  const Eigen::Index n = points.rows();
  if (n < 2) failConical("polyline: need at least 2 points, got " + std::to_string(n));
  if (!points.allFinite()) failConical("polyline: points must be finite");
  std::vector<double> knots{0.0, 0.0};
  double total = 0.0;
  std::vector<double> cumulative{0.0};
  for (Eigen::Index k = 1; k < n; ++k) {
    const double len = (points.row(k) - points.row(k - 1)).norm();
    if (!(len > 0.0)) failConical("polyline: points[" + std::to_string(k) + "] repeats the previous point");
    total += len;
    cumulative.push_back(total);
  }
  for (Eigen::Index k = 1; k + 1 < n; ++k) knots.push_back(cumulative[k] / total);
  knots.push_back(1.0);
  knots.push_back(1.0);
  spline::BSplineCurve c;
  c.knots = spline::KnotVector::clamped(1, knots, static_cast<int>(n));
  c.points = points;
  return c;
}

ConicalStripModel::ConicalStripModel(ConicalStripDesign design, ConicalStripOptions options)
    : design_(validated(design, options)),
      options_(options),
      curveP_(makeCurve(design_.p, "p", options.arcLengthIntervalsPerSpan)),
      curveQ_(makeCurve(design_.q, "q", options.arcLengthIntervalsPerSpan)) {
  requireCurvePairWidth(design_.p, design_.q, "p", "q");
}

const ConicalStripResult& ConicalStripModel::result() const {
  if (!solved_) throw std::logic_error("ConicalStripModel::result: call solve() first");
  return result_;
}

const ConicalStripSummary& ConicalStripModel::solve() {
  const Clock::time_point start = Clock::now();
  const engine::Deadline& deadline = options_.deadline;
  solved_ = false;
  deadline.check();
  summary_ = ConicalStripSummary{};
  result_ = ConicalStripResult{};
  ConicalStripResult& r = result_;

  // Step 1: equal arc-length samples.
  r.paramsP = curveP_.equalArcLengthParameters(design_.np);
  r.paramsQ = curveQ_.equalArcLengthParameters(design_.nq);
  r.samplesP.resize(design_.np, 3);
  r.samplesQ.resize(design_.nq, 3);
  deadline.check();
  for (int k = 0; k < design_.np; ++k) r.samplesP.row(k) = curveP_.point(r.paramsP[k]).transpose();
  for (int k = 0; k < design_.nq; ++k) r.samplesQ.row(k) = curveQ_.point(r.paramsQ[k]).transpose();
  r.cornersP = r.samplesP;
  r.cornersQ = r.samplesQ;
  r.replacedP.assign(design_.np, false);
  r.replacedQ.assign(design_.nq, false);
  r.skippedP.assign(design_.np, false);
  r.skippedQ.assign(design_.nq, false);

  SideState p{&curveP_, &r.paramsP, &r.samplesP, 0, r.samplesP.row(0).transpose(), r.paramsP[0]};
  SideState q{&curveQ_, &r.paramsQ, &r.samplesQ, 0, r.samplesQ.row(0).transpose(), r.paramsQ[0]};

  const auto countQuadOutcome = [this](const QuadOutcome& o) {
    summary_.quadCandidatesTested += o.sideTestPassed ? 1 : 0;
    using R = QuadOutcome::Rejection;
    summary_.quadRejectedNoCrossing += o.rejection == R::NoCrossing ? 1 : 0;
    summary_.quadRejectedDistance += o.rejection == R::Distance ? 1 : 0;
    summary_.quadRejectedRatio += o.rejection == R::Ratio ? 1 : 0;
    summary_.quadRejectedCorner += o.rejection == R::Corner ? 1 : 0;
  };
  // Steps 2–5.
  while (p.index < p.last() || q.index < q.last()) {
    deadline.check();
    const ConicalPatch* previous = r.greedyPatches.empty() ? nullptr : &r.greedyPatches.back();
    std::vector<Candidate> quads, triangles;
    if (p.index < p.last() && q.index + 2 <= q.last()) {
      QuadOutcome o = quadrilateral(p, q, StripSide::P, p, q, design_, options_);
      countQuadOutcome(o);
      if (o.candidate) quads.push_back(std::move(*o.candidate));
    }
    if (q.index < q.last() && p.index + 2 <= p.last()) {
      QuadOutcome o = quadrilateral(q, p, StripSide::Q, p, q, design_, options_);
      countQuadOutcome(o);
      if (o.candidate) quads.push_back(std::move(*o.candidate));
    }
    summary_.quadCandidatesFeasible += static_cast<int>(quads.size());
    std::vector<Candidate> forced;
    if (p.index < p.last()) {  // apex on Q, advance P (Step 3 (4))
      Candidate c = triangle(p, q, StripSide::P, p, q);
      ((p.sample(p.index + 1) - q.corner).norm() <= design_.h3 ? triangles : forced)
          .push_back(std::move(c));
    }
    if (q.index < q.last()) {  // apex on P, advance Q (Step 3 (3))
      Candidate c = triangle(q, p, StripSide::Q, p, q);
      ((q.sample(q.index + 1) - p.corner).norm() <= design_.h3 ? triangles : forced)
          .push_back(std::move(c));
    }
    // Step 4: quadrilaterals first, then feasible triangles, then (forced) any triangle, the one of
    // smallest criterion. Not in the paper: each pool without the candidates that fold the strip
    // back or trap it (options.foldBackAngle), as long as some candidate does neither.
    const auto foldsBack = [this](const ConicalPatch* before, const ConicalPatch& after) {
      return before != nullptr &&
             angleBetween(before->normal(1.0), after.normal(0.0)) > options_.foldBackAngle;
    };
    // A trap: after the candidate, a side that is not finished can only advance (by a triangle)
    // folding back. A fan of triangles on one apex has no normal jump, so the criterion keeps it
    // going until the other side's next triangle turns by 180° (the hat brim at h3 = 9).
    // Once a side is finished the rest is determined: a fan on its last corner over the other
    // side's remaining samples; that fan must not fold back either.
    const auto trapsOrFoldsBack = [&p, &q, previous, &foldsBack](const Candidate& c) {
      if (foldsBack(previous, c.patch)) return true;
      SideState p2 = p, q2 = q;
      advanceSides(c, p2, q2);
      const bool pOpen = p2.index < p2.last(), qOpen = q2.index < q2.last();
      if (pOpen && qOpen) {
        return foldsBack(&c.patch, triangle(p2, q2, StripSide::P, p2, q2).patch) ||
               foldsBack(&c.patch, triangle(q2, p2, StripSide::Q, p2, q2).patch);
      }
      ConicalPatch before = c.patch;
      while (p2.index < p2.last() || q2.index < q2.last()) {
        const bool advanceP = p2.index < p2.last();
        Candidate fan = advanceP ? triangle(p2, q2, StripSide::P, p2, q2) : triangle(q2, p2, StripSide::Q, p2, q2);
        if (foldsBack(&before, fan.patch)) return true;
        advanceSides(fan, p2, q2);
        before = std::move(fan.patch);
      }
      return false;
    };
    std::vector<Candidate>* const pools[] = {&quads, &triangles, &forced};
    int paperPool = -1, guardedPool = -1;
    std::vector<Candidate*> pool;
    for (int k = 0; k < 3; ++k) {
      for (Candidate& c : *pools[k]) c.criterion = criterion(c.patch, previous, design_.objective);
      if (paperPool < 0 && !pools[k]->empty()) paperPool = k;
    }
    assert(paperPool >= 0 && "a triangle always exists");
    const auto firstPool = [&pools, &pool, &guardedPool](const auto& acceptable) {
      for (int k = 0; k < 3 && pool.empty(); ++k) {
        for (Candidate& c : *pools[k])
          if (acceptable(c)) pool.push_back(&c);
        guardedPool = k;
      }
    };
    const size_t candidates = quads.size() + triangles.size() + forced.size();
    if (options_.foldBackAngle < kPi && candidates > 1) {  // one candidate: nothing to choose
      firstPool([&trapsOrFoldsBack](const Candidate& c) { return !trapsOrFoldsBack(c); });
      if (pool.empty())
        firstPool([&foldsBack, previous](const Candidate& c) { return !foldsBack(previous, c.patch); });
    }
    if (pool.empty()) {  // Step 4 as published
      for (Candidate& c : *pools[paperPool]) pool.push_back(&c);
      guardedPool = paperPool;
    }
    if (pools[guardedPool] == &forced) ++summary_.forcedTriangles;
    // A forced step (no triangle within h3) takes the shorter new ruling, not the criterion, which
    // would keep a fan going.
    const auto byCriterion = [](const Candidate& c) { return c.criterion; };
    const auto byRulingLength = [](const Candidate& c) { return c.newRulingLength; };
    Candidate chosen = pools[guardedPool] == &forced ? *smallest(pool, byRulingLength) : *smallest(pool, byCriterion);
    if (previous != nullptr && angleBetween(previous->normal(1.0), chosen.patch.normal(0.0)) > kRightAngle)
      ++summary_.foldBacksTaken;

    // Advance.
    const bool baseIsP = chosen.patch.baseSide == StripSide::P;
    if (chosen.patch.type == PatchType::Quadrilateral) {
      const SideState& y = baseIsP ? q : p;
      std::vector<bool>& skipped = baseIsP ? r.skippedQ : r.skippedP;
      for (int k = y.index + 1; k < chosen.newIndexY; ++k) skipped[k] = true;
      Eigen::MatrixX3d& corners = baseIsP ? r.cornersQ : r.cornersP;
      corners.row(chosen.newIndexY) = chosen.newCornerY.transpose();
      (baseIsP ? r.replacedQ : r.replacedP)[chosen.newIndexY] = true;
    }
    advanceSides(chosen, p, q);
    chosen.patch.pEnd = p.index;
    chosen.patch.qEnd = q.index;
    chosen.patch.pParamEnd = p.param;
    chosen.patch.qParamEnd = q.param;
    r.greedyPatches.push_back(std::move(chosen.patch));
  }
  summary_.greedyMs = millisecondsSince(start);

  // §4: degree elevation and G1 adjustment.
  const Clock::time_point g1Start = Clock::now();
  if (design_.g1) {
    const size_t m = r.greedyPatches.size();
    r.rulingPlaneNormals.resize(m + 1);
    for (size_t k = 0; k <= m; ++k) {
      const bool end = k == m;
      const ConicalPatch& patch = r.greedyPatches[end ? m - 1 : k];
      const double u = end ? 1.0 : 0.0;
      const double up = end ? patch.pParamEnd : patch.pParamBegin;
      const double uq = end ? patch.qParamEnd : patch.qParamBegin;
      const Eigen::Vector3d own = patch.derivativeA(u) + patch.derivativeB(u);
      r.rulingPlaneNormals[k] = rulingPlaneNormal(
          patch.pointA(u), patch.pointB(u), curveP_.unitTangent(up), curveQ_.unitTangent(uq), own);
    }
    r.patches.reserve(m);
    for (size_t k = 0; k < m; ++k) {
      if (k % 64 == 0) deadline.check();
      const ConicalPatch& greedy = r.greedyPatches[k];
      const ConicalPatch elevated = elevateDegree(greedy);
      const bool baseIsP = elevated.baseSide == StripSide::P;
      const ArcLengthCurve& curve = baseIsP ? curveP_ : curveQ_;
      const double u0 = baseIsP ? greedy.pParamBegin : greedy.qParamBegin;
      const double u1 = baseIsP ? greedy.pParamEnd : greedy.qParamEnd;
      const Eigen::MatrixX3d& e = elevated.base();
      const Eigen::Vector3d b0 = e.row(0).transpose(), b3 = e.row(3).transpose();
      const Eigen::Vector3d ruling0 = greedy.pointB(0.0) - greedy.pointA(0.0);
      const Eigen::Vector3d ruling1 = greedy.pointB(1.0) - greedy.pointA(1.0);
      const Eigen::Vector3d t0 =
          tangentInPlane(curve.unitTangent(u0), r.rulingPlaneNormals[k], ruling0);
      const Eigen::Vector3d t1 =
          tangentInPlane(curve.unitTangent(u1), r.rulingPlaneNormals[k + 1], ruling1);
      const double chord = (b3 - b0).norm();
      const double lo = options_.tangentLengthMin * chord, hi = options_.tangentLengthMax * chord;
      const double w1 = std::clamp((e.row(1).transpose() - b0).dot(t0), lo, hi);
      const double w2 = std::clamp((b3 - e.row(2).transpose()).dot(t1), lo, hi);
      Eigen::MatrixX3d base = e;
      base.row(1) = (b0 + w1 * t0).transpose();
      base.row(2) = (b3 - w2 * t1).transpose();
      ConicalPatch adjusted = elevated;
      setConicalForm(adjusted, base, elevated.scaled().row(0).transpose(), elevated.scale);
      r.patches.push_back(std::move(adjusted));
    }
  } else {
    r.patches = r.greedyPatches;
  }
  summary_.g1Ms = millisecondsSince(g1Start);

  const Clock::time_point metricsStart = Clock::now();
  r.metrics = measureStrip(r.patches, curveP_, curveQ_, options_.outlineSamples, deadline);
  r.greedyMetrics = design_.g1 ? measureStrip(r.greedyPatches, curveP_, curveQ_,
                                              options_.outlineSamples, deadline)
                               : r.metrics;
  r.unfolded = unfoldStrip(r.patches, options_.outlineSamples, deadline);
  summary_.metricsMs = millisecondsSince(metricsStart);

  summary_.termination = "completed";
  summary_.patches = static_cast<int>(r.patches.size());
  summary_.triangular = r.metrics.n3;
  summary_.quadrilateral = r.metrics.n4;
  summary_.timeMs = millisecondsSince(start);
  solved_ = true;
  return summary_;
}

ConicalStripMetrics measureStrip(const std::vector<ConicalPatch>& patches,
                                 const ArcLengthCurve& curveP, const ArcLengthCurve& curveQ,
                                 int outlineSamples, const engine::Deadline& deadline) {
  ConicalStripMetrics m;
  const auto searchRange = [](const ArcLengthCurve& c, double u0, double u1) {
    const double s0 = c.arcLength(u0), s1 = c.arcLength(u1);
    const double margin = std::max(s1 - s0, 1e-3 * c.length());
    return std::pair<double, double>{c.parameterAt(s0 - margin), c.parameterAt(s1 + margin)};
  };
  for (size_t k = 0; k < patches.size(); ++k) {
    if (k % 16 == 0) deadline.check();
    const ConicalPatch& patch = patches[k];
    (patch.type == PatchType::Triangular ? m.n3 : m.n4) += 1;
    m.projectionResidualMax = std::max(m.projectionResidualMax, projectionResidual(patch));
    m.coplanarityResidualMax = std::max(m.coplanarityResidualMax, coplanarityResidual(patch));
    const auto rangeP = searchRange(curveP, patch.pParamBegin, patch.pParamEnd);
    const auto rangeQ = searchRange(curveQ, patch.qParamBegin, patch.qParamEnd);
    for (int s = 0; s <= outlineSamples; ++s) {
      const double u = static_cast<double>(s) / outlineSamples;
      const double dp = curveP.closestPoint(patch.pointA(u), rangeP.first, rangeP.second).distance;
      const double dq = curveQ.closestPoint(patch.pointB(u), rangeQ.first, rangeQ.second).distance;
      m.deviationMax = std::max({m.deviationMax, dp, dq});
      if (s == 0 || s == outlineSamples) m.cornerDeviationMax = std::max({m.cornerDeviationMax, dp, dq});
    }
    if (k + 1 < patches.size()) {
      const ConicalPatch& next = patches[k + 1];
      const Eigen::Vector3d n0 = patch.normal(1.0), n1 = next.normal(0.0);
      m.normalVariation += 1.0 - n0.dot(n1);
      m.normalJumpMaxRad = std::max(m.normalJumpMaxRad, angleBetween(n0, n1));
      const double arm = patch.momentArm(patch.pointA(1.0), patch.pointB(1.0));
      if (arm > 0.0) m.bendingEnergy += next.area() * n0.cross(n1).squaredNorm() / (arm * arm);
    }
  }
  return m;
}

std::vector<UnfoldedPatch> unfoldStrip(const std::vector<ConicalPatch>& patches,
                                       int outlineSamples, const engine::Deadline& deadline) {
  std::vector<UnfoldedPatch> out;
  out.reserve(patches.size());
  // Places X given placed Y, Z (2D) from 3D distances, on the side that keeps the orientation of
  // the 3D triangle (Y, Z, X) about the normal n.
  const auto place = [](const Eigen::Vector3d& y3, const Eigen::Vector3d& z3,
                        const Eigen::Vector3d& x3, const Eigen::Vector3d& n,
                        const Eigen::Vector2d& y2, const Eigen::Vector2d& z2) {
    const double yz = (z2 - y2).norm(), xy = (x3 - y3).norm(), xz = (x3 - z3).norm();
    if (!(yz > 0.0)) return Eigen::Vector2d(y2);
    const Eigen::Vector2d e = (z2 - y2) / yz;
    const Eigen::Vector2d ePerp(-e.y(), e.x());
    const double along = (xy * xy - xz * xz + yz * yz) / (2.0 * yz);
    const double across = std::sqrt(std::max(0.0, xy * xy - along * along));
    const double orientation = (z3 - y3).cross(x3 - y3).dot(n) >= 0.0 ? 1.0 : -1.0;
    return Eigen::Vector2d(y2 + along * e + orientation * across * ePerp);
  };
  Eigen::Vector2d a2(0.0, 0.0), b2(0.0, 0.0);
  for (size_t k = 0; k < patches.size(); ++k) {
    if (k % 64 == 0) deadline.check();
    const ConicalPatch& patch = patches[k];
    UnfoldedPatch u;
    u.a.resize(outlineSamples + 1, 2);
    u.b.resize(outlineSamples + 1, 2);
    Eigen::Vector3d a3 = patch.pointA(0.0), b3 = patch.pointB(0.0);
    if (k == 0) b2 = Eigen::Vector2d(0.0, (b3 - a3).norm());
    u.a.row(0) = a2.transpose();
    u.b.row(0) = b2.transpose();
    for (int s = 1; s <= outlineSamples; ++s) {
      const double t = static_cast<double>(s) / outlineSamples;
      const double tMid = (s - 0.5) / outlineSamples;
      const Eigen::Vector3d n = patch.normal(tMid);
      const Eigen::Vector3d aNext = patch.pointA(t), bNext = patch.pointB(t);
      const Eigen::Vector2d aNext2 = aNext == a3 ? a2 : place(a3, b3, aNext, n, a2, b2);
      const Eigen::Vector2d bNext2 =
          bNext == b3 ? b2 : place(b3, aNext, bNext, n, b2, aNext2);
      a3 = aNext;
      b3 = bNext;
      a2 = aNext2;
      b2 = bNext2;
      u.a.row(s) = a2.transpose();
      u.b.row(s) = b2.transpose();
    }
    out.push_back(std::move(u));
  }
  return out;
}

}  // namespace devsurf::models::conical_strip
