// Bo et al. quasi-developable strip (001_…): one full solve (T = t → optimized σ, results and
// Algorithm 1 included) with 50 quadratic mapping coefficients and 100 samples, for both
// optimizers, on the exact cylinder pair (Fig. 6 in spirit) and the twisted cone pair (Fig. 2).
// Budget (../shared/ARCHITECTURE.md §7): ≤ 20 ms per solve. Counters: final max warp (°),
// iterations, rounds.

#include <benchmark/benchmark.h>

#include <Eigen/Core>

#include "devsurf/models/quasi_strip/QuasiStripModel.h"
#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/KnotVector.h"

namespace {

namespace qs = devsurf::models::quasi_strip;
namespace spline = devsurf::spline;

spline::BSplineCurve bezier(const Eigen::MatrixXd& points) {
  spline::BSplineCurve c;
  c.knots = spline::KnotVector::clampedUniform(static_cast<int>(points.rows()) - 1,
                                               static_cast<int>(points.rows()));
  c.points = points;
  return c;
}

qs::QuasiStripDesign exactPair() {
  Eigen::MatrixXd q(4, 3);
  q << 0, 0, 0, 1, 0.6, 0.3, 2, -0.4, 0.8, 3, 0.2, 0.1;
  Eigen::VectorXd phi(3);
  phi << 0.0, 0.25, 1.0;
  Eigen::MatrixXd c1 = spline::composeBezier(q, phi);
  c1.rowwise() += Eigen::RowVector3d(0.3, 1.2, 0.5);
  qs::QuasiStripDesign d;
  d.c1 = bezier(c1);
  d.c2 = bezier(q);
  return d;
}

qs::QuasiStripDesign twistedPair() {
  Eigen::MatrixXd q(6, 3);
  q << 0, 0, 0, 1, 1.2, 0.4, 2, -0.8, 1.0, 3, 1.0, -0.6, 4, -0.6, 0.3, 5, 0.4, 0.0;
  Eigen::VectorXd psi(4);
  psi << 0.0, 0.08, 0.33, 1.0;
  const Eigen::RowVector3d apex(2.5, 0.2, -3.0);
  Eigen::MatrixXd c1 = spline::composeBezier(q, psi);
  c1 = ((c1.rowwise() - apex) * 1.8).rowwise() + apex;
  qs::QuasiStripDesign d;
  d.c1 = bezier(c1);
  d.c2 = bezier(q);
  return d;
}

void solve(benchmark::State& state, qs::QuasiStripDesign design, qs::Optimizer optimizer) {
  design.mapping = {2, 50};
  design.samples = 100;
  qs::QuasiStripOptions options;
  options.optimizer = optimizer;
  double warp = 0, iterations = 0, rounds = 0;
  for (auto _ : state) {
    qs::QuasiStripModel model(design, options);
    const qs::QuasiStripSummary s = model.solve();
    warp = model.results().warpAngleMaxDeg;
    iterations = static_cast<double>(s.iterations.size()) - 1;
    rounds = s.rounds;
    benchmark::DoNotOptimize(model.results().surface.side0.data());
  }
  state.counters["warp_max_deg"] = warp;
  state.counters["iterations"] = iterations;
  state.counters["rounds"] = rounds;
}

void BM_QuasiStripExact_GuidedProjection(benchmark::State& s) { solve(s, exactPair(), qs::Optimizer::GuidedProjection); }
void BM_QuasiStripExact_Lbfgs(benchmark::State& s) { solve(s, exactPair(), qs::Optimizer::Lbfgs); }
void BM_QuasiStripTwisted_GuidedProjection(benchmark::State& s) { solve(s, twistedPair(), qs::Optimizer::GuidedProjection); }
void BM_QuasiStripTwisted_Lbfgs(benchmark::State& s) { solve(s, twistedPair(), qs::Optimizer::Lbfgs); }

}  // namespace

BENCHMARK(BM_QuasiStripExact_GuidedProjection)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(BM_QuasiStripExact_Lbfgs)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(BM_QuasiStripTwisted_GuidedProjection)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(BM_QuasiStripTwisted_Lbfgs)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);

BENCHMARK_MAIN();
