#include "devsurf/models/strip/StripModel.h"

#include <Eigen/Geometry>
#include <algorithm>

#include "devsurf/models/HandleValidation.h"
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/SparseCholesky>

#include "devsurf/spatial/MatrixRowsKdTree.h"
#include "devsurf/spline/RationalBasis.h"
#include "devsurf/terms/ControlPolygonFairnessTerm.h"
#include "devsurf/terms/HandleTargetTerm.h"
#include "devsurf/terms/PolygonBacktrackTerm.h"
#include "devsurf/terms/RulingLengthTerm.h"
#include "devsurf/terms/StripWidthTerm.h"
#include "devsurf/terms/CurveTangentLineDistanceTerm.h"
#include "devsurf/terms/LinearPoints.h"
#include "devsurf/terms/StripDevelopabilityTerm.h"
#include "devsurf/terms/StripFootPoints.h"
#include "devsurf/terms/StripOverhangTerm.h"
#include "devsurf/terms/StripPointDistanceTerm.h"
#include "devsurf/terms/StripReferenceTangencyTerm.h"
#include "devsurf/terms/StripTangentPlaneDistanceTerm.h"
#include "devsurf/terms/UnitNormalTerm.h"

namespace devsurf::models::strip {
namespace {

using engine::Strength;
using engine::WeightSchedule;

/// Median distance from a row of q to its nearest other row (0 for fewer than two rows).
double medianNeighbourSpacing(const Eigen::MatrixX3d& q) {
  if (q.rows() < 2) return 0.0;
  const spatial::MatrixRows rows{q};
  const spatial::MatrixRowsKdTree tree(3, rows, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  std::vector<double> spacing;
  spacing.reserve(static_cast<std::size_t>(q.rows()));
  for (Eigen::Index j = 0; j < q.rows(); ++j) {
    std::size_t found[2] = {0, 0};
    double squared[2] = {0.0, 0.0};
    const Eigen::Vector3d p = q.row(j).transpose();  // a row of a column-major matrix is strided
    tree.knnSearch(p.data(), 2, found, squared);
    spacing.push_back(std::sqrt(squared[1]));
  }
  std::nth_element(spacing.begin(), spacing.begin() + static_cast<std::ptrdiff_t>(spacing.size() / 2), spacing.end());
  return spacing[spacing.size() / 2];
}

bool allFinite(const Eigen::MatrixXd& m) { return m.allFinite(); }

bool degenerate(const Eigen::MatrixXd& points) {
  return (points.rowwise() - points.row(0)).rowwise().norm().maxCoeff() == 0.0;
}

void validateStripCurve(const spline::BSplineCurve& c, const char* name) {
  const std::string n(name);
  if (c.points.cols() != 3) throw std::invalid_argument(n + ".points: expected 3 coordinates per point");
  if (c.points.rows() != c.knots.numControlPoints())
    throw std::invalid_argument(n + ".points: knot vector is for " +
                                std::to_string(c.knots.numControlPoints()) + " control points, got " +
                                std::to_string(c.points.rows()));
  if (!allFinite(c.points)) throw std::invalid_argument(n + ".points: coordinates must be finite");
  if (c.weights.size() > 0) {
    if (c.weights.size() != c.points.rows())
      throw std::invalid_argument(n + ".weights: expected one weight per control point");
    if (!c.weights.allFinite() || (c.weights.array() <= 0.0).any())
      throw std::invalid_argument(n + ".weights: weights must be finite and positive");
  }
}

}  // namespace

const char* curveName(Curve c) { return c == Curve::A ? "a" : "b"; }

void StripModel::validateDesign(StripDesign& design) {
  const spline::BSplineCurve& a = design.a;
  const spline::BSplineCurve& b = design.b;
  validateStripCurve(a, "a");
  validateStripCurve(b, "b");
  if (a.degree() != b.degree())
    throw std::invalid_argument("b.degree: must equal a.degree (" + std::to_string(a.degree()) +
                                "), got " + std::to_string(b.degree()));
  if (a.knots.kind() != b.knots.kind())
    throw std::invalid_argument("b.closed: a and b must both be open or both be closed");
  if (a.points.rows() != b.points.rows())
    throw std::invalid_argument("b.points: expected " + std::to_string(a.points.rows()) +
                                " control points like a, got " + std::to_string(b.points.rows()));
  {
    const auto& ka = a.knots.knots();
    const auto& kb = b.knots.knots();
    const double tol = 1e-12 * std::max(1.0, a.knots.domainEnd() - a.knots.domainBegin());
    bool same = ka.size() == kb.size();
    for (std::size_t i = 0; same && i < ka.size(); ++i) same = std::abs(ka[i] - kb[i]) <= tol;
    if (!same) throw std::invalid_argument("b.knots: must equal a.knots (the strip needs one knot vector)");
  }
  if (degenerate(a.points) && degenerate(b.points))
    throw std::invalid_argument("a.points: a and b are both single points; the strip is degenerate");
  {
    // b on a: every ruling has length 0, a strip of no width (no surface to solve or export).
    const double extent = (a.points.colwise().maxCoeff() - a.points.colwise().minCoeff()).norm() +
                          (b.points.colwise().maxCoeff() - b.points.colwise().minCoeff()).norm();
    if ((a.points - b.points).rowwise().norm().maxCoeff() <= 1e-12 * extent)
      throw std::invalid_argument("b.points: b coincides with a; the strip has no width");
  }
  const int n = static_cast<int>(a.points.rows());
  auto checkRef = [n](const ControlPointRef& r, const std::string& path) {
    if (r.index < 0 || r.index >= n)
      throw std::invalid_argument(path + ".index: " + std::to_string(r.index) +
                                  " is out of range (curve " + curveName(r.curve) + " has " +
                                  std::to_string(n) + " control points)");
  };
  validateUserConstraints(design.fixed, design.handles, checkRef);
  if (design.normals.type == NormalRepresentation::Type::Spline) {
    if (design.normals.degree < 1)
      throw std::invalid_argument("normals.degree: must be at least 1");
    if (design.normals.points == 0) design.normals.points = n;
    if (design.normals.points < design.normals.degree + 1)
      throw std::invalid_argument("normals.points: need at least degree+1 = " +
                                  std::to_string(design.normals.degree + 1) + " control points");
  }
  if (design.approximation) {
    const ApproximationTarget& t = *design.approximation;
    if (t.points.rows() == 0) throw std::invalid_argument("approximation.points: no points");
    if (!t.points.allFinite()) throw std::invalid_argument("approximation.points: coordinates must be finite");
    if (t.normals.rows() != t.points.rows())
      throw std::invalid_argument("approximation.normals: expected one normal per point (" +
                                  std::to_string(t.points.rows()) + "), got " + std::to_string(t.normals.rows()));
    if (!t.normals.allFinite() || (t.normals.rowwise().norm().array() < 1e-12).any())
      throw std::invalid_argument("approximation.normals: normals must be finite and non-zero");
    const std::pair<const char*, double> weights[] = {{"point", t.pointWeight},
                                                      {"tangency", t.tangencyWeight},
                                                      {"tangent_plane", t.tangentPlaneWeight},
                                                      {"overhang", t.overhangWeight}};
    for (const auto& [name, w] : weights)
      if (!std::isfinite(w) || w < 0.0)
        throw std::invalid_argument(std::string("approximation.weights.") + name + ": must be finite and ≥ 0");
    if (!std::isfinite(t.overhangReach) || t.overhangReach < 0.0)
      throw std::invalid_argument("approximation.overhang_reach: must be finite and ≥ 0");
  }
  for (std::size_t t = 0; t < design.boundaryTargets.size(); ++t) {
    const BoundaryTarget& target = design.boundaryTargets[t];
    const std::string path = "boundary_targets[" + std::to_string(t) + "]";
    if (target.polyline.rows() < 2 || !target.polyline.allFinite())
      throw std::invalid_argument(path + ".polyline: expected at least 2 finite points");
    for (Eigen::Index k = 0; k + 1 < target.polyline.rows(); ++k)
      if (!((target.polyline.row(k + 1) - target.polyline.row(k)).norm() > 0.0))
        throw std::invalid_argument(path + ".polyline: points " + std::to_string(k) + " and " +
                                    std::to_string(k + 1) + " coincide");
    if (!std::isfinite(target.weight) || target.weight < 0.0)
      throw std::invalid_argument(path + ".weight: must be finite and ≥ 0");
    if (target.samples < 0 || target.samples == 1 || target.samples > 10000)
      throw std::invalid_argument(path + ".samples: expected 0 (automatic) or 2 … 10000");
  }
  const int perSpan = (a.isRational() || b.isRational()) ? 6 * a.degree() - 3 : 3 * a.degree() - 2;
  const int K = perSpan * a.knots.numSpans();
  if (design.normals.type == NormalRepresentation::Type::Spline && design.normals.points > K)
    throw std::invalid_argument("normals.points: at most " + std::to_string(K) +
                                " (the number of evaluation parameters)");
}

StripModel::StripModel(StripDesign design, StripOptions options)
    : design_(std::move(design)), options_(options) {
  validateDesign(design_);
  if (design_.approximation) {
    options_.widthGuardRatio = std::min(options_.widthGuardRatio, options_.approximationGuardRatio);
    options_.legGuardRatio = std::min(options_.legGuardRatio, options_.approximationGuardRatio);
  }
  const spline::BSplineCurve& a = design_.a;
  const spline::BSplineCurve& b = design_.b;
  const int n = static_cast<int>(a.points.rows());
  // Normalize: centre and scale to unit size (003_… §5.5).
  if (options_.normalize) {
    Eigen::MatrixX3d all(2 * n, 3);
    all << a.points, b.points;
    normalization_ = engine::Normalization::fromPoints(all);
  }
  buildProblem();
  options_.deadline = {};  // it bounds the construction only
}

void StripModel::buildProblem() {
  const spline::BSplineCurve& a = design_.a;
  const spline::BSplineCurve& b = design_.b;
  const int n = static_cast<int>(a.points.rows());
  const int m = a.degree();
  const bool rational = a.isRational() || b.isRational();
  // det(b−a, a′, b′) has degree 3m−3 per span, so 3m−2 parameters suffice (000_… §2.1); for
  // NURBS its numerator has degree ≤ 6m−4 and we use 6m−3.
  params_ = a.knots.spanSamples(rational ? 6 * m - 3 : 3 * m - 2);
  const int K = static_cast<int>(params_.size());

  blockA_ = problem_.addBlock("curve a", 3 * n);
  blockB_ = problem_.addBlock("curve b", 3 * n);
  const bool vectors = design_.normals.type == NormalRepresentation::Type::Vectors;
  const int normalCount = vectors ? K : design_.normals.points;
  blockNormals_ = problem_.addBlock(vectors ? "normals" : "normal spline", 3 * normalCount);
  problem_.layout().setRegularizationScale(blockNormals_, options_.normalRegularizationScale);

  for (int i = 0; i < n; ++i) {
    problem_.blockValues(blockA_).segment<3>(3 * i) =
        normalization_.toNormalized(a.points.row(i).transpose());
    problem_.blockValues(blockB_).segment<3>(3 * i) =
        normalization_.toNormalized(b.points.row(i).transpose());
  }
  for (const ControlPointRef& f : design_.fixed)
    problem_.layout().setFixed(f.curve == Curve::A ? blockA_ : blockB_, 3 * f.index, 3);

  const int offA = problem_.layout().block(blockA_).offset;
  const int offB = problem_.layout().block(blockB_).offset;
  const int offN = problem_.layout().block(blockNormals_).offset;
  curveRows_ = {
      terms::LinearPoints{spline::curveEvaluationMatrix(a.knots, a.weights, params_, 0), offA},
      terms::LinearPoints{spline::curveEvaluationMatrix(a.knots, a.weights, params_, 1), offA},
      terms::LinearPoints{spline::curveEvaluationMatrix(b.knots, b.weights, params_, 0), offB},
      terms::LinearPoints{spline::curveEvaluationMatrix(b.knots, b.weights, params_, 1), offB}};
  const auto& [Pa, Da, Pb, Db] = curveRows_;
  terms::LinearPoints N;
  if (vectors) {
    N = terms::LinearPoints::identity(K, offN);
  } else {
    const double u0 = a.knots.domainBegin(), u1 = a.knots.domainEnd();
    std::vector<double> t(params_.size());
    for (std::size_t k = 0; k < params_.size(); ++k) t[k] = (params_[k] - u0) / (u1 - u0);
    const spline::KnotVector nk =
        a.knots.kind() == spline::KnotKind::Periodic
            ? spline::KnotVector::periodicUniform(design_.normals.degree, normalCount)
            : spline::KnotVector::clampedUniform(design_.normals.degree, normalCount);
    normalEvaluation_ = spline::evaluationMatrix(nk, t, 0);
    N = terms::LinearPoints{normalEvaluation_, offN};
  }
  problem_.addTerm(std::make_unique<terms::StripDevelopabilityTerm>("developability", Pa, Da, Pb,
                                                                    Db, N),
                   options_.developabilityWeight, Strength::Hard);

  // Degeneracy guard: no ruling shrinks below rulingGuardRatio of its length at build time.
  // Guarded rulings: twice as dense as the developability rows, and both ends (an end ruling is
  // the first to collapse when a corner is pulled along it).
  if (options_.rulingGuardRatio > 0.0) {
    std::vector<double> at = a.knots.spanSamples(2 * (3 * m - 2));
    if (a.knots.kind() != spline::KnotKind::Periodic) {
      at.insert(at.begin(), a.knots.domainBegin());
      at.push_back(a.knots.domainEnd());
    }
    const terms::LinearPoints ga{spline::curveEvaluationMatrix(a.knots, a.weights, at, 0), offA};
    const terms::LinearPoints gb{spline::curveEvaluationMatrix(b.knots, b.weights, at, 0), offB};
    std::vector<double> minLength(at.size());
    for (std::size_t k = 0; k < at.size(); ++k) {
      const double length = (gb.point(problem_.x(), static_cast<int>(k)) - ga.point(problem_.x(), static_cast<int>(k))).norm();
      minLength[k] = length > 1e-9 ? options_.rulingGuardRatio * length : 0.0;
    }
    rulingTerm_ = problem_.addTerm(std::make_unique<terms::RulingLengthTerm>("ruling_length", ga, gb, minLength),
                                   1.0, Strength::Hard);
    if (options_.widthGuardRatio > 0.0) {
      // … nor does the strip collapse across its rulings (|(b − a) × (a′ + b′)|), nor does either
      // curve turn into the ruling direction (|(b − a) × a′|, |(b − a) × b′|: sliver quads that
      // fold over).
      const std::vector<terms::StripWidthTerm::SignedPoints> ruling{{ga, -1.0}, {gb, 1.0}};
      const terms::StripWidthTerm::SignedPoints da{
          terms::LinearPoints{spline::curveEvaluationMatrix(a.knots, a.weights, at, 1), offA}, 1.0};
      const terms::StripWidthTerm::SignedPoints db{
          terms::LinearPoints{spline::curveEvaluationMatrix(b.knots, b.weights, at, 1), offB}, 1.0};
      const std::vector<terms::StripWidthTerm::SignedPoints> tangents[] = {{da, db}, {da}, {db}};
      for (const auto& tangent : tangents) {
        std::vector<double> minWidth = terms::StripWidthTerm::widths(ruling, tangent, problem_.x());
        for (double& w : minWidth) w = w > 1e-9 ? options_.widthGuardRatio * w : 0.0;
        widthTerms_.push_back(problem_.addTerm(
            std::make_unique<terms::StripWidthTerm>("strip_width", ruling, tangent, minWidth), 1.0, Strength::Hard));
      }
    }
  }

  // Degeneracy guard: neither control polygon turns back (a cusp in a or b, where the rulings'
  // directions jump and the dense warp angle with them).
  if (options_.backtrackGuard && n >= 3 && a.knots.kind() != spline::KnotKind::Periodic) {
    for (const int off : {offA, offB}) {
      std::vector<int> offsets;
      for (int i = 0; i < n; ++i) offsets.push_back(off + 3 * i);
      // The window pairs legs up to m apart, and at least consecutive ones (a degree-1 strip's
      // polygon is its curve: the fuzzer's degree-1 strip was refused with this term's message).
      problem_.addTerm(std::make_unique<terms::PolygonBacktrackTerm>("curve_backtrack", offsets, problem_.x(), std::max(2, m)),
                       1.0, Strength::Hard);
      // … nor do its legs collapse (coalescing control points turn back unseen).
      spline::EvaluationMatrix W(n - 1, n);
      std::vector<double> minLength(static_cast<std::size_t>(n - 1));
      for (int i = 0; i + 1 < n; ++i) {
        W.insert(i, i) = -1.0;
        W.insert(i, i + 1) = 1.0;
        const double length = (problem_.x().segment<3>(offsets[i + 1]) - problem_.x().segment<3>(offsets[i])).norm();
        minLength[i] = length > 1e-9 ? options_.legGuardRatio * length : 0.0;
      }
      W.makeCompressed();
      spline::EvaluationMatrix none(n - 1, n);
      none.makeCompressed();
      problem_.addTerm(std::make_unique<terms::RulingLengthTerm>("curve_leg_length", terms::LinearPoints{none, off},
                                                                 terms::LinearPoints{W, off}, minLength),
                       1.0, Strength::Hard);
    }
  }

  // Unit normals: hard at the first parameter (the normal spline's first control point), soft
  // elsewhere (000_… §2.2). Mundilova (003_… §5.2.3) also holds the spline's last control point
  // hard; that over-constrains exact developables whose normal field a′×(b−a) has different
  // lengths at the two ends, so we follow Tang et al.
  std::vector<int> hard, soft;
  for (int i = 0; i < normalCount; ++i) {
    (i == 0 ? hard : soft).push_back(offN + 3 * i);
  }
  problem_.addTerm(std::make_unique<terms::UnitNormalTerm>("unit_normal_hard", hard), 1.0,
                   Strength::Hard);
  if (!soft.empty())
    problem_.addTerm(std::make_unique<terms::UnitNormalTerm>("unit_normal", soft),
                     options_.unitNormalWeight, Strength::Soft);

  const bool closed = a.knots.kind() == spline::KnotKind::Periodic;
  problem_.addTerm(std::make_unique<terms::ControlPolygonFairnessTerm>("fairness", offA, n, 3, closed),
                   1.0, Strength::Soft, WeightSchedule::Fairness);
  problem_.addTerm(std::make_unique<terms::ControlPolygonFairnessTerm>("fairness", offB, n, 3, closed),
                   1.0, Strength::Soft, WeightSchedule::Fairness);

  for (const Handle& h : design_.handles) {
    handleTerms_.push_back(problem_.addTerm(
        std::make_unique<terms::HandleTargetTerm>("handle", pointOffset(h.point),
                                                  normalization_.toNormalized(h.position)),
        h.weight, Strength::Soft));
  }
  for (int t : handleTerms_) problem_.term(t).relaxable = true;  // step control may weaken the pull

  if (design_.approximation) {
    // 000_… §4.2: eq. (9)–(11) over closest points shared by the three terms and renewed at every
    // linearization; the points in the solver's normalized coordinates (normals only rotate, and
    // the normalization is a similarity).
    const ApproximationTarget& target = *design_.approximation;
    Eigen::MatrixX3d q(target.points.rows(), 3);
    for (Eigen::Index j = 0; j < q.rows(); ++j)
      q.row(j) = normalization_.toNormalized(target.points.row(j).transpose()).transpose();
    if (target.overhangWeight > 0.0) {
      // Not in the paper: samples of the strip beyond reach of every q_j pulled back (a flap).
      const double reach = target.overhangReach > 0.0 ? target.overhangReach / normalization_.scale
                                                      : 2.0 * medianNeighbourSpacing(q);
      if (reach > 0.0)
        problem_.addTerm(std::make_unique<terms::StripOverhangTerm>("approximation_overhang", a.knots, a.weights, offA,
                                                                    offB, q, reach, 4 * n, 5),
                         target.overhangWeight, Strength::Soft);
    }
    auto feet = std::make_shared<terms::StripFootPoints>(a.knots, a.weights, offA, offB, std::move(q));
    problem_.addTerm(std::make_unique<terms::StripPointDistanceTerm>("approximation_point", feet),
                     target.pointWeight, Strength::Soft);
    problem_.addTerm(std::make_unique<terms::StripReferenceTangencyTerm>("approximation_tangency", feet, target.normals),
                     target.tangencyWeight, Strength::Soft);
    std::optional<terms::StripTangentPlaneDistanceTerm::NormalSpline> normalSpline;
    if (!vectors)
      normalSpline = terms::StripTangentPlaneDistanceTerm::NormalSpline{
          a.knots.kind() == spline::KnotKind::Periodic
              ? spline::KnotVector::periodicUniform(design_.normals.degree, normalCount)
              : spline::KnotVector::clampedUniform(design_.normals.degree, normalCount),
          offN};
    problem_.addTerm(std::make_unique<terms::StripTangentPlaneDistanceTerm>(
                         "approximation_tangent_plane", feet, std::move(normalSpline), a.knots.domainBegin(),
                         a.knots.domainEnd()),
                     target.tangentPlaneWeight, Strength::Soft);
  }

  for (const BoundaryTarget& target : design_.boundaryTargets) {
    // 000_… §4.2: "sampling the curve a_i(u) at regularly spaced parameter values creates vertices
    // v_i,k … connected to the remaining variables by the linear evaluation relation (5)".
    const spline::BSplineCurve& c = target.curve == Curve::A ? a : b;
    const int samples = target.samples > 0 ? target.samples : 4 * n;
    std::vector<double> u(static_cast<std::size_t>(samples));
    for (int k = 0; k < samples; ++k)
      u[static_cast<std::size_t>(k)] =
          c.knots.domainBegin() + (c.knots.domainEnd() - c.knots.domainBegin()) * k / (samples - 1);
    std::vector<Eigen::Vector3d> polyline;
    for (Eigen::Index k = 0; k < target.polyline.rows(); ++k)
      polyline.push_back(normalization_.toNormalized(target.polyline.row(k).transpose()));
    problem_.addTerm(std::make_unique<terms::CurveTangentLineDistanceTerm>(
                         "boundary_proximity",
                         terms::LinearPoints{spline::curveEvaluationMatrix(c.knots, c.weights, u, 0),
                                             target.curve == Curve::A ? offA : offB},
                         std::move(polyline), target.pinEnds),
                     target.weight, Strength::Soft);
  }

  initializeNormals();
  solver_ = std::make_unique<engine::GuidedProjectionSolver>(problem_, options_.linearSolver, options_.deadline);
}

int StripModel::pointOffset(const ControlPointRef& p) const {
  return problem_.layout().block(p.curve == Curve::A ? blockA_ : blockB_).offset + 3 * p.index;
}

void StripModel::initializeNormals() {
  const Eigen::VectorXd& x = problem_.x();
  const auto& [Pa, Da, Pb, Db] = curveRows_;
  const int K = static_cast<int>(params_.size());
  Eigen::MatrixX3d samples(K, 3);
  Eigen::Vector3d previous = Eigen::Vector3d::Zero();
  for (int k = 0; k < K; ++k) {
    const Eigen::Vector3d ruling = Pb.point(x, k) - Pa.point(x, k);
    const Eigen::Vector3d ta = Da.point(x, k), tb = Db.point(x, k);
    // Tangent plane spanned by the ruling and the (mean) tangent: a′×(b−a) in the limit.
    Eigen::Vector3d nk = (ta + tb).cross(ruling);
    if (nk.norm() < 1e-12) nk = ta.cross(tb);
    if (nk.norm() < 1e-12) nk = previous.norm() > 0 ? previous : Eigen::Vector3d::UnitZ();
    nk.normalize();
    if (previous.norm() > 0 && nk.dot(previous) < 0) nk = -nk;
    samples.row(k) = nk.transpose();
    previous = nk;
  }
  Eigen::Map<Eigen::VectorXd> normals = problem_.blockValues(blockNormals_);
  if (design_.normals.type == NormalRepresentation::Type::Vectors) {
    for (int k = 0; k < K; ++k) normals.segment<3>(3 * k) = samples.row(k).transpose();
    return;
  }
  // Normal spline: least-squares fit of its control points to the sampled unit normals (a tiny
  // Tikhonov term keeps the fit well posed).
  const int m = static_cast<int>(normalEvaluation_.cols());
  Eigen::SparseMatrix<double> M = normalEvaluation_;
  Eigen::SparseMatrix<double> A = M.transpose() * M;
  for (int i = 0; i < m; ++i) A.coeffRef(i, i) += 1e-10;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(A);
  const Eigen::MatrixXd rhs = M.transpose() * Eigen::MatrixXd(samples);
  Eigen::MatrixXd control = ldlt.solve(rhs);
  // The first control point is held at unit length (hard): scale the fit so it starts there.
  const double first = control.row(0).norm();
  if (first > 1e-12) control /= first;
  for (int i = 0; i < m; ++i) normals.segment<3>(3 * i) = control.row(i).transpose();
}

void StripModel::resetNormals() { initializeNormals(); }

engine::SolveSummary StripModel::solve(const engine::SolverOptions& options) {
  return solver_->solve(options);
}

void StripModel::setHandleTarget(int i, const Eigen::Vector3d& position) {
  if (i < 0 || i >= static_cast<int>(handleTerms_.size()))
    throw std::out_of_range("handles[" + std::to_string(i) + "]: no such handle");
  if (!position.allFinite())
    throw std::invalid_argument("handles[" + std::to_string(i) + "].position: must be finite");
  design_.handles[static_cast<std::size_t>(i)].position = position;
  auto* term = static_cast<terms::HandleTargetTerm*>(problem_.term(handleTerms_[i]).term.get());
  term->setTarget(normalization_.toNormalized(position));
}

void StripModel::setHandleWeight(int i, double weight) {
  if (i < 0 || i >= static_cast<int>(handleTerms_.size()))
    throw std::out_of_range("handles[" + std::to_string(i) + "]: no such handle");
  if (!(weight >= 0.0) || !std::isfinite(weight))
    throw std::invalid_argument("handles[" + std::to_string(i) + "].weight: must be finite and ≥ 0");
  design_.handles[static_cast<std::size_t>(i)].weight = weight;
  problem_.setWeight(handleTerms_[i], weight);
}

double StripModel::rulingLengthMinRatio() const {
  if (rulingTerm_ < 0) return 1.0;
  const auto* term = static_cast<const terms::RulingLengthTerm*>(problem_.term(rulingTerm_).term.get());
  return term->lengthRatioMin(problem_.x(), options_.rulingGuardRatio);
}

double StripModel::stripWidthMinRatio() const {
  double ratio = 1.0;
  for (int t : widthTerms_)
    ratio = std::min(ratio, static_cast<const terms::StripWidthTerm*>(problem_.term(t).term.get())
                                ->widthRatioMin(problem_.x(), options_.widthGuardRatio));
  return ratio;
}

Eigen::MatrixXd StripModel::controlPoints(Curve c) const {
  const int block = c == Curve::A ? blockA_ : blockB_;
  const Eigen::Map<const Eigen::VectorXd> v = problem_.blockValues(block);
  const int offset = problem_.layout().block(block).offset;
  const Eigen::MatrixXd& original = c == Curve::A ? design_.a.points : design_.b.points;
  const int n = static_cast<int>(v.size() / 3);
  Eigen::MatrixXd points(n, 3);
  for (int i = 0; i < n; ++i) {
    // A fixed point is returned exactly as given (the normalization round trip would perturb
    // it in the last bit).
    const bool fixed = problem_.layout().isFixed(offset + 3 * i);
    points.row(i) = fixed ? Eigen::RowVector3d(original.row(i))
                          : normalization_.fromNormalized(v.segment<3>(3 * i)).transpose();
  }
  return points;
}

StripDesign StripModel::design() const {
  StripDesign d = design_;
  d.a.points = controlPoints(Curve::A);
  d.b.points = controlPoints(Curve::B);
  return d;
}

metrics::StripQuality StripModel::quality(int rulings) const {
  const StripDesign d = design();
  return metrics::stripQuality(d.a, d.b, rulings);
}

StripGeometry StripModel::geometry(int uSamples, int vSamples, int rulings) const {
  if (uSamples < 2 || vSamples < 2 || rulings < 2)
    throw std::invalid_argument("geometry: need at least 2 samples in u and v and 2 rulings");
  const StripDesign d = design();
  const bool closed = d.a.knots.kind() == spline::KnotKind::Periodic;
  const double u0 = d.a.knots.domainBegin(), u1 = d.a.knots.domainEnd();
  auto uAt = [u0, u1, closed](int i, int count) {
    return u0 + (u1 - u0) * static_cast<double>(i) / (closed ? count : count - 1);
  };
  StripGeometry g;
  std::vector<double> us(static_cast<std::size_t>(uSamples));
  for (int i = 0; i < uSamples; ++i) us[static_cast<std::size_t>(i)] = uAt(i, uSamples);
  const Eigen::MatrixXd A = d.a.evaluate(us, 0), B = d.b.evaluate(us, 0);
  g.curveA = A;
  g.curveB = B;
  g.surface.vertices.resize(static_cast<Eigen::Index>(uSamples) * vSamples, 3);
  for (int i = 0; i < uSamples; ++i)
    for (int j = 0; j < vSamples; ++j) {
      const double v = static_cast<double>(j) / (vSamples - 1);
      g.surface.vertices.row(i * vSamples + j) = (1.0 - v) * A.row(i) + v * B.row(i);
    }
  const int uQuads = closed ? uSamples : uSamples - 1;
  g.surface.quads.resize(static_cast<Eigen::Index>(uQuads) * (vSamples - 1), 4);
  int f = 0;
  for (int i = 0; i < uQuads; ++i) {
    const int i1 = (i + 1) % uSamples;
    for (int j = 0; j + 1 < vSamples; ++j)
      g.surface.quads.row(f++) << i * vSamples + j, i1 * vSamples + j, i1 * vSamples + j + 1,
          i * vSamples + j + 1;
  }
  std::vector<double> ur(static_cast<std::size_t>(rulings));
  for (int i = 0; i < rulings; ++i) ur[static_cast<std::size_t>(i)] = uAt(i, rulings);
  g.rulingStart = d.a.evaluate(ur, 0);
  g.rulingEnd = d.b.evaluate(ur, 0);
  const Eigen::MatrixXd Ta = d.a.evaluate(ur, 1);
  g.normals.resize(rulings, 3);
  for (int i = 0; i < rulings; ++i) {
    Eigen::Vector3d nrm = Eigen::Vector3d(Ta.row(i)).cross(
        Eigen::Vector3d(g.rulingEnd.row(i) - g.rulingStart.row(i)));
    g.normals.row(i) = (nrm.norm() > 0 ? nrm.normalized() : nrm).transpose();
  }
  return g;
}

}  // namespace devsurf::models::strip
