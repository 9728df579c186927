#include "devsurf/models/composite/ClosedFormDesigns.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "devsurf/spline/Basis.h"
#include "devsurf/spline/KnotVector.h"

namespace devsurf::models::composite {

namespace {

CompositeEdge splineEdge(int v0, int v1, const spline::KnotVector& knots, const Eigen::MatrixX3d& points,
                         CreaseKind crease = CreaseKind::None) {
  CompositeEdge e;
  e.v0 = v0;
  e.v1 = v1;
  e.type = EdgeType::Spline;
  e.curve.knots = knots;
  e.curve.points = points;
  e.crease = crease;
  return e;
}

CompositeEdge rulingEdge(int v0, int v1) {
  CompositeEdge e;
  e.v0 = v0;
  e.v1 = v1;
  e.type = EdgeType::Ruling;
  return e;
}

/// Least-squares fit of f over t ∈ [0, 1] in the span of the clamped B-splines of `knots`, with
/// both end points interpolated: control points n×3.
template <class Function>
Eigen::MatrixX3d designFitWithEnds(const spline::KnotVector& knots, int samplesPerSpan, const Function& f) {
  const int n = knots.numControlPoints();
  std::vector<double> params = knots.spanSamples(samplesPerSpan);
  const spline::EvaluationMatrix basis = spline::evaluationMatrix(knots, params, 0);
  const Eigen::MatrixXd dense = Eigen::MatrixXd(basis);
  Eigen::MatrixX3d values(static_cast<Eigen::Index>(params.size()), 3);
  for (std::size_t k = 0; k < params.size(); ++k) values.row(static_cast<Eigen::Index>(k)) = f(params[k]).transpose();
  Eigen::MatrixX3d points(n, 3);
  points.row(0) = f(knots.domainBegin()).transpose();
  points.row(n - 1) = f(knots.domainEnd()).transpose();
  const Eigen::MatrixXd rhs =
      values - dense.col(0) * points.row(0) - dense.col(n - 1) * points.row(n - 1);
  const Eigen::MatrixXd interior = dense.middleCols(1, n - 2).colPivHouseholderQr().solve(rhs);
  points.middleRows(1, n - 2) = interior;
  return points;
}

}  // namespace

CompositeDesign twoSheetFoldDesign(const spline::KnotVector& knots, const Eigen::MatrixX3d& crease,
                                   const Eigen::MatrixX3d& firstBoundary,
                                   const Eigen::MatrixX3d& secondBoundary) {
  if (knots.kind() != spline::KnotKind::Clamped)
    throw std::invalid_argument("twoSheetFoldDesign: the knot vector must be clamped");
  const Eigen::Index n = knots.numControlPoints();
  if (crease.rows() != n || firstBoundary.rows() != n || secondBoundary.rows() != n)
    throw std::invalid_argument("twoSheetFoldDesign: the knot vector has " + std::to_string(n) +
                                " control points, the curves have " + std::to_string(crease.rows()) + ", " +
                                std::to_string(firstBoundary.rows()) + ", " + std::to_string(secondBoundary.rows()));
  CompositeDesign d;
  d.vertices.resize(6, 3);
  d.vertices.row(0) = crease.row(0);
  d.vertices.row(1) = crease.row(n - 1);
  d.vertices.row(2) = firstBoundary.row(n - 1);
  d.vertices.row(3) = firstBoundary.row(0);
  d.vertices.row(4) = secondBoundary.row(0);
  d.vertices.row(5) = secondBoundary.row(n - 1);
  // b₁ is traversed 2→3 (against u): its stored curve is reversed, with the mirrored knots.
  std::vector<double> reversedKnots(knots.knots().rbegin(), knots.knots().rend());
  const double sum = knots.domainBegin() + knots.domainEnd();
  for (double& t : reversedKnots) t = sum - t;
  const spline::KnotVector firstKnots = spline::KnotVector::clamped(knots.degree(), reversedKnots, static_cast<int>(n));
  const Eigen::MatrixX3d firstReversed = firstBoundary.colwise().reverse();
  d.edges = {splineEdge(0, 1, knots, crease, CreaseKind::Fold),
             rulingEdge(1, 2),
             splineEdge(2, 3, firstKnots, firstReversed),
             rulingEdge(3, 0),
             rulingEdge(0, 4),
             splineEdge(4, 5, knots, secondBoundary),
             rulingEdge(5, 1)};
  d.faces = {{0, 1, 2, 3}, {4, 5, 6, 0}};
  return d;
}

PlanarFoldSpec defaultPlanarFoldSpec() {
  PlanarFoldSpec s;
  Eigen::MatrixXd g(7, 2);
  g << 0.0, 0.0, 0.5, 0.45, 1.0, 0.6, 1.5, 0.1, 2.0, -0.45, 2.5, -0.3, 3.0, 0.2;
  s.profile.knots = spline::KnotVector::clampedUniform(3, 7);
  s.profile.points = g;
  return s;
}

CompositeDesign planarFoldDesign(const PlanarFoldSpec& spec) {
  spec.profile.validate();
  if (spec.profile.isRational() || spec.profile.dimension() != 2)
    throw std::invalid_argument("planarFoldDesign: the profile must be a polynomial B-spline in the plane (n×2 points)");
  if (spec.profile.knots.kind() != spline::KnotKind::Clamped)
    throw std::invalid_argument("planarFoldDesign: the profile must be clamped");
  const double length = spec.planeNormal.norm();
  if (!(length > 0.0) || std::abs(spec.planeNormal.z()) < 1e-9 * length)
    throw std::invalid_argument("planarFoldDesign: the crease plane must not contain e3 (planeNormal.z ≈ 0)");
  const Eigen::Vector3d normal = spec.planeNormal / length;
  const double offset = spec.planeOffset / length;
  const Eigen::Index n = spec.profile.points.rows();
  Eigen::MatrixX3d crease(n, 3), first(n, 3), second(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double x = spec.profile.points(i, 0), y = spec.profile.points(i, 1);
    const double z = (offset - normal.x() * x - normal.y() * y) / normal.z();
    if (!(spec.top > z) || !(spec.bottom < z))
      throw std::invalid_argument("planarFoldDesign: profile point " + std::to_string(i) + " meets the crease plane at z = " +
                                  std::to_string(z) + ", outside (bottom, top) = (" + std::to_string(spec.bottom) +
                                  ", " + std::to_string(spec.top) + ")");
    crease.row(i) << x, y, z;
    first.row(i) << x, y, spec.top;
    const Eigen::Vector3d low(x, y, spec.bottom);
    second.row(i) = (low - 2.0 * (normal.dot(low) - offset) * normal).transpose();
  }
  return twoSheetFoldDesign(spec.profile.knots, crease, first, second);
}

CompositeDesign cylinderCatenaryCreaseDesign(const creases::CylinderCatenaryCrease& crease, const ClosedFormFit& fit) {
  if (fit.degree < 2) throw std::invalid_argument("cylinderCatenaryCreaseDesign: degree must be ≥ 2 (the fold needs c″)");
  if (fit.spans < 1) throw std::invalid_argument("cylinderCatenaryCreaseDesign: spans must be ≥ 1");
  if (fit.samplesPerSpan < 1) throw std::invalid_argument("cylinderCatenaryCreaseDesign: samplesPerSpan must be ≥ 1");
  const spline::KnotVector knots = spline::KnotVector::clampedUniform(fit.degree, fit.spans + fit.degree);
  const double u0 = crease.u0(), du = crease.u1() - crease.u0(), length = crease.rulingLength();
  auto creaseAt = [&crease, u0, du](double t) -> Eigen::Vector3d { return crease.crease(u0 + du * t); };
  auto secondAt = [&crease, u0, du, length](double t) -> Eigen::Vector3d {
    const double u = u0 + du * t;
    return crease.crease(u) + length * crease.ruling(1, u);
  };
  const Eigen::MatrixX3d c = designFitWithEnds(knots, fit.samplesPerSpan, creaseAt);
  const Eigen::MatrixX3d b2 = designFitWithEnds(knots, fit.samplesPerSpan, secondAt);
  const Eigen::MatrixX3d b1 = c.rowwise() + Eigen::RowVector3d(0.0, 0.0, length * crease.side());
  return twoSheetFoldDesign(knots, c, b1, b2);
}

double cylinderCatenaryFitError(const creases::CylinderCatenaryCrease& crease, const CompositeDesign& design,
                                int samples) {
  if (design.edges.size() != 7 || design.edges[kClosedFormCreaseEdge].type != EdgeType::Spline ||
      design.edges[kClosedFormSecondBoundaryEdge].type != EdgeType::Spline)
    throw std::invalid_argument("cylinderCatenaryFitError: not a closed-form fold design (7 edges, S edges 0 and 5)");
  if (samples < 2) throw std::invalid_argument("cylinderCatenaryFitError: samples must be ≥ 2");
  const spline::BSplineCurve& c = design.edges[kClosedFormCreaseEdge].curve;
  const spline::BSplineCurve& b2 = design.edges[kClosedFormSecondBoundaryEdge].curve;
  const double t0 = c.knots.domainBegin(), t1 = c.knots.domainEnd();
  double error = 0.0;
  for (int k = 0; k < samples; ++k) {
    const double s = static_cast<double>(k) / (samples - 1);
    const double t = t0 + (t1 - t0) * s;
    const double u = crease.u0() + (crease.u1() - crease.u0()) * s;
    const Eigen::Vector3d exactCrease = crease.crease(u);
    const Eigen::Vector3d exactSecond = exactCrease + crease.rulingLength() * crease.ruling(1, u);
    error = std::max({error, (Eigen::Vector3d(c.evaluate(t)) - exactCrease).norm(),
                      (Eigen::Vector3d(b2.evaluate(t)) - exactSecond).norm()});
  }
  return error;
}

creases::CylinderCatenaryCrease defaultCylinderCatenaryCrease() {
  return creases::CylinderCatenaryCrease(1.0, -1.0, 1.0, 0.8, +1);
}

}  // namespace devsurf::models::composite
