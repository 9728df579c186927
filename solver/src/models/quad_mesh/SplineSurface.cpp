// Developable spline surfaces (004_… §4, Algorithm 2): the refinement S^k(M) of a control mesh
// made of rectangular patches, the smoothness rows across shared sides, and the analysis of the
// bicubic surface M^∞ itself (curvature, normal jumps, rulings).
#include "devsurf/models/quad_mesh/SplineSurface.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Geometry>

#include "devsurf/spline/Basis.h"
#include "devsurf/spline/CubicSubdivision.h"
#include "devsurf/spline/KnotVector.h"

namespace devsurf::models::quad_mesh {

namespace {

[[noreturn]] void failSplineSurface(const std::string& message) { throw std::invalid_argument(message); }

std::string patchPath(const ControlNet& net, std::size_t p) {
  return net.patches.empty() ? std::string("control") : "control.patches[" + std::to_string(p) + "]";
}

/// Control-point index of grid point (r, c) of a patch.
int at(const ControlPatch& patch, int r, int c) { return patch.indices[static_cast<std::size_t>(r * patch.columns + c)]; }

/// Grid coordinates of position i (loop order) on side s, and of its neighbour one step inward.
std::array<int, 2> sidePoint(const ControlPatch& p, int side, int i, int inward) {
  const int R = p.rows, C = p.columns;
  switch (side) {
    case 0: return {inward, i};
    case 1: return {i, C - 1 - inward};
    case 2: return {R - 1 - inward, C - 1 - i};
    default: return {R - 1 - i, inward};
  }
}
int sideLength(const ControlPatch& p, int side) { return side % 2 == 0 ? p.columns : p.rows; }

std::vector<int> sideIndices(const ControlPatch& p, int side, int inward) {
  std::vector<int> s(static_cast<std::size_t>(sideLength(p, side)));
  for (int i = 0; i < sideLength(p, side); ++i) {
    const auto rc = sidePoint(p, side, i, inward);
    s[static_cast<std::size_t>(i)] = at(p, rc[0], rc[1]);
  }
  return s;
}

void validateNet(const ControlNet& net) {
  if (net.rounds < 0 || net.rounds > 4) failSplineSurface("control.rounds: 0 … 4, got " + std::to_string(net.rounds));
  if (net.points.rows() == 0) failSplineSurface("control.points: at least 16 points are needed");
  if (!net.points.allFinite()) failSplineSurface("control.points: every coordinate must be a finite number");
  if (!std::isfinite(net.smoothness) || net.smoothness < 0)
    failSplineSurface("control.smoothness: a finite weight ≥ 0 is needed");
  const int P = static_cast<int>(net.points.rows());
  if (net.patches.empty()) {
    if (net.rows < 4 || net.columns < 4)
      failSplineSurface("control: a bicubic net needs at least 4 rows and 4 columns, got " + std::to_string(net.rows) + " × " +
           std::to_string(net.columns));
    if (static_cast<long long>(net.rows) * net.columns != P)
      failSplineSurface("control.points: " + std::to_string(static_cast<long long>(net.rows) * net.columns) + " expected, got " +
           std::to_string(P));
    return;
  }
  std::vector<char> used(static_cast<std::size_t>(P), 0);
  for (std::size_t p = 0; p < net.patches.size(); ++p) {
    const ControlPatch& patch = net.patches[p];
    const std::string path = patchPath(net, p);
    if (patch.rows < 4 || patch.columns < 4)
      failSplineSurface(path + ": a bicubic patch needs at least 4 rows and 4 columns, got " + std::to_string(patch.rows) + " × " +
           std::to_string(patch.columns));
    if (static_cast<long long>(patch.rows) * patch.columns != static_cast<long long>(patch.indices.size()))
      failSplineSurface(path + ".indices: rows × columns = " + std::to_string(static_cast<long long>(patch.rows) * patch.columns) +
           " expected, got " + std::to_string(patch.indices.size()));
    std::vector<int> sorted = patch.indices;
    for (std::size_t i = 0; i < patch.indices.size(); ++i) {
      const int j = patch.indices[i];
      if (j < 0 || j >= P)
        failSplineSurface(path + ".indices[" + std::to_string(i) + "]: " + std::to_string(j) + " is not a control point (0 … " +
             std::to_string(P - 1) + ")");
      used[static_cast<std::size_t>(j)] = 1;
    }
    std::sort(sorted.begin(), sorted.end());
    const auto repeated = std::adjacent_find(sorted.begin(), sorted.end());
    if (repeated != sorted.end())
      failSplineSurface(path + ".indices: control point " + std::to_string(*repeated) + " appears twice in one patch");
  }
  for (int j = 0; j < P; ++j)
    if (!used[static_cast<std::size_t>(j)])
      failSplineSurface("control.points[" + std::to_string(j) + "]: no patch uses it (every control point must belong to a patch)");
}

/// A control point in two patches must lie on a whole side the two share, or be a corner of
/// both (patches touching at a corner). Anything else — a corner of one patch in the middle of
/// another's side (a T-junction), sides overlapping in part, an interior point reused — leaves a
/// gap between the refined patches, because the refined boundary curves are not the same curve.
void refuseJunctionsOffSharedSides(const ControlNet& net, const std::vector<ControlPatch>& patches,
                                   const std::vector<SharedSide>& shared) {
  if (patches.size() < 2) return;
  std::map<std::pair<int, int>, std::vector<int>> sharedPoints;  // (patch a < patch b) → indices on shared sides
  for (const SharedSide& s : shared) {
    const std::vector<int> side = sideIndices(patches[static_cast<std::size_t>(s.patchA)], s.sideA, 0);
    auto& points = sharedPoints[{std::min(s.patchA, s.patchB), std::max(s.patchA, s.patchB)}];
    points.insert(points.end(), side.begin(), side.end());
  }
  struct Place {
    int patch, position;
    bool corner;
  };
  std::map<int, std::vector<Place>> placesOfPoint;
  for (int p = 0; p < static_cast<int>(patches.size()); ++p) {
    const ControlPatch& patch = patches[static_cast<std::size_t>(p)];
    for (int r = 0; r < patch.rows; ++r)
      for (int c = 0; c < patch.columns; ++c) {
        const bool corner = (r == 0 || r == patch.rows - 1) && (c == 0 || c == patch.columns - 1);
        placesOfPoint[at(patch, r, c)].push_back({p, r * patch.columns + c, corner});
      }
  }
  for (const auto& [point, places] : placesOfPoint)
    for (std::size_t i = 0; i < places.size(); ++i)
      for (std::size_t j = i + 1; j < places.size(); ++j) {
        const Place &a = places[i], &b = places[j];
        if (a.corner && b.corner) continue;
        const auto found = sharedPoints.find({std::min(a.patch, b.patch), std::max(a.patch, b.patch)});
        if (found != sharedPoints.end() &&
            std::find(found->second.begin(), found->second.end(), point) != found->second.end())
          continue;
        failSplineSurface(patchPath(net, static_cast<std::size_t>(b.patch)) + ".indices[" + std::to_string(b.position) +
             "]: control point " + std::to_string(point) + " is also in patch " + std::to_string(a.patch) +
             ", but the two patches do not share a whole side through it (a T-junction or a partly shared "
             "side leaves a gap); split the longer patch so that the sides match point for point");
      }
}

}  // namespace

std::vector<ControlPatch> controlPatches(const ControlNet& net) {
  if (!net.patches.empty()) return net.patches;
  ControlPatch p;
  p.rows = net.rows;
  p.columns = net.columns;
  p.indices.resize(static_cast<std::size_t>(std::max(0, net.rows * net.columns)));
  for (std::size_t i = 0; i < p.indices.size(); ++i) p.indices[i] = static_cast<int>(i);
  return {p};
}

std::vector<SharedSide> splineSharedSides(const ControlNet& net) {
  validateNet(net);
  const std::vector<ControlPatch> patches = controlPatches(net);
  struct Occurrence {
    int patch, side;
    std::vector<int> sequence;
  };
  std::map<std::vector<int>, std::vector<Occurrence>> bySide;
  for (int p = 0; p < static_cast<int>(patches.size()); ++p)
    for (int s = 0; s < 4; ++s) {
      std::vector<int> seq = sideIndices(patches[static_cast<std::size_t>(p)], s, 0);
      std::vector<int> reversed(seq.rbegin(), seq.rend());
      bySide[std::min(seq, reversed)].push_back({p, s, std::move(seq)});
    }
  std::vector<SharedSide> shared;
  for (const auto& [key, occurrences] : bySide) {
    if (occurrences.size() < 2) continue;
    const Occurrence &a = occurrences[0], &b = occurrences[1];
    if (occurrences.size() > 2)
      failSplineSurface(patchPath(net, static_cast<std::size_t>(occurrences[2].patch)) + ": its side " +
           std::to_string(occurrences[2].side) + " is already shared by patches " + std::to_string(a.patch) + " and " +
           std::to_string(b.patch) + " (a side joins at most two patches)");
    if (a.sequence == b.sequence)
      failSplineSurface(patchPath(net, static_cast<std::size_t>(b.patch)) + ": its side " + std::to_string(b.side) +
           " runs the same way as side " + std::to_string(a.side) + " of patch " + std::to_string(a.patch) +
           ", so the two patches face opposite ways; reverse the rows of one of them");
    shared.push_back({a.patch, a.side, b.patch, b.side});
  }
  refuseJunctionsOffSharedSides(net, patches, shared);
  return shared;
}

std::vector<std::array<int, 3>> splineSmoothnessTriples(const ControlNet& net) {
  const std::vector<ControlPatch> patches = controlPatches(net);
  std::vector<std::array<int, 3>> triples;
  for (const SharedSide& s : splineSharedSides(net)) {
    const ControlPatch &a = patches[static_cast<std::size_t>(s.patchA)], &b = patches[static_cast<std::size_t>(s.patchB)];
    const std::vector<int> sideA = sideIndices(a, s.sideA, 0), inA = sideIndices(a, s.sideA, 1),
                           inB = sideIndices(b, s.sideB, 1);
    const int m = static_cast<int>(sideA.size());
    for (int i = 0; i < m; ++i)
      triples.push_back({inA[static_cast<std::size_t>(i)], sideA[static_cast<std::size_t>(i)],
                         inB[static_cast<std::size_t>(m - 1 - i)]});
  }
  return triples;
}

SplineRefinement splineRefinement(const ControlNet& net) {
  validateNet(net);
  splineSharedSides(net);  // orientation and sharing checks
  const std::vector<ControlPatch> patches = controlPatches(net);
  SplineRefinement out;
  // Refined vertices keyed by their row of S (column, value in units of 2^-40: the stencils are
  // dyadic, so equal rows are bitwise equal).
  std::map<std::vector<std::pair<int, long long>>, int> vertexOfRow;
  std::vector<Eigen::Triplet<double>> triplets;
  for (std::size_t p = 0; p < patches.size(); ++p) {
    const ControlPatch& patch = patches[p];
    const int R = spline::cubicSubdividedCount(patch.rows, net.rounds);
    const int C = spline::cubicSubdividedCount(patch.columns, net.rounds);
    const Eigen::SparseMatrix<double, Eigen::RowMajor> local =
        spline::cubicGridSubdivisionMatrix(patch.rows, patch.columns, net.rounds);
    std::vector<int> grid(static_cast<std::size_t>(R) * C);
    for (int v = 0; v < R * C; ++v) {
      std::vector<std::pair<int, long long>> key;
      std::vector<std::pair<int, double>> entries;
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(local, v); it; ++it) {
        if (it.value() == 0.0) continue;
        const int column = patch.indices[static_cast<std::size_t>(it.col())];
        key.push_back({column, std::llround(it.value() * 1099511627776.0)});
        entries.push_back({column, it.value()});
      }
      std::sort(key.begin(), key.end());
      const auto [found, inserted] = vertexOfRow.emplace(std::move(key), static_cast<int>(vertexOfRow.size()));
      grid[static_cast<std::size_t>(v)] = found->second;
      if (inserted)
        for (const auto& [column, value] : entries) triplets.emplace_back(found->second, column, value);
    }
    for (int r = 0; r + 1 < R; ++r)
      for (int c = 0; c + 1 < C; ++c) {
        auto g = [&grid, C](int rr, int cc) { return grid[static_cast<std::size_t>(rr * C + cc)]; };
        out.faces.push_back({g(r, c), g(r, c + 1), g(r + 1, c + 1), g(r + 1, c)});
      }
    out.patchVertices.push_back(std::move(grid));
    out.patchGridSize.push_back({R, C});
  }
  out.subdivision.resize(static_cast<Eigen::Index>(vertexOfRow.size()), net.points.rows());
  out.subdivision.setFromTriplets(triplets.begin(), triplets.end());
  return out;
}

std::vector<SplinePatchSurface> splinePatchSurfaces(const ControlNet& net, const Eigen::MatrixX3d& points) {
  validateNet(net);
  if (points.rows() != net.points.rows()) failSplineSurface("control.points: the net has " + std::to_string(net.points.rows()) + " points");
  auto knots = [](int n) {
    std::vector<double> k(4, 0.0);
    for (int i = 1; i <= n - 4; ++i) k.push_back(i);
    for (int i = 0; i < 4; ++i) k.push_back(n - 3);
    return k;
  };
  std::vector<SplinePatchSurface> out;
  for (const ControlPatch& patch : controlPatches(net)) {
    SplinePatchSurface s;
    s.nu = patch.columns;
    s.nv = patch.rows;
    s.knotsU = knots(s.nu);
    s.knotsV = knots(s.nv);
    s.points.resize(static_cast<Eigen::Index>(s.nu) * s.nv, 3);
    for (int j = 0; j < s.nv; ++j)
      for (int i = 0; i < s.nu; ++i) s.points.row(i + s.nu * j) = points.row(at(patch, j, i));
    out.push_back(std::move(s));
  }
  return out;
}

namespace {

/// A bicubic patch evaluated with derivatives up to order 2.
class PatchEvaluator {
 public:
  explicit PatchEvaluator(const SplinePatchSurface& s)
      : surface_(s),
        knotsU_(spline::KnotVector::clamped(3, s.knotsU, s.nu)),
        knotsV_(spline::KnotVector::clamped(3, s.knotsV, s.nv)) {}

  double uMax() const { return surface_.nu - 3.0; }
  double vMax() const { return surface_.nv - 3.0; }

  struct Jet {
    Eigen::Vector3d p, pu, pv, puu, puv, pvv;
  };
  Jet at(double u, double v) const {
    const spline::BasisValues bu = spline::basisFunctions(knotsU_, u, 2), bv = spline::basisFunctions(knotsV_, v, 2);
    Jet j;
    j.p = j.pu = j.pv = j.puu = j.puv = j.pvv = Eigen::Vector3d::Zero();
    for (int b = 0; b < 4; ++b)
      for (int a = 0; a < 4; ++a) {
        const Eigen::Vector3d q =
            surface_.points.row(bu.controlIndex[static_cast<std::size_t>(a)] + surface_.nu * bv.controlIndex[static_cast<std::size_t>(b)])
                .transpose();
        j.p += bu.values(0, a) * bv.values(0, b) * q;
        j.pu += bu.values(1, a) * bv.values(0, b) * q;
        j.pv += bu.values(0, a) * bv.values(1, b) * q;
        j.puu += bu.values(2, a) * bv.values(0, b) * q;
        j.puv += bu.values(1, a) * bv.values(1, b) * q;
        j.pvv += bu.values(0, a) * bv.values(2, b) * q;
      }
    return j;
  }

 private:
  const SplinePatchSurface& surface_;
  spline::KnotVector knotsU_, knotsV_;
};

/// Curvatures at a point: K, H, principal curvatures and the parameter-space direction of the
/// principal curvature of least magnitude.
struct PointCurvature {
  Eigen::Vector3d normal;
  double gauss = 0.0, kappaMax = 0.0, kappaMin = 0.0;  ///< |kappaMax| ≥ |kappaMin|
  Eigen::Vector2d rulingParameter = Eigen::Vector2d::Zero();
  double areaElement = 0.0;
};

PointCurvature curvatureAt(const PatchEvaluator::Jet& j) {
  PointCurvature c;
  const Eigen::Vector3d cross = j.pu.cross(j.pv);
  c.areaElement = cross.norm();
  if (!(c.areaElement > 0.0)) return c;
  c.normal = cross / c.areaElement;
  const double E = j.pu.dot(j.pu), F = j.pu.dot(j.pv), G = j.pv.dot(j.pv);
  const double L = j.puu.dot(c.normal), M = j.puv.dot(c.normal), N = j.pvv.dot(c.normal);
  const double det = E * G - F * F;
  c.gauss = (L * N - M * M) / det;
  const double H = (E * N - 2.0 * F * M + G * L) / (2.0 * det);
  const double root = std::sqrt(std::max(0.0, H * H - c.gauss));
  const double k1 = H + root, k2 = H - root;
  c.kappaMax = std::abs(k1) >= std::abs(k2) ? k1 : k2;
  c.kappaMin = std::abs(k1) >= std::abs(k2) ? k2 : k1;
  // (II − κ I) w = 0 for κ = kappaMin: the better-conditioned row's null vector.
  const double a = L - c.kappaMin * E, b = M - c.kappaMin * F, d = N - c.kappaMin * G;
  const Eigen::Vector2d w1(b, -a), w2(d, -b);
  c.rulingParameter = w1.squaredNorm() >= w2.squaredNorm() ? w1 : w2;
  if (c.rulingParameter.squaredNorm() > 0.0) c.rulingParameter.normalize();
  return c;
}

/// (u, v) of position t ∈ [0, 1] along side s in loop order.
Eigen::Vector2d sideParameter(const PatchEvaluator& e, int side, double t) {
  switch (side) {
    case 0: return {t * e.uMax(), 0.0};
    case 1: return {e.uMax(), t * e.vMax()};
    case 2: return {(1.0 - t) * e.uMax(), e.vMax()};
    default: return {0.0, (1.0 - t) * e.vMax()};
  }
}

}  // namespace

SplineSurfaceAnalysis analyzeSplineSurface(const ControlNet& net, const Eigen::MatrixX3d& points,
                                           const SplineAnalysisOptions& options) {
  const std::vector<SplinePatchSurface> surfaces = splinePatchSurfaces(net, points);
  std::vector<PatchEvaluator> evaluators;
  evaluators.reserve(surfaces.size());
  for (const SplinePatchSurface& s : surfaces) evaluators.emplace_back(s);
  const int s = std::max(1, options.samplesPerSpan);
  SplineSurfaceAnalysis out;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = Eigen::Vector3d::Constant(-1e300);
  std::vector<Eigen::VectorXd> areas;
  for (const PatchEvaluator& e : evaluators) {
    const int nu = static_cast<int>(e.uMax()) * s + 1, nv = static_cast<int>(e.vMax()) * s + 1;
    Eigen::MatrixX3d p(nu * nv, 3);
    Eigen::VectorXd k(nu * nv), area(nu * nv);
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i) {
        const PatchEvaluator::Jet jet = e.at(i * e.uMax() / (nu - 1), j * e.vMax() / (nv - 1));
        const PointCurvature c = curvatureAt(jet);
        p.row(j * nu + i) = jet.p.transpose();
        k[j * nu + i] = c.gauss;
        // Trapezoid weights: half on the border, a quarter at corners.
        const double w = ((i == 0 || i == nu - 1) ? 0.5 : 1.0) * ((j == 0 || j == nv - 1) ? 0.5 : 1.0);
        area[j * nu + i] = w * c.areaElement;
        lo = lo.cwiseMin(jet.p);
        hi = hi.cwiseMax(jet.p);
      }
    out.sampleGridSize.push_back({nv, nu});
    out.samples.push_back(std::move(p));
    out.gauss.push_back(std::move(k));
    areas.push_back(std::move(area));
  }
  out.diameter = (hi - lo).norm();
  const double d2 = out.diameter * out.diameter;
  double weighted = 0.0, total = 0.0;
  for (std::size_t p = 0; p < out.gauss.size(); ++p) {
    out.gaussMaxScaled = std::max(out.gaussMaxScaled, out.gauss[p].cwiseAbs().maxCoeff() * d2);
    weighted += out.gauss[p].cwiseAbs().dot(areas[p]) * d2;
    total += areas[p].sum();
  }
  out.gaussMeanScaled = total > 0 ? weighted / total : 0.0;

  for (const SharedSide& shared : splineSharedSides(net)) {
    ++out.sharedSides;
    const PatchEvaluator &a = evaluators[static_cast<std::size_t>(shared.patchA)],
                         &b = evaluators[static_cast<std::size_t>(shared.patchB)];
    const int spans = static_cast<int>(shared.sideA % 2 == 0 ? a.uMax() : a.vMax());
    const int n = spans * s;
    for (int i = 0; i <= n; ++i) {
      const double t = static_cast<double>(i) / n;
      const Eigen::Vector2d pa = sideParameter(a, shared.sideA, t), pb = sideParameter(b, shared.sideB, 1.0 - t);
      const PatchEvaluator::Jet ja = a.at(pa.x(), pa.y()), jb = b.at(pb.x(), pb.y());
      const Eigen::Vector3d na = ja.pu.cross(ja.pv), nb = jb.pu.cross(jb.pv);
      if (!(na.norm() > 0.0) || !(nb.norm() > 0.0)) continue;
      const double angle = std::atan2(na.cross(nb).norm(), na.dot(nb)) * 180.0 / M_PI;
      out.normalJumpMaxDegrees = std::max(out.normalJumpMaxDegrees, angle);
    }
  }

  if (options.rulingSeedsPerSpan > 0 && out.diameter > 0.0) {
    auto developable = [&options, &out](const PointCurvature& c) {
      return std::abs(c.kappaMax) * out.diameter >= options.curvedMin &&
             std::abs(c.gauss) <= options.developableRatio * c.kappaMax * c.kappaMax &&
             c.rulingParameter.squaredNorm() > 0.0;
    };
    for (const PatchEvaluator& e : evaluators) {
      const double step = out.diameter / (4.0 * s * std::max(e.uMax(), e.vMax()));
      const int seedsU = static_cast<int>(e.uMax()) * options.rulingSeedsPerSpan;
      const int seedsV = static_cast<int>(e.vMax()) * options.rulingSeedsPerSpan;
      auto inside = [&e](const Eigen::Vector2d& q) {
        return q.x() >= 0.0 && q.y() >= 0.0 && q.x() <= e.uMax() && q.y() <= e.vMax();
      };
      // Parameter-space direction of the ruling at q, oriented along `previous` (3D), scaled to
      // move `step` in space; zero where the surface is not developable there.
      auto direction = [&e, &developable, step](const Eigen::Vector2d& q, const Eigen::Vector3d& previous,
                                                Eigen::Vector3d* tangent) -> Eigen::Vector2d {
        const PatchEvaluator::Jet j = e.at(q.x(), q.y());
        const PointCurvature c = curvatureAt(j);
        if (!developable(c)) return Eigen::Vector2d::Zero();
        Eigen::Vector2d w = c.rulingParameter;
        Eigen::Vector3d t = j.pu * w.x() + j.pv * w.y();
        if (t.dot(previous) < 0.0) {
          w = -w;
          t = -t;
        }
        const double length = t.norm();
        if (!(length > 0.0)) return Eigen::Vector2d::Zero();
        *tangent = t / length;
        return w * (step / length);
      };
      for (int sv = 0; sv < seedsV; ++sv)
        for (int su = 0; su < seedsU; ++su) {
          const Eigen::Vector2d seed((su + 0.5) / options.rulingSeedsPerSpan, (sv + 0.5) / options.rulingSeedsPerSpan);
          const PatchEvaluator::Jet j0 = e.at(seed.x(), seed.y());
          const PointCurvature c0 = curvatureAt(j0);
          if (!developable(c0)) continue;
          const Eigen::Vector3d t0 = (j0.pu * c0.rulingParameter.x() + j0.pv * c0.rulingParameter.y()).normalized();
          std::vector<Eigen::Vector3d> halves[2];
          for (int sign = 0; sign < 2; ++sign) {
            Eigen::Vector2d q = seed;
            Eigen::Vector3d previous = sign == 0 ? t0 : Eigen::Vector3d(-t0);
            for (int k = 0; k < 4000; ++k) {
              Eigen::Vector3d tangent;
              const Eigen::Vector2d d1 = direction(q, previous, &tangent);
              if (d1.squaredNorm() == 0.0) break;
              Eigen::Vector3d tangentMid;
              const Eigen::Vector2d d2 = direction(q + 0.5 * d1, tangent, &tangentMid);  // midpoint rule
              if (d2.squaredNorm() == 0.0) break;
              const Eigen::Vector2d next = q + d2;
              if (!inside(next)) {
                // Stop on the boundary: the largest fraction of the step that stays inside.
                double f = 1.0;
                if (next.x() < 0.0) f = std::min(f, -q.x() / d2.x());
                if (next.y() < 0.0) f = std::min(f, -q.y() / d2.y());
                if (next.x() > e.uMax()) f = std::min(f, (e.uMax() - q.x()) / d2.x());
                if (next.y() > e.vMax()) f = std::min(f, (e.vMax() - q.y()) / d2.y());
                const Eigen::Vector2d end = q + std::clamp(f, 0.0, 1.0) * d2;
                halves[sign].push_back(e.at(end.x(), end.y()).p);
                break;
              }
              q = next;
              previous = tangentMid;
              halves[sign].push_back(e.at(q.x(), q.y()).p);
            }
          }
          const std::size_t count = halves[0].size() + halves[1].size() + 1;
          if (count < 3) continue;
          Eigen::MatrixX3d line(static_cast<Eigen::Index>(count), 3);
          Eigen::Index row = 0;
          for (auto it = halves[1].rbegin(); it != halves[1].rend(); ++it) line.row(row++) = it->transpose();
          line.row(row++) = j0.p.transpose();
          for (const Eigen::Vector3d& q : halves[0]) line.row(row++) = q.transpose();
          out.rulings.push_back(std::move(line));
        }
    }
  }
  return out;
}

}  // namespace devsurf::models::quad_mesh
