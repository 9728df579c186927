#pragma once

// Structured quad meshes sampled from a parametrized surface, for the curvature and Gauss image
// tests: vertices, counter-clockwise faces, the polyline triples of the grid lines (what
// QuadMeshTopology::polylineTriples gives for such a grid) and the parameters of face centres.

#include <array>
#include <functional>
#include <vector>

#include <Eigen/Core>

namespace devsurf::testing {

struct QuadGrid {
  Eigen::MatrixX3d vertices;                ///< vertex (i, j) is row j·columns + i
  std::vector<std::array<int, 4>> faces;    ///< (i,j), (i+1,j), (i+1,j+1), (i,j+1)
  std::vector<std::array<int, 3>> triples;  ///< successive vertices along u and along v lines
  std::vector<Eigen::Vector2d> faceCentres; ///< (u, v) at the centre of each face's cell
  std::vector<std::array<int, 2>> faceCells;  ///< cell (i, j) of each face
};

/// Samples surface(u, v) on cellsU × cellsV cells of [u0, u1] × [v0, v1]. A periodic direction
/// wraps (its last sample is not repeated). Faces are counter-clockwise seen from the side
/// ∂u × ∂v points to.
inline QuadGrid quadGrid(const std::function<Eigen::Vector3d(double, double)>& surface, double u0,
                         double u1, int cellsU, double v0, double v1, int cellsV,
                         bool periodicU = false, bool periodicV = false) {
  QuadGrid grid;
  const int columns = periodicU ? cellsU : cellsU + 1;
  const int rows = periodicV ? cellsV : cellsV + 1;
  const double du = (u1 - u0) / cellsU, dv = (v1 - v0) / cellsV;
  grid.vertices.resize(columns * rows, 3);
  const auto id = [columns, rows](int i, int j) { return (j % rows) * columns + (i % columns); };
  for (int j = 0; j < rows; ++j)
    for (int i = 0; i < columns; ++i)
      grid.vertices.row(id(i, j)) = surface(u0 + i * du, v0 + j * dv).transpose();
  for (int j = 0; j < cellsV; ++j)
    for (int i = 0; i < cellsU; ++i) {
      grid.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
      grid.faceCentres.emplace_back(u0 + (i + 0.5) * du, v0 + (j + 0.5) * dv);
      grid.faceCells.push_back({i, j});
    }
  for (int j = 0; j < rows; ++j)
    for (int i = periodicU ? 0 : 1; i < (periodicU ? columns : columns - 1); ++i)
      grid.triples.push_back({id(i + columns - 1, j), id(i, j), id(i + 1, j)});
  for (int i = 0; i < columns; ++i)
    for (int j = periodicV ? 0 : 1; j < (periodicV ? rows : rows - 1); ++j)
      grid.triples.push_back({id(i, j + rows - 1), id(i, j), id(i, j + 1)});
  return grid;
}

}  // namespace devsurf::testing
