// The current state of a composite measured and sampled: its curves per face, the surface normal,
// crease samples and fold angles (creases), the quality metrics of Tang et al. 2016 Fig. 17
// (quality), the sampled mesh for drawing and export (geometry) and IGES entities.

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "CompositeModelState.h"
#include "devsurf/metrics/PolygonFlatness.h"
#include "devsurf/metrics/QuadFlatness.h"
#include "devsurf/metrics/StripQuality.h"
#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/models/composite/CompositePieces.h"
#include "devsurf/spatial/PolygonTriangulation.h"
#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/BasisTable.h"

namespace devsurf::models::composite {

namespace {

using metrics::polygonFlatness;
using metrics::quadFlatness;

/// π as a double (EIGEN_PI is a long double: the angle sums of a flat vertex would no longer
/// cancel to 0).
constexpr double kMeasurementPi = 3.14159265358979323846;

/// The angle (rad, in [0, π]) at p between the legs to prev and next.
double angleAt(const Eigen::Vector3d& prev, const Eigen::Vector3d& p, const Eigen::Vector3d& next) {
  const Eigen::Vector3d u = prev - p, v = next - p;
  return std::atan2(u.cross(v).norm(), u.dot(v));
}

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
      // (The sides' parameters were made from the edge's samples: only with them.)
      const bool tabled1 = tabled && sideTabled(f1, table.sides[0], count),
                 tabled2 = tabled && sideTabled(f2, table.sides[1], count);
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
      c.foldAngleDeg[i] = -theta * 180.0 / kMeasurementPi;
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
      if (info.type == FaceType::Planar)  // the corners against their least-squares plane
        delta = polygonFlatness(points, poly, tiny);
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
    const double k = std::abs(angleSum[v] - 2.0 * kMeasurementPi);
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
