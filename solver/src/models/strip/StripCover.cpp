#include "devsurf/models/strip/StripCover.h"

#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "devsurf/reference/PointThinning.h"

namespace devsurf::models::strip {

namespace {

const spline::BSplineCurve& coverCurveOf(const StripDesign& s, Curve c) { return c == Curve::A ? s.a : s.b; }

/// The curve at `count` parameters equally spaced over its domain (rows), reversed when asked.
Eigen::MatrixX3d sampleCurve(const spline::BSplineCurve& c, int count, bool reversed = false) {
  std::vector<double> u(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k)
    u[static_cast<std::size_t>(k)] =
        c.knots.domainBegin() + (c.knots.domainEnd() - c.knots.domainBegin()) * k / (count - 1);
  Eigen::MatrixX3d p = c.evaluate(u, 0);
  if (reversed) p = p.colwise().reverse().eval();
  return p;
}

/// Distance from p to the polyline (rows in order).
double distanceToPolyline(const Eigen::Vector3d& p, const Eigen::MatrixX3d& polyline) {
  double best = std::numeric_limits<double>::infinity();
  for (Eigen::Index s = 0; s + 1 < polyline.rows(); ++s) {
    const Eigen::Vector3d a = polyline.row(s).transpose(), d = polyline.row(s + 1).transpose() - a;
    const double len2 = d.squaredNorm();
    const double t = len2 > 0.0 ? std::clamp((p - a).dot(d) / len2, 0.0, 1.0) : 0.0;
    best = std::min(best, (a + t * d - p).norm());
  }
  return best;
}

/// Mean distance of the rows of `samples` from the polyline, and the largest.
std::pair<double, double> sampleDistances(const Eigen::MatrixX3d& samples, const Eigen::MatrixX3d& polyline) {
  double sum = 0.0, worst = 0.0;
  for (Eigen::Index k = 0; k < samples.rows(); ++k) {
    const double d = distanceToPolyline(samples.row(k).transpose(), polyline);
    sum += d;
    worst = std::max(worst, d);
  }
  return {sum / static_cast<double>(samples.rows()), worst};
}

/// Mean length of the strip's rulings a(u)b(u) over 32 parameters.
double meanRulingLength(const StripDesign& s) {
  const Eigen::MatrixX3d a = sampleCurve(s.a, 32), b = sampleCurve(s.b, 32);
  return (b - a).rowwise().norm().mean();
}

void checkOpenPolynomial(const StripDesign& s, std::size_t i) {
  if (s.a.knots.kind() != spline::KnotKind::Clamped || s.a.isRational() || s.b.isRational())
    throw std::invalid_argument("strips[" + std::to_string(i) + "]: pairing needs open, polynomial curves");
}

}  // namespace

std::vector<BoundaryPairing> proposeBoundaryPairings(const std::vector<StripDesign>& strips, double tolerance) {
  if (!(tolerance > 0.0) || !std::isfinite(tolerance)) throw std::invalid_argument("tolerance: must be finite and > 0");
  constexpr int kSamples = 64, kPolyline = 256;
  std::vector<std::array<Eigen::MatrixX3d, 2>> samples, polylines;
  std::vector<double> widths;
  for (std::size_t i = 0; i < strips.size(); ++i) {
    checkOpenPolynomial(strips[i], i);
    samples.push_back({sampleCurve(strips[i].a, kSamples), sampleCurve(strips[i].b, kSamples)});
    polylines.push_back({sampleCurve(strips[i].a, kPolyline), sampleCurve(strips[i].b, kPolyline)});
    widths.push_back(meanRulingLength(strips[i]));
  }
  std::vector<BoundaryPairing> candidates;
  for (std::size_t i = 0; i < strips.size(); ++i)
    for (std::size_t j = i + 1; j < strips.size(); ++j)
      for (int ci = 0; ci < 2; ++ci)
        for (int cj = 0; cj < 2; ++cj) {
          const Eigen::MatrixX3d& x = samples[i][static_cast<std::size_t>(ci)];
          const Eigen::MatrixX3d& y = samples[j][static_cast<std::size_t>(cj)];
          const double distance = 0.5 * (sampleDistances(x, polylines[j][static_cast<std::size_t>(cj)]).first +
                                         sampleDistances(y, polylines[i][static_cast<std::size_t>(ci)]).first);
          if (distance > tolerance * std::min(widths[i], widths[j])) continue;
          const long last = kSamples - 1;
          const double same = (x.row(0) - y.row(0)).norm() + (x.row(last) - y.row(last)).norm();
          const double opposite = (x.row(0) - y.row(last)).norm() + (x.row(last) - y.row(0)).norm();
          candidates.push_back({static_cast<int>(i), ci == 0 ? Curve::A : Curve::B, static_cast<int>(j),
                                cj == 0 ? Curve::A : Curve::B, opposite < same, distance});
        }
  std::sort(candidates.begin(), candidates.end(),
            [](const BoundaryPairing& p, const BoundaryPairing& q) { return p.distance < q.distance; });
  std::set<std::pair<int, int>> used;
  std::set<std::pair<int, int>> stripPairs;
  std::vector<BoundaryPairing> pairings;
  for (const BoundaryPairing& c : candidates) {
    const std::pair<int, int> x{c.first, static_cast<int>(c.firstCurve)}, y{c.second, static_cast<int>(c.secondCurve)};
    // Each curve once; two strips share at most one curve (a second would close a ring of two).
    if (used.count(x) || used.count(y) || stripPairs.count({c.first, c.second})) continue;
    used.insert(x);
    used.insert(y);
    stripPairs.insert({c.first, c.second});
    pairings.push_back(c);
  }
  return pairings;
}

std::pair<double, double> pairingGap(const std::vector<StripDesign>& strips, const std::vector<BoundaryPairing>& pairings) {
  double worst = 0.0, sum = 0.0;
  int count = 0;
  for (const BoundaryPairing& p : pairings) {
    const spline::BSplineCurve& x = coverCurveOf(strips.at(static_cast<std::size_t>(p.first)), p.firstCurve);
    const spline::BSplineCurve& y = coverCurveOf(strips.at(static_cast<std::size_t>(p.second)), p.secondCurve);
    for (const auto& [from, to] : {std::pair{&x, &y}, std::pair{&y, &x}}) {
      const auto [mean, max] = sampleDistances(sampleCurve(*from, 64), sampleCurve(*to, 256));
      worst = std::max(worst, max);
      sum += mean;
      ++count;
    }
    // The corners: each end of the first curve at the matching end of the second.
    const Eigen::MatrixX3d xs = sampleCurve(x, 2), ys = sampleCurve(y, 2, p.reversed);
    worst = std::max(worst, (xs - ys).rowwise().norm().maxCoeff());
  }
  return {worst, count > 0 ? sum / count : 0.0};
}

StripPairingResult pairStripBoundaries(std::vector<StripDesign> strips, const std::vector<BoundaryPairing>& pairings,
                                       const StripPairingOptions& options) {
  if (options.rounds < 0 || options.iterationsPerRound < 0 || options.lastRoundIterations < 0)
    throw std::invalid_argument("rounds, iterations: must be ≥ 0");
  if (!(options.initialWeightRatio > 0.0 && options.initialWeightRatio <= 1.0))
    throw std::invalid_argument("initialWeightRatio: must be in (0, 1]");
  std::set<std::pair<int, int>> used;
  for (std::size_t k = 0; k < pairings.size(); ++k) {
    const BoundaryPairing& p = pairings[k];
    const std::string path = "pairings[" + std::to_string(k) + "]";
    for (const int s : {p.first, p.second})
      if (s < 0 || s >= static_cast<int>(strips.size()))
        throw std::invalid_argument(path + ": strip " + std::to_string(s) + " does not exist");
    if (p.first == p.second) throw std::invalid_argument(path + ": pairs a strip with itself");
    for (const auto& c : {std::pair{p.first, static_cast<int>(p.firstCurve)},
                          std::pair{p.second, static_cast<int>(p.secondCurve)}})
      if (!used.insert(c).second)
        throw std::invalid_argument(path + ": curve " + curveName(static_cast<Curve>(c.second)) + " of strip " +
                                    std::to_string(c.first) + " is already paired");
  }
  for (std::size_t i = 0; i < strips.size(); ++i) checkOpenPolynomial(strips[i], i);

  StripPairingResult result;
  engine::SolverOptions solve;
  solve.maxIterations = options.iterationsPerRound;
  solve.regularization = options.regularization;
  solve.fairness = options.fairness;
  solve.deadline = options.deadline;
  for (int round = 0; round < options.rounds; ++round) {
    StripPairingRound record;
    const double ramp = options.rounds > 1 ? double(options.rounds - 1 - round) / (options.rounds - 1) : 0.0;
    const double weight = options.boundaryWeight * std::pow(options.initialWeightRatio, ramp);
    for (std::size_t i = 0; i < strips.size(); ++i) {
      StripDesign design = strips[i];
      design.boundaryTargets.clear();
      for (const BoundaryPairing& p : pairings) {
        const bool isFirst = p.first == static_cast<int>(i), isSecond = p.second == static_cast<int>(i);
        if (!isFirst && !isSecond) continue;
        // The partner's current curve, ordered from the end this curve starts at.
        const StripDesign& partner = strips[static_cast<std::size_t>(isFirst ? p.second : p.first)];
        BoundaryTarget target;
        target.curve = isFirst ? p.firstCurve : p.secondCurve;
        target.polyline = sampleCurve(coverCurveOf(partner, isFirst ? p.secondCurve : p.firstCurve), 256, p.reversed);
        target.weight = weight;
        design.boundaryTargets.push_back(std::move(target));
      }
      StripModel model(std::move(design), options.strip);
      solve.maxIterations = round + 1 == options.rounds ? std::max(options.iterationsPerRound, options.lastRoundIterations)
                                                        : options.iterationsPerRound;
      model.solve(solve);
      strips[i] = model.design();
      strips[i].boundaryTargets.clear();
      record.warpMaxDeg = std::max(record.warpMaxDeg, model.quality().warpAngleMaxDeg);
    }
    std::tie(record.gapMax, record.gapMean) = pairingGap(strips, pairings);
    result.rounds.push_back(record);
  }
  result.strips = std::move(strips);
  return result;
}

RegionLayout regionLayout(const Eigen::MatrixX3d& points, int count, double keep) {
  if (count < 1) throw std::invalid_argument("count: at least one band");
  if (!(keep > 0.0 && keep <= 1.0)) throw std::invalid_argument("keep: must be in (0, 1]");
  if (points.rows() < 6 * count)
    throw std::invalid_argument("region: " + std::to_string(points.rows()) + " points are too few for " +
                                std::to_string(count) + " bands (6 per band at least)");
  if (!points.allFinite()) throw std::invalid_argument("region: points must be finite");
  RegionLayout layout;
  layout.centroid = points.colwise().mean().transpose();
  const Eigen::MatrixX3d centred = points.rowwise() - layout.centroid.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> pca(centred.transpose() * centred);
  if (!(pca.eigenvalues()(1) > 1e-12 * pca.eigenvalues()(2)))
    throw std::invalid_argument("region: the points lie on a line");
  // The bands are stacked along the direction of least normal curvature (where the rulings of
  // each band's strip run, across it) and run along the other one.
  layout.e1 = pca.eigenvectors().col(2);
  layout.e2 = pca.eigenvectors().col(1);
  layout.normal = layout.e1.cross(layout.e2);
  Eigen::MatrixXd local(points.rows(), 3);
  local.col(0) = centred * layout.e1;
  local.col(1) = centred * layout.e2;
  local.col(2) = centred * layout.normal;
  layout.size = std::sqrt(pca.eigenvalues()(2) / static_cast<double>(points.rows()));
  layout.field = fitQuadraticHeightField(local, layout.size);
  layout.across = layout.field.curved ? layout.field.leastCurvature : Eigen::Vector2d(0.0, 1.0);
  layout.along = Eigen::Vector2d(layout.across.y(), -layout.across.x());
  const Eigen::VectorXd t1 = local.leftCols<2>() * layout.along, t2 = local.leftCols<2>() * layout.across;
  layout.halfLength = keep * t1.cwiseAbs().maxCoeff();
  const double h2 = keep * t2.cwiseAbs().maxCoeff();
  std::vector<int> kept;
  for (Eigen::Index j = 0; j < points.rows(); ++j)
    if (std::abs(t1(j)) <= layout.halfLength && std::abs(t2(j)) <= h2) kept.push_back(static_cast<int>(j));
  if (static_cast<int>(kept.size()) < 6 * count)
    throw std::invalid_argument("region: " + std::to_string(kept.size()) +
                                " points inside the rectangle are too few for " + std::to_string(count) + " bands");
  std::sort(kept.begin(), kept.end(), [&t2](int p, int q) { return t2(p) < t2(q); });
  layout.bands.resize(static_cast<std::size_t>(count));
  layout.cuts.push_back(-h2);
  for (std::size_t k = 0; k < kept.size(); ++k) {
    const std::size_t band = k * static_cast<std::size_t>(count) / kept.size();
    if (band > 0 && layout.bands[band].empty())
      layout.cuts.push_back(0.5 * (t2(kept[k - 1]) + t2(kept[k])));
    layout.bands[band].push_back(kept[k]);
  }
  layout.cuts.push_back(h2);
  assert(static_cast<int>(layout.cuts.size()) == count + 1 && "one cut between neighbouring bands");
  return layout;
}

Eigen::Vector3d RegionLayout::pointAt(double t1, double t2) const {
  const Eigen::Vector2d xy = t1 * along + t2 * across;
  const Eigen::VectorXd& c = field.coefficients;
  const double x = xy.x() / size, y = xy.y() / size;
  const double h = size * (c(0) + c(1) * x + c(2) * y + c(3) * x * x + c(4) * x * y + c(5) * y * y);
  return centroid + xy.x() * e1 + xy.y() * e2 + h * normal;
}

RegionCover coverRegion(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& normals,
                        const RegionCoverOptions& options) {
  if (normals.rows() != 0 && normals.rows() != points.rows())
    throw std::invalid_argument("normals: expected none or one per point");
  const RegionStripOptions& placement = options.placement;
  if (placement.degree < 1 || placement.controlPoints < placement.degree + 1)
    throw std::invalid_argument("control points: need at least degree + 1");
  RegionCover cover;
  cover.layout = regionLayout(points, options.strips, options.keep);
  const RegionLayout& layout = cover.layout;
  reference::ThinningOptions thinning;
  thinning.radius = options.thinRadius > 0.0 ? options.thinRadius : reference::suggestedThinningRadius(points, normals.rows() > 0);
  thinning.seed = options.seed;
  // The cut lines between the bands (and the rectangle's two long sides) lifted onto the region's
  // quadratic height field: neighbouring strips start on one shared curve, ends lined up
  // (fitting each band alone first and pairing afterwards, strips on CGAL's bunny grew and turned
  // until a middle strip offered one curve to both neighbours).
  const int n = placement.controlPoints;
  const spline::KnotVector knots = spline::KnotVector::clampedUniform(placement.degree, n);
  std::vector<spline::BSplineCurve> cuts;
  for (const double t2 : layout.cuts) {
    spline::BSplineCurve curve;
    curve.knots = knots;
    curve.points.resize(n, 3);
    for (int i = 0; i < n; ++i)
      curve.points.row(i) =
          layout.pointAt(layout.halfLength * (2.0 * i / (n - 1) - 1.0), t2).transpose();
    cuts.push_back(std::move(curve));
  }
  long steep = 0, thinned = 0;
  for (std::size_t k = 0; k < layout.bands.size(); ++k) {
    const std::vector<int>& band = layout.bands[k];
    Eigen::MatrixX3d bandPoints(static_cast<Eigen::Index>(band.size()), 3), bandNormals(0, 3);
    if (normals.rows() > 0) bandNormals.resize(bandPoints.rows(), 3);
    for (std::size_t j = 0; j < band.size(); ++j) {
      bandPoints.row(static_cast<Eigen::Index>(j)) = points.row(band[j]);
      if (normals.rows() > 0) bandNormals.row(static_cast<Eigen::Index>(j)) = normals.row(band[j]);
    }
    const reference::ThinnedCloud thin = reference::thinPointCloud(bandPoints, bandNormals, thinning);
    ApproximationTarget target = approximationTargetFrom(thin.points, thin.normals);
    target.overhangWeight = options.overhangWeight;
    if (target.points.rows() < 6)
      throw std::invalid_argument("bands[" + std::to_string(k) + "]: " + std::to_string(target.points.rows()) +
                                  " thinned points with a normal; a smaller thinning radius or fewer strips");
    for (Eigen::Index j = 0; j < target.normals.rows(); ++j)
      steep += std::abs(target.normals.row(j).normalized().dot(layout.normal.transpose())) < std::cos(75.0 * M_PI / 180.0);
    thinned += target.normals.rows();
    StripDesign design;
    design.a = cuts[k];
    design.b = cuts[k + 1];
    design.normals.type = NormalRepresentation::Type::Spline;
    design.approximation = std::move(target);
    cover.placed.push_back(std::move(design));
    if (k > 0) cover.pairings.push_back({static_cast<int>(k) - 1, Curve::B, static_cast<int>(k), Curve::A, false, 0.0});
  }
  cover.steepFraction = thinned > 0 ? double(steep) / double(thinned) : 0.0;
  // Fig. 10b and d at once: every sweep fits each strip to its band and keeps its curves on its
  // neighbours'.
  cover.paired = pairStripBoundaries(cover.placed, cover.pairings, options.pairing);
  return cover;
}

}  // namespace devsurf::models::strip
