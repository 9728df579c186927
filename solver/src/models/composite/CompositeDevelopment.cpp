// Development management of the composite model (000_… §5 eq. 12, 003_… §5.2.5): a sampled
// quad-dominant mesh of the whole composite, its planar development as variables, the isometry
// between the two, and the crease pattern built from them.
#include <Eigen/Geometry>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <cmath>
#include <deque>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/spatial/PolygonTriangulation.h"
#include "devsurf/spline/Basis.h"
#include "devsurf/terms/DevelopmentPeriodTerm.h"
#include "devsurf/terms/EdgeIsometryTerm.h"
#include "devsurf/terms/TriangleOrientationTerm.h"
#include "devsurf/terms/TangentDistanceTerm.h"

namespace devsurf::models::composite {
namespace {

/// A development triangle whose area is under this fraction of its longest side squared (its
/// height under 2e-6 of its base) has its three corners on a line, up to the accuracy of the
/// unfolding that placed them: the orientation guard leaves it out.
constexpr double kSliverAreaRatio = 1e-6;

/// Second differences of a polyline of 2D points anywhere in x (the developed boundary and crease
/// curves): one row per interior point and coordinate; linear. The 2D counterpart of
/// terms::PolygonFairnessTerm.
class PlanarPolylineFairnessTerm final : public engine::Term {
 public:
  PlanarPolylineFairnessTerm(std::string name, std::vector<int> pointOffsets)
      : Term(std::move(name)), points_(std::move(pointOffsets)) {}
  int numResiduals() const override { return points_.size() < 3 ? 0 : 2 * static_cast<int>(points_.size() - 2); }
  bool evaluatesFromXAlone() const override { return true; }
  void jacobianStructure(std::vector<engine::JacobianEntry>& entries) const override {
    for (std::size_t i = 1; i + 1 < points_.size(); ++i)
      for (int c = 0; c < 2; ++c) {
        const int row = 2 * static_cast<int>(i - 1) + c;
        entries.push_back({row, points_[i - 1] + c});
        entries.push_back({row, points_[i] + c});
        entries.push_back({row, points_[i + 1] + c});
      }
  }
  void evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const override {
    for (std::size_t i = 1; i + 1 < points_.size(); ++i)
      for (int c = 0; c < 2; ++c) {
        const std::size_t row = 2 * (i - 1) + static_cast<std::size_t>(c);
        residuals[row] = x[points_[i - 1] + c] - 2.0 * x[points_[i] + c] + x[points_[i + 1] + c];
        if (jacobian) {
          jacobian[3 * row] = 1.0;
          jacobian[3 * row + 1] = -2.0;
          jacobian[3 * row + 2] = 1.0;
        }
      }
  }

 private:
  std::vector<int> points_;
};

using PairKind = CompositeDevelopment::PairKind;

int sampleCount(const CompositeTopology& topo, int e, int samples) {
  return topo.knots(e).numSpans() * samples + 1;
}

}  // namespace

void CompositeModel::buildDevelopmentMesh() {
  const CompositeTopology& topo = *topology_;
  const int samples = design_.developmentSamples;
  const int V = topo.numVertices(), E = topo.numEdges(), F = topo.numFaces();
  CompositeDevelopment& m = devMesh_;
  m = {};
  std::vector<int> edgeBase(E, -1), edgeCount(E, 0);
  int n = V;
  for (int v = 0; v < V; ++v) m.vertexSource.push_back(v);
  for (int e = 0; e < E; ++e) {
    if (topo.edgeType(e) != EdgeType::Spline) continue;
    edgeCount[e] = sampleCount(topo, e, samples);
    edgeBase[e] = n;
    for (int i = 1; i + 1 < edgeCount[e]; ++i) m.vertexSource.push_back(-1);
    n += edgeCount[e] - 2;
  }
  // 3D rows: vertices are their blocks, samples are evaluation rows of the edge's curve.
  const int P = static_cast<int>(problem_.x().size() / 3);
  std::vector<Eigen::Triplet<double>> t;
  for (int v = 0; v < V; ++v) t.emplace_back(v, pointIndex({v, -1, 0}), 1.0);
  for (int e = 0; e < E; ++e) {
    if (edgeBase[e] < 0 || edgeCount[e] <= 2) continue;
    const spline::KnotVector knots = topo.knots(e);
    const std::vector<double> all = knots.uniformSamples(edgeCount[e]);
    const std::vector<double> inner(all.begin() + 1, all.end() - 1);
    const spline::EvaluationMatrix M = spline::evaluationMatrix(knots, inner, 0);
    const std::vector<PointSlot> slots = topo.controlSlots(e);
    for (int k = 0; k < M.rows(); ++k)
      for (spline::EvaluationMatrix::InnerIterator it(M, k); it; ++it)
        t.emplace_back(edgeBase[e] + k, pointIndex(slots[static_cast<std::size_t>(it.col())]), it.value());
  }

  auto sampleId = [&](const OrientedEdge& oe, int i) {
    const int U = edgeCount[oe.edge];
    const int stored = oe.reversed ? U - 1 - i : i;
    const auto ends = topo.edgeVertices(oe.edge);
    if (stored == 0) return ends[0];
    if (stored == U - 1) return ends[1];
    return edgeBase[oe.edge] + stored - 1;
  };
  std::map<std::pair<int, int>, int> rulingEdge;
  for (int e = 0; e < E; ++e)
    if (topo.edgeType(e) == EdgeType::Ruling) {
      const auto ends = topo.edgeVertices(e);
      rulingEdge[std::minmax(ends[0], ends[1])] = e;
    }
  // Candidate pairs; the first (by kind priority) of each vertex pair wins.
  std::vector<CompositeDevelopment::Pair> candidates;
  auto addPair = [&](int i, int j, PairKind kind, int edge, int segment, int face) {
    if (i == j) return;
    candidates.push_back({i, j, kind, edge, segment, face});
  };
  devTriangles_.clear();
  devTriangleFace_.clear();
  auto addTriangle = [&](int a, int b, int c, int f) {
    if (a == b || b == c || a == c) return;
    devTriangles_.push_back({a, b, c});
    devTriangleFace_.push_back(f);
  };
  for (int f = 0; f < F; ++f) {
    options_.deadline.check();
    const FaceInfo& info = topo.face(f);
    if (info.type == FaceType::Planar) {
      const std::vector<int>& c = info.corners;
      const int N = static_cast<int>(c.size());
      m.polygons.push_back(c);
      m.polygonFace.push_back(f);
      for (int i = 0; i < N; ++i) {
        const int e = info.loop[static_cast<std::size_t>(i)].edge;
        addPair(c[i], c[(i + 1) % N], PairKind::Ruling, e, -1, f);
        for (int j = i + 2; j < N; ++j)
          if (!(i == 0 && j == N - 1)) addPair(c[i], c[j], PairKind::Diagonal, -1, -1, f);
      }
      // A fan from the first corner, unless the face is not convex (a notch, a face beside a
      // hole's bridge): a fan there holds triangles outside the face, turned over, and the
      // unfolding that follows them (unfold) mirrors the sheet beyond.
      Eigen::MatrixX3d corners(N, 3);
      for (int i = 0; i < N; ++i) corners.row(i) = design_.vertices.row(c[i]);
      const Eigen::MatrixX2d plane = spatial::polygonInItsPlane(corners);
      std::vector<std::array<int, 3>> triangles;
      if (!spatial::isConvexPolygon(plane)) {
        try {
          triangles = spatial::triangulateSimplePolygon(plane);
        } catch (const std::invalid_argument&) {
          triangles.clear();  // not simple (a face warped over itself): the fan, as before
        }
      }
      if (triangles.empty())
        for (int i = 1; i + 1 < N; ++i) triangles.push_back({0, i, i + 1});
      for (const auto& t : triangles) addTriangle(c[t[0]], c[t[1]], c[t[2]], f);
      continue;
    }
    const int U = edgeCount[info.a.edge];
    auto bId = [&](int i) { return info.type == FaceType::Cone ? info.apex : sampleId(info.b, i); };
    for (int i = 0; i < U; ++i) {
      const int a = sampleId(info.a, i), b = bId(i);
      const auto r = rulingEdge.find(std::minmax(a, b));
      if ((i == 0 || i == U - 1) && r != rulingEdge.end())
        addPair(a, b, PairKind::Ruling, r->second, -1, f);
      else
        addPair(a, b, PairKind::Interior, -1, -1, f);
    }
    for (int i = 0; i + 1 < U; ++i) {
      const int a0 = sampleId(info.a, i), a1 = sampleId(info.a, i + 1), b0 = bId(i), b1 = bId(i + 1);
      addPair(a0, a1, PairKind::Spline, info.a.edge, info.a.reversed ? U - 2 - i : i, f);
      if (info.type != FaceType::Cone)
        addPair(b0, b1, PairKind::Spline, info.b.edge, info.b.reversed ? U - 2 - i : i, f);
      addPair(a0, b1, PairKind::Diagonal, -1, -1, f);
      addPair(a1, b0, PairKind::Diagonal, -1, -1, f);
      std::vector<int> poly;
      for (int id : {a0, a1, b1, b0})
        if (poly.empty() || poly.back() != id) poly.push_back(id);
      while (poly.size() > 1 && poly.front() == poly.back()) poly.pop_back();
      if (poly.size() >= 3) {
        m.polygons.push_back(poly);
        m.polygonFace.push_back(f);
      }
      addTriangle(a0, a1, b1, f);
      addTriangle(a0, b1, b0, f);
    }
  }
  // Cut along the seam: corners (f, u) of faces at sample u are the same development vertex when
  // the faces share a non-seam edge through u; every further class of corners at u is a copy with
  // u's 3D row.
  seamEdge_.assign(static_cast<std::size_t>(E), false);
  for (int e : design_.developmentSeam) seamEdge_[static_cast<std::size_t>(e)] = true;
  devPeriodic_.clear();
  std::map<std::pair<int, int>, int> cornerId;  // (face, sample) -> development vertex after the cut
  if (!design_.developmentSeam.empty()) {
    std::map<std::pair<int, int>, std::pair<int, int>> parent;
    std::function<std::pair<int, int>(std::pair<int, int>)> root = [&parent, &root](std::pair<int, int> c) {
      const auto it = parent.find(c);
      if (it == parent.end() || it->second == c) return c;
      const auto r = root(it->second);
      parent[c] = r;
      return r;
    };
    auto touch = [&parent](int f, int u) { parent.emplace(std::make_pair(f, u), std::make_pair(f, u)); };
    for (std::size_t k = 0; k < devTriangles_.size(); ++k)
      for (int u : devTriangles_[k]) touch(devTriangleFace_[k], u);
    for (std::size_t k = 0; k < m.polygons.size(); ++k)
      for (int u : m.polygons[k]) touch(m.polygonFace[k], u);
    for (int e = 0; e < E; ++e) {
      const EdgeInfo& info = topo.edge(e);
      if (!info.interior() || seamEdge_[static_cast<std::size_t>(e)]) continue;
      const auto ends = topo.edgeVertices(e);
      std::vector<int> us{ends[0], ends[1]};
      for (int i = 1; i + 1 < edgeCount[e]; ++i) us.push_back(edgeBase[e] + i - 1);
      for (int u : us) {
        const auto a = std::make_pair(info.faces[0], u), b = std::make_pair(info.faces[1], u);
        if (!parent.count(a) || !parent.count(b)) continue;
        const auto ra = root(a), rb = root(b);
        if (ra != rb) parent[ra] = rb;
      }
    }
    std::map<int, std::vector<std::pair<int, int>>> classesAt;  // u -> class roots, first seen first
    for (const auto& entry : parent) {
      const auto r = root(entry.first);
      auto& list = classesAt[entry.first.second];
      if (std::find(list.begin(), list.end(), r) == list.end()) list.push_back(r);
    }
    std::vector<std::vector<std::pair<int, double>>> rowsOf(static_cast<std::size_t>(n));
    for (const auto& tr : t) rowsOf[static_cast<std::size_t>(tr.row())].emplace_back(tr.col(), tr.value());
    std::map<std::pair<int, int>, int> classId;
    for (const auto& [u, roots] : classesAt) {
      classId[roots[0]] = u;
      for (std::size_t c = 1; c < roots.size(); ++c) {
        classId[roots[c]] = n;
        for (const auto& [col, value] : rowsOf[static_cast<std::size_t>(u)]) t.emplace_back(n, col, value);
        m.vertexSource.push_back(m.vertexSource[static_cast<std::size_t>(u)]);
        devPeriodic_.push_back({u, n});
        ++n;
      }
    }
    for (const auto& entry : parent) cornerId[entry.first] = classId.at(root(entry.first));
    auto remap = [&cornerId](int f, int u) { return cornerId.at({f, u}); };
    for (std::size_t k = 0; k < devTriangles_.size(); ++k)
      for (int& u : devTriangles_[k]) u = remap(devTriangleFace_[k], u);
    for (std::size_t k = 0; k < m.polygons.size(); ++k)
      for (int& u : m.polygons[k]) u = remap(m.polygonFace[k], u);
    for (auto& p : candidates) {
      p.v0 = remap(p.face, p.v0);
      p.v1 = remap(p.face, p.v1);
    }
  }
  // Samples of every edge as development vertices, per side (faces[0], faces[1]).
  devEdgeSamples_.assign(static_cast<std::size_t>(E), {});
  for (int e = 0; e < E; ++e) {
    const auto ends = topo.edgeVertices(e);
    std::vector<int> us{ends[0]};
    for (int i = 1; i + 1 < edgeCount[e]; ++i) us.push_back(edgeBase[e] + i - 1);
    us.push_back(ends[1]);
    for (int side = 0; side < 2; ++side) {
      const int f = topo.edge(e).faces[static_cast<std::size_t>(side)];
      if (f < 0) continue;
      std::vector<int>& out = devEdgeSamples_[static_cast<std::size_t>(e)][static_cast<std::size_t>(side)];
      for (int u : us) {
        const auto it = cornerId.find({f, u});
        out.push_back(it == cornerId.end() ? u : it->second);
      }
    }
  }
  spline::EvaluationMatrix W(n, P);
  W.setFromTriplets(t.begin(), t.end());
  // A sample at a knot has a basis function that is exactly 0 there: dropped, the isometry rows
  // of a curve's samples hold the control points of one span and do not widen the band of the
  // normal matrix (issue 17: 40 × 40 sheet with development, nnz(H) 1.84M → 1.77M, 8–14 % off
  // the iteration).
  W.prune(0.0);
  W.makeCompressed();
  devSpatial_ = {W, 0};

  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const auto& p, const auto& q) { return static_cast<int>(p.kind) < static_cast<int>(q.kind); });
  std::map<std::pair<int, int>, bool> seen;
  for (const auto& p : candidates)
    if (seen.emplace(std::minmax(p.v0, p.v1), true).second) m.pairs.push_back(p);
  if (devTriangles_.empty()) throw std::invalid_argument("development: the sampled mesh has no faces");
  m.anchor0 = devTriangles_[0][0];
  m.anchor1 = devTriangles_[0][1];
}

Eigen::MatrixX2d CompositeModel::unfold(const Eigen::VectorXd& x) const {
  const CompositeTopology& topo = *topology_;
  const int n = devSpatial_.rows();
  std::vector<Eigen::Vector3d> p3(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) p3[k] = devSpatial_.point(x, k);
  Eigen::MatrixX2d out = Eigen::MatrixX2d::Zero(n, 2);
  std::vector<bool> placed(static_cast<std::size_t>(n), false);
  auto pt = [&](int i) -> Eigen::Vector2d { return out.row(i).transpose(); };
  // r to the left of p → q (the triangle (p, q, r) is counterclockwise), keeping |pr| and |qr|.
  auto place = [&](int p, int q, int r) {
    const Eigen::Vector2d P = pt(p), Q = pt(q);
    const double L = (Q - P).norm();
    const double lpr = (p3[r] - p3[p]).norm(), lqr = (p3[r] - p3[q]).norm();
    Eigen::Vector2d e = L > 0 ? Eigen::Vector2d((Q - P) / L) : Eigen::Vector2d(1.0, 0.0);
    const Eigen::Vector2d nrm(-e.y(), e.x());
    const double along = L > 0 ? (lpr * lpr - lqr * lqr + L * L) / (2.0 * L) : 0.0;
    const double perp = std::sqrt(std::max(0.0, lpr * lpr - along * along));
    out.row(r) = (P + along * e + perp * nrm).transpose();
    placed[r] = true;
  };
  const int T = static_cast<int>(devTriangles_.size());
  std::vector<std::vector<int>> faceTriangles(static_cast<std::size_t>(topo.numFaces()));
  for (int k = 0; k < T; ++k) faceTriangles[devTriangleFace_[k]].push_back(k);
  std::vector<bool> done(static_cast<std::size_t>(T), false);
  auto tryTriangle = [&](int k) {
    if (done[k]) return false;
    const auto& tri = devTriangles_[k];
    int missing = -1, count = 0;
    for (int c = 0; c < 3; ++c)
      if (!placed[tri[c]]) {
        missing = c;
        ++count;
      }
    if (count == 0) {
      done[k] = true;
      return true;
    }
    if (count > 1) return false;
    place(tri[(missing + 1) % 3], tri[(missing + 2) % 3], tri[missing]);
    done[k] = true;
    return true;
  };
  std::vector<bool> visited(static_cast<std::size_t>(topo.numFaces()), false);
  for (int root = 0; root < topo.numFaces(); ++root) {
    if (visited[root] || faceTriangles[root].empty()) continue;
    // Seed a component: its first triangle, vertex 0 at the origin (for the first component the
    // anchors), the first edge along +x.
    const auto& tri = devTriangles_[faceTriangles[root][0]];
    if (!placed[tri[0]] && !placed[tri[1]]) {
      out.row(tri[0]).setZero();
      placed[tri[0]] = true;
      out.row(tri[1]) << (p3[tri[1]] - p3[tri[0]]).norm(), 0.0;
      placed[tri[1]] = true;
    }
    std::deque<int> queue{root};
    visited[root] = true;
    while (!queue.empty()) {
      options_.deadline.check();
      const int f = queue.front();
      queue.pop_front();
      const std::vector<int>& ts = faceTriangles[f];
      for (bool progress = true; progress;) {
        progress = false;
        for (int k : ts) progress = tryTriangle(k) || progress;
        for (auto it = ts.rbegin(); it != ts.rend(); ++it) progress = tryTriangle(*it) || progress;
      }
      for (const OrientedEdge& oe : topo.face(f).loop) {
        if (seamEdge_[static_cast<std::size_t>(oe.edge)]) continue;  // cut open
        const EdgeInfo& info = topo.edge(oe.edge);
        for (int g : info.faces)
          if (g >= 0 && !visited[g]) {
            visited[g] = true;
            queue.push_back(g);
          }
      }
    }
  }
  return out;
}

Eigen::MatrixX2d CompositeModel::unfoldedDevelopment() const {
  if (!hasDevelopment()) throw std::logic_error("the composite has no development");
  return unfold(problem_.x()) * normalization_.scale;
}

CompositeDevelopment CompositeModel::development() const {
  if (!hasDevelopment()) throw std::logic_error("the composite has no development");
  CompositeDevelopment d = devMesh_;
  const Eigen::VectorXd& x = problem_.x();
  const int n = devSpatial_.rows();
  d.vertices3d.resize(n, 3);
  d.vertices2d.resize(n, 2);
  const int offset = problem_.layout().block(developmentBlock_).offset;
  for (int k = 0; k < n; ++k) {
    d.vertices3d.row(k) = normalization_.fromNormalized(devSpatial_.point(x, k)).transpose();
    d.vertices2d.row(k) = normalization_.scale * x.segment<2>(offset + 2 * k).transpose();
  }
  d.periodic = devPeriodic_;
  d.period = developmentPeriod();
  return d;
}

namespace {

double signedArea(const Eigen::VectorXd& x, int offset, const std::vector<int>& loop) {
  double area = 0.0;
  for (std::size_t i = 0; i < loop.size(); ++i) {
    const int a = offset + 2 * loop[i], b = offset + 2 * loop[(i + 1) % loop.size()];
    area += x[a] * x[b + 1] - x[b] * x[a + 1];
  }
  return 0.5 * area;
}

}  // namespace

int CompositeModel::flippedDevelopmentFaces() const {
  if (!hasDevelopment()) return 0;
  const int offset = problem_.layout().block(developmentBlock_).offset;
  int flipped = 0;
  for (const std::vector<int>& loop : devMesh_.polygons)
    if (!(signedArea(problem_.x(), offset, loop) > 0.0)) ++flipped;
  return flipped;
}

bool CompositeModel::repairDevelopment() {
  if (!hasDevelopment()) return false;
  const int n = devSpatial_.rows();
  const int offset = problem_.layout().block(developmentBlock_).offset;
  Eigen::VectorXd& x = problem_.x();
  const Eigen::MatrixX2d fresh = unfold(x);
  // Rigid fit (rotation + translation) of the fresh unfolding onto the current development.
  Eigen::Vector2d cf = Eigen::Vector2d::Zero(), ct = Eigen::Vector2d::Zero();
  for (int k = 0; k < n; ++k) {
    cf += fresh.row(k).transpose() / n;
    ct += x.segment<2>(offset + 2 * k) / n;
  }
  double sx = 0.0, sy = 0.0;
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector2d f = fresh.row(k).transpose() - cf, t = x.segment<2>(offset + 2 * k) - ct;
    sx += f.x() * t.x() + f.y() * t.y();
    sy += f.x() * t.y() - f.y() * t.x();
  }
  const double angle = std::atan2(sy, sx);
  Eigen::Matrix2d R;
  R << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
  for (int k = 0; k < n; ++k) {
    const Eigen::Vector2d p = R * (fresh.row(k).transpose() - cf) + ct;
    for (int c = 0; c < 2; ++c)
      if (!problem_.layout().isFixed(offset + 2 * k + c)) x[offset + 2 * k + c] = p[c];
  }
  if (periodBlock_ >= 0) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const std::array<int, 2>& p : devPeriodic_)
      mean += (x.segment<2>(offset + 2 * p[1]) - x.segment<2>(offset + 2 * p[0])) / static_cast<double>(devPeriodic_.size());
    problem_.blockValues(periodBlock_) = mean;
  }
  return true;
}

Eigen::Vector2d CompositeModel::developmentPeriod() const {
  if (periodBlock_ < 0) return Eigen::Vector2d::Zero();
  return normalization_.scale * problem_.x().segment<2>(problem_.layout().block(periodBlock_).offset);
}

double CompositeModel::developmentLengthError() const {
  if (!hasDevelopment()) return 0.0;
  const Eigen::VectorXd& x = problem_.x();
  const int offset = problem_.layout().block(developmentBlock_).offset;
  double num = 0.0, den = 0.0;
  for (const CompositeDevelopment::Pair& p : devMesh_.pairs) {
    const double l3 = (devSpatial_.point(x, p.v0) - devSpatial_.point(x, p.v1)).norm();
    const double l2 = (x.segment<2>(offset + 2 * p.v0) - x.segment<2>(offset + 2 * p.v1)).norm();
    num += (l3 - l2) * (l3 - l2);
    den += l3 * l3;
  }
  return den > 0 ? std::sqrt(num / den) : 0.0;
}

double CompositeModel::developmentEdgeStrainMax() const {
  if (!hasDevelopment()) return 0.0;
  const Eigen::VectorXd& x = problem_.x();
  const int offset = problem_.layout().block(developmentBlock_).offset;
  double worst = 0.0;
  for (const CompositeDevelopment::Pair& p : devMesh_.pairs) {
    if (p.kind == PairKind::Diagonal) continue;
    const double l3 = (devSpatial_.point(x, p.v0) - devSpatial_.point(x, p.v1)).norm();
    const double l2 = (x.segment<2>(offset + 2 * p.v0) - x.segment<2>(offset + 2 * p.v1)).norm();
    const double base = l2 > 0.0 ? l2 : l3;  // a 2D edge of length 0: its whole 3D length, ratio 1
    if (base > 0.0) worst = std::max(worst, std::abs(l3 - l2) / base);
  }
  return worst;
}

void CompositeModel::addDevelopmentTerms() {
  const CompositeTopology& topo = *topology_;
  const int n = devSpatial_.rows();
  const int offset = problem_.layout().block(developmentBlock_).offset;
  const DevelopmentDomain& domain = design_.developmentDomain;
  const double unit = normalization_.scale;  // design units per normalized unit
  const bool saved = design_.developmentVertices.rows() == n && design_.developmentVertices.allFinite();
  Eigen::MatrixX2d start = saved ? Eigen::MatrixX2d(design_.developmentVertices / unit) : unfold(problem_.x());
  if (!saved && !domain.empty()) {
    // Place the unfolding in the domain's frame: the rotation and translation that best map it
    // onto the corners (two or more), else onto the design's own x, y (a flat start).
    std::vector<Eigen::Vector2d> from, to;
    if (domain.corners.size() >= 2) {
      for (const DomainCorner& c : domain.corners) {
        from.push_back(start.row(c.vertex).transpose());
        to.push_back(c.at / unit);
      }
    } else {
      for (int v = 0; v < topo.numVertices(); ++v) {
        from.push_back(start.row(v).transpose());
        to.push_back(design_.vertices.row(v).head<2>().transpose() / unit);
      }
    }
    Eigen::Vector2d cf = Eigen::Vector2d::Zero(), ct = Eigen::Vector2d::Zero();
    for (std::size_t i = 0; i < from.size(); ++i) {
      cf += from[i] / static_cast<double>(from.size());
      ct += to[i] / static_cast<double>(from.size());
    }
    double sx = 0.0, sy = 0.0;
    for (std::size_t i = 0; i < from.size(); ++i) {
      const Eigen::Vector2d f = from[i] - cf, t = to[i] - ct;
      sx += f.x() * t.x() + f.y() * t.y();
      sy += f.x() * t.y() - f.y() * t.x();
    }
    const double angle = std::atan2(sy, sx);
    Eigen::Matrix2d R;
    R << std::cos(angle), -std::sin(angle), std::sin(angle), std::cos(angle);
    for (int k = 0; k < n; ++k) start.row(k) = (R * (start.row(k).transpose() - cf) + ct).transpose();
    for (const DomainCorner& c : domain.corners) start.row(c.vertex) = (c.at / unit).transpose();
  }
  Eigen::Map<Eigen::VectorXd> values = problem_.blockValues(developmentBlock_);
  for (int k = 0; k < n; ++k) values.segment<2>(2 * k) = start.row(k).transpose();
  if (domain.empty()) {
    problem_.layout().setFixed(developmentBlock_, 2 * devMesh_.anchor0, 2);
    problem_.layout().setFixed(developmentBlock_, 2 * devMesh_.anchor1 + 1, 1);
  }
  for (const DomainCorner& c : domain.corners) problem_.layout().setFixed(developmentBlock_, 2 * c.vertex, 2);

  // Periodicity across the seam: orient every (vertex, copy) pair like the first one.
  if (periodBlock_ >= 0) {
    const Eigen::RowVector2d first = start.row(devPeriodic_[0][1]) - start.row(devPeriodic_[0][0]);
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    std::vector<std::array<int, 2>> pairs;
    for (std::array<int, 2>& p : devPeriodic_) {
      if ((start.row(p[1]) - start.row(p[0])).dot(first) < 0.0) std::swap(p[0], p[1]);
      mean += (start.row(p[1]) - start.row(p[0])).transpose() / static_cast<double>(devPeriodic_.size());
      pairs.push_back({offset + 2 * p[0], offset + 2 * p[1]});
    }
    problem_.blockValues(periodBlock_) = mean;
    problem_.addTerm(std::make_unique<terms::DevelopmentPeriodTerm>(
                         "development_period", pairs, problem_.layout().block(periodBlock_).offset),
                     1.0, engine::Strength::Hard);
  }

  // Domain curves: the samples of every boundary edge stay on the domain curve nearest to it, and
  // those of an interior S edge on a curve it already lies on (a drawn crease).
  if (!domain.boundary.empty()) {
    // Domain curve c in normalized units.
    auto curvePoints = [&domain, unit](std::size_t c) {
      std::vector<Eigen::Vector2d> pts;
      for (Eigen::Index i = 0; i < domain.boundary[c].points.rows(); ++i)
        pts.push_back(domain.boundary[c].points.row(i).transpose() / unit);
      return pts;
    };
    std::vector<std::unique_ptr<terms::TangentDistanceTerm>> curves;
    for (std::size_t c = 0; c < domain.boundary.size(); ++c)
      curves.push_back(std::make_unique<terms::TangentDistanceTerm>("development_domain", std::vector<int>{},
                                                                    curvePoints(c), domain.boundary[c].closed));
    std::vector<bool> corner(static_cast<std::size_t>(n), false);
    for (const DomainCorner& c : domain.corners) corner[static_cast<std::size_t>(c.vertex)] = true;
    std::vector<std::vector<int>> onCurve(domain.boundary.size()), creaseOnCurve(domain.boundary.size());
    std::vector<bool> taken(static_cast<std::size_t>(n), false);
    for (int e = 0; e < topo.numEdges(); ++e) {
      const EdgeInfo& info = topo.edge(e);
      const bool inside = info.interior();
      if (inside && topo.edgeType(e) != EdgeType::Spline) continue;
      const std::vector<int>& samples = devEdgeSamples_[static_cast<std::size_t>(e)][info.faces[0] >= 0 ? 0 : 1];
      std::size_t best = 0;
      double bestDistance = std::numeric_limits<double>::infinity();
      for (std::size_t c = 0; c < curves.size(); ++c) {
        double sum = 0.0;
        for (int v : samples) {
          Eigen::Vector2d foot, normal;
          const Eigen::Vector2d p = start.row(v).transpose();
          curves[c]->project(p, foot, normal);
          sum += (p - foot).norm();
        }
        if (sum < bestDistance) {
          bestDistance = sum;
          best = c;
        }
      }
      if (inside) {
        const double chord = samples.size() < 2 ? 0.0 : (start.row(samples.front()) - start.row(samples.back())).norm();
        if (samples.empty() || bestDistance / static_cast<double>(samples.size()) > 0.02 * chord) continue;
      }
      for (int v : samples)
        if (!corner[static_cast<std::size_t>(v)] && !taken[static_cast<std::size_t>(v)]) {
          taken[static_cast<std::size_t>(v)] = true;
          (inside ? creaseOnCurve : onCurve)[best].push_back(offset + 2 * v);
        }
    }
    // A drawn crease holds its samples softly: its spline cannot follow the drawing exactly while
    // the sheet folds (hard, the rows fight the isometry at ~1e-4 strain and a polish unfolds
    // the sheet to meet them); the projections of a polish leave it out.
    for (std::size_t c = 0; c < curves.size(); ++c) {
      if (!onCurve[c].empty())
        problem_.addTerm(std::make_unique<terms::TangentDistanceTerm>("development_domain", onCurve[c], curvePoints(c),
                                                                      domain.boundary[c].closed),
                         1.0, engine::Strength::Hard);
      if (!creaseOnCurve[c].empty())
        problem_.addTerm(std::make_unique<terms::TangentDistanceTerm>("development_crease", creaseOnCurve[c],
                                                                      curvePoints(c), domain.boundary[c].closed),
                         options_.developmentCreaseWeight, engine::Strength::Soft);
    }
  }
  std::vector<int> offsets;
  for (int k = 0; k < n; ++k) offsets.push_back(offset + 2 * k);
  std::vector<std::pair<int, int>> pairs;
  for (const CompositeDevelopment::Pair& p : devMesh_.pairs) pairs.emplace_back(p.v0, p.v1);
  problem_.addTerm(std::make_unique<terms::EdgeIsometryTerm>("development_isometry", devSpatial_, offsets, pairs),
                   1.0, engine::Strength::Hard);
  if (options_.developmentAreaRatio > 0.0) {
    // Degeneracy guard: every development triangle stays counterclockwise with a fraction of its
    // area (the isometry rows cannot tell a face from its mirror image).
    std::vector<double> minArea(devTriangles_.size());
    for (std::size_t t = 0; t < devTriangles_.size(); ++t) {
      const auto& tri = devTriangles_[t];
      const Eigen::Vector2d p0 = start.row(tri[0]).transpose(), p1 = start.row(tri[1]).transpose(),
                            p2 = start.row(tri[2]).transpose();
      const double area = 0.5 * ((p1.x() - p0.x()) * (p2.y() - p0.y()) - (p2.x() - p0.x()) * (p1.y() - p0.y()));
      // ≤ 0 (flipped at build): not guarded; nor is a sliver of three points on a line (a vertex
      // added on a straight side, area 1.5e-10 for sides of 0.12): a row scaled by the inverse of
      // such an area blew a drag's first step up by 1e12, and its Jacobian made the next
      // normal matrix numerically indefinite.
      const double longest =
          std::max({(p1 - p0).squaredNorm(), (p2 - p1).squaredNorm(), (p0 - p2).squaredNorm()});
      minArea[t] = area > kSliverAreaRatio * longest ? options_.developmentAreaRatio * area : 0.0;
    }
    problem_.addTerm(std::make_unique<terms::TriangleOrientationTerm>("development_orientation", offset, devTriangles_,
                                                                     minArea),
                     1.0, engine::Strength::Hard);
  }
  // Fairness of the developed S edges (boundary and crease polylines), decaying; a seam edge's
  // polyline as the first of its faces sees it (its copies follow through the period).
  for (int e = 0; e < topo.numEdges(); ++e) {
    if (topo.edgeType(e) != EdgeType::Spline) continue;
    const auto& sides = devEdgeSamples_[static_cast<std::size_t>(e)];
    const std::vector<int>& samples = sides[0].empty() ? sides[1] : sides[0];
    if (samples.size() < 3) continue;
    std::vector<int> poly;
    for (int v : samples) poly.push_back(offset + 2 * v);
    problem_.addTerm(std::make_unique<PlanarPolylineFairnessTerm>("development_fairness", poly), 1.0,
                     engine::Strength::Soft, engine::WeightSchedule::Fairness);
  }
}

io::CreasePattern CompositeModel::creasePattern(const std::string& title) const {
  const CompositeDevelopment d = development();
  const CompositeTopology& topo = *topology_;
  const CompositeDesign des = design();
  io::CreasePattern cp;
  cp.title = title;
  cp.vertices2d = d.vertices2d;
  cp.vertices3d = d.vertices3d;
  std::map<int, Eigen::VectorXd> angles;
  for (const CreaseGeometry& c : creases(design_.developmentSamples)) angles[c.edge] = c.foldAngleDeg;
  // The designed fold angles (design.foldAngles, at 100 %) per edge end: a crease of a sheet that
  // is not folded (fold amount 0, or folded by less than kUnfoldedDeg) keeps its mountain or
  // valley and its angle.
  constexpr double kUnfoldedDeg = 0.5;
  std::map<int, std::array<std::optional<double>, 2>> designed;
  for (const FoldAngleTarget& t : design_.foldAngles)
    if (t.end == 0 || t.end == 1) designed[t.edge][static_cast<std::size_t>(t.end)] = t.angleDeg;
  // S edges joined with one tangent (tangent_continuity: a crease the import split at a ruling
  // halfway along) are one crease line: their edges share the first one's curve id, so a FOLD or
  // SVG export read back gives one crease, not two that the next import splits again.
  std::vector<int> lineOf(static_cast<std::size_t>(topo.numEdges()));
  for (int e = 0; e < topo.numEdges(); ++e) lineOf[static_cast<std::size_t>(e)] = e;
  const auto lineRoot = [&lineOf](int e) {
    while (lineOf[static_cast<std::size_t>(e)] != e) e = lineOf[static_cast<std::size_t>(e)] = lineOf[static_cast<std::size_t>(lineOf[static_cast<std::size_t>(e)])];
    return e;
  };
  for (const std::array<int, 2>& pair : design_.tangentContinuity) {
    const int a = lineRoot(pair[0]), b = lineRoot(pair[1]);
    lineOf[static_cast<std::size_t>(std::max(a, b))] = std::min(a, b);
  }
  auto assign = [](double angle) {
    if (angle > 1e-6) return io::EdgeAssignment::Valley;
    if (angle < -1e-6) return io::EdgeAssignment::Mountain;
    return io::EdgeAssignment::Flat;
  };
  std::vector<Eigen::Vector4d> rulings;
  for (const CompositeDevelopment::Pair& p : d.pairs) {
    io::CreaseEdge ce;
    ce.v0 = p.v0;
    ce.v1 = p.v1;
    double angle = 0.0;
    switch (p.kind) {
      case PairKind::Diagonal:
        continue;
      case PairKind::Interior: {
        ce.assignment = io::EdgeAssignment::Flat;
        Eigen::Vector4d r;
        r << d.vertices2d(p.v0, 0), d.vertices2d(p.v0, 1), d.vertices2d(p.v1, 0), d.vertices2d(p.v1, 1);
        rulings.push_back(r);
        break;
      }
      case PairKind::Spline:
      case PairKind::Ruling: {
        if (p.kind == PairKind::Spline) ce.curve = lineRoot(p.edge);
        const auto it = angles.find(p.edge);
        if (!topo.edge(p.edge).interior() || seamEdge_[static_cast<std::size_t>(p.edge)] || it == angles.end()) {
          ce.assignment = io::EdgeAssignment::Boundary;
        } else if (design_.edges[static_cast<std::size_t>(p.edge)].crease == CreaseKind::Smooth) {
          ce.assignment = io::EdgeAssignment::Flat;  // one tangent plane on both sides: not a fold
          // A straight one (R) is kept so when the pattern is read back (CreaseEdge::proposed);
          // a smooth curve (S) keeps its curve id instead.
          ce.proposed = p.kind == PairKind::Ruling;
        } else {
          const Eigen::VectorXd& a = it->second;
          const int s = p.kind == PairKind::Spline ? p.segment : 0;
          const auto designedAt = designed.find(p.edge);
          std::optional<double> designedAngle;  // between the two ends' along an S edge
          if (designedAt != designed.end()) {
            const auto& [atStart, atEnd] = designedAt->second;
            const double f = a.size() > 1 ? std::clamp((s + 0.5) / static_cast<double>(a.size() - 1), 0.0, 1.0) : 0.5;
            designedAngle = atStart && atEnd ? (1.0 - f) * *atStart + f * *atEnd : atStart ? *atStart : *atEnd;
          }
          // A measured angle is defined up to a full turn, and near ±180° it comes out with either
          // sign (a mountain folded to 180° measures 179.9° as readily as −180.1°): each sample is
          // taken at the turn nearer the designed angle — or, without one, nearer the first sample
          // — before the two are averaged (179.9° and −179.9° are a fold of 180°, not of 0°).
          auto nearer = [](double measured, double to) {
            const double other = measured - std::copysign(360.0, measured);
            return std::abs(other - to) < std::abs(measured - to) ? other : measured;
          };
          const double first = a[std::min<Eigen::Index>(s, a.size() - 1)];
          const double reference = designedAngle ? *designedAngle : first;
          angle = 0.5 * (nearer(first, reference) + nearer(a[std::min<Eigen::Index>(s + 1, a.size() - 1)], reference));
          if (designedAngle && std::abs(angle) < kUnfoldedDeg) {
            // Not folded here (the slider at 0 %, or not yet this far): the designed angle. A
            // crease folded by a drag keeps its own.
            angle = *designedAngle;
          }
          angle = std::clamp(angle, -180.0, 180.0);
          ce.assignment = assign(angle);
          if (ce.assignment == io::EdgeAssignment::Flat) angle = 0.0;
        }
        break;
      }
    }
    ce.foldAngle = angle;
    cp.edges.push_back(ce);
  }
  cp.faces = d.polygons;
  cp.rulings.resize(static_cast<Eigen::Index>(rulings.size()), 4);
  for (std::size_t i = 0; i < rulings.size(); ++i) cp.rulings.row(static_cast<Eigen::Index>(i)) = rulings[i].transpose();
  for (int e = 0; e < topo.numEdges(); ++e) {
    if (topo.edgeType(e) != EdgeType::Spline) continue;
    io::CreaseCurve c;
    c.id = e;
    c.degree = des.edges[e].curve.degree();
    c.knots = des.edges[e].curve.knots.knots();
    c.controlPoints = des.edges[e].curve.points;
    cp.curves.push_back(std::move(c));
  }
  cp.validate();
  return cp;
}

}  // namespace devsurf::models::composite
