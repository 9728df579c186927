#include "devsurf/models/strip/StripFromRegion.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>

#include "devsurf/spline/Basis.h"

namespace devsurf::models::strip {

ApproximationTarget approximationTargetFrom(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& normals) {
  if (normals.rows() != points.rows()) throw std::invalid_argument("approximation.normals: expected one normal per point");
  std::vector<Eigen::Index> kept;
  for (Eigen::Index k = 0; k < points.rows(); ++k)
    if (normals.row(k).allFinite() && normals.row(k).norm() > 1e-12 && points.row(k).allFinite()) kept.push_back(k);
  ApproximationTarget target;
  target.points = points(kept, Eigen::all);
  target.normals = normals(kept, Eigen::all);
  return target;
}

std::vector<int> pointsInBall(const Eigen::MatrixX3d& points, const Eigen::Vector3d& centre, double radius) {
  if (!centre.allFinite()) throw std::invalid_argument("region.centre: must be finite");
  if (!(radius > 0.0) || !std::isfinite(radius)) throw std::invalid_argument("region.radius: must be positive");
  std::vector<int> inside;
  const double r2 = radius * radius;
  for (Eigen::Index j = 0; j < points.rows(); ++j)
    if ((points.row(j).transpose() - centre).squaredNorm() <= r2) inside.push_back(static_cast<int>(j));
  return inside;
}

QuadraticHeightField fitQuadraticHeightField(const Eigen::MatrixXd& local, double size) {
  QuadraticHeightField field;
  field.coefficients = Eigen::VectorXd::Zero(6);
  if (local.rows() < 6 || !(size > 0.0)) return field;
  // h(x, y) = c0 + c1 x + c2 y + c3 x² + c4 xy + c5 y² (least squares, coordinates scaled by
  // `size`); its Hessian [[2c3, c4], [c4, 2c5]] gives the normal curvatures.
  Eigen::MatrixXd A(local.rows(), 6);
  for (Eigen::Index j = 0; j < local.rows(); ++j) {
    const double x = local(j, 0) / size, y = local(j, 1) / size;
    A.row(j) << 1.0, x, y, x * x, x * y, y * y;
  }
  Eigen::VectorXd c = A.colPivHouseholderQr().solve(local.col(2) / size);
  if (!c.allFinite()) return field;
  field.coefficients = c;
  Eigen::Matrix2d H;
  H << 2.0 * c(3), c(4), c(4), 2.0 * c(5);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> curvature(H);
  const Eigen::Vector2d k = curvature.eigenvalues();
  // Curved enough to tell the directions apart: a developable's rulings follow the flatter one.
  field.curved = std::max(std::abs(k(0)), std::abs(k(1))) > 1e-3;
  if (field.curved)
    field.leastCurvature = (std::abs(k(0)) <= std::abs(k(1)) ? Eigen::Vector2d(curvature.eigenvectors().col(0))
                                                              : Eigen::Vector2d(curvature.eigenvectors().col(1)))
                               .normalized();
  return field;
}

StripDesign flatStripOverRegion(const Eigen::MatrixX3d& points, const RegionStripOptions& options) {
  if (points.rows() < 3) throw std::invalid_argument("region: needs at least 3 points, got " + std::to_string(points.rows()));
  if (!points.allFinite()) throw std::invalid_argument("region: points must be finite");
  if (options.degree < 1) throw std::invalid_argument("degree: must be at least 1");
  if (options.controlPoints < options.degree + 1)
    throw std::invalid_argument("control points: need at least degree + 1 = " + std::to_string(options.degree + 1));
  if (!(options.margin >= 0.0) || !std::isfinite(options.margin))
    throw std::invalid_argument("margin: must be finite and ≥ 0");

  const Eigen::RowVector3d centroid = points.colwise().mean();
  const Eigen::MatrixX3d centred = points.rowwise() - centroid;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> pca(centred.transpose() * centred / static_cast<double>(points.rows()));
  // Eigenvalues ascending: e3 (normal) first, e1 (longest) last.
  const Eigen::Vector3d e1 = pca.eigenvectors().col(2), e2 = pca.eigenvectors().col(1);
  const Eigen::Vector3d normal = e1.cross(e2).normalized();
  if (!(pca.eigenvalues()(1) > 1e-12 * pca.eigenvalues()(2)))
    throw std::invalid_argument("region: the points lie on a line; a strip needs an area");

  // Coordinates in the PCA frame.
  Eigen::MatrixXd local(points.rows(), 3);
  local.col(0) = centred * e1;
  local.col(1) = centred * e2;
  local.col(2) = centred * normal;

  Eigen::Vector2d ruling(0.0, 1.0);  // in (e1, e2) coordinates: across the longest extent
  if (options.rulings == RegionStripOptions::Rulings::AlongLongest) ruling = Eigen::Vector2d(1.0, 0.0);
  // Height field over the PCA plane (leastCurvatureDirection); needs 6 points, fewer leave the
  // strip flat.
  const double size = std::sqrt(pca.eigenvalues()(2));
  const QuadraticHeightField field = fitQuadraticHeightField(local, size);
  const Eigen::VectorXd& c = field.coefficients;
  auto height = [&c, size](double x, double y) {
    x /= size, y /= size;
    return size * (c(0) + c(1) * x + c(2) * y + c(3) * x * x + c(4) * x * y + c(5) * y * y);
  };
  if (options.rulings == RegionStripOptions::Rulings::Auto && field.curved) ruling = field.leastCurvature;
  ruling.normalize();
  const Eigen::Vector2d along(ruling.y(), -ruling.x());
  const Eigen::Vector3d rulingDir = ruling.x() * e1 + ruling.y() * e2;
  const Eigen::Vector3d alongDir = along.x() * e1 + along.y() * e2;

  double t0 = 1e300, t1 = -1e300, r0 = 1e300, r1 = -1e300;
  for (Eigen::Index j = 0; j < points.rows(); ++j) {
    const Eigen::Vector2d p(local(j, 0), local(j, 1));
    t0 = std::min(t0, p.dot(along)), t1 = std::max(t1, p.dot(along));
    r0 = std::min(r0, p.dot(ruling)), r1 = std::max(r1, p.dot(ruling));
  }
  const double grow = options.margin;
  const double dt = (t1 - t0) * grow, dr = (r1 - r0) * grow;
  t0 -= dt, t1 += dt, r0 -= dr, r1 += dr;

  StripDesign design;
  const int n = options.controlPoints;
  const spline::KnotVector knots = spline::KnotVector::clampedUniform(options.degree, n);
  Eigen::MatrixXd A(n, 3), B(n, 3);
  for (int i = 0; i < n; ++i) {
    const double t = t0 + (t1 - t0) * i / (n - 1);
    const Eigen::Vector3d base = centroid.transpose() + t * alongDir;
    for (const auto& [r, rows] : {std::pair{r0, &A}, std::pair{r1, &B}}) {
      const Eigen::Vector2d inPlane = t * along + r * ruling;  // (e1, e2) coordinates
      const double lift = options.liftToHeightField ? height(inPlane.x(), inPlane.y()) : 0.0;
      rows->row(i) = (base + r * rulingDir + lift * normal).transpose();
    }
  }
  design.a = spline::BSplineCurve{knots, A, {}};
  design.b = spline::BSplineCurve{knots, B, {}};
  return design;
}

}  // namespace devsurf::models::strip

namespace devsurf::models::strip {

StripMerge mergeStrips(const StripDesign& first, const StripDesign& second) {
  for (const auto& [design, name] : {std::pair{&first, "first"}, std::pair{&second, "second"}}) {
    if (design->a.knots.kind() == spline::KnotKind::Periodic)
      throw std::invalid_argument(std::string(name) + ": closed strips cannot be merged");
    if (design->a.isRational() || design->b.isRational())
      throw std::invalid_argument(std::string(name) + ": rational (NURBS) curves cannot be merged");
  }
  if (first.a.degree() != second.a.degree())
    throw std::invalid_argument("second: degree " + std::to_string(second.a.degree()) + " differs from the first's " +
                                std::to_string(first.a.degree()));
  auto reversed = [](const Eigen::MatrixXd& p) { return Eigen::MatrixXd(p.colwise().reverse()); };
  StripMerge best;
  double bestScore = std::numeric_limits<double>::infinity(), bestGap = 0.0;
  for (int combo = 0; combo < 8; ++combo) {
    const bool r1 = combo & 1, r2 = combo & 2, swap = combo & 4;
    const Eigen::MatrixXd a1 = r1 ? reversed(first.a.points) : first.a.points;
    const Eigen::MatrixXd b1 = r1 ? reversed(first.b.points) : first.b.points;
    Eigen::MatrixXd a2 = r2 ? reversed(second.a.points) : second.a.points;
    Eigen::MatrixXd b2 = r2 ? reversed(second.b.points) : second.b.points;
    if (swap) std::swap(a2, b2);
    // Joined ends close, outer ends far apart: with overlapping strips the closest ends alone
    // picked a layout that doubles back over the overlap.
    const double gap = (a1.row(a1.rows() - 1) - a2.row(0)).norm() + (b1.row(b1.rows() - 1) - b2.row(0)).norm();
    const double outer = (a1.row(0) - a2.row(a2.rows() - 1)).norm() + (b1.row(0) - b2.row(b2.rows() - 1)).norm();
    const double score = gap - outer;
    if (score < bestScore) {
      bestGap = gap;
      bestScore = score;
      best.reversedFirst = r1, best.reversedSecond = r2, best.swappedSecond = swap;
    }
  }
  best.gap = 0.5 * bestGap;
  // Dense samples of both strips in the chosen orientation; where the strips overlap, each is cut
  // at the middle of the overlap (joining them as they are would fold the strip back there).
  const int degree = first.a.degree();
  // The curves' own knots need not be uniform: sample them as given.
  auto samplesOf = [](const spline::BSplineCurve& c, bool reverse, int count) {
    std::vector<double> u(static_cast<std::size_t>(count));
    const double u0 = c.knots.domainBegin(), u1 = c.knots.domainEnd();
    for (int k = 0; k < count; ++k) {
      const double t = static_cast<double>(k) / (count - 1);
      u[static_cast<std::size_t>(k)] = u0 + (u1 - u0) * (reverse ? 1.0 - t : t);
    }
    return c.evaluate(u, 0);
  };
  const int K1 = 24 * static_cast<int>(first.a.points.rows()), K2 = 24 * static_cast<int>(second.a.points.rows());
  const Eigen::MatrixXd Pa = samplesOf(first.a, best.reversedFirst, K1), Pb = samplesOf(first.b, best.reversedFirst, K1);
  Eigen::MatrixXd Qa = samplesOf(second.a, best.reversedSecond, K2), Qb = samplesOf(second.b, best.reversedSecond, K2);
  if (best.swappedSecond) std::swap(Qa, Qb);
  const Eigen::MatrixXd Pm = 0.5 * (Pa + Pb), Qm = 0.5 * (Qa + Qb);
  Eigen::Index iStar = 0, jStar = 0;
  (Pm.rowwise() - Qm.row(0)).rowwise().squaredNorm().minCoeff(&iStar);
  (Qm.rowwise() - Pm.row(K1 - 1)).rowwise().squaredNorm().minCoeff(&jStar);
  best.overlap = iStar < K1 - 1 || jStar > 0;
  const Eigen::Index iCut = best.overlap ? (iStar + K1 - 1) / 2 : K1 - 1;
  const Eigen::Index jCut = best.overlap ? jStar / 2 : 0;
  best.keptFirst = static_cast<double>(iCut + 1) / K1;
  best.keptSecond = static_cast<double>(K2 - jCut) / K2;
  // Side by side, not end to end: the merged strip would step across (a user's two fits of
  // neighbouring bands merged into one strip warped by 18°).
  const double narrower = std::min((Pa - Pb).rowwise().norm().mean(), (Qa - Qb).rowwise().norm().mean());
  // The directions the middle lines run in where they are joined, over a few samples.
  const Eigen::RowVector3d runFirst = Pm.row(iCut) - Pm.row(std::max<Eigen::Index>(0, iCut - 6));
  const Eigen::RowVector3d runSecond = Qm.row(std::min<Eigen::Index>(K2 - 1, jCut + 6)) - Qm.row(jCut);
  const double turn = runFirst.norm() > 0.0 && runSecond.norm() > 0.0
                          ? std::acos(std::clamp(runFirst.normalized().dot(runSecond.normalized()), -1.0, 1.0))
                          : 0.0;
  // The step across: the join's offset less its part along the way the strips run there (a gap
  // between ends in line is bridged, as before; the CLI refuses ends farther apart than a width).
  const Eigen::RowVector3d offset = Qm.row(jCut) - Pm.row(iCut);
  Eigen::RowVector3d along = Eigen::RowVector3d::Zero();
  if (runFirst.norm() > 0.0) along += runFirst.normalized();
  if (runSecond.norm() > 0.0) along += runSecond.normalized();
  best.joinOffset = along.norm() > 0.0 ? (offset - offset.dot(along.normalized()) * along.normalized()).norm() : offset.norm();
  if (turn > 0.5 * M_PI) {
    std::ostringstream message;
    message << "second: the strips lie side by side, not end to end: joined, the strip would turn back by "
            << std::lround(turn * 180.0 / M_PI) << "°; merge strips that continue one another";
    throw std::invalid_argument(message.str());
  }
  if (std::min(best.keptFirst, best.keptSecond) < 0.6) {
    std::ostringstream message;
    message << "second: the strips lie side by side, not end to end: joined at the middle of their overlap, "
            << std::lround(100.0 * (1.0 - std::min(best.keptFirst, best.keptSecond)))
            << " % of one would be dropped; merge strips that continue one another";
    throw std::invalid_argument(message.str());
  }
  if (narrower > 0.0 && best.joinOffset > 0.5 * narrower) {
    std::ostringstream message;
    message << "second: the strips do not continue one another: where they are joined their middle lines are "
            << best.joinOffset << " apart across the strip, more than half the narrower strip's width (" << narrower
            << "); merge strips that continue one another";
    throw std::invalid_argument(message.str());
  }
  const Eigen::Index count = (iCut + 1) + (K2 - jCut);
  Eigen::MatrixXd joinedA(count, 3), joinedB(count, 3);
  joinedA << Pa.topRows(iCut + 1), Qa.bottomRows(K2 - jCut);
  joinedB << Pb.topRows(iCut + 1), Qb.bottomRows(K2 - jCut);
  // Chord-length parameters along the middle line, so a(u) and b(u) keep their rulings paired.
  std::vector<double> t(static_cast<std::size_t>(count), 0.0);
  for (Eigen::Index k = 1; k < count; ++k)
    t[static_cast<std::size_t>(k)] =
        t[static_cast<std::size_t>(k - 1)] + (0.5 * (joinedA.row(k) + joinedB.row(k) - joinedA.row(k - 1) - joinedB.row(k - 1))).norm();
  if (!(t.back() > 0.0)) throw std::invalid_argument("second: the strips are degenerate");
  for (double& value : t) value /= t.back();
  const int n = static_cast<int>(first.a.points.rows() + second.a.points.rows() - 1);
  const spline::KnotVector knots = spline::KnotVector::clampedUniform(degree, n);
  const Eigen::SparseMatrix<double> N = spline::evaluationMatrix(knots, t, 0);
  Eigen::SparseMatrix<double> normal = N.transpose() * N;
  for (int i = 0; i < n; ++i) normal.coeffRef(i, i) += 1e-12;
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
  if (solver.info() != Eigen::Success) throw std::invalid_argument("second: the merged strip cannot be fitted");
  const Eigen::MatrixXd A = solver.solve(Eigen::MatrixXd(N.transpose() * joinedA));
  const Eigen::MatrixXd B = solver.solve(Eigen::MatrixXd(N.transpose() * joinedB));
  StripDesign& merged = best.merged;
  merged.a = spline::BSplineCurve{knots, A, {}};
  merged.b = spline::BSplineCurve{knots, B, {}};
  merged.normals.type = NormalRepresentation::Type::Spline;
  merged.normals.degree = first.normals.type == NormalRepresentation::Type::Spline ? first.normals.degree : 3;
  merged.normals.points = static_cast<int>(A.rows());
  if (first.approximation || second.approximation) {
    ApproximationTarget target = first.approximation ? *first.approximation : *second.approximation;
    if (first.approximation && second.approximation) {
      const ApproximationTarget& other = *second.approximation;
      target.points.conservativeResize(target.points.rows() + other.points.rows(), 3);
      target.normals.conservativeResize(target.normals.rows() + other.normals.rows(), 3);
      target.points.bottomRows(other.points.rows()) = other.points;
      target.normals.bottomRows(other.normals.rows()) = other.normals;
    }
    merged.approximation = std::move(target);
  }
  return best;
}

}  // namespace devsurf::models::strip
