// Reference shapes (issue 15): thinning with fitted normals, and one-sided distances to a surface.
// Clouds are sampled on a unit sphere (seeded), so sizes and radii are exact and repeatable.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "devsurf/reference/PointThinning.h"
#include "devsurf/reference/SurfaceDistance.h"

namespace {

Eigen::MatrixX3d sphereCloud(int n, std::uint32_t seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> g;
  Eigen::MatrixX3d points(n, 3);
  for (int i = 0; i < n; ++i) {
    Eigen::RowVector3d p(g(random), g(random), g(random));
    points.row(i) = p.normalized();
  }
  return points;
}

/// A UV sphere of (rings × segments) quads split into triangles.
void sphereMesh(int rings, int segments, Eigen::MatrixX3d& V, Eigen::MatrixX3i& T) {
  V.resize((rings + 1) * segments, 3);
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const double theta = M_PI * r / rings, phi = 2 * M_PI * s / segments;
      V.row(r * segments + s) << std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta);
    }
  T.resize(2 * rings * segments, 3);
  int t = 0;
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const int a = r * segments + s, b = r * segments + (s + 1) % segments, c = a + segments, d = b + segments;
      T.row(t++) << a, b, d;
      T.row(t++) << a, d, c;
    }
}

/// Thinning n points on the unit sphere at radius 0.02 (≈ 10 000 kept, as Fig. 10's clouds).
void BM_ThinSphereCloud(benchmark::State& state) {
  const Eigen::MatrixX3d points = sphereCloud(static_cast<int>(state.range(0)), 1);
  devsurf::reference::ThinningOptions options;
  options.radius = 0.02;
  std::size_t kept = 0;
  for (auto _ : state) {
    const auto thin = devsurf::reference::thinPointCloud(points, Eigen::MatrixX3d(0, 3), options);
    kept = thin.kept.size();
    benchmark::DoNotOptimize(thin.normals.data());
  }
  state.counters["kept"] = static_cast<double>(kept);
  state.counters["points"] = static_cast<double>(points.rows());
}
BENCHMARK(BM_ThinSphereCloud)->Arg(100000)->Arg(1000000)->Unit(benchmark::kMillisecond)->UseRealTime();

/// Distances of n reference points to a 200 × 400 UV sphere (160 000 triangles), AABB tree
/// built inside (as devsurf solve --reference does once per report).
void BM_SurfaceDistance(benchmark::State& state) {
  const Eigen::MatrixX3d points = 1.01 * sphereCloud(static_cast<int>(state.range(0)), 2);
  Eigen::MatrixX3d V;
  Eigen::MatrixX3i T;
  sphereMesh(200, 400, V, T);
  for (auto _ : state) {
    const auto d = devsurf::reference::surfaceDistance(points, V, T);
    benchmark::DoNotOptimize(d.rmsDistance);
  }
  state.counters["triangles"] = static_cast<double>(T.rows());
}
BENCHMARK(BM_SurfaceDistance)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
