#include "devsurf/models/composite/CompositeModel.h"

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <memory>

#include "devsurf/models/HandleValidation.h"
#include <cmath>
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>

#include "devsurf/metrics/QuadFlatness.h"
#include "devsurf/metrics/StripQuality.h"
#include "devsurf/models/composite/CompositePieces.h"
#include "devsurf/terms/PolygonBacktrackTerm.h"
#include "devsurf/terms/PolygonFairnessTerm.h"
#include "devsurf/terms/RulingLengthTerm.h"
#include "devsurf/terms/StripWidthTerm.h"
#include "devsurf/spline/Basis.h"
#include "devsurf/spline/BasisTable.h"
#include "devsurf/terms/CurvedFoldTerm.h"
#include "devsurf/terms/HandleTargetTerm.h"
#include "devsurf/terms/NormalMatchTerm.h"
#include "devsurf/terms/NormalSplineUnitTerm.h"
#include "devsurf/spatial/PolygonTriangulation.h"
#include "devsurf/terms/PlanarPolygonTerm.h"
#include "devsurf/terms/StraightUnfoldingTerm.h"
#include "devsurf/terms/StripDevelopabilityTerm.h"
#include "devsurf/terms/UnitNormalTerm.h"
#include "devsurf/terms/VertexAngleSumTerm.h"
#include "devsurf/terms/VertexTangentContinuityTerm.h"

namespace devsurf::models::composite {
namespace {

using engine::Strength;
using engine::WeightSchedule;
using spline::EvaluationMatrix;

constexpr double kPi = 3.14159265358979323846;

std::string refPath(const std::string& list, std::size_t i) { return list + "[" + std::to_string(i) + "]"; }

bool stripLike(const FaceInfo& f) { return f.type != FaceType::Planar; }

/// [begin] + 3m−2 per span + [end] (000_… §2.1, plus both ends for ruling edges).
std::vector<double> evaluationParams(const spline::KnotVector& k) {
  std::vector<double> p;
  p.push_back(k.domainBegin());
  const std::vector<double> inner = k.spanSamples(3 * k.degree() - 2);
  p.insert(p.end(), inner.begin(), inner.end());
  p.push_back(k.domainEnd());
  return p;
}

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

Eigen::Vector3d newellNormal(const std::vector<Eigen::Vector3d>& poly) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < poly.size(); ++i) n += poly[i].cross(poly[(i + 1) % poly.size()]);
  return n;
}

using metrics::quadFlatness;

double angleAt(const Eigen::Vector3d& prev, const Eigen::Vector3d& p, const Eigen::Vector3d& next) {
  const Eigen::Vector3d u = prev - p, v = next - p;
  return std::atan2(u.cross(v).norm(), u.dot(v));
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// validation and setup

void CompositeModel::validateDesign(const CompositeDesign& design) {
  if (design.vertices.rows() > 0 && !design.vertices.allFinite()) {
    for (Eigen::Index v = 0; v < design.vertices.rows(); ++v)
      if (!design.vertices.row(v).allFinite())
        throw std::invalid_argument(refPath("vertices", static_cast<std::size_t>(v)) + ": coordinates must be finite");
  }
  if (design.developmentSamples < 0 || design.developmentSamples > 64)
    throw std::invalid_argument("development.samples: must be between 1 and 64 (0: no development), got " +
                                std::to_string(design.developmentSamples));
  const CompositeTopology topology(design);
  auto checkRef = [&](const PointRef& r, const std::string& path) {
    if (r.vertex >= 0) {
      if (r.vertex >= topology.numVertices())
        throw std::invalid_argument(path + ".vertex: vertex " + std::to_string(r.vertex) + " does not exist (" +
                                    std::to_string(topology.numVertices()) + " vertices)");
      return;
    }
    if (r.edge < 0 || r.edge >= topology.numEdges())
      throw std::invalid_argument(path + ".edge: edge " + std::to_string(r.edge) + " does not exist (" +
                                  std::to_string(topology.numEdges()) + " edges)");
    if (topology.edgeType(r.edge) != EdgeType::Spline)
      throw std::invalid_argument(path + ".edge: edge " + std::to_string(r.edge) +
                                  " is a ruling (R) and has no control points; refer to its vertices");
    const int n = topology.interiorPoints(r.edge) + 2;
    if (r.index < 0 || r.index >= n)
      throw std::invalid_argument(path + ".index: " + std::to_string(r.index) + " is out of range (edge " +
                                  std::to_string(r.edge) + " has " + std::to_string(n) +
                                  " control points; 0 and " + std::to_string(n - 1) + " are its vertices)");
  };
  validateUserConstraints(design.fixed, design.handles, checkRef);
  if (!(design.foldAmount >= 0.0 && design.foldAmount <= 1.0))
    throw std::invalid_argument("fold_amount: must lie in [0, 1]");
  for (std::size_t i = 0; i < design.foldAngles.size(); ++i) {
    const FoldAngleTarget& t = design.foldAngles[i];
    const std::string path = refPath("fold_angles", i);
    if (t.edge < 0 || t.edge >= topology.numEdges())
      throw std::invalid_argument(path + ".edge: edge " + std::to_string(t.edge) + " does not exist");
    if (!topology.edge(t.edge).interior())
      throw std::invalid_argument(path + ".edge: edge " + std::to_string(t.edge) + " is on the boundary; a fold joins two faces");
    if (!(std::abs(t.angleDeg) <= 180.0)) throw std::invalid_argument(path + ".angle: must lie in [-180, 180] degrees");
    if (!hasFoldHinge(topology, t.edge, t.end))
      throw std::invalid_argument(path + ".end: edge " + std::to_string(t.edge) + " has no hinge at end " + std::to_string(t.end) +
                                  (topology.edgeType(t.edge) == EdgeType::Ruling ? " (an R edge is one hinge, end 0)"
                                                                                 : " (a face has no ruling there)"));
    for (std::size_t j = 0; j < i; ++j)
      if (design.foldAngles[j].edge == t.edge && design.foldAngles[j].end == t.end)
        throw std::invalid_argument(path + ": repeats fold_angles[" + std::to_string(j) + "]");
  }

  const DevelopmentDomain& domain = design.developmentDomain;
  if (design.developmentSamples == 0 && (!domain.empty() || !design.developmentSeam.empty()))
    throw std::invalid_argument("development.samples: a domain or a seam needs a development (samples ≥ 1)");
  if (design.developmentVertices.rows() > 0 && !design.developmentVertices.allFinite())
    for (Eigen::Index i = 0; i < design.developmentVertices.rows(); ++i)
      if (!design.developmentVertices.row(i).allFinite())
        throw std::invalid_argument(refPath("development.vertices", static_cast<std::size_t>(i)) +
                                    ": coordinates must be finite");
  for (std::size_t i = 0; i < design.tangentContinuity.size(); ++i) {
    const auto& pair = design.tangentContinuity[i];
    const std::string path = refPath("tangent_continuity", i);
    for (int k = 0; k < 2; ++k) {
      const int e = pair[static_cast<std::size_t>(k)];
      if (e < 0 || e >= topology.numEdges())
        throw std::invalid_argument(path + "[" + std::to_string(k) + "]: edge " + std::to_string(e) + " does not exist");
      if (topology.edgeType(e) != EdgeType::Spline)
        throw std::invalid_argument(path + "[" + std::to_string(k) + "]: edge " + std::to_string(e) +
                                    " is a ruling; tangent continuity joins S edges");
    }
    const auto a = topology.edgeVertices(pair[0]), b = topology.edgeVertices(pair[1]);
    int shared = 0;
    for (int u : a)
      for (int w : b) shared += u == w ? 1 : 0;
    if (pair[0] == pair[1] || shared != 1)
      throw std::invalid_argument(path + ": edges " + std::to_string(pair[0]) + " and " + std::to_string(pair[1]) +
                                  " must be two S edges sharing exactly one vertex");
  }
  std::vector<bool> seamSeen(static_cast<std::size_t>(topology.numEdges()), false);
  for (std::size_t i = 0; i < design.developmentSeam.size(); ++i) {
    const int e = design.developmentSeam[i];
    const std::string path = refPath("development.seam", i);
    if (e < 0 || e >= topology.numEdges())
      throw std::invalid_argument(path + ": edge " + std::to_string(e) + " does not exist (" +
                                  std::to_string(topology.numEdges()) + " edges)");
    if (!topology.edge(e).interior())
      throw std::invalid_argument(path + ": edge " + std::to_string(e) + " is on the boundary; a seam cuts interior edges");
    if (seamSeen[static_cast<std::size_t>(e)])
      throw std::invalid_argument(path + ": edge " + std::to_string(e) + " is listed twice");
    seamSeen[static_cast<std::size_t>(e)] = true;
  }
  for (std::size_t c = 0; c < domain.boundary.size(); ++c) {
    const DomainCurve& curve = domain.boundary[c];
    const std::string path = refPath("development.domain.boundary", c);
    const Eigen::Index need = curve.closed ? 3 : 2;
    if (curve.points.rows() < need)
      throw std::invalid_argument(path + ".points: needs at least " + std::to_string(need) + " points");
    if (!curve.points.allFinite()) throw std::invalid_argument(path + ".points: coordinates must be finite");
    for (Eigen::Index i = 0; i < curve.points.rows(); ++i) {
      const Eigen::Index j = (i + 1) % curve.points.rows();
      if ((j != 0 || curve.closed) && (curve.points.row(i) - curve.points.row(j)).norm() == 0.0)
        throw std::invalid_argument(path + ".points[" + std::to_string(j) + "]: repeats the previous point");
    }
  }
  std::vector<bool> cornerSeen(static_cast<std::size_t>(topology.numVertices()), false);
  for (std::size_t c = 0; c < domain.corners.size(); ++c) {
    const DomainCorner& corner = domain.corners[c];
    const std::string path = refPath("development.domain.corners", c);
    if (corner.vertex < 0 || corner.vertex >= topology.numVertices())
      throw std::invalid_argument(path + ".vertex: vertex " + std::to_string(corner.vertex) + " does not exist (" +
                                  std::to_string(topology.numVertices()) + " vertices)");
    if (cornerSeen[static_cast<std::size_t>(corner.vertex)])
      throw std::invalid_argument(path + ".vertex: vertex " + std::to_string(corner.vertex) + " is pinned twice");
    cornerSeen[static_cast<std::size_t>(corner.vertex)] = true;
    if (!corner.at.allFinite()) throw std::invalid_argument(path + ".at: coordinates must be finite");
  }
}

struct CompositeModel::StateCache {
  /// Per strip-like face, the basis of its first curve at the dense warp metric's 1 000 rulings
  /// (metrics::stripQuality's parameters): depends on the topology only, built on first use.
  std::once_flag warpOnce;
  std::vector<spline::BasisTable> warpRulings;

  /// The basis at computeCreases' samples of one interior S edge, for one samples-per-span: of
  /// the edge's own curve (up to the second derivative) and of each adjacent face's curves at the
  /// face's parameters of those samples (up to the first). Depends on the topology only.
  struct CreaseEdgeTables {
    spline::BasisTable curve;
    std::array<spline::BasisTable, 2> sides;
  };
  std::mutex creaseTablesMutex;
  std::map<int, std::shared_ptr<const std::vector<CreaseEdgeTables>>> creaseTables;  ///< per samples per span

  std::mutex mutex;
  Eigen::VectorXd x;  ///< the variables every entry below was computed from
  std::map<int, CompositeQuality> quality;
  std::map<int, CreaseSamples> creases;

  /// The entry for `key` in `entries` if it was computed from `now`; drops everything when the
  /// variables moved. Entries are copied out: the lock is not held while computing.
  template <class Value>
  std::optional<Value> find(const Eigen::VectorXd& now, std::map<int, Value>& entries, int key) {
    std::lock_guard<std::mutex> lock(mutex);
    if (x.size() != now.size() || x != now) {
      quality.clear();
      creases.clear();
      x = now;
      return std::nullopt;
    }
    const auto it = entries.find(key);
    if (it == entries.end()) return std::nullopt;
    return it->second;
  }
  template <class Value>
  void store(const Eigen::VectorXd& from, std::map<int, Value>& entries, int key, const Value& value) {
    std::lock_guard<std::mutex> lock(mutex);
    if (x.size() == from.size() && x == from) entries[key] = value;
  }
};

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

namespace {

/// Rows `rows` of a linear map, in that order.
EvaluationMatrix selectRows(const EvaluationMatrix& m, const std::vector<int>& rows) {
  std::vector<Eigen::Triplet<double>> t;
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (EvaluationMatrix::InnerIterator it(m, rows[i]); it; ++it) t.emplace_back(static_cast<int>(i), it.col(), it.value());
  EvaluationMatrix out(static_cast<Eigen::Index>(rows.size()), m.cols());
  out.setFromTriplets(t.begin(), t.end());
  out.makeCompressed();
  return out;
}

}  // namespace

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
  if (!softUnit.empty())
    problem_.addTerm(std::make_unique<terms::UnitNormalTerm>("unit_normal", softUnit), options_.unitNormalWeight,
                     Strength::Soft);

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
      if (kind == CreaseKind::Smooth) {
        problem_.addTerm(std::make_unique<terms::NormalMatchTerm>("smooth", n1, n2), options_.developabilityWeight,
                         Strength::Hard);
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

  initializeNormals();
  initializeOsculatingNormals();
  solver_ = std::make_unique<engine::GuidedProjectionSolver>(problem_, options_.linearSolver, options_.deadline);
}

std::vector<int> CompositeModel::vertexStar(int v) const {
  const CompositeTopology& topo = *topology_;
  if (topo.boundaryVertex()[v]) return {};
  // Per face around v: the edge entering v and the edge leaving it (faces run counterclockwise).
  std::map<int, int> nextFace;  // leaving edge -> face
  std::vector<std::pair<int, int>> corners;  // (face, leaving edge)
  std::map<int, int> leavingOf;              // face -> leaving edge
  for (int f = 0; f < topo.numFaces(); ++f) {
    const FaceInfo& info = topo.face(f);
    if (info.type == FaceType::Cone && info.apex == v) return {};  // a cone's apex angle is not a corner angle
    const int N = static_cast<int>(info.loop.size());
    for (int i = 0; i < N; ++i)
      if (info.corners[static_cast<std::size_t>(i)] == v) leavingOf[f] = info.loop[static_cast<std::size_t>(i)].edge;
  }
  if (leavingOf.size() < 2) return {};
  // The neighbour of v along edge e: the next control point of an S edge, the other end otherwise.
  auto neighbour = [this, &topo, v](int e) {
    const auto ends = topo.edgeVertices(e);
    if (topo.edgeType(e) == EdgeType::Spline && topo.interiorPoints(e) > 0) {
      const std::vector<PointSlot> slots = topo.controlSlots(e, ends[0] != v);
      return pointIndex(slots[1]);
    }
    return pointIndex({ends[0] == v ? ends[1] : ends[0], -1, 0});
  };
  // Walk around v: the face on the other side of f's leaving edge enters v through that edge.
  std::vector<int> star;
  int f = leavingOf.begin()->first;
  for (std::size_t step = 0; step < leavingOf.size(); ++step) {
    const int e = leavingOf.at(f);
    star.push_back(neighbour(e));
    const EdgeInfo& info = topo.edge(e);
    const int g = info.faces[0] == f ? info.faces[1] : info.faces[0];
    if (g < 0 || !leavingOf.count(g)) return {};
    f = g;
  }
  if (f != leavingOf.begin()->first) return {};
  return star;
}

int CompositeModel::neighbourPoint(int e, int v) const {
  const CompositeTopology& topo = *topology_;
  const auto ends = topo.edgeVertices(e);
  if (topo.edgeType(e) == EdgeType::Spline && topo.interiorPoints(e) > 0)
    return pointIndex(topo.controlSlots(e, ends[0] != v)[1]);
  return pointIndex({ends[0] == v ? ends[1] : ends[0], -1, 0});
}

void CompositeModel::addTangentContinuityTerms() {
  for (const auto& pair : design_.tangentContinuity) {
    const auto a = topology_->edgeVertices(pair[0]), b = topology_->edgeVertices(pair[1]);
    const int v = (a[0] == b[0] || a[0] == b[1]) ? a[0] : a[1];
    problem_.addTerm(std::make_unique<terms::VertexTangentContinuityTerm>(
                         "tangent_continuity", 3 * pointIndex({v, -1, 0}), 3 * neighbourPoint(pair[0], v),
                         3 * neighbourPoint(pair[1], v)),
                     options_.developabilityWeight, Strength::Hard);
  }
}

void CompositeModel::addVertexDevelopabilityTerms() {
  for (int v = 0; v < topology_->numVertices(); ++v) {
    const std::vector<int> star = vertexStar(v);
    if (star.size() < 3) continue;
    std::vector<int> offsets;
    for (int p : star) offsets.push_back(3 * p);
    vertexTerms_.push_back(problem_.addTerm(
        std::make_unique<terms::VertexAngleSumTerm>("vertex_developability", 3 * pointIndex({v, -1, 0}), offsets),
        options_.developabilityWeight, Strength::Hard));
  }
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
  if (problem_.layout().isFixed(offset)) {
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

namespace {

spline::BSplineCurve orientedCurve(const CompositeTopology& topo, const CompositeDesign& d, const OrientedEdge& oe) {
  spline::BSplineCurve c;
  c.knots = topo.knots(oe.edge, oe.reversed);
  c.points = d.edges[oe.edge].curve.points;
  if (oe.reversed) c.points = c.points.colwise().reverse().eval();
  return c;
}

std::pair<spline::BSplineCurve, spline::BSplineCurve> curvesOf(const CompositeTopology& topo,
                                                               const CompositeDesign& d, int f) {
  const FaceInfo& info = topo.face(f);
  if (info.type == FaceType::Planar) throw std::logic_error("face " + std::to_string(f) + " is planar");
  spline::BSplineCurve a = orientedCurve(topo, d, info.a);
  spline::BSplineCurve b;
  if (info.type == FaceType::Cone) {
    b.knots = a.knots;
    b.points = d.vertices.row(info.apex).replicate(a.points.rows(), 1);
  } else {
    b = orientedCurve(topo, d, info.b);
  }
  return {std::move(a), std::move(b)};
}

/// Unit normal of a ruled strip from the point and tangent of each boundary at one parameter
/// (columns 0 and 1 of da, db): (a′ + b′) × (b − a), or a′ × b′ where the ruling degenerates.
Eigen::Vector3d geometricNormal(const Eigen::Matrix<double, 3, 2>& da, const Eigen::Matrix<double, 3, 2>& db) {
  const Eigen::Vector3d ta = da.col(1), tb = db.col(1);
  const Eigen::Vector3d r = db.col(0) - da.col(0);
  Eigen::Vector3d n = (ta + tb).cross(r);
  if (n.norm() <= 1e-9 * (ta.norm() + tb.norm()) * std::max(r.norm(), 1e-300)) n = ta.cross(tb);
  const double len = n.norm();
  return len > 0 ? Eigen::Vector3d(n / len) : n;
}

Eigen::Vector3d geometricNormal(const spline::CurvePair& c, double u) {
  Eigen::Matrix<double, 3, 2> da, db;  // point and tangent of each boundary (one basis evaluation for both)
  c.derivatives(u, 1, da, db);
  return geometricNormal(da, db);
}

}  // namespace

std::pair<spline::BSplineCurve, spline::BSplineCurve> CompositeModel::faceCurves(int f) const {
  return curvesOf(*topology_, design(), f);
}

void CompositeModel::igesEntities(std::vector<io::IgesSurface>& surfaces, std::vector<io::IgesCurve>& curves) const {
  const CompositeTopology& topo = *topology_;
  const CompositeDesign d = design();
  for (int f = 0; f < topo.numFaces(); ++f) {
    const FaceInfo& info = topo.face(f);
    if (info.type != FaceType::Planar) {
      const auto [a, b] = curvesOf(topo, d, f);
      io::IgesSurface s;
      s.degreeU = a.degree();
      s.degreeV = 1;
      s.nu = static_cast<int>(a.points.rows());
      s.nv = 2;
      s.knotsU = a.knots.knots();
      s.knotsV = {0.0, 0.0, 1.0, 1.0};
      s.points.resize(2 * s.nu, 3);
      s.points.topRows(s.nu) = a.points;
      s.points.bottomRows(s.nu) = b.points;
      s.label = "F" + std::to_string(f);
      surfaces.push_back(std::move(s));
      continue;
    }
    const int N = static_cast<int>(info.corners.size());
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int c : info.corners) centroid += d.vertices.row(c).transpose() / N;
    for (int k = 0; k < N; ++k) {
      const Eigen::Vector3d p = d.vertices.row(info.corners[k]).transpose();
      const Eigen::Vector3d q = d.vertices.row(info.corners[(k + 1) % N]).transpose();
      io::IgesSurface s;
      s.degreeU = s.degreeV = 1;
      s.nu = s.nv = 2;
      s.knotsU = s.knotsV = {0.0, 0.0, 1.0, 1.0};
      s.points.resize(4, 3);
      // P(0,0) centroid, P(1,0) corner, P(0,1) next corner, P(1,1) edge midpoint: planar patch.
      s.points.row(0) = centroid.transpose();
      s.points.row(1) = p.transpose();
      s.points.row(2) = q.transpose();
      s.points.row(3) = (0.5 * (p + q)).transpose();
      s.label = "F" + std::to_string(f) + "P" + std::to_string(k);
      surfaces.push_back(std::move(s));
    }
  }
  for (int e = 0; e < topo.numEdges(); ++e) {
    if (topo.edgeType(e) != EdgeType::Spline) continue;
    io::IgesCurve c;
    c.degree = d.edges[e].curve.degree();
    c.knots = d.edges[e].curve.knots.knots();
    c.points = d.edges[e].curve.points;
    c.label = "E" + std::to_string(e);
    curves.push_back(std::move(c));
  }
}

Eigen::Vector3d CompositeModel::faceNormal(int f, double u) const {
  const FaceInfo& info = topology_->face(f);
  const CompositeDesign d = design();
  if (info.type == FaceType::Planar) {
    std::vector<Eigen::Vector3d> corners;
    for (int c : info.corners) corners.push_back(d.vertices.row(c).transpose());
    return newellNormal(corners).normalized();
  }
  const auto curves = curvesOf(*topology_, d, f);
  return geometricNormal(spline::CurvePair(curves.first, curves.second), u);
}

namespace {

/// Everything the metrics and the extraction need, computed once from the current state.
struct Evaluation {
  const CompositeTopology& topo;
  CompositeDesign d;
  std::vector<std::pair<spline::BSplineCurve, spline::BSplineCurve>> curves;  ///< per face (planar: empty)
  std::vector<std::optional<spline::CurvePair>> pairs;                        ///< over `curves` (planar: none)
  std::vector<Eigen::Vector3d> planarNormal;                                   ///< per face (planar)
  /// Variable normals per face (orientation reference), with their parameters.
  std::vector<std::vector<Eigen::Vector3d>> varNormals;
  std::vector<std::vector<double>> varParams;

  Evaluation(const CompositeTopology& t, CompositeDesign design) : topo(t), d(std::move(design)) {}
  Evaluation(const Evaluation&) = delete;  // `pairs` refer to this object's `curves`
  Evaluation& operator=(const Evaluation&) = delete;

  /// Unit normal of face f at its parameter u, oriented like the face's normal variables.
  Eigen::Vector3d normal(int f, double u) const { return oriented(f, u, geometric(f, u)); }
  /// The surface's own unit normal of face f at u (planar: Newell's), unoriented.
  Eigen::Vector3d geometric(int f, double u) const {
    if (topo.face(f).type == FaceType::Planar) return planarNormal[f];
    return geometricNormal(*pairs[f], u);
  }
  /// n turned like the face's normal variable nearest to u.
  Eigen::Vector3d oriented(int f, double u, Eigen::Vector3d n) const {
    if (topo.face(f).type == FaceType::Planar) return planarNormal[f];
    const std::vector<double>& p = varParams[f];
    const auto it = std::lower_bound(p.begin(), p.end(), u);
    std::size_t k = static_cast<std::size_t>(std::min<std::ptrdiff_t>(it - p.begin(), static_cast<std::ptrdiff_t>(p.size()) - 1));
    if (k > 0 && std::abs(p[k - 1] - u) < std::abs(p[k] - u)) --k;
    if (n.dot(varNormals[f][k]) < 0) n = -n;
    return n;
  }
};

}  // namespace

CompositeModel::~CompositeModel() = default;

std::vector<CreaseGeometry> CompositeModel::creases(int samplesPerSpan) const {
  return creaseSamples(samplesPerSpan).creases;
}

CompositeModel::CreaseSamples CompositeModel::creaseSamples(int samplesPerSpan) const {
  const Eigen::VectorXd& x = problem_.x();
  if (auto hit = stateCache_->find(x, stateCache_->creases, samplesPerSpan)) return std::move(*hit);
  CreaseSamples value;
  value.creases = computeCreases(samplesPerSpan, &value.foldResidualMax);
  stateCache_->store(x, stateCache_->creases, samplesPerSpan, value);
  return value;
}

CompositeQuality CompositeModel::quality(int samplesPerSpan) const {
  const Eigen::VectorXd& x = problem_.x();
  if (auto hit = stateCache_->find(x, stateCache_->quality, samplesPerSpan)) return std::move(*hit);
  CompositeQuality value = computeQuality(samplesPerSpan);
  stateCache_->store(x, stateCache_->quality, samplesPerSpan, value);
  return value;
}

std::vector<CreaseGeometry> CompositeModel::computeCreases(int samplesPerSpan, double* foldResidualMax) const {
  if (samplesPerSpan < 1) throw std::invalid_argument("creases: need at least 1 sample per span");
  const CompositeTopology& topo = *topology_;
  Evaluation ev(topo, design());
  ev.curves.resize(topo.numFaces());
  ev.pairs.resize(topo.numFaces());
  ev.planarNormal.resize(topo.numFaces());
  ev.varNormals.resize(topo.numFaces());
  ev.varParams = faceParams_;
  for (int f = 0; f < topo.numFaces(); ++f) {
    const FaceInfo& info = topo.face(f);
    if (info.type == FaceType::Planar) {
      std::vector<Eigen::Vector3d> corners;
      for (int c : info.corners) corners.push_back(ev.d.vertices.row(c).transpose());
      Eigen::Vector3d n = newellNormal(corners);
      ev.planarNormal[f] = n.norm() > 0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::UnitZ();
      continue;
    }
    ev.curves[f] = curvesOf(topo, ev.d, f);
    ev.pairs[f].emplace(ev.curves[f].first, ev.curves[f].second);
    for (std::size_t k = 0; k < faceParams_[f].size(); ++k)
      ev.varNormals[f].push_back(normalVariable(f, static_cast<int>(k)));
  }
  // The basis at the samples, tabled once per samples-per-span (half of an iterate's metrics was
  // basis evaluation here: three per sample).
  std::shared_ptr<const std::vector<StateCache::CreaseEdgeTables>> tables;
  {
    std::lock_guard<std::mutex> lock(stateCache_->creaseTablesMutex);
    auto& slot = stateCache_->creaseTables[samplesPerSpan];
    if (!slot) {
      auto built = std::make_shared<std::vector<StateCache::CreaseEdgeTables>>(static_cast<std::size_t>(topo.numEdges()));
      for (int e = 0; e < topo.numEdges(); ++e) {
        const EdgeInfo& info = topo.edge(e);
        if (!info.interior() || topo.edgeType(e) != EdgeType::Spline) continue;
        const spline::KnotVector& knots = ev.d.edges[e].curve.knots;
        const std::vector<double> us = knots.uniformSamples(knots.numSpans() * samplesPerSpan + 1);
        const double sum = knots.domainBegin() + knots.domainEnd();
        StateCache::CreaseEdgeTables& t = (*built)[static_cast<std::size_t>(e)];
        t.curve = spline::BasisTable(knots, us, 2);
        for (int side = 0; side < 2; ++side) {
          const int f = info.faces[side];
          if (topo.face(f).type == FaceType::Planar) continue;
          std::vector<double> params(us.size());
          for (std::size_t k = 0; k < us.size(); ++k) params[k] = topo.edgeRunsWithU(f, e) ? us[k] : sum - us[k];
          t.sides[static_cast<std::size_t>(side)] =
              spline::BasisTable(topo.knots(topo.face(f).a.edge, topo.face(f).a.reversed), std::move(params), 1);
        }
      }
      slot = std::move(built);
    }
    tables = slot;
  }
  // Whether a side's table serves face f's curves at the edge's `count` samples.
  auto sideTabled = [&ev, &topo](int f, const spline::BasisTable& table, int count) {
    return topo.face(f).type != FaceType::Planar && table.size() == count && table.fits(ev.curves[f].first) &&
           table.fits(ev.curves[f].second);
  };
  // Face f's surface normal at sample k of a crease (its parameter u), from the table if `tabled`.
  auto sideNormal = [&ev, &topo](int f, const spline::BasisTable& table, bool tabled, int k, double u) {
    if (topo.face(f).type == FaceType::Planar) return ev.planarNormal[f];
    if (!tabled) return ev.geometric(f, u);
    const auto& [a, b] = ev.curves[f];
    Eigen::Matrix<double, 3, 2> da, db;
    table.evaluate(k, a.points, 1, da);
    table.evaluate(k, b.points, 1, db);
    return geometricNormal(da, db);
  };

  std::vector<CreaseGeometry> out;
  for (int e = 0; e < topo.numEdges(); ++e) {
    const EdgeInfo& info = topo.edge(e);
    if (!info.interior()) continue;
    CreaseGeometry c;
    c.edge = e;
    c.type = topo.edgeType(e);
    c.kind = ev.d.edges[e].crease;
    const int f1 = info.faces[0], f2 = info.faces[1];
    std::vector<Eigen::Vector3d> pts, tangents, n1s, n2s;
    if (c.type == EdgeType::Spline) {
      const spline::BSplineCurve& curve = ev.d.edges[e].curve;
      const int count = curve.knots.numSpans() * samplesPerSpan + 1;
      const std::vector<double> us = curve.knots.uniformSamples(count);
      const double sum = curve.knots.domainBegin() + curve.knots.domainEnd();
      // The crease rows' residual (eq. 7/8 with the surfaces' unit normals) from the same samples.
      const bool measured = foldResidualMax && (c.kind == CreaseKind::Fold || c.kind == CreaseKind::Geodesic);
      const double sign = c.kind == CreaseKind::Fold ? 1.0 : -1.0;
      const StateCache::CreaseEdgeTables& table = (*tables)[static_cast<std::size_t>(e)];
      const bool tabled = table.curve.size() == count && table.curve.fits(curve);
      const bool tabled1 = sideTabled(f1, table.sides[0], count), tabled2 = sideTabled(f2, table.sides[1], count);
      Eigen::Matrix<double, 3, 3> point;
      for (int k = 0; k < count; ++k) {
        const double u = us[static_cast<std::size_t>(k)];
        if (tabled)
          table.curve.evaluate(k, curve.points, 2, point);
        else
          curve.derivatives(u, 2, point);
        pts.push_back(point.col(0));
        tangents.push_back(point.col(1));
        const double u1 = topo.edgeRunsWithU(f1, e) ? u : sum - u, u2 = topo.edgeRunsWithU(f2, e) ? u : sum - u;
        const Eigen::Vector3d g1 = sideNormal(f1, table.sides[0], tabled1, k, u1),
                              g2 = sideNormal(f2, table.sides[1], tabled2, k, u2);
        n1s.push_back(ev.oriented(f1, u1, g1));
        n2s.push_back(ev.oriented(f2, u2, g2));
        if (!measured) continue;
        const Eigen::Vector3d m = g1 + sign * g2;
        const Eigen::Vector3d t1 = point.col(1), t2 = point.col(2);
        const double s1 = t1.norm() > 1e-12 ? 1.0 / t1.norm() : 1.0;
        const double s2 = t2.norm() > 1e-12 ? 1.0 / t2.norm() : 1.0;
        *foldResidualMax = std::max({*foldResidualMax, std::abs(s1 * t1.dot(m)), std::abs(s2 * t2.dot(m))});
      }
    } else {
      const auto ends = topo.edgeVertices(e);
      const Eigen::Vector3d p0 = ev.d.vertices.row(ends[0]).transpose(), p1 = ev.d.vertices.row(ends[1]).transpose();
      auto endNormal = [&](int f) {
        const FaceInfo& fi = topo.face(f);
        if (fi.type == FaceType::Planar) return ev.normal(f, 0.0);
        const int end = topo.rulingEnd(f, e);
        return ev.normal(f, end == 0 ? fi.knots.domainBegin() : fi.knots.domainEnd());
      };
      const Eigen::Vector3d n1 = endNormal(f1), n2 = endNormal(f2);
      for (const Eigen::Vector3d& p : {p0, p1}) {
        pts.push_back(p);
        tangents.push_back(p1 - p0);
        n1s.push_back(n1);
        n2s.push_back(n2);
      }
    }
    const int S = static_cast<int>(pts.size());
    c.polyline.resize(S, 3);
    c.foldAngleDeg.resize(S);
    double mean = 0.0;
    for (int i = 0; i < S; ++i) {
      c.polyline.row(i) = pts[i].transpose();
      const Eigen::Vector3d t = tangents[i].norm() > 0 ? Eigen::Vector3d(tangents[i].normalized()) : tangents[i];
      const double theta = std::atan2(t.dot(n1s[i].cross(n2s[i])), n1s[i].dot(n2s[i]));
      c.foldAngleDeg[i] = -theta * 180.0 / kPi;
      mean += c.foldAngleDeg[i] / S;
    }
    c.assignment = mean > 0.01 ? 'V' : (mean < -0.01 ? 'M' : 'F');
    out.push_back(std::move(c));
  }
  return out;
}

CompositeQuality CompositeModel::computeQuality(int samplesPerSpan) const {
  if (samplesPerSpan < 1) throw std::invalid_argument("quality: need at least 1 sample per span");
  const CompositeTopology& topo = *topology_;
  const CompositeDesign d = design();
  const double tiny = 1e-12 * scale_;
  CompositeQuality q;

  // The welded auxiliary mesh: vertices, S-edge samples, one quad per pair of rulings.
  const SampledComposite sampled = sampleComposite(d, topo, samplesPerSpan);
  const std::vector<Eigen::Vector3d>& points = sampled.points;
  const std::vector<int>& edgeCount = sampled.edgeCount;
  std::vector<std::vector<int>> polygons;
  double flatSum = 0.0;
  int flatCount = 0;
  q.faceFlatness.assign(topo.numFaces(), 0.0);
  for (int f = 0; f < topo.numFaces(); ++f) {
    const FaceInfo& info = topo.face(f);
    for (const std::vector<int>& poly : sampled.facePolygons[static_cast<std::size_t>(f)]) {
      const int N = static_cast<int>(poly.size());
      double delta = 0.0;
      if (info.type == FaceType::Planar && N >= 4)  // every quadruple of consecutive corners
        for (int i = 0; i < N; ++i)
          delta = std::max(delta, quadFlatness(points[poly[i]], points[poly[(i + 1) % N]], points[poly[(i + 2) % N]],
                                               points[poly[(i + 3) % N]], tiny));
      else if (N == 4)  // a(u_i), a(u_i+1), b(u_i+1), b(u_i)
        delta = quadFlatness(points[poly[0]], points[poly[1]], points[poly[2]], points[poly[3]], tiny);
      q.faceFlatnessMax = std::max(q.faceFlatnessMax, delta);
      q.faceFlatness[f] = std::max(q.faceFlatness[f], delta);
      flatSum += delta;
      ++flatCount;
      if (N >= 3) polygons.push_back(poly);
    }
  }
  q.faceFlatnessMean = flatCount > 0 ? flatSum / flatCount : 0.0;
  q.quads = flatCount;

  // Angle sums at interior vertices.
  std::vector<double> angleSum(points.size(), 0.0);
  std::map<std::pair<int, int>, int> edgeUse;
  for (const std::vector<int>& poly : polygons) {
    const std::size_t n = poly.size();
    for (std::size_t i = 0; i < n; ++i) {
      const int prev = poly[(i + n - 1) % n], cur = poly[i], next = poly[(i + 1) % n];
      angleSum[cur] += angleAt(points[prev], points[cur], points[next]);
      ++edgeUse[std::minmax(cur, next)];
    }
  }
  std::vector<bool> boundary(points.size(), false), used(points.size(), false);
  for (const auto& [edge, count] : edgeUse) {
    used[edge.first] = used[edge.second] = true;
    if (count == 1) boundary[edge.first] = boundary[edge.second] = true;
  }
  // Without a development nothing claims one flat sheet: an interior S edge with no crease
  // condition is a seam, a line the pieces are cut apart along (strips side by side covering a
  // shape, CompositeFromStrips), and its points are boundary points of each piece. With a
  // development the sheet is one, and every shared point counts.
  for (int e = 0; e < topo.numEdges(); ++e)
    if (isSeam(d, topo, e))
      for (int i = 0; i < edgeCount[e]; ++i) boundary[sampled.sampleId(topo, e, i)] = true;
  q.vertexCurvature.assign(topo.numVertices(), 0.0);
  for (std::size_t v = 0; v < points.size(); ++v) {
    if (!used[v] || boundary[v]) continue;
    ++q.interiorVertices;
    const double k = std::abs(angleSum[v] - 2.0 * kPi);
    if (v < static_cast<std::size_t>(topo.numVertices())) q.vertexCurvature[v] = k;
    q.vertexCurvatureMax = std::max(q.vertexCurvatureMax, k);
  }

  // Warp angles over all strip-like faces (1 000 rulings each; the basis at them tabled once).
  std::call_once(stateCache_->warpOnce, [this, &topo]() {
    std::vector<spline::BasisTable>& tables = stateCache_->warpRulings;
    tables.resize(static_cast<std::size_t>(topo.numFaces()));
    for (int f = 0; f < topo.numFaces(); ++f) {
      const FaceInfo& info = topo.face(f);
      if (info.type == FaceType::Planar) continue;
      const spline::KnotVector knots = topo.knots(info.a.edge, info.a.reversed);
      const double u0 = knots.domainBegin(), u1 = knots.domainEnd();
      std::vector<double> params(1000);
      for (int i = 0; i < 1000; ++i) params[static_cast<std::size_t>(i)] = u0 + (u1 - u0) * static_cast<double>(i) / 999;
      tables[static_cast<std::size_t>(f)] = spline::BasisTable(knots, std::move(params), 1);
    }
  });
  const std::vector<spline::BasisTable>& warpRulings = stateCache_->warpRulings;
  double warpSum = 0.0;
  int warpFaces = 0;
  for (int f = 0; f < topo.numFaces(); ++f) {
    if (topo.face(f).type == FaceType::Planar) continue;
    const auto curves = curvesOf(topo, d, f);
    const spline::BasisTable& rulings = warpRulings[static_cast<std::size_t>(f)];
    const metrics::StripQuality sq = rulings.fits(curves.first) && rulings.fits(curves.second)
                                         ? metrics::stripQuality(rulings, curves.first, curves.second)
                                         : metrics::stripQuality(curves.first, curves.second, 1000);
    q.warpAngleMaxDeg = std::max(q.warpAngleMaxDeg, sq.warpAngleMaxDeg);
    warpSum += sq.warpAngleMeanDeg;
    ++warpFaces;
  }
  q.warpAngleMeanDeg = warpFaces > 0 ? warpSum / warpFaces : 0.0;

  // Crease rows (eq. 7/8) with the surfaces' unit normals; fold angles.
  const CreaseSamples cs = creaseSamples(samplesPerSpan);
  for (const CreaseGeometry& c : cs.creases)
    if (c.foldAngleDeg.size() > 0) q.foldAngleMaxDeg = std::max(q.foldAngleMaxDeg, c.foldAngleDeg.cwiseAbs().maxCoeff());
  q.creaseFoldResidualMax = cs.foldResidualMax;
  return q;
}

namespace {

/// The triangles of a planar face that is not convex (corner indices into info.corners), or none
/// when it is convex or not simple (a face warped over itself mid-solve): those keep the fan.
std::vector<std::array<int, 3>> nonConvexFaceTriangles(const CompositeDesign& d, const FaceInfo& info) {
  Eigen::MatrixX3d corners(static_cast<Eigen::Index>(info.corners.size()), 3);
  for (std::size_t i = 0; i < info.corners.size(); ++i) corners.row(static_cast<Eigen::Index>(i)) = d.vertices.row(info.corners[i]);
  const Eigen::MatrixX2d plane = spatial::polygonInItsPlane(corners);
  if (spatial::isConvexPolygon(plane)) return {};
  try {
    return spatial::triangulateSimplePolygon(plane);
  } catch (const std::invalid_argument&) {
    return {};
  }
}

}  // namespace

CompositeGeometry CompositeModel::geometry(int samplesPerSpan, int vSamples) const {
  if (samplesPerSpan < 1 || vSamples < 2)
    throw std::invalid_argument("geometry: need at least 1 sample per span and 2 across the rulings");
  const CompositeTopology& topo = *topology_;
  const CompositeDesign d = design();
  CompositeGeometry g;
  for (int f = 0; f < topo.numFaces(); ++f) {
    const FaceInfo& info = topo.face(f);
    io::QuadMesh mesh;
    const std::vector<std::array<int, 3>> triangles =
        info.type == FaceType::Planar ? nonConvexFaceTriangles(d, info) : std::vector<std::array<int, 3>>{};
    if (!triangles.empty()) {
      // Not convex (a notch, a face beside a hole's bridge): its corners' triangles, each a quad
      // with its last corner repeated (a fan from the centre would cover the notch).
      const int N = static_cast<int>(info.corners.size());
      mesh.vertices.resize(N, 3);
      for (int i = 0; i < N; ++i) mesh.vertices.row(i) = d.vertices.row(info.corners[i]);
      mesh.quads.resize(static_cast<Eigen::Index>(triangles.size()), 4);
      for (std::size_t t = 0; t < triangles.size(); ++t)
        mesh.quads.row(static_cast<Eigen::Index>(t)) << triangles[t][0], triangles[t][1], triangles[t][2], triangles[t][2];
    } else if (info.type == FaceType::Planar) {
      const int N = static_cast<int>(info.corners.size());
      mesh.vertices.resize(2 * N + 1, 3);
      Eigen::RowVector3d centre = Eigen::RowVector3d::Zero();
      for (int i = 0; i < N; ++i) {
        const Eigen::RowVector3d p = d.vertices.row(info.corners[i]);
        const Eigen::RowVector3d next = d.vertices.row(info.corners[(i + 1) % N]);
        mesh.vertices.row(2 * i) = p;
        mesh.vertices.row(2 * i + 1) = 0.5 * (p + next);
        centre += p / N;
      }
      mesh.vertices.row(2 * N) = centre;
      mesh.quads.resize(N, 4);
      for (int i = 0; i < N; ++i) mesh.quads.row(i) << 2 * N, 2 * i, 2 * i + 1, (2 * i + 2) % (2 * N);
    } else {
      const auto curves = curvesOf(topo, d, f);
      const int U = info.knots.numSpans() * samplesPerSpan + 1;
      const std::vector<double> us = info.knots.uniformSamples(U);
      const Eigen::MatrixXd A = curves.first.evaluate(us, 0), B = curves.second.evaluate(us, 0);
      mesh.vertices.resize(static_cast<Eigen::Index>(U) * vSamples, 3);
      for (int i = 0; i < U; ++i)
        for (int j = 0; j < vSamples; ++j) {
          const double v = static_cast<double>(j) / (vSamples - 1);
          mesh.vertices.row(i * vSamples + j) = (1.0 - v) * A.row(i) + v * B.row(i);
        }
      mesh.quads.resize(static_cast<Eigen::Index>(U - 1) * (vSamples - 1), 4);
      int q = 0;
      for (int i = 0; i + 1 < U; ++i)
        for (int j = 0; j + 1 < vSamples; ++j)
          mesh.quads.row(q++) << i * vSamples + j, (i + 1) * vSamples + j, (i + 1) * vSamples + j + 1,
              i * vSamples + j + 1;
    }
    g.faces.push_back(std::move(mesh));
  }
  Eigen::Index nv = 0, nq = 0;
  for (const io::QuadMesh& m : g.faces) {
    nv += m.vertices.rows();
    nq += m.quads.rows();
  }
  g.merged.vertices.resize(nv, 3);
  g.merged.quads.resize(nq, 4);
  nv = nq = 0;
  for (const io::QuadMesh& m : g.faces) {
    g.merged.vertices.middleRows(nv, m.vertices.rows()) = m.vertices;
    g.merged.quads.middleRows(nq, m.quads.rows()) = m.quads.array() + static_cast<int>(nv);
    nv += m.vertices.rows();
    nq += m.quads.rows();
  }
  g.creases = creases(samplesPerSpan);
  return g;
}

}  // namespace devsurf::models::composite
