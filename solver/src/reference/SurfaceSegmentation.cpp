#include "devsurf/reference/SurfaceSegmentation.h"

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

namespace devsurf::reference {

std::vector<int> segmentByNormals(const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& T,
                                  const NormalSegmentationOptions& options) {
  const std::string who = "segmentByNormals: ";
  if (T.rows() == 0) throw std::invalid_argument(who + "no triangles");
  if (!V.allFinite()) throw std::invalid_argument(who + "a vertex coordinate is not finite");
  if (options.patches < 1) throw std::invalid_argument(who + "patches must be ≥ 1");
  if (!(options.positionWeight >= 0.0)) throw std::invalid_argument(who + "positionWeight must be ≥ 0");
  if ((T.array() < 0).any() || (T.array() >= V.rows()).any())
    throw std::invalid_argument(who + "a triangle's vertex index is out of range");

  const Eigen::Index t = T.rows();
  const double diagonal = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
  const double positionScale = diagonal > 0.0 ? options.positionWeight / diagonal : 0.0;
  Eigen::Matrix<double, Eigen::Dynamic, 6> feature(t, 6);
  Eigen::VectorXd weight(t);
  for (Eigen::Index f = 0; f < t; ++f) {
    const Eigen::Vector3d a = V.row(T(f, 0)), b = V.row(T(f, 1)), c = V.row(T(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);
    weight(f) = 0.5 * n.norm();
    feature.block<1, 3>(f, 0) = n.norm() > 0.0 ? Eigen::RowVector3d(n.normalized()) : Eigen::RowVector3d::Zero();
    feature.block<1, 3>(f, 3) = positionScale * (a + b + c).transpose() / 3.0;
  }
  if (!(weight.sum() > 0.0)) weight.setOnes();

  // k-means++ seeding, weighted by area.
  const int k = static_cast<int>(std::min<Eigen::Index>(options.patches, t));
  std::mt19937 random(options.seed);
  Eigen::Matrix<double, Eigen::Dynamic, 6> centre(k, 6);
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
    Eigen::Matrix<double, Eigen::Dynamic, 6> sum = Eigen::Matrix<double, Eigen::Dynamic, 6>::Zero(k, 6);
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

}  // namespace devsurf::reference
