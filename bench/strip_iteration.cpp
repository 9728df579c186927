// One guided-projection iteration of a developable strip (Tang et al. 2016 §2), and the model
// setup (construction = variables, terms, pattern, ordering, symbolic factorization), for
// 10 / 100 / 1000 / 1500 cubic spans, normals as free vectors, with both linear solvers.
//
// Counters (per benchmark run, averaged over its iterations): unknowns, nnz of the normal
// matrix (upper triangle as stored), and the solver's own per-phase timings of iteration 1.
// bench/paper_tables.sh turns the JSON output into the paper comparison table.

#include <benchmark/benchmark.h>

#include <cmath>
#include <map>
#include <memory>
#include <stdexcept>
#include <utility>

#include <Eigen/Core>

#include "devsurf/engine/GuidedProjectionSolver.h"
#include "devsurf/engine/LinearSolver.h"
#include "devsurf/models/strip/StripModel.h"
#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/spline/KnotVector.h"

namespace {

using devsurf::engine::LinearSolverKind;
using devsurf::engine::SolverOptions;
using devsurf::engine::SolveSummary;
using devsurf::models::strip::Curve;
using devsurf::models::strip::NormalRepresentation;
using devsurf::models::strip::StripDesign;
using devsurf::models::strip::StripModel;
using devsurf::models::strip::StripOptions;
namespace spline = devsurf::spline;

constexpr double kPi = 3.14159265358979323846;

/// Gently twisted, non-developable strip: a_i = (i h, 0, 0.1 sin(i h)), b_i = a_i + R_x(θ_i)·(0,1,0)
/// with θ growing linearly from 0 to 40°; width 1, length = spans + 2 (h = 1).
StripDesign twistedStrip(int spans) {
  const int degree = 3;
  const int n = spans + degree;  // clamped uniform: n − p spans
  const double h = 1.0;
  Eigen::MatrixXd pa(n, 3), pb(n, 3);
  for (int i = 0; i < n; ++i) {
    const double x = i * h;
    const double theta = (40.0 * kPi / 180.0) * i / (n - 1);
    pa.row(i) << x, 0.0, 0.1 * std::sin(x);
    pb.row(i) = pa.row(i) + Eigen::RowVector3d(0.0, std::cos(theta), std::sin(theta));
  }
  StripDesign d;
  d.a.knots = spline::KnotVector::clampedUniform(degree, n);
  d.a.points = pa;
  d.b.knots = d.a.knots;
  d.b.points = pb;
  d.normals.type = NormalRepresentation::Type::Vectors;
  d.fixed.push_back({Curve::A, 0});
  return d;
}

StripOptions stripOptions(LinearSolverKind kind) {
  StripOptions o;
  o.linearSolver = kind;
  return o;
}

SolverOptions oneIteration() {
  SolverOptions o;
  o.maxIterations = 1;
  o.fairness = 0.01;
  o.regularization = 0.01;
  return o;
}

/// One model (and its saved initial state) per (spans, solver), built once and shared by the
/// iteration-count probe and all repetitions of a benchmark.
struct Fixture {
  std::unique_ptr<StripModel> model;
  Eigen::VectorXd x0;
};

Fixture& fixture(int spans, LinearSolverKind kind) {
  static std::map<std::pair<int, int>, Fixture> cache;
  Fixture& f = cache[{spans, static_cast<int>(kind)}];
  if (!f.model) {
    f.model = std::make_unique<StripModel>(twistedStrip(spans), stripOptions(kind));
    f.x0 = f.model->problem().x();
  }
  return f;
}

void BM_StripIteration(benchmark::State& state, LinearSolverKind kind) {
  const int spans = static_cast<int>(state.range(0));
  Fixture& f = fixture(spans, kind);
  StripModel& model = *f.model;
  const SolverOptions options = oneIteration();

  double assembly = 0, factorization = 0, solve = 0, evaluation = 0, iteration = 0;
  for (auto _ : state) {
    state.PauseTiming();
    model.problem().x() = f.x0;  // every timed solve starts from the same state
    state.ResumeTiming();
    const SolveSummary summary = model.solve(options);
    state.PauseTiming();
    if (summary.iterations.size() < 2) {
      state.SkipWithError("solve() did not complete an iteration");
      break;
    }
    const auto& rec = summary.iterations[1];
    assembly += rec.assemblyMs;
    factorization += rec.factorizationMs;
    solve += rec.solveMs;
    evaluation += rec.evaluationMs;
    iteration += rec.totalMs;
    state.ResumeTiming();
  }
  model.problem().x() = f.x0;

  using benchmark::Counter;
  state.counters["spans"] = Counter(spans);
  state.counters["unknowns"] = Counter(model.numUnknowns());
  state.counters["nnz"] = Counter(static_cast<double>(model.solver().normalMatrixNonZeros()));
  state.counters["assembly_ms"] = Counter(assembly, Counter::kAvgIterations);
  state.counters["factorization_ms"] = Counter(factorization, Counter::kAvgIterations);
  state.counters["solve_ms"] = Counter(solve, Counter::kAvgIterations);
  state.counters["evaluation_ms"] = Counter(evaluation, Counter::kAvgIterations);
  state.counters["iteration_ms"] = Counter(iteration, Counter::kAvgIterations);
  state.counters["iter_per_fact"] = Counter(factorization > 0 ? iteration / factorization : 0.0);
  state.SetLabel(model.solver().linearSolverName());
}

void BM_StripSetup(benchmark::State& state, LinearSolverKind kind) {
  const int spans = static_cast<int>(state.range(0));
  const StripOptions opts = stripOptions(kind);
  int unknowns = 0;
  long nnz = 0;
  for (auto _ : state) {
    state.PauseTiming();
    StripDesign design = twistedStrip(spans);
    state.ResumeTiming();
    StripModel model(std::move(design), opts);
    benchmark::DoNotOptimize(model.problem().x().data());
    state.PauseTiming();
    unknowns = model.numUnknowns();
    nnz = model.solver().normalMatrixNonZeros();
    state.ResumeTiming();
  }
  using benchmark::Counter;
  state.counters["spans"] = Counter(spans);
  state.counters["unknowns"] = Counter(unknowns);
  state.counters["nnz"] = Counter(static_cast<double>(nnz));
  state.SetLabel(kind == LinearSolverKind::Cholmod ? "cholmod" : "ldlt");
}

void registerAll() {
  struct Solver {
    const char* name;
    LinearSolverKind kind;
  };
  std::vector<Solver> solvers{{"ldlt", LinearSolverKind::SimplicialLDLT}};
  if (devsurf::engine::cholmodAvailable()) solvers.push_back({"cholmod", LinearSolverKind::Cholmod});

  for (const Solver& s : solvers) {
    benchmark::RegisterBenchmark((std::string("StripIteration/") + s.name).c_str(),
                                 BM_StripIteration, s.kind)
        ->Arg(10)->Arg(100)->Arg(1000)->Arg(1500)
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.3)
        ->Repetitions(5)
        ->ReportAggregatesOnly(true);
  }
  for (const Solver& s : solvers) {
    benchmark::RegisterBenchmark((std::string("StripSetup/") + s.name).c_str(), BM_StripSetup,
                                 s.kind)
        ->Arg(10)->Arg(100)->Arg(1000)->Arg(1500)
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.1)
        ->Repetitions(5)
        ->ReportAggregatesOnly(true);
  }
}

}  // namespace

int main(int argc, char** argv) {
  registerAll();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
