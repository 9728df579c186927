// CompositeModel: the rows built from the faces' rulings along an edge — crease rows and smooth
// edges without free normals (`crease_normals: ruling`) — and the vertex rows (tangent continuity,
// vertex developability). The free-normal rows and the per-edge choice are in CompositeModel.cpp.
#include "devsurf/models/composite/CompositeModel.h"

#include "CompositeModelState.h"
#include "CompositeRows.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "devsurf/terms/CurvedFoldRulingTerm.h"
#include "devsurf/terms/CurvedFoldTerm.h"
#include "devsurf/terms/RulingNormalMatchTerm.h"
#include "devsurf/terms/VertexAngleSumTerm.h"
#include "devsurf/terms/VertexTangentContinuityTerm.h"

namespace devsurf::models::composite {

using detail::evaluationParams;
using detail::selectRows;

namespace {

using engine::Strength;
using spline::EvaluationMatrix;

/// ±1 per entry: the sign of dots[i], or where that is 0 (no direction at build time; the guards
/// keep that from happening later) the sign of the nearest nonzero entry; +1 when all are 0.
std::vector<double> orientationSigns(const std::vector<double>& dots) {
  const int n = static_cast<int>(dots.size());
  std::vector<double> sign(dots.size(), 1.0);
  for (int i = 0; i < n; ++i) {
    int best = -1;
    for (int d = 0; d < n && best < 0; ++d) {
      if (i - d >= 0 && dots[static_cast<std::size_t>(i - d)] != 0.0) best = i - d;
      else if (i + d < n && dots[static_cast<std::size_t>(i + d)] != 0.0) best = i + d;
    }
    if (best >= 0) sign[static_cast<std::size_t>(i)] = dots[static_cast<std::size_t>(best)] > 0.0 ? 1.0 : -1.0;
  }
  return sign;
}

}  // namespace

CompositeModel::CreaseSides CompositeModel::creaseSides(int e) const {
  const CompositeTopology& topo = *topology_;
  const EdgeInfo& info = topo.edge(e);
  const spline::KnotVector knots = topo.knots(e);
  const std::vector<PointSlot> slots = topo.controlSlots(e);
  // The rows hold at the 3m − 2 parameters of every span (000_… §2.1), not at the crease's two
  // ends, which the faces sample only for their ruling edges (and where a face whose curves meet
  // at a vertex has a ruling of no length).
  const std::vector<double> all = evaluationParams(knots);
  const int K = static_cast<int>(all.size());
  CreaseSides sides;
  sides.params.assign(all.begin() + 1, all.end() - 1);
  const int rows = K - 2;
  sides.da = curveRows(knots, slots, sides.params, 1);
  const Eigen::VectorXd& x = problem_.x();
  // Per side: the face's ruling b − a at each row's parameter and the orientation that makes
  // a′ × (b − a) point like the face's normal.
  for (int side = 0; side < 2; ++side) {
    const int f = info.faces[side];
    const FaceRows& face = faceRows_[f];
    if (static_cast<int>(faceParams_[f].size()) != K)
      throw std::logic_error("edge " + std::to_string(e) + ": crease and face parameters differ");
    const bool runs = topo.edgeRunsWithU(f, e);
    EvaluationMatrix ruling = face.b.weights - face.a.weights;  // merges a control point a and b share
    std::vector<int> faceRows;
    std::vector<double> dots;
    for (int i = 0; i < rows; ++i) {
      const int k = i + 1, r = runs ? k : K - 1 - k;
      faceRows.push_back(r);
      const Eigen::Vector3d g = sides.da.point(x, i).cross(face.b.point(x, r) - face.a.point(x, r));
      const Eigen::Vector3d n = normalVariable(f, r);
      const double dot = g.dot(n);
      dots.push_back(std::abs(dot) > 1e-9 * g.norm() * n.norm() ? dot : 0.0);
    }
    sides.across[static_cast<std::size_t>(side)] = {selectRows(ruling, faceRows), 0};
    sides.orientation[static_cast<std::size_t>(side)] = orientationSigns(dots);
  }
  return sides;
}

void CompositeModel::addRulingCreaseTerm(int e) {
  const spline::KnotVector knots = topology_->knots(e);
  CreaseSides sides = creaseSides(e);
  const bool fold = design_.edges[e].crease == CreaseKind::Fold;
  const bool soften = options_.softening != terms::SofteningBreakpoints{0.0, 0.0, 1.0, 1.0};
  problem_.addTerm(std::make_unique<terms::CurvedFoldRulingTerm>(
                       fold ? "crease_fold" : "crease_geodesic", sides.da,
                       curveRows(knots, topology_->controlSlots(e), sides.params, 2), sides.across[0], sides.across[1],
                       std::move(sides.orientation[0]), std::move(sides.orientation[1]),
                       fold ? terms::CurvedFoldTerm::Mode::CurvedFold : terms::CurvedFoldTerm::Mode::Geodesic,
                       soften ? terms::softeningWeights(sides.params, options_.softening, knots.domainBegin(), knots.domainEnd())
                              : std::vector<double>{}),
                   options_.developabilityWeight, Strength::Hard);
}

void CompositeModel::addRulingSmoothTerm(int e) {
  const CompositeTopology& topo = *topology_;
  const EdgeInfo& info = topo.edge(e);
  if (topo.edgeType(e) == EdgeType::Spline) {
    // Across a smooth S edge both faces' tangent planes hold the edge's tangent a′: they agree
    // where a′ × (b − a) of the two faces point alike (each oriented like its face's normal).
    CreaseSides sides = creaseSides(e);
    problem_.addTerm(std::make_unique<terms::RulingNormalMatchTerm>("smooth", sides.da, sides.across[0], sides.da,
                                                                   sides.across[1], std::move(sides.orientation[0]),
                                                                   std::move(sides.orientation[1])),
                     options_.developabilityWeight, Strength::Hard);
    return;
  }
  // A smooth ruling shared by two faces: each face's tangent plane there is spanned by a′ + b′ of
  // that face and the ruling b − a (one pair of rows).
  const Eigen::VectorXd& x = problem_.x();
  terms::LinearPoints tangent[2], ruling[2];
  std::vector<double> orientation[2];
  for (int side = 0; side < 2; ++side) {
    const int f = info.faces[side];
    const FaceRows& face = faceRows_[f];
    const int K = static_cast<int>(faceParams_[f].size());
    const int end = topo.rulingEnd(f, e);
    if (end < 0) throw std::logic_error("edge " + std::to_string(e) + " is not a ruling of face " + std::to_string(f));
    const int r = end == 0 ? 0 : K - 1;
    const EvaluationMatrix t = face.da.weights + face.db.weights, d = face.b.weights - face.a.weights;
    tangent[side] = {selectRows(t, {r}), 0};
    ruling[side] = {selectRows(d, {r}), 0};
    // The orientation at the ruling, or where (t × d) is no direction there at build time (a
    // curve's end tangent of no length) at the nearest of the face's parameters where it is.
    std::vector<double> dots;
    for (int step = 0; step < K; ++step) {
      const int k = end == 0 ? step : K - 1 - step;
      const terms::LinearPoints tk{selectRows(t, {k}), 0}, dk{selectRows(d, {k}), 0};
      const Eigen::Vector3d g = tk.point(x, 0).cross(dk.point(x, 0));
      const Eigen::Vector3d n = normalVariable(f, k);
      const double dot = g.dot(n);
      dots.push_back(std::abs(dot) > 1e-9 * g.norm() * n.norm() ? dot : 0.0);
      if (dots.back() != 0.0) break;
    }
    orientation[side] = {orientationSigns(dots).front()};
  }
  problem_.addTerm(std::make_unique<terms::RulingNormalMatchTerm>("smooth", tangent[0], ruling[0], tangent[1], ruling[1],
                                                                 std::move(orientation[0]), std::move(orientation[1])),
                   options_.developabilityWeight, Strength::Hard);
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

}  // namespace devsurf::models::composite
