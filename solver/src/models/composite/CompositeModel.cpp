#include "devsurf/models/composite/CompositeModel.h"

#include "CompositeModelState.h"
#include "CompositeRows.h"

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <memory>

#include "devsurf/models/HandleValidation.h"
#include <cmath>
#include <stdexcept>
#include <string>

#include "devsurf/terms/PolygonBacktrackTerm.h"
#include "devsurf/terms/PolygonFairnessTerm.h"
#include "devsurf/terms/RulingLengthTerm.h"
#include "devsurf/terms/StripWidthTerm.h"
#include "devsurf/spline/Basis.h"
#include "devsurf/terms/CurvedFoldTerm.h"
#include "devsurf/terms/HandleTargetTerm.h"
#include "devsurf/terms/NormalMatchTerm.h"
#include "devsurf/terms/NormalSplineUnitTerm.h"
#include "devsurf/terms/PlanarPolygonTerm.h"
#include "devsurf/terms/StraightUnfoldingTerm.h"
#include "devsurf/terms/StripDevelopabilityTerm.h"
#include "devsurf/terms/UnitNormalTerm.h"

namespace devsurf::models::composite {

using detail::evaluationParams;
using detail::selectRows;

namespace {

using engine::Strength;
using engine::WeightSchedule;
using spline::EvaluationMatrix;

bool stripLike(const FaceInfo& f) { return f.type != FaceType::Planar; }

/// The normal spline of a face (000_… §2.2, §7) evaluated at `params`: on the face's own knots
/// when its curves are cubic (one control point per curve control point, C² across simple knots:
/// Tang's degree 3 and smoothness C²); otherwise of degree min(3, m) on the face's breakpoints with
/// simple knots (spans + degree control points — never more than the parameters, so the fit of
/// initializeNormals is determined: a linear face of one span has 3 parameters and 2 control
/// points). Composite edges are clamped (CompositeTopology), so the spline is too.
EvaluationMatrix normalSplineEvaluation(const spline::KnotVector& faceKnots, const std::vector<double>& params) {
  const int m = faceKnots.degree();
  if (m == 3) return spline::evaluationMatrix(faceKnots, params, 0);
  const int d = std::min(3, m);
  const std::vector<double> breaks = faceKnots.breakpoints();
  std::vector<double> knots(static_cast<std::size_t>(d + 1), breaks.front());
  for (std::size_t i = 1; i + 1 < breaks.size(); ++i) knots.push_back(breaks[i]);
  knots.insert(knots.end(), static_cast<std::size_t>(d + 1), breaks.back());
  const int count = static_cast<int>(knots.size()) - d - 1;
  return spline::evaluationMatrix(spline::KnotVector::clamped(d, knots, count), params, 0);
}

EvaluationMatrix emptyRows(int rows, int cols) {
  EvaluationMatrix m(rows, cols);
  m.makeCompressed();
  return m;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// validation and setup

CompositeModel::CompositeModel(CompositeDesign design, CompositeOptions options)
    : design_(std::move(design)), options_(options), stateCache_(std::make_unique<StateCache>()) {
  validateDesign(design_);
  topology_ = std::make_unique<CompositeTopology>(design_);
  std::vector<Eigen::Vector3d> all;
  for (Eigen::Index v = 0; v < design_.vertices.rows(); ++v) all.push_back(design_.vertices.row(v).transpose());
  for (const CompositeEdge& e : design_.edges)
    for (Eigen::Index i = 0; i < e.curve.points.rows(); ++i) all.push_back(e.curve.points.row(i).transpose());
  Eigen::MatrixX3d pts(static_cast<Eigen::Index>(all.size()), 3);
  for (std::size_t i = 0; i < all.size(); ++i) pts.row(static_cast<Eigen::Index>(i)) = all[i].transpose();
  scale_ = std::max((pts.colwise().maxCoeff() - pts.colwise().minCoeff()).norm(), 1e-300);
  if (options_.normalize) normalization_ = engine::Normalization::fromPoints(pts);
  buildProblem();
  options_.deadline = {};  // it bounds the construction only (unfold() runs in solves too)
}

CompositeModel::~CompositeModel() = default;

int CompositeModel::pointIndex(const PointSlot& s) const {
  if (s.vertex >= 0) return problem_.layout().block(vertexBlock_[s.vertex]).offset / 3;
  return problem_.layout().block(edgeBlock_[s.edge]).offset / 3 + s.index;
}

PointSlot CompositeModel::slotOf(const PointRef& r) const {
  if (r.vertex >= 0) return {r.vertex, -1, 0};
  const auto ends = topology_->edgeVertices(r.edge);
  const int n = topology_->interiorPoints(r.edge) + 2;
  if (r.index == 0) return {ends[0], -1, 0};
  if (r.index == n - 1) return {ends[1], -1, 0};
  return {-1, r.edge, r.index - 1};
}

terms::LinearPoints CompositeModel::curveRows(const spline::KnotVector& knots, const std::vector<PointSlot>& slots,
                                              const std::vector<double>& params, int derivative) const {
  const EvaluationMatrix M = spline::evaluationMatrix(knots, params, derivative);
  std::vector<Eigen::Triplet<double>> t;
  for (int k = 0; k < M.rows(); ++k)
    for (EvaluationMatrix::InnerIterator it(M, k); it; ++it)
      t.emplace_back(k, pointIndex(slots[static_cast<std::size_t>(it.col())]), it.value());
  EvaluationMatrix W(M.rows(), problem_.x().size() / 3);
  W.setFromTriplets(t.begin(), t.end());
  W.makeCompressed();
  return {W, 0};
}

terms::LinearPoints CompositeModel::faceNormals(int f) const {
  const int offset = problem_.layout().block(normalBlock_[f]).offset;
  if (!stripLike(topology_->face(f))) return terms::LinearPoints::identity(1, offset);
  if (!normalSplineRows_.empty() && normalSplineRows_[f].rows() > 0) return {normalSplineRows_[f], offset};
  return terms::LinearPoints::identity(static_cast<int>(faceParams_[f].size()), offset);
}

terms::LinearPoints CompositeModel::normalsAlongEdge(int f, int e) const {
  const terms::LinearPoints all = faceNormals(f);
  const int K = static_cast<int>(faceParams_[f].size());
  const bool runs = topology_->edgeRunsWithU(f, e);
  std::vector<int> rows(static_cast<std::size_t>(K));
  for (int k = 0; k < K; ++k) rows[static_cast<std::size_t>(k)] = runs ? k : K - 1 - k;
  return {selectRows(all.weights, rows), all.offset};
}

terms::LinearPoints CompositeModel::normalAtRuling(int f, int e) const {
  const terms::LinearPoints all = faceNormals(f);
  if (!stripLike(topology_->face(f))) return all;
  const int K = static_cast<int>(faceParams_[f].size());
  const int end = topology_->rulingEnd(f, e);
  if (end < 0) throw std::logic_error("edge " + std::to_string(e) + " is not a ruling of face " + std::to_string(f));
  return {selectRows(all.weights, {end == 0 ? 0 : K - 1}), all.offset};
}

void CompositeModel::buildProblem() {
  const CompositeTopology& topo = *topology_;
  const int V = topo.numVertices(), E = topo.numEdges(), F = topo.numFaces();
  vertexBlock_.assign(V, -1);
  edgeBlock_.assign(E, -1);
  normalBlock_.assign(F, -1);
  faceParams_.assign(F, {});
  normalSplineRows_.assign(options_.normalSplines ? F : 0, EvaluationMatrix());
  faceRows_.assign(F, {});
  for (int v = 0; v < V; ++v) vertexBlock_[v] = problem_.addBlock("vertex " + std::to_string(v), 3);
  for (int e = 0; e < E; ++e)
    if (topo.edgeType(e) == EdgeType::Spline && topo.interiorPoints(e) > 0)
      edgeBlock_[e] = problem_.addBlock("edge " + std::to_string(e) + " points", 3 * topo.interiorPoints(e));
  for (int f = 0; f < F; ++f) {
    const FaceInfo& info = topo.face(f);
    if (stripLike(info)) {
      faceParams_[f] = evaluationParams(info.knots);
      int count = static_cast<int>(faceParams_[f].size());
      if (options_.normalSplines) {
        normalSplineRows_[f] = normalSplineEvaluation(info.knots, faceParams_[f]);
        count = static_cast<int>(normalSplineRows_[f].cols());
      }
      normalBlock_[f] = problem_.addBlock("face " + std::to_string(f) + (options_.normalSplines ? " normal spline" : " normals"),
                                          3 * count);
    } else {
      normalBlock_[f] = problem_.addBlock("face " + std::to_string(f) + " normal", 3);
    }
    problem_.layout().setRegularizationScale(normalBlock_[f], options_.normalRegularizationScale);
  }
  oscBlock_.assign(E, -1);
  for (int e = 0; e < E; ++e)
    if (topo.edgeType(e) == EdgeType::Spline && design_.edges[e].crease == CreaseKind::Straight) {
      oscBlock_[e] = problem_.addBlock("edge " + std::to_string(e) + " osculating normals",
                                       3 * static_cast<int>(evaluationParams(topo.knots(e)).size()));
      problem_.layout().setRegularizationScale(oscBlock_[e], options_.normalRegularizationScale);
    }
  if (design_.developmentSamples > 0) {
    buildDevelopmentMesh();
    developmentBlock_ = problem_.addBlock("development", 2 * devSpatial_.rows());
    if (!devPeriodic_.empty()) periodBlock_ = problem_.addBlock("development period", 2);
  }

  // Values (normalized coordinates).
  for (int v = 0; v < V; ++v)
    problem_.blockValues(vertexBlock_[v]) = normalization_.toNormalized(design_.vertices.row(v).transpose());
  for (int e = 0; e < E; ++e) {
    if (edgeBlock_[e] < 0) continue;
    Eigen::Map<Eigen::VectorXd> values = problem_.blockValues(edgeBlock_[e]);
    for (int i = 0; i < topo.interiorPoints(e); ++i)
      values.segment<3>(3 * i) = normalization_.toNormalized(design_.edges[e].curve.points.row(i + 1).transpose());
  }
  for (const PointRef& r : design_.fixed) {
    const PointSlot s = slotOf(r);
    if (s.vertex >= 0)
      problem_.layout().setFixed(vertexBlock_[s.vertex], 0, 3);
    else
      problem_.layout().setFixed(edgeBlock_[s.edge], 3 * s.index, 3);
  }

  if (developmentBlock_ >= 0 && options_.developmentSolve == DevelopmentSolve::Alternating) {
    problem_.layout().setAlternating(developmentBlock_);
    problem_.layout().setRegularizationScale(developmentBlock_, options_.alternatingDevelopmentRegularizationScale);
    if (periodBlock_ >= 0) problem_.layout().setAlternating(periodBlock_);
  }
  rulingCreases_ = options_.creaseNormals == CreaseNormals::Ruling ||
                   (options_.creaseNormals == CreaseNormals::Auto && problem_.x().size() >= options_.rulingCreaseUnknowns);
  const int P = static_cast<int>(problem_.x().size() / 3);
  std::vector<int> hardUnit, softUnit;
  for (int f = 0; f < F; ++f) {
    options_.deadline.check();
    const FaceInfo& info = topo.face(f);
    const int offN = problem_.layout().block(normalBlock_[f]).offset;
    if (!stripLike(info)) {
      std::vector<int> corners;
      for (int c : info.corners) corners.push_back(3 * pointIndex({c, -1, 0}));
      problem_.addTerm(std::make_unique<terms::PlanarPolygonTerm>("planarity", offN, corners),
                       options_.developabilityWeight, Strength::Hard);
      hardUnit.push_back(offN);
      continue;
    }
    const std::vector<double>& params = faceParams_[f];
    const int K = static_cast<int>(params.size());
    FaceRows& rows = faceRows_[f];
    const std::vector<PointSlot> slotsA = topo.controlSlots(info.a.edge, info.a.reversed);
    rows.a = curveRows(info.knots, slotsA, params, 0);
    rows.da = curveRows(info.knots, slotsA, params, 1);
    if (info.type == FaceType::Cone) {
      EvaluationMatrix W(K, P);
      const int apex = pointIndex({info.apex, -1, 0});
      for (int k = 0; k < K; ++k) W.insert(k, apex) = 1.0;
      W.makeCompressed();
      rows.b = {W, 0};
      rows.db = {emptyRows(K, P), 0};
    } else {
      const std::vector<PointSlot> slotsB = topo.controlSlots(info.b.edge, info.b.reversed);
      const spline::KnotVector knotsB = topo.knots(info.b.edge, info.b.reversed);
      rows.b = curveRows(knotsB, slotsB, params, 0);
      rows.db = curveRows(knotsB, slotsB, params, 1);
    }
    // b − a as one linear map: where a and b share a control point (the vertex of a degenerate
    // ruling) the coefficients merge, so no row lists a variable twice.
    EvaluationMatrix diff = rows.b.weights - rows.a.weights;
    diff.makeCompressed();
    problem_.addTerm(std::make_unique<terms::StripDevelopabilityTerm>(
                         "developability", terms::LinearPoints{emptyRows(K, P), 0}, rows.da,
                         terms::LinearPoints{diff, 0}, rows.db, faceNormals(f)),
                     options_.developabilityWeight, Strength::Hard);
    if (options_.rulingGuardRatio > 0.0) {
      // Degeneracy guard: no ruling shrinks below a fraction of its length at build time (a
      // degenerate ruling by design has length 0 and no row).
      const terms::LinearPoints ruling{diff, 0};
      std::vector<double> minLength(static_cast<std::size_t>(K));
      for (int k = 0; k < K; ++k) {
        const double length = ruling.point(problem_.x(), k).norm();
        minLength[k] = length > 1e-9 ? options_.rulingGuardRatio * length : 0.0;
      }
      rulingTerms_.push_back(problem_.addTerm(
          std::make_unique<terms::RulingLengthTerm>("ruling_length", terms::LinearPoints{emptyRows(K, P), 0}, ruling,
                                                    minLength),
          1.0, Strength::Hard));
    }
    if (options_.widthGuardRatio > 0.0) {
      // … nor does the strip collapse across its rulings (|(b − a) × (a′ + b′)|), nor does either
      // curve turn into the ruling direction (|(b − a) × a′|, |(b − a) × b′|): a ruling along a
      // crease makes sliver quads that fold over (folded annulus, an outer crease point pulled
      // inward across the inner rings: vertex curvature 0.07 at flat quads). A side that is
      // degenerate by design (a cone's apex) has no reference width and no row.
      const std::vector<terms::StripWidthTerm::SignedPoints> ruling{{terms::LinearPoints{diff, 0}, 1.0}};
      const std::vector<terms::StripWidthTerm::SignedPoints> tangents[] = {
          {{rows.da, 1.0}, {rows.db, 1.0}}, {{rows.da, 1.0}}, {{rows.db, 1.0}}};
      for (const auto& tangent : tangents) {
        std::vector<double> minWidth = terms::StripWidthTerm::widths(ruling, tangent, problem_.x());
        for (double& w : minWidth) w = w > 1e-9 ? options_.widthGuardRatio * w : 0.0;
        widthTerms_.push_back(problem_.addTerm(
            std::make_unique<terms::StripWidthTerm>("strip_width", ruling, tangent, minWidth), 1.0, Strength::Hard));
      }
    }
    // Unit normals: hard at the first parameter (a normal spline's first control point, the
    // normal at the face's first parameter), soft at the other normals. A normal spline's soft
    // rows hold the normals it gives at the parameters, where the crease rows compare two faces'
    // normals, rather than its control points (000_… §2.2 holds those; between them the spline's
    // normals then drifted to |n| = 0.9957 on the cylinder crease, and eq. 7 wants them equal).
    hardUnit.push_back(offN);
    if (!normalSplineRows_.empty() && normalSplineRows_[f].rows() > 0) {
      std::vector<int> rest(static_cast<std::size_t>(K - 1));
      for (int k = 1; k < K; ++k) rest[static_cast<std::size_t>(k - 1)] = k;
      problem_.addTerm(std::make_unique<terms::NormalSplineUnitTerm>(
                           "unit_normal", terms::LinearPoints{selectRows(normalSplineRows_[f], rest), offN}),
                       options_.unitNormalWeight, Strength::Soft);
    } else {
      for (int k = 1; k < K; ++k) softUnit.push_back(offN + 3 * k);
    }
  }
  problem_.addTerm(std::make_unique<terms::UnitNormalTerm>("unit_normal_hard", hardUnit), 1.0, Strength::Hard);
  initializeNormals();  // the ruling crease rows orient themselves by the faces' normals
  if (!softUnit.empty())
    problem_.addTerm(std::make_unique<terms::UnitNormalTerm>("unit_normal", softUnit), options_.unitNormalWeight,
                     Strength::Soft);

  // Smooth rows on the faces' rulings where both faces have them (a planar face has one free
  // normal, which NormalMatchTerm compares).
  auto bothStripLike = [&topo](const EdgeInfo& info) {
    return info.faces[0] >= 0 && info.faces[1] >= 0 && stripLike(topo.face(info.faces[0])) &&
           stripLike(topo.face(info.faces[1]));
  };
  for (int e = 0; e < E; ++e) {
    const CreaseKind kind = design_.edges[e].crease;
    const EdgeInfo& info = topo.edge(e);
    if (topo.edgeType(e) == EdgeType::Spline) {
      const std::vector<PointSlot> slots = topo.controlSlots(e);
      if (slots.size() >= 3) {
        std::vector<int> offsets;
        for (const PointSlot& s : slots) offsets.push_back(3 * pointIndex(s));
        problem_.addTerm(std::make_unique<terms::PolygonFairnessTerm>("fairness", offsets), 1.0, Strength::Soft,
                         WeightSchedule::Fairness);
        // Degeneracy guards: the control polygon does not turn back (a crease folding over itself),
        // and its legs do not collapse (coalescing control points let it turn back unseen and
        // make c′ vanish at the crease's ends).
        if (options_.creaseBacktrackGuard) {
          problem_.addTerm(std::make_unique<terms::PolygonBacktrackTerm>("crease_backtrack", offsets, problem_.x(),
                                                                         topo.knots(e).degree()),
                           1.0, Strength::Hard);
          const int legs = static_cast<int>(slots.size()) - 1;
          EvaluationMatrix W(legs, P);
          std::vector<double> minLength(static_cast<std::size_t>(legs));
          for (int i = 0; i < legs; ++i) {
            W.insert(i, pointIndex(slots[i])) = -1.0;
            W.insert(i, pointIndex(slots[i + 1])) = 1.0;
            const double length = (problem_.x().segment<3>(offsets[i + 1]) - problem_.x().segment<3>(offsets[i])).norm();
            minLength[i] = length > 1e-9 ? options_.legGuardRatio * length : 0.0;
          }
          W.makeCompressed();
          problem_.addTerm(std::make_unique<terms::RulingLengthTerm>("crease_leg_length",
                                                                     terms::LinearPoints{emptyRows(legs, P), 0},
                                                                     terms::LinearPoints{W, 0}, minLength),
                           1.0, Strength::Hard);
        }
      }
      if (kind == CreaseKind::Straight) {
        // Straight unfolding (000_… §3.3): the osculating plane of the edge contains the normal of
        // the face beside it (faces[0], or faces[1] on a boundary traversed the other way).
        const spline::KnotVector knots = topo.knots(e);
        const std::vector<double> params = evaluationParams(knots);
        const int side = info.faces[0] >= 0 ? info.faces[0] : info.faces[1];
        const int offO = problem_.layout().block(oscBlock_[e]).offset;
        const int K = static_cast<int>(params.size());
        problem_.addTerm(std::make_unique<terms::StraightUnfoldingTerm>(
                             "straight_unfolding", curveRows(knots, slots, params, 1),
                             curveRows(knots, slots, params, 2), normalsAlongEdge(side, e),
                             terms::LinearPoints::identity(K, offO)),
                         options_.developabilityWeight, Strength::Hard);
        std::vector<int> osc;
        for (int k = 0; k < K; ++k) osc.push_back(offO + 3 * k);
        problem_.addTerm(std::make_unique<terms::UnitNormalTerm>("osculating_unit_normal", osc), 1.0, Strength::Hard);
        continue;
      }
      if (!info.interior() || kind == CreaseKind::None) continue;
      const spline::KnotVector knots = topo.knots(e);
      const std::vector<double> params = evaluationParams(knots);
      terms::LinearPoints n1 = normalsAlongEdge(info.faces[0], e);
      terms::LinearPoints n2 = normalsAlongEdge(info.faces[1], e);
      if (n1.rows() != static_cast<int>(params.size()) || n2.rows() != static_cast<int>(params.size()))
        throw std::logic_error("edge " + std::to_string(e) + ": crease and face parameters differ");
      if (kind == CreaseKind::Smooth && rulingCreases_ && bothStripLike(info)) {
        addRulingSmoothTerm(e);
      } else if (kind == CreaseKind::Smooth) {
        problem_.addTerm(std::make_unique<terms::NormalMatchTerm>("smooth", n1, n2), options_.developabilityWeight,
                         Strength::Hard);
      } else if (rulingCreases_) {
        addRulingCreaseTerm(e);
      } else {
        const bool fold = kind == CreaseKind::Fold;
        const bool soften = options_.softening != terms::SofteningBreakpoints{0.0, 0.0, 1.0, 1.0};
        problem_.addTerm(std::make_unique<terms::CurvedFoldTerm>(
                             fold ? "crease_fold" : "crease_geodesic", curveRows(knots, slots, params, 1),
                             curveRows(knots, slots, params, 2), n1, n2,
                             fold ? terms::CurvedFoldTerm::Mode::CurvedFold : terms::CurvedFoldTerm::Mode::Geodesic,
                             soften ? terms::softeningWeights(params, options_.softening, knots.domainBegin(),
                                                              knots.domainEnd())
                                    : std::vector<double>{}),
                         options_.developabilityWeight, Strength::Hard);
      }
    } else if (kind == CreaseKind::Smooth && rulingCreases_ && bothStripLike(info)) {
      addRulingSmoothTerm(e);
    } else if (kind == CreaseKind::Smooth) {
      problem_.addTerm(std::make_unique<terms::NormalMatchTerm>("smooth", normalAtRuling(info.faces[0], e),
                                                                normalAtRuling(info.faces[1], e)),
                       options_.developabilityWeight, Strength::Hard);
    }
  }

  addVertexDevelopabilityTerms();
  addTangentContinuityTerms();
  addFoldAngleTerm();
  if (developmentBlock_ >= 0) addDevelopmentTerms();

  for (const Handle& h : design_.handles)
    handleTerms_.push_back(problem_.addTerm(
        std::make_unique<terms::HandleTargetTerm>("handle", 3 * pointIndex(slotOf(h.point)),
                                                  normalization_.toNormalized(h.position)),
        h.weight, Strength::Soft));
  for (int t : handleTerms_) problem_.term(t).relaxable = true;  // step control may weaken the pull

  initializeOsculatingNormals();
  builtPoints_ = problem_.x();
  solver_ = std::make_unique<engine::GuidedProjectionSolver>(problem_, options_.linearSolver, options_.deadline);
}

void CompositeModel::initializeNormals() {
  const Eigen::VectorXd& x = problem_.x();
  const CompositeTopology& topo = *topology_;
  for (int f = 0; f < topo.numFaces(); ++f) {
    const FaceInfo& info = topo.face(f);
    std::vector<Eigen::Vector3d> corners;
    for (int c : info.corners) corners.push_back(x.segment<3>(3 * pointIndex({c, -1, 0})));
    Eigen::Vector3d polygonNormal = newellNormal(corners);
    if (polygonNormal.norm() < 1e-300) polygonNormal = Eigen::Vector3d::UnitZ();
    polygonNormal.normalize();
    Eigen::Map<Eigen::VectorXd> normals = problem_.blockValues(normalBlock_[f]);
    if (!stripLike(info)) {
      normals = polygonNormal;
      continue;
    }
    const FaceRows& rows = faceRows_[f];
    const int K = static_cast<int>(faceParams_[f].size());
    std::vector<Eigen::Vector3d> n(static_cast<std::size_t>(K));
    std::vector<bool> ok(static_cast<std::size_t>(K), false);
    for (int k = 0; k < K; ++k) {
      const Eigen::Vector3d ruling = rows.b.point(x, k) - rows.a.point(x, k);
      const Eigen::Vector3d ta = rows.da.point(x, k), tb = rows.db.point(x, k);
      Eigen::Vector3d nk = (ta + tb).cross(ruling);
      const double ref = (ta.norm() + tb.norm()) * std::max(ruling.norm(), 1e-300);
      if (nk.norm() <= 1e-9 * ref) nk = ta.cross(tb);  // a degenerate ruling: the limit a′ × b′
      if (nk.norm() > 1e-12 * std::max(ta.squaredNorm() + tb.squaredNorm(), 1e-300)) {
        n[k] = nk.normalized();
        ok[k] = true;
      }
    }
    // Fill gaps from the nearest good parameter; keep one orientation along the face.
    for (int k = 0; k < K; ++k) {
      if (ok[k]) continue;
      int best = -1;
      for (int d = 1; d < K && best < 0; ++d) {
        if (k - d >= 0 && ok[k - d]) best = k - d;
        else if (k + d < K && ok[k + d]) best = k + d;
      }
      n[k] = best >= 0 ? n[best] : polygonNormal;
    }
    if (normalSplineRows_.empty() || normalSplineRows_[f].rows() == 0) {
      for (int k = 0; k < K; ++k) normals.segment<3>(3 * k) = n[k];
      continue;
    }
    // Normal spline: least-squares fit of its control points to the unit normals (a tiny
    // Tikhonov term keeps the fit well posed), scaled so the first control point (held at unit
    // length) starts there.
    const EvaluationMatrix& N = normalSplineRows_[f];
    Eigen::MatrixXd samples(K, 3);
    for (int k = 0; k < K; ++k) samples.row(k) = n[k].transpose();
    Eigen::SparseMatrix<double> A = Eigen::SparseMatrix<double>(N.transpose()) * N;
    for (int i = 0; i < A.rows(); ++i) A.coeffRef(i, i) += 1e-10;
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(A);
    Eigen::MatrixXd control = ldlt.solve(Eigen::MatrixXd(N.transpose() * samples));
    const double first = control.row(0).norm();
    if (first > 1e-12) control /= first;
    for (Eigen::Index i = 0; i < control.rows(); ++i) normals.segment<3>(3 * i) = control.row(i).transpose();
  }
}

void CompositeModel::initializeOsculatingNormals() {
  const CompositeTopology& topo = *topology_;
  const Eigen::VectorXd& x = problem_.x();
  for (int e = 0; e < topo.numEdges(); ++e) {
    if (oscBlock_.empty() || oscBlock_[e] < 0) continue;
    const spline::KnotVector knots = topo.knots(e);
    const std::vector<double> params = evaluationParams(knots);
    const std::vector<PointSlot> slots = topo.controlSlots(e);
    const terms::LinearPoints d1 = curveRows(knots, slots, params, 1);
    const EdgeInfo& info = topo.edge(e);
    const terms::LinearPoints n = normalsAlongEdge(info.faces[0] >= 0 ? info.faces[0] : info.faces[1], e);
    Eigen::Map<Eigen::VectorXd> values = problem_.blockValues(oscBlock_[e]);
    for (int k = 0; k < static_cast<int>(params.size()); ++k) {
      Eigen::Vector3d o = d1.point(x, k).cross(n.point(x, k));
      values.segment<3>(3 * k) = o.norm() > 1e-300 ? Eigen::Vector3d(o.normalized()) : Eigen::Vector3d::UnitZ();
    }
  }
}

void CompositeModel::resetNormals() {
  initializeNormals();
  initializeOsculatingNormals();
}

engine::SolveSummary CompositeModel::solve(const engine::SolverOptions& options) {
  engine::SolveSummary summary = solver_->solve(options);
  if (hasDevelopment() && flippedDevelopmentFaces() > 0) repairDevelopment();
  return summary;
}

void CompositeModel::setHandleTarget(int i, const Eigen::Vector3d& position) {
  if (i < 0 || i >= static_cast<int>(handleTerms_.size()))
    throw std::out_of_range("handles[" + std::to_string(i) + "]: no such handle");
  if (!position.allFinite())
    throw std::invalid_argument("handles[" + std::to_string(i) + "].position: must be finite");
  design_.handles[static_cast<std::size_t>(i)].position = position;
  auto* term = static_cast<terms::HandleTargetTerm*>(problem_.term(handleTerms_[i]).term.get());
  term->setTarget(normalization_.toNormalized(position));
}

void CompositeModel::setHandleWeight(int i, double weight) {
  if (i < 0 || i >= static_cast<int>(handleTerms_.size()))
    throw std::out_of_range("handles[" + std::to_string(i) + "]: no such handle");
  if (!(weight >= 0.0) || !std::isfinite(weight))
    throw std::invalid_argument("handles[" + std::to_string(i) + "].weight: must be finite and ≥ 0");
  design_.handles[static_cast<std::size_t>(i)].weight = weight;
  problem_.setWeight(handleTerms_[i], weight);
}

double CompositeModel::rulingLengthMinRatio() const {
  double ratio = 1.0;
  for (int t : rulingTerms_)
    ratio = std::min(ratio, static_cast<const terms::RulingLengthTerm*>(problem_.term(t).term.get())
                                ->lengthRatioMin(problem_.x(), options_.rulingGuardRatio));
  return ratio;
}

double CompositeModel::stripWidthMinRatio() const {
  double ratio = 1.0;
  for (int t : widthTerms_)
    ratio = std::min(ratio, static_cast<const terms::StripWidthTerm*>(problem_.term(t).term.get())
                                ->widthRatioMin(problem_.x(), options_.widthGuardRatio));
  return ratio;
}

double CompositeModel::creaseBacktrackMax() const {
  double worst = 0.0;
  const CompositeDesign d = design();
  for (int e = 0; e < topology_->numEdges(); ++e) {
    if (topology_->edgeType(e) != EdgeType::Spline) continue;
    const Eigen::MatrixX3d& p = d.edges[e].curve.points;
    for (Eigen::Index i = 1; i + 1 < p.rows(); ++i) {
      const Eigen::Vector3d d0 = p.row(i) - p.row(i - 1), d1 = p.row(i + 1) - p.row(i);
      const double n = d0.norm() * d1.norm();
      if (n > 1e-300) worst = std::max(worst, -d0.dot(d1) / n);
    }
  }
  return worst;
}

// ---------------------------------------------------------------------------------------------
// results

Eigen::Vector3d CompositeModel::pointValue(const PointSlot& s) const {
  const int offset = 3 * pointIndex(s);
  // Fixed points, and points where the solver left them, read back exactly as given (the
  // normalization's round trip is not exact: an undo that rebuilds a model would move them).
  const bool unmoved = builtPoints_.size() == problem_.x().size() &&  // (not yet during the build)
                      problem_.x().segment<3>(offset) == builtPoints_.segment<3>(offset);
  if (problem_.layout().isFixed(offset) || unmoved) {
    if (s.vertex >= 0) return design_.vertices.row(s.vertex).transpose();
    return design_.edges[s.edge].curve.points.row(s.index + 1).transpose();
  }
  return normalization_.fromNormalized(problem_.x().segment<3>(offset));
}

Eigen::Vector3d CompositeModel::normalVariable(int f, int k) const {
  const int offset = problem_.layout().block(normalBlock_[f]).offset;
  if (!normalSplineRows_.empty() && normalSplineRows_[f].rows() > 0) {
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    for (EvaluationMatrix::InnerIterator it(normalSplineRows_[f], k); it; ++it)
      n += it.value() * problem_.x().segment<3>(offset + 3 * static_cast<int>(it.col()));
    return n;
  }
  return problem_.x().segment<3>(offset + 3 * k);
}

CompositeDesign CompositeModel::design() const {
  CompositeDesign d = design_;
  if (hasDevelopment()) {
    const int offset = problem_.layout().block(developmentBlock_).offset;
    d.developmentVertices.resize(devSpatial_.rows(), 2);
    for (int k = 0; k < devSpatial_.rows(); ++k)
      d.developmentVertices.row(k) = normalization_.scale * problem_.x().segment<2>(offset + 2 * k).transpose();
  }
  for (int v = 0; v < topology_->numVertices(); ++v) d.vertices.row(v) = pointValue({v, -1, 0}).transpose();
  for (int e = 0; e < topology_->numEdges(); ++e) {
    if (topology_->edgeType(e) != EdgeType::Spline) continue;
    const std::vector<PointSlot> slots = topology_->controlSlots(e);
    for (std::size_t i = 0; i < slots.size(); ++i)
      d.edges[e].curve.points.row(static_cast<Eigen::Index>(i)) = pointValue(slots[i]).transpose();
  }
  return d;
}

}  // namespace devsurf::models::composite
