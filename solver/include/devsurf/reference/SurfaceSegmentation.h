#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace devsurf::reference {

/// How segmentByNormals clusters a mesh's triangles.
struct NormalSegmentationOptions {
  int patches = 6;              ///< k, clusters wanted (≥ 1)
  /// Weight of position against normal in the clustering features [n, w·p/diagonal]: 0 clusters
  /// by normal alone (patches may be scattered over the shape), larger values give compact ones.
  double positionWeight = 1.0;
  int iterations = 50;          ///< Lloyd iterations at most
  std::uint32_t seed = 1;       ///< k-means++ seeding (std::mt19937)
};

/// A segmentation of a triangle mesh into patches of similar normals (the Gauss image clustered,
/// as developable panelling segments a shape, 004_… §5 citing Gavril et al. 2018): area-weighted
/// k-means++ over features [unit normal, w·centroid/diagonal] of the triangles. 004_… leaves
/// segmentation to the user; this gives one to start from when the input has none.
/// @param[in] V  n×3 vertices
/// @param[in] T  t×3 triangles
/// @return t patch ids in 0 … k′−1 (k′ ≤ k: empty clusters are dropped), numbered by first triangle
/// @throws std::invalid_argument if there are no triangles, an index is out of range, a coordinate
///         is not finite, or patches < 1 or positionWeight < 0
std::vector<int> segmentByNormals(const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& T,
                                  const NormalSegmentationOptions& options = {});

}  // namespace devsurf::reference
