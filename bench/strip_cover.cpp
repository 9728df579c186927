// Covering a region by strips side by side (issue 15, 000_… Fig. 10d–e): the whole cover
// (layout, thinning, the sweeps that fit the strips and pair their boundaries) and one iteration
// of the composite made from them. A sphere cap of radius 2 sampled at 8000 seeded points (doubly
// curved, as the bunny's back), so sizes are repeatable. Compare with 000_… Fig. 17 row 10
// (approximating the bunny: 12 777 variables, 0.5 s per iteration).
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "devsurf/models/composite/CompositeFromStrips.h"
#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/models/strip/StripCover.h"

namespace {

Eigen::MatrixX3d sphereCap(int n) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  Eigen::MatrixX3d points(n, 3);
  for (int j = 0; j < n; ++j) {
    const double x = uniform(rng), y = uniform(rng);
    points.row(j) << x, y, std::sqrt(4.0 - x * x - y * y);
  }
  return points;
}

/// coverRegion with state.range(0) strips: 8 sweeps × 10 iterations per strip; the time per strip
/// iteration includes building each strip's model once per sweep and the thinning.
void BM_CoverSphereCap(benchmark::State& state) {
  const Eigen::MatrixX3d points = sphereCap(8000);
  devsurf::models::strip::RegionCoverOptions options;
  options.strips = static_cast<int>(state.range(0));
  for (auto _ : state) {
    const auto cover = devsurf::models::strip::coverRegion(points, Eigen::MatrixX3d(0, 3), options);
    benchmark::DoNotOptimize(cover.paired.strips.data());
  }
  const double stripIterations = options.strips * options.pairing.rounds * options.pairing.iterationsPerRound;
  state.counters["strip_iterations"] = stripIterations;
  state.counters["ms_per_strip_iteration"] =
      benchmark::Counter(stripIterations * 1e-3, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_CoverSphereCap)->Arg(4)->Arg(8)->Unit(benchmark::kMillisecond)->UseRealTime();

/// One guided-projection iteration of the composite made from the cover (seams, no fairness).
void BM_CompositeFromCoverIteration(benchmark::State& state) {
  const Eigen::MatrixX3d points = sphereCap(8000);
  devsurf::models::strip::RegionCoverOptions options;
  options.strips = static_cast<int>(state.range(0));
  const auto cover = devsurf::models::strip::coverRegion(points, Eigen::MatrixX3d(0, 3), options);
  devsurf::models::composite::CompositeModel model(devsurf::models::composite::compositeFromStrips(
      cover.paired.strips, cover.pairings, devsurf::models::composite::CreaseKind::None));
  devsurf::engine::SolverOptions solve;
  solve.maxIterations = 1;
  solve.fairness = 0.0;
  solve.residualTolerance = 0.0;
  solve.relativeChangeTolerance = 0.0;
  for (auto _ : state) benchmark::DoNotOptimize(model.solve(solve).iterations.size());
  state.counters["unknowns"] = model.numUnknowns();
}
BENCHMARK(BM_CompositeFromCoverIteration)->Arg(4)->Arg(8)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
