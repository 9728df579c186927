#include "devsurf/terms/VertexProductRows.h"

#include <algorithm>
#include <stdexcept>

namespace devsurf::terms {

void VertexProductRows::add(const std::string& who, const int* vertices, const double* alpha,
                            const double* beta, int count, const std::vector<int>& meshOffsets,
                            const std::vector<int>& unfoldingOffsets, int factorOffset) {
  const int numVertices = static_cast<int>(meshOffsets.size());
  std::array<int, 4> ids{};
  Row row;
  row.factor = factorOffset;
  for (int n = 0; n < count; ++n) {
    const int v = vertices[n];
    if (v < 0 || v >= numVertices)
      throw std::invalid_argument(who + ": vertex index " + std::to_string(v) +
                                  " out of range [0, " + std::to_string(numVertices) + ")");
    int k = 0;
    while (k < row.count && ids[k] != v) ++k;
    if (k == row.count) {
      if (row.count == 4) throw std::invalid_argument(who + ": more than four vertices in a row");
      ids[k] = v;
      row.mesh[k] = meshOffsets[v];
      row.unfolding[k] = unfoldingOffsets[v];
      ++row.count;
    }
    row.alpha[k] += alpha[n];
    row.beta[k] += beta[n];
  }
  rows_.push_back(row);
}

void VertexProductRows::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (int r = 0; r < size(); ++r) {
    const Row& row = rows_[r];
    for (int k = 0; k < row.count; ++k)
      for (int c = 0; c < 3; ++c) entries.push_back({r, row.mesh[k] + c});
    for (int k = 0; k < row.count; ++k)
      for (int c = 0; c < 3; ++c) entries.push_back({r, row.unfolding[k] + c});
    if (row.factor >= 0) entries.push_back({r, row.factor});
  }
}

void VertexProductRows::evaluate(const Eigen::VectorXd& x, double* residuals,
                                 double* jacobian) const {
  double* J = jacobian;
  for (int r = 0; r < size(); ++r) {
    const Row& row = rows_[r];
    Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
    Eigen::Vector3d a2 = Eigen::Vector3d::Zero(), b2 = Eigen::Vector3d::Zero();
    for (int k = 0; k < row.count; ++k) {
      const Eigen::Vector3d v = x.segment<3>(row.mesh[k]);
      const Eigen::Vector3d w = x.segment<3>(row.unfolding[k]);
      a += row.alpha[k] * v;
      b += row.beta[k] * v;
      a2 += row.alpha[k] * w;
      b2 += row.beta[k] * w;
    }
    const double lambda = row.factor >= 0 ? x[row.factor] : 1.0;
    const double product = a.dot(b);
    residuals[r] = lambda * product - a2.dot(b2);
    if (!J) continue;
    for (int k = 0; k < row.count; ++k) {
      const Eigen::Vector3d d = lambda * (row.alpha[k] * b + row.beta[k] * a);
      for (int c = 0; c < 3; ++c) *J++ = d[c];
    }
    for (int k = 0; k < row.count; ++k) {
      const Eigen::Vector3d d = -(row.alpha[k] * b2 + row.beta[k] * a2);
      for (int c = 0; c < 3; ++c) *J++ = d[c];
    }
    if (row.factor >= 0) *J++ = product;
  }
}

void addCheckerboardFaceRows(VertexProductRows& rows, const std::string& who,
                             const std::array<int, 4>& face, const std::vector<int>& meshOffsets,
                             const std::vector<int>& unfoldingOffsets, int factorOffset) {
  if (face[3] >= 0) {
    // d0 = v0 − v2, d1 = v1 − v3: ‖d0‖², ‖d1‖², ⟨d0, d1⟩.
    const int diagonal0[2] = {face[0], face[2]}, diagonal1[2] = {face[1], face[3]};
    const double difference[2] = {1.0, -1.0};
    rows.add(who, diagonal0, difference, difference, 2, meshOffsets, unfoldingOffsets,
             factorOffset);
    rows.add(who, diagonal1, difference, difference, 2, meshOffsets, unfoldingOffsets,
             factorOffset);
    const int all[4] = {face[0], face[1], face[2], face[3]};
    const double alpha[4] = {1.0, 0.0, -1.0, 0.0}, beta[4] = {0.0, 1.0, 0.0, -1.0};
    rows.add(who, all, alpha, beta, 4, meshOffsets, unfoldingOffsets, factorOffset);
    return;
  }
  const double difference[2] = {1.0, -1.0};
  for (int e = 0; e < 3; ++e) {
    const int edge[2] = {face[e], face[(e + 1) % 3]};
    rows.add(who, edge, difference, difference, 2, meshOffsets, unfoldingOffsets, factorOffset);
  }
}

void requireValidFaces(const std::string& who, const std::vector<std::array<int, 4>>& faces,
                       int vertexCount) {
  for (std::size_t f = 0; f < faces.size(); ++f) {
    const std::array<int, 4>& face = faces[f];
    const int corners = face[3] == -1 ? 3 : 4;
    for (int k = 0; k < corners; ++k) {
      if (face[k] < 0 || face[k] >= vertexCount)
        throw std::invalid_argument(who + ": face " + std::to_string(f) + " has vertex index " +
                                    std::to_string(face[k]) + " out of range [0, " +
                                    std::to_string(vertexCount) + ")");
      for (int m = 0; m < k; ++m)
        if (face[m] == face[k])
          throw std::invalid_argument(who + ": face " + std::to_string(f) + " lists vertex " +
                                      std::to_string(face[k]) + " twice");
    }
  }
}

void requireDisjointBlocks(const std::string& who, std::vector<std::pair<int, int>> blocks) {
  for (const auto& [offset, length] : blocks)
    if (offset < 0) throw std::invalid_argument(who + ": negative variable offset");
  blocks.erase(std::remove_if(blocks.begin(), blocks.end(),
                              [](const std::pair<int, int>& b) { return b.second <= 0; }),
               blocks.end());
  std::sort(blocks.begin(), blocks.end());
  for (std::size_t i = 1; i < blocks.size(); ++i)
    if (blocks[i - 1].first + blocks[i - 1].second > blocks[i].first)
      throw std::invalid_argument(who + ": variable blocks at offsets " +
                                  std::to_string(blocks[i - 1].first) + " and " +
                                  std::to_string(blocks[i].first) + " overlap");
}

void appendPointBlocks(const std::vector<int>& pointOffsets,
                       std::vector<std::pair<int, int>>& blocks) {
  for (int offset : pointOffsets) blocks.emplace_back(offset, 3);
}

}  // namespace devsurf::terms
