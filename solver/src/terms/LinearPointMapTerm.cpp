#include "devsurf/terms/LinearPointMapTerm.h"

#include <cmath>
#include <stdexcept>
#include <utility>

#include "devsurf/terms/VertexProductRows.h"

namespace devsurf::terms {

LinearPointMapTerm::LinearPointMapTerm(std::string name, const Eigen::SparseMatrix<double, Eigen::RowMajor>& map,
                                       std::vector<int> mappedOffsets, std::vector<int> sourceOffsets)
    : Term(std::move(name)), map_(map.pruned(0.0)), mapped_(std::move(mappedOffsets)), source_(std::move(sourceOffsets)) {
  const std::string who = "LinearPointMapTerm";
  if (map_.rows() != static_cast<Eigen::Index>(mapped_.size()) || map_.cols() != static_cast<Eigen::Index>(source_.size()))
    throw std::invalid_argument(who + ": the map is " + std::to_string(map_.rows()) + " × " + std::to_string(map_.cols()) +
                                " for " + std::to_string(mapped_.size()) + " mapped and " + std::to_string(source_.size()) +
                                " source points");
  for (Eigen::Index i = 0; i < map_.outerSize(); ++i)
    for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(map_, i); it; ++it)
      if (!std::isfinite(it.value()))
        throw std::invalid_argument(who + ": weight (" + std::to_string(i) + ", " + std::to_string(it.col()) +
                                    ") is not finite");
  std::vector<std::pair<int, int>> blocks;
  appendPointBlocks(mapped_, blocks);
  appendPointBlocks(source_, blocks);
  requireDisjointBlocks(who, std::move(blocks));
  map_.makeCompressed();
}

void LinearPointMapTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (Eigen::Index i = 0; i < map_.outerSize(); ++i)
    for (int c = 0; c < 3; ++c) {
      const int row = static_cast<int>(3 * i) + c;
      entries.push_back({row, mapped_[i] + c});
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(map_, i); it; ++it)
        entries.push_back({row, source_[it.col()] + c});
    }
}

void LinearPointMapTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  double* J = jacobian;
  for (Eigen::Index i = 0; i < map_.outerSize(); ++i)
    for (int c = 0; c < 3; ++c) {
      double r = x[mapped_[i] + c];
      if (J) *J++ = 1.0;
      for (Eigen::SparseMatrix<double, Eigen::RowMajor>::InnerIterator it(map_, i); it; ++it) {
        r -= it.value() * x[source_[it.col()] + c];
        if (J) *J++ = -it.value();
      }
      residuals[3 * i + c] = r;
    }
}

}  // namespace devsurf::terms
