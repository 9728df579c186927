#include "devsurf/models/strip/StripFromRegion.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>

namespace devsurf::models::strip {

std::vector<int> pointsInBall(const Eigen::MatrixX3d& points, const Eigen::Vector3d& centre, double radius) {
  if (!centre.allFinite()) throw std::invalid_argument("region.centre: must be finite");
  if (!(radius > 0.0) || !std::isfinite(radius)) throw std::invalid_argument("region.radius: must be positive");
  std::vector<int> inside;
  const double r2 = radius * radius;
  for (Eigen::Index j = 0; j < points.rows(); ++j)
    if ((points.row(j).transpose() - centre).squaredNorm() <= r2) inside.push_back(static_cast<int>(j));
  return inside;
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
  // Height field over the PCA plane, h(x, y) = c0 + c1 x + c2 y + c3 x² + c4 xy + c5 y² (least
  // squares, coordinates scaled by `size`); its Hessian [[2c3, c4], [c4, 2c5]] gives the normal
  // curvatures. Needs 6 points; fewer leave the strip flat.
  const double size = std::sqrt(pca.eigenvalues()(2));
  Eigen::VectorXd c = Eigen::VectorXd::Zero(6);
  if (points.rows() >= 6) {
    Eigen::MatrixXd A(points.rows(), 6);
    for (Eigen::Index j = 0; j < points.rows(); ++j) {
      const double x = local(j, 0) / size, y = local(j, 1) / size;
      A.row(j) << 1.0, x, y, x * x, x * y, y * y;
    }
    c = A.colPivHouseholderQr().solve(local.col(2) / size);
    if (!c.allFinite()) c.setZero();
  }
  auto height = [&c, size](double x, double y) {
    x /= size, y /= size;
    return size * (c(0) + c(1) * x + c(2) * y + c(3) * x * x + c(4) * x * y + c(5) * y * y);
  };
  if (options.rulings == RegionStripOptions::Rulings::Auto && points.rows() >= 6) {
    Eigen::Matrix2d H;
    H << 2.0 * c(3), c(4), c(4), 2.0 * c(5);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> curvature(H);
    const Eigen::Vector2d k = curvature.eigenvalues();
    // Curved enough to tell the directions apart: the rulings follow the flatter one.
    if (std::max(std::abs(k(0)), std::abs(k(1))) > 1e-3)
      ruling = std::abs(k(0)) <= std::abs(k(1)) ? Eigen::Vector2d(curvature.eigenvectors().col(0))
                                                 : Eigen::Vector2d(curvature.eigenvectors().col(1));
  }
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
