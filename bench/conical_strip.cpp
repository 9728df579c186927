// The conical strip of Chu, Wang, Tsai 2008 on the Fig. 11-like input (figure11LikeDesign():
// a twisted helical band, Np/Nq = 55/65, H3 = H4 = 4, ra = 1.2):
//
// - BM_ConicalStripSolve/<objective>/<g1>: the whole solve() (sampling, greedy Steps 1–5, degree
//   elevation and G1 adjustment, metrics and development);
// - counters from the model's own summary: the greedy part, the G1 part and the metrics part
//   (ms, averaged over the run), n3, n4.
//
// Run with --benchmark_repetitions=5 --benchmark_report_aggregates_only=true for medians.

#include <benchmark/benchmark.h>

#include "devsurf/models/conical_strip/ConicalStripModel.h"
#include "devsurf/models/conical_strip/ConicalStripPresets.h"

namespace {

namespace conical_strip = devsurf::models::conical_strip;

void BM_ConicalStripSolve(benchmark::State& state) {
  conical_strip::ConicalStripDesign design = conical_strip::figure11LikeDesign();
  design.objective = state.range(0) == 0 ? conical_strip::Objective::NormalVariation
                                         : conical_strip::Objective::BendingEnergy;
  design.g1 = state.range(1) != 0;
  conical_strip::ConicalStripModel model(design);
  double greedyMs = 0.0, g1Ms = 0.0, metricsMs = 0.0;
  int iterations = 0;
  for (auto _ : state) {
    const conical_strip::ConicalStripSummary& s = model.solve();
    greedyMs += s.greedyMs;
    g1Ms += s.g1Ms;
    metricsMs += s.metricsMs;
    ++iterations;
    benchmark::DoNotOptimize(model.result().metrics.normalVariation);
  }
  state.counters["greedy_ms"] = greedyMs / iterations;
  state.counters["g1_ms"] = g1Ms / iterations;
  state.counters["metrics_ms"] = metricsMs / iterations;
  state.counters["n3"] = model.result().metrics.n3;
  state.counters["n4"] = model.result().metrics.n4;
  state.SetLabel(std::string(conical_strip::objectiveName(design.objective)) +
                 (design.g1 ? " g1" : " g0"));
}
BENCHMARK(BM_ConicalStripSolve)
    ->ArgsProduct({{0, 1}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
