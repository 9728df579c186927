#pragma once

#include <Eigen/Core>

namespace devsurf::testing {

/// A test surface: an nu × nv grid of quads over [0, width] × [0, height], each split into two
/// counter-clockwise triangles, its vertex (i, j) at row j·(nu + 1) + i lifted by `lift(x, y)`.
template <typename Lift>
void triangulatedGrid(int nu, int nv, double width, double height, Lift lift, Eigen::MatrixX3d& V, Eigen::MatrixX3i& T) {
  V.resize((nu + 1) * (nv + 1), 3);
  T.resize(2 * nu * nv, 3);
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) V.row(j * (nu + 1) + i) = lift(width * i / nu, height * j / nv).transpose();
  int t = 0;
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const int a = j * (nu + 1) + i;
      T.row(t++) << a, a + 1, a + nu + 2;
      T.row(t++) << a, a + nu + 2, a + nu + 1;
    }
}

}  // namespace devsurf::testing
