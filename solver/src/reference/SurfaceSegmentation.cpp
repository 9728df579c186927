#include "devsurf/reference/SurfaceSegmentation.h"

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

namespace devsurf::reference {

namespace {

using SegmentFeatures = Eigen::Matrix<double, Eigen::Dynamic, 6>;

/// Weighted k-means++ over the rows of `feature`: labels 0 … k′−1 numbered by first row.
std::vector<int> clusterSegmentFeatures(const SegmentFeatures& feature, Eigen::VectorXd weight,
                                        const NormalSegmentationOptions& options) {
  const Eigen::Index t = feature.rows();
  if (!(weight.sum() > 0.0)) weight.setOnes();

  // k-means++ seeding, weighted.
  const int k = static_cast<int>(std::min<Eigen::Index>(options.patches, t));
  std::mt19937 random(options.seed);
  SegmentFeatures centre(k, 6);
  {
    std::discrete_distribution<Eigen::Index> byArea(weight.data(), weight.data() + t);
    centre.row(0) = feature.row(byArea(random));
    Eigen::VectorXd nearest = (feature.rowwise() - centre.row(0)).rowwise().squaredNorm();
    for (int c = 1; c < k; ++c) {
      const Eigen::VectorXd chance = nearest.cwiseProduct(weight);
      if (!(chance.sum() > 0.0)) {
        centre.row(c) = centre.row(c - 1);
        continue;
      }
      std::discrete_distribution<Eigen::Index> pick(chance.data(), chance.data() + t);
      centre.row(c) = feature.row(pick(random));
      nearest = nearest.cwiseMin((feature.rowwise() - centre.row(c)).rowwise().squaredNorm());
    }
  }
  std::vector<int> label(t, 0);
  for (int iteration = 0; iteration < std::max(1, options.iterations); ++iteration) {
    bool changed = iteration == 0;
    for (Eigen::Index f = 0; f < t; ++f) {
      int best = 0;
      double bestDistance = std::numeric_limits<double>::infinity();
      for (int c = 0; c < k; ++c) {
        const double d = (feature.row(f) - centre.row(c)).squaredNorm();
        if (d < bestDistance) bestDistance = d, best = c;
      }
      if (best != label[f]) changed = true, label[f] = best;
    }
    if (!changed) break;
    SegmentFeatures sum = SegmentFeatures::Zero(k, 6);
    Eigen::VectorXd mass = Eigen::VectorXd::Zero(k);
    for (Eigen::Index f = 0; f < t; ++f) sum.row(label[f]) += weight(f) * feature.row(f), mass(label[f]) += weight(f);
    for (int c = 0; c < k; ++c)
      if (mass(c) > 0.0) centre.row(c) = sum.row(c) / mass(c);
  }
  // Compact numbering by first appearance (empty clusters dropped).
  std::vector<int> renumber(k, -1);
  int next = 0;
  for (Eigen::Index f = 0; f < t; ++f) {
    if (renumber[label[f]] < 0) renumber[label[f]] = next++;
    label[f] = renumber[label[f]];
  }
  return label;
}

void checkSegmentationOptions(const std::string& who, const NormalSegmentationOptions& options) {
  if (options.patches < 1) throw std::invalid_argument(who + "patches must be ≥ 1");
  if (!(options.positionWeight >= 0.0)) throw std::invalid_argument(who + "positionWeight must be ≥ 0");
}

}  // namespace

std::vector<int> segmentByNormals(const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& T,
                                  const NormalSegmentationOptions& options) {
  const std::string who = "segmentByNormals: ";
  if (T.rows() == 0) throw std::invalid_argument(who + "no triangles");
  if (!V.allFinite()) throw std::invalid_argument(who + "a vertex coordinate is not finite");
  checkSegmentationOptions(who, options);
  if ((T.array() < 0).any() || (T.array() >= V.rows()).any())
    throw std::invalid_argument(who + "a triangle's vertex index is out of range");

  const Eigen::Index t = T.rows();
  const double diagonal = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
  const double positionScale = diagonal > 0.0 ? options.positionWeight / diagonal : 0.0;
  SegmentFeatures feature(t, 6);
  Eigen::VectorXd weight(t);
  for (Eigen::Index f = 0; f < t; ++f) {
    const Eigen::Vector3d a = V.row(T(f, 0)), b = V.row(T(f, 1)), c = V.row(T(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    weight(f) = 0.5 * n.norm();
    feature.block<1, 3>(f, 0) = n.norm() > 0.0 ? Eigen::RowVector3d(n.normalized()) : Eigen::RowVector3d::Zero();
    feature.block<1, 3>(f, 3) = positionScale * (a + b + c).transpose() / 3.0;
  }

  return clusterSegmentFeatures(feature, weight, options);
}

std::vector<int> segmentPointsByNormals(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& normals,
                                        const NormalSegmentationOptions& options) {
  const std::string who = "segmentPointsByNormals: ";
  if (points.rows() == 0) throw std::invalid_argument(who + "no points");
  if (normals.rows() != points.rows()) throw std::invalid_argument(who + "one normal per point is needed");
  if (!points.allFinite() || !normals.allFinite())
    throw std::invalid_argument(who + "a coordinate or a normal is not finite");
  checkSegmentationOptions(who, options);
  const double diagonal = (points.colwise().maxCoeff() - points.colwise().minCoeff()).norm();
  const double positionScale = diagonal > 0.0 ? options.positionWeight / diagonal : 0.0;
  SegmentFeatures feature(points.rows(), 6);
  for (Eigen::Index j = 0; j < points.rows(); ++j) {
    const double length = normals.row(j).norm();
    feature.block<1, 3>(j, 0) = length > 0.0 ? Eigen::RowVector3d(normals.row(j) / length) : Eigen::RowVector3d::Zero();
    feature.block<1, 3>(j, 3) = positionScale * points.row(j);
  }
  return clusterSegmentFeatures(feature, Eigen::VectorXd::Ones(points.rows()), options);
}

}  // namespace devsurf::reference
