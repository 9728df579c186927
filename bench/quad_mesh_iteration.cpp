// Developable approximation with quad meshes (Jiang et al. 2020, 004_… Fig. 8 and §5) against the
// number of unknowns, up to the paper's largest: 250 000 variables (Fig. 8: 65.8–412 s for 10–20
// iterations on one core; ARCHITECTURE §7: ≤ 1 s per iteration, 10 iterations ≤ 10 s).
//
// The problem is the preset examples/quad-developable-approx.json scaled up: M is the doubly
// curved saddle z = 0.35(x² − y²) + 0.15xy² over [−1, 1]² as an n × n vertex quad grid, M and the
// planar unfolding M′ both variable (5 free scalars per vertex: 3 for M, x and y for M′), M′
// started as M projected onto its least-squares plane. Two weight sets:
//
// - "preset": the preset's weights (position 10, fairness 0.1 on M and M′, E_map 1, proximity
//   0.001 / 0.001 to the reference Φ = M triangulated, foot points renewed every iteration);
// - "defaults": QuadMeshWeights{} (no reference, no proximity);
// - "preset_factorize": the preset's weights with a factorization in every iteration
//   (QuadMeshOptions::factorizationReuseFrom off), what the model did before factorization reuse;
// - "segmented": 004_… §5 / Fig. 20 (issue 15): the saddle z = 0.35(x² − y²) + 0.15xy² as a
//   reference triangle mesh (120 × 120 quads split), segmented into 3 × 3 patches, turned into
//   glued patches by models::quad_mesh::segmentedApproximation with about N quads (the size in
//   the name) and its default weights (proximity to the reference with foot points renewed every
//   iteration, gluing); compare Fig. 22 row 20b (160k variables, 42.9 s for 10 iterations).
//
// One benchmark iteration = 10 guided-projection iterations of Algorithm 1 (round 0) from the same
// start (tolerances 0, so all 10 run; step control on as in `devsurf solve`). The model is built
// once per benchmark, outside the timing; its build time (topology, terms, symbolic analysis of the
// normal equations and of the linear solver) is the counter build_ms.
//
// Counters: unknowns, nnz (structural upper-triangular nonzeros of the full normal matrix), the
// steps (iterations run), factorizations and pcg_solves (preconditioned solves with an earlier
// factorization) per 10 iterations,
// per-iteration phase times from the engine's IterationRecords (averaged over the 10 iterations
// and the repetitions), ten_iterations_ms, length_error (L-Err after the 10 iterations) and
// peak_rss_mb (getrusage, whole process: run one size per process for a size's own peak, as
// bench/quad_mesh_table.sh does). The label says which linear solver "auto" chose.

#include <benchmark/benchmark.h>

#include <sys/resource.h>

#include <chrono>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/GuidedProjectionSolver.h"
#include "devsurf/models/quad_mesh/QuadMeshDesign.h"
#include "devsurf/models/quad_mesh/QuadMeshModel.h"
#include "devsurf/models/quad_mesh/SegmentedApproximation.h"
#include "devsurf/proto/Scene.h"

namespace {

namespace engine = devsurf::engine;
namespace proto = devsurf::proto;
namespace quad = devsurf::models::quad_mesh;

constexpr int kIterations = 10;

/// The preset's saddle on an n × n vertex grid over [−1, 1]²: vertex (i, j) = i + n·j, faces
/// counter-clockwise seen from +z.
quad::QuadMeshDesign saddleGrid(int n, bool presetWeights) {
  quad::QuadMeshDesign d;
  d.mesh.resize(static_cast<Eigen::Index>(n) * n, 3);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double x = -1.0 + 2.0 * i / (n - 1), y = -1.0 + 2.0 * j / (n - 1);
      d.mesh.row(i + n * j) << x, y, 0.35 * (x * x - y * y) + 0.15 * x * y * y;
    }
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int v = i + n * j;
      d.faces.push_back({v, v + 1, v + 1 + n, v + n});
    }
  d.unfoldingPlanar = true;
  d.variable = quad::VariableMeshes::Both;  // unfolding empty: M projected onto its plane
  d.schedule.energyMin = 0.0;               // all 10 iterations run
  d.schedule.isometryMin = 0.0;
  d.schedule.roundIterations = 20;  // as the preset: the 10 iterations are round 0
  d.schedule.rounds = 10;
  if (presetWeights) {
    d.weights.position = 10;
    d.weights.proximityPoint = 0.001;
    d.weights.proximityPlane = 0.001;
    quad::ReferenceSurface reference;
    reference.vertices = d.mesh;
    reference.triangles.resize(2 * static_cast<Eigen::Index>(d.faces.size()), 3);
    for (std::size_t f = 0; f < d.faces.size(); ++f) {
      const quad::Face& q = d.faces[f];
      reference.triangles.row(2 * f) << q[0], q[1], q[2];
      reference.triangles.row(2 * f + 1) << q[0], q[2], q[3];
    }
    d.reference = std::move(reference);
  }
  return d;
}

/// The segmented saddle of the "segmented" variant with about `quads` quads.
quad::QuadMeshDesign segmentedSaddle(int quads) {
  const int n = 120;
  Eigen::MatrixX3d V((n + 1) * (n + 1), 3);
  Eigen::MatrixX3i T(2 * n * n, 3);
  std::vector<int> patch;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const double x = -1.0 + 2.0 * i / n, y = -1.0 + 2.0 * j / n;
      V.row(i + (n + 1) * j) << x, y, 0.35 * (x * x - y * y) + 0.15 * x * y * y;
    }
  int t = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int a = i + (n + 1) * j;
      T.row(t++) << a, a + 1, a + n + 2;
      T.row(t++) << a, a + n + 2, a + n + 1;
      const int p = (3 * i / n) + 3 * (3 * j / n);
      patch.push_back(p);
      patch.push_back(p);
    }
  quad::SegmentedApproximationOptions options;
  options.targetFaces = quads;
  quad::QuadMeshDesign d = quad::segmentedApproximation(V, T, patch, options).design;
  d.schedule.energyMin = 0.0;
  d.schedule.isometryMin = 0.0;
  return d;
}

double peakRssMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // KiB on Linux
}

/// The model of the benchmark that runs now (one at a time: the previous one is freed first).
struct Fixture {
  std::string key;
  std::unique_ptr<quad::QuadMeshModel> model;
  Eigen::VectorXd x0;
  engine::SolverOptions options;
  double buildMs = 0.0;
};

Fixture& fixture(const std::string& key, int n, bool presetWeights, bool factorizeEveryIteration, bool segmented) {
  static Fixture f;
  if (f.key == key) return f;
  f.model.reset();
  f.key = key;
  const quad::QuadMeshDesign design = segmented ? segmentedSaddle(n) : saddleGrid(n, presetWeights);
  const auto start = std::chrono::steady_clock::now();
  quad::QuadMeshOptions modelOptions;
  if (factorizeEveryIteration) modelOptions.factorizationReuseFrom = std::numeric_limits<int>::max();
  f.model = std::make_unique<quad::QuadMeshModel>(design, modelOptions);
  f.buildMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  f.x0 = f.model->problem().x();
  proto::SolverSettings settings;  // what `devsurf solve` uses for a scene without a solver object
  f.options = settings.solverOptions();
  f.options.maxIterations = kIterations;
  f.options.residualTolerance = 0.0;
  f.options.relativeChangeTolerance = 0.0;
  return f;
}

void runTenIterations(benchmark::State& state, int n, bool presetWeights, bool factorizeEveryIteration,
                      bool segmented = false) {
  const std::string key = std::to_string(n) + (segmented ? "/segmented" : presetWeights ? "/preset" : "/defaults") +
                          (factorizeEveryIteration ? "/factorize" : "");
  Fixture& f = fixture(key, n, presetWeights, factorizeEveryIteration, segmented);
  quad::QuadMeshModel& model = *f.model;
  double assembly = 0, factorization = 0, solve = 0, iteration = 0, total = 0, lengthError = 0;
  int steps = 0, runs = 0, factorizations = 0, pcgSolves = 0;
  for (auto _ : state) {
    state.PauseTiming();
    model.problem().x() = f.x0;  // every timed solve starts from the same state
    model.solver().resetStepControl();
    state.ResumeTiming();
    const quad::QuadMeshSolveSummary result = model.solve(f.options);
    state.PauseTiming();
    const std::vector<engine::IterationRecord>& records = result.summary.iterations;
    if (records.size() < 2) {
      state.SkipWithError("solve() did not complete an iteration");
      break;
    }
    for (std::size_t k = 1; k < records.size(); ++k) {
      assembly += records[k].assemblyMs;
      factorization += records[k].factorizationMs;
      solve += records[k].solveMs;
      iteration += records[k].totalMs;
      factorizations += records[k].factorized ? 1 : 0;
      pcgSolves += records[k].pcgIterations;
    }
    steps += static_cast<int>(records.size()) - 1;
    total += result.summary.totalMs;
    ++runs;
    lengthError = model.quality().lengthError;
    state.ResumeTiming();
  }
  model.problem().x() = f.x0;
  if (runs == 0) return;
  using benchmark::Counter;
  const double perStep = steps > 0 ? 1.0 / steps : 0.0;
  state.counters["n"] = Counter(n);
  state.counters["unknowns"] = Counter(model.numUnknowns());
  state.counters["nnz"] = Counter(static_cast<double>(model.solver().normalMatrixNonZeros()));
  state.counters["steps"] = Counter(static_cast<double>(steps) / runs);
  state.counters["factorizations"] = Counter(static_cast<double>(factorizations) / runs);
  state.counters["pcg_solves"] = Counter(static_cast<double>(pcgSolves) / runs);
  state.counters["build_ms"] = Counter(f.buildMs);
  state.counters["assembly_ms"] = Counter(assembly * perStep);
  state.counters["factorization_ms"] = Counter(factorization * perStep);
  state.counters["solve_ms"] = Counter(solve * perStep);
  state.counters["iteration_ms"] = Counter(iteration * perStep);
  state.counters["ten_iterations_ms"] = Counter(total / runs);
  state.counters["length_error"] = Counter(lengthError);
  state.counters["peak_rss_mb"] = Counter(peakRssMb());
  state.SetLabel(model.solver().linearSolverName());  // "auto (cholmod)" says what auto chose
}

void registerAll() {
  struct Size {
    int n;
    int repetitions;
  };
  // 5n² unknowns: 10 125, 40 500, 100 820, 250 880.
  const std::vector<Size> sizes{{45, 5}, {90, 5}, {142, 3}, {224, 1}};
  struct Variant {
    const char* name;
    bool presetWeights, factorizeEveryIteration;
  };
  const std::vector<Variant> variants{{"preset", true, false}, {"preset_factorize", true, true},
                                      {"defaults", false, false}};
  // Segmented approximation: about 2 000, 8 000 and 32 000 quads (≈ 5 unknowns per vertex).
  for (const Size& s : std::vector<Size>{{2000, 5}, {8000, 3}, {32000, 1}}) {
    const std::string name = "QuadMeshApprox/segmented/" + std::to_string(s.n);
    benchmark::RegisterBenchmark(name.c_str(), [s](benchmark::State& state) {
      runTenIterations(state, s.n, false, false, true);
    })
        ->Unit(benchmark::kMillisecond)
        ->Iterations(1)
        ->Repetitions(s.repetitions)
        ->ReportAggregatesOnly(s.repetitions > 1);
  }
  for (const Variant& v : variants) {
    for (const Size& s : sizes) {
      const std::string name = std::string("QuadMeshApprox/") + v.name + "/" + std::to_string(s.n);
      benchmark::RegisterBenchmark(name.c_str(), [s, v](benchmark::State& state) {
        runTenIterations(state, s.n, v.presetWeights, v.factorizeEveryIteration);
      })
          ->Unit(benchmark::kMillisecond)
          ->Iterations(1)
          ->Repetitions(s.repetitions)
          ->ReportAggregatesOnly(s.repetitions > 1);
    }
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
