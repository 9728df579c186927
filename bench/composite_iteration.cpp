// One guided-projection iteration of a composite developable (Tang et al. 2016 §3, §5) against
// the number of unknowns, with and without development management (000_… §5, eq. 12):
//
// - every preset examples/composite-*.json as `devsurf solve` builds it ("dev": the preset's
//   development samples, 4 where it has none; "nodev": development off);
// - programmatic sheets with many parallel curved creases (parallelCreaseSheet), scaled up to
//   ~40 000 unknowns without a development (Tang Fig. 17: 39 648 variables, 0.8 s per iteration),
//   with the auto, LDLT and CHOLMOD linear solvers (CHOLMOD where compiled in; presets use their
//   scene's solver, by default auto).
//
// Counters (per benchmark run): unknowns, nnz of the normal matrix (upper triangle as stored), and
// the solver's own per-phase timings of iteration 1 averaged over the run. bench/paper_tables.sh
// prints the table.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/GuidedProjectionSolver.h"
#include "devsurf/engine/LinearSolver.h"
#include "devsurf/models/composite/CompositeDesign.h"
#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/proto/BoundedJson.h"
#include "devsurf/proto/Geometry.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/spline/KnotVector.h"

namespace {

namespace composite = devsurf::models::composite;
namespace engine = devsurf::engine;
namespace proto = devsurf::proto;
namespace spline = devsurf::spline;

constexpr double kPi = 3.14159265358979323846;

/// A flat sheet of `strips` strips between strips + 1 parallel wavy cubic S edges (each with
/// `spans` spans) running along y, the interior ones curved folds, lifted at one corner by a
/// handle; the first S edge's ends are held.
///
/// S edge i (0…strips): x = i·w + 0.2·w·sin(2πt), y = L·t, z = 0, from vertex 2i (bottom) to 2i+1
/// (top). Edges: S edges 0…strips, then the bottom rulings 2i → 2i+2, then the top rulings
/// 2i+3 → 2i+1. Face j: [bottom j, S j+1, top j, S j] (counterclockwise seen from +z).
/// Unknowns ≈ strips·(21·spans + 6) + (strips + 1)·(3·spans + 9).
composite::CompositeDesign parallelCreaseSheet(int strips, int spans) {
  const int degree = 3;
  const int n = spans + degree;
  const double w = 1.0, length = 4.0;
  composite::CompositeDesign d;
  d.vertices.resize(2 * (strips + 1), 3);
  const spline::KnotVector knots = spline::KnotVector::clampedUniform(degree, n);
  for (int i = 0; i <= strips; ++i) {
    composite::CompositeEdge e;
    e.v0 = 2 * i;
    e.v1 = 2 * i + 1;
    e.type = composite::EdgeType::Spline;
    e.curve.knots = knots;
    e.curve.points.resize(n, 3);
    for (int k = 0; k < n; ++k) {
      const double t = static_cast<double>(k) / (n - 1);
      e.curve.points.row(k) << i * w + 0.2 * w * std::sin(2.0 * kPi * t), length * t, 0.0;
    }
    e.crease = (i > 0 && i < strips) ? composite::CreaseKind::Fold : composite::CreaseKind::None;
    d.vertices.row(2 * i) = e.curve.points.row(0);
    d.vertices.row(2 * i + 1) = e.curve.points.row(n - 1);
    d.edges.push_back(e);
  }
  auto ruling = [](int v0, int v1) {
    composite::CompositeEdge e;
    e.v0 = v0;
    e.v1 = v1;
    e.type = composite::EdgeType::Ruling;
    return e;
  };
  for (int j = 0; j < strips; ++j) d.edges.push_back(ruling(2 * j, 2 * j + 2));
  for (int j = 0; j < strips; ++j) d.edges.push_back(ruling(2 * j + 3, 2 * j + 1));
  for (int j = 0; j < strips; ++j)
    d.faces.push_back({strips + 1 + j, j + 1, 2 * strips + 1 + j, j});
  d.fixed = {composite::PointRef::ofVertex(0), composite::PointRef::ofVertex(1),
             composite::PointRef::ofEdgePoint(0, n / 2)};
  const int corner = 2 * strips + 1;
  d.handles.push_back({composite::PointRef::ofVertex(corner),
                       Eigen::Vector3d(d.vertices(corner, 0) - 0.1 * w, d.vertices(corner, 1), 0.5 * w), 1.0});
  return d;
}

/// One model per benchmark (built on first use, kept for all repetitions) and its initial x.
struct Fixture {
  std::unique_ptr<composite::CompositeModel> model;
  Eigen::VectorXd x0;
  engine::SolverOptions options;
  std::string error;
};

std::map<std::string, Fixture>& fixtures() {
  static std::map<std::string, Fixture> cache;
  return cache;
}

Fixture& fixture(const std::string& key, const std::function<composite::CompositeDesign()>& make,
                 const composite::CompositeOptions& modelOptions, const engine::SolverOptions& solverOptions) {
  Fixture& f = fixtures()[key];
  if (!f.model && f.error.empty()) {
    try {
      f.model = std::make_unique<composite::CompositeModel>(make(), modelOptions);
      f.x0 = f.model->problem().x();
      f.options = solverOptions;
      f.options.maxIterations = 1;
      f.options.residualTolerance = 0.0;
      f.options.relativeChangeTolerance = 0.0;
    } catch (const std::exception& e) {
      f.error = e.what();
    }
  }
  return f;
}

void runIteration(benchmark::State& state, Fixture& f, int development) {
  if (!f.model) {
    state.SkipWithError(f.error.c_str());
    for (auto _ : state) {
    }
    return;
  }
  composite::CompositeModel& model = *f.model;
  double assembly = 0, factorization = 0, solve = 0, evaluation = 0, iteration = 0;
  for (auto _ : state) {
    state.PauseTiming();
    model.problem().x() = f.x0;  // every timed solve starts from the same state
    state.ResumeTiming();
    const engine::SolveSummary summary = model.solve(f.options);
    state.PauseTiming();
    if (summary.iterations.size() < 2) {
      state.SkipWithError("solve() did not complete an iteration");
      break;
    }
    const engine::IterationRecord& rec = summary.iterations[1];
    assembly += rec.assemblyMs;
    factorization += rec.factorizationMs;
    solve += rec.solveMs;
    evaluation += rec.evaluationMs;
    iteration += rec.totalMs;
    state.ResumeTiming();
  }
  model.problem().x() = f.x0;
  using benchmark::Counter;
  state.counters["unknowns"] = Counter(model.numUnknowns());
  state.counters["nnz"] = Counter(static_cast<double>(model.solver().normalMatrixNonZeros()));
  state.counters["development"] = Counter(development);
  state.counters["assembly_ms"] = Counter(assembly, Counter::kAvgIterations);
  state.counters["factorization_ms"] = Counter(factorization, Counter::kAvgIterations);
  state.counters["solve_ms"] = Counter(solve, Counter::kAvgIterations);
  state.counters["evaluation_ms"] = Counter(evaluation, Counter::kAvgIterations);
  state.counters["iteration_ms"] = Counter(iteration, Counter::kAvgIterations);
  state.counters["assembly_threads"] = Counter(model.solver().assemblyThreads());
  state.SetLabel(model.solver().linearSolverName());  // "auto (cholmod)" says what auto chose
}

std::string readFile(const std::filesystem::path& path) {
  std::ifstream file(path);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

void registerPresets() {
  const std::filesystem::path dir = std::filesystem::path(DEVSURF_SOURCE_DIR) / "examples";
  std::vector<std::filesystem::path> presets;
  if (std::filesystem::is_directory(dir))
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
      const std::string name = entry.path().filename().string();
      if (name.rfind("composite-", 0) == 0 && entry.path().extension() == ".json") presets.push_back(entry.path());
    }
  std::sort(presets.begin(), presets.end());
  for (const std::filesystem::path& path : presets) {
    const std::string stem = path.stem().string();
    // Without and with development as the scene says, then with development and the ruling crease
    // and smooth rows (CreaseNormals::Ruling; the presets' `auto` keeps free rows below 5 000
    // unknowns): what the factorized system loses and what that buys.
    for (const int variantIndex : {0, 1, 2}) {
      const bool withDevelopment = variantIndex > 0, ruling = variantIndex == 2;
      const std::string variant = !withDevelopment ? "nodev" : ruling ? "dev/ruling" : "dev";
      const std::string key = "CompositePreset/" + stem + "/" + variant;
      benchmark::RegisterBenchmark(key.c_str(), [path, key, withDevelopment, ruling, stem](benchmark::State& state) {
        proto::Scene scene;
        int samples = 0;
        auto make = [&scene, &samples, withDevelopment]() {
          composite::CompositeDesign d = std::get<composite::CompositeDesign>(scene.model);
          if (!withDevelopment) d.developmentSamples = 0;
          else if (d.developmentSamples == 0) d.developmentSamples = 4;
          samples = d.developmentSamples;
          return d;
        };
        try {
          scene = proto::sceneFromText(readFile(path));
        } catch (const std::exception& e) {
          fixtures()[key].error = e.what();
        }
        composite::CompositeOptions modelOptions = scene.solver.compositeOptions();
        if (ruling) modelOptions.creaseNormals = composite::CreaseNormals::Ruling;
        Fixture& f = fixture(key, make, modelOptions, scene.solver.solverOptions());
        if (f.model) samples = f.model->design().developmentSamples;
        runIteration(state, f, samples);
      })
          ->Unit(benchmark::kMillisecond)
          ->MinTime(0.2)
          ->Repetitions(5)
          ->ReportAggregatesOnly(true);
    }
  }
}

void registerScaled() {
  struct Size {
    int strips, spans;
  };
  // ≈ 1.1k, 5.0k, 11.8k, 23.5k, 39.1k unknowns without development (+35% with).
  const std::vector<Size> sizes{{4, 10}, {8, 25}, {12, 40}, {24, 40}, {40, 40}};
  struct Solver {
    const char* name;
    engine::LinearSolverKind kind;
    bool normalSplines = false;
    composite::CreaseNormals creaseNormals = composite::CreaseNormals::Ruling;
    composite::DevelopmentSolve developmentSolve = composite::DevelopmentSolve::Coupled;
  };
  // "splines": the auto solver with normal splines (CompositeOptions::normalSplines); "free": the
  // crease rows with the faces' free normals (CreaseNormals::Free, before issue 17's change);
  // "alternating": auto with the development solved apart (DevelopmentSolve::Alternating).
  std::vector<Solver> solvers{{"auto", engine::LinearSolverKind::Auto},
                              {"alternating", engine::LinearSolverKind::Auto, false, composite::CreaseNormals::Ruling,
                               composite::DevelopmentSolve::Alternating},
                              {"free", engine::LinearSolverKind::Auto, false, composite::CreaseNormals::Free},
                              {"splines", engine::LinearSolverKind::Auto, true},
                              {"splines_free", engine::LinearSolverKind::Auto, true, composite::CreaseNormals::Free},
                              {"ldlt", engine::LinearSolverKind::SimplicialLDLT}};
  if (engine::cholmodAvailable()) solvers.push_back({"cholmod", engine::LinearSolverKind::Cholmod});
  for (const Solver& solver : solvers) {
    for (const Size& s : sizes) {
      for (const bool withDevelopment : {false, true}) {
        if (!withDevelopment && solver.developmentSolve == composite::DevelopmentSolve::Alternating) continue;
        const std::string variant = withDevelopment ? "dev" : "nodev";
        const std::string key = "CompositeSheet/" + std::to_string(s.strips) + "x" + std::to_string(s.spans) + "/" +
                                variant + "/" + solver.name;
        benchmark::RegisterBenchmark(key.c_str(), [s, key, withDevelopment, solver](benchmark::State& state) {
          auto make = [s, withDevelopment]() {
            composite::CompositeDesign d = parallelCreaseSheet(s.strips, s.spans);
            d.developmentSamples = withDevelopment ? 4 : 0;
            return d;
          };
          composite::CompositeOptions options;
          options.linearSolver = solver.kind;
          options.normalSplines = solver.normalSplines;
          options.creaseNormals = solver.creaseNormals;
          options.developmentSolve = solver.developmentSolve;
          Fixture& f = fixture(key, make, options, engine::SolverOptions{});
          runIteration(state, f, withDevelopment ? 4 : 0);
        })
            ->Unit(benchmark::kMillisecond)
            ->MinTime(0.2)
            ->Repetitions(5)
            ->ReportAggregatesOnly(true);
      }
    }
  }
}

/// Ten iterations of the large sheets from the same start (the corner handle pulling), each
/// factorized or — `reuse` — solved by CG preconditioned with the first factorization (to a
/// relative residual of 1e-3, refactorizing when CG needs more than 10 solves), or — `alternating`,
/// with a development — with the development solved apart (CompositeOptions::developmentSolve): the mean of iterations 1…10, the hard residual and the
/// largest hard row after them, and the handle's distance from its target (the variants must end
/// alike).
void registerTenIterations() {
  struct Size {
    int strips, spans;
  };
  for (const Size s : std::vector<Size>{{24, 40}, {40, 40}})
    for (const bool withDevelopment : {false, true})
      for (const std::string variant : {"factorize", "reuse", "alternating"}) {
        if (variant == "alternating" && !withDevelopment) continue;
        const bool reuse = variant == "reuse";
        const std::string key = "CompositeSheetTen/" + std::to_string(s.strips) + "x" + std::to_string(s.spans) + "/" +
                                (withDevelopment ? "dev" : "nodev") + "/" + variant;
        benchmark::RegisterBenchmark(key.c_str(), [s, key, withDevelopment, reuse, variant](benchmark::State& state) {
          auto make = [s, withDevelopment]() {
            composite::CompositeDesign d = parallelCreaseSheet(s.strips, s.spans);
            d.developmentSamples = withDevelopment ? 4 : 0;
            return d;
          };
          composite::CompositeOptions modelOptions;
          if (variant == "alternating") modelOptions.developmentSolve = composite::DevelopmentSolve::Alternating;
          Fixture& f = fixture(key, make, modelOptions, engine::SolverOptions{});
          if (!f.model) {
            state.SkipWithError(f.error.c_str());
            for (auto _ : state) {
            }
            return;
          }
          engine::SolverOptions options = f.options;
          options.maxIterations = 10;
          if (reuse) {
            options.factorizationReuse.maxAge = 10;
            options.factorizationReuse.maxIterations = 10;
            options.factorizationReuse.tolerance = 1e-3;
          }
          composite::CompositeModel& model = *f.model;
          double iteration = 0, factorizations = 0, hard = 0, hardMax = 0, handle = 0;
          double assembly = 0, factorization = 0, solve = 0, pcg = 0, alternating = 0, steps = 0;
          for (auto _ : state) {
            state.PauseTiming();
            model.problem().x() = f.x0;
            model.solver().resetStepControl();
            state.ResumeTiming();
            const engine::SolveSummary summary = model.solve(options);
            state.PauseTiming();
            double total = 0;
            for (std::size_t k = 1; k < summary.iterations.size(); ++k) {
              total += summary.iterations[k].totalMs;
              factorizations += summary.iterations[k].factorized ? 1 : 0;
              assembly += summary.iterations[k].assemblyMs;
              factorization += summary.iterations[k].factorizationMs;
              solve += summary.iterations[k].solveMs;
              pcg += summary.iterations[k].pcgIterations;
              alternating += summary.iterations[k].alternatingStepScale;
              steps += 1;
            }
            iteration += total / static_cast<double>(std::max<std::size_t>(1, summary.iterations.size() - 1));
            hard = summary.iterations.back().hardResidual;
            hardMax = summary.iterations.back().hardResidualMax;
            handle = 0;
            for (const auto& [name, value] : summary.finalResidualsByName())
              if (name == "handle") handle += value;
            state.ResumeTiming();
          }
          model.problem().x() = f.x0;
          using benchmark::Counter;
          state.counters["unknowns"] = Counter(model.numUnknowns());
          state.counters["iteration_ms"] = Counter(iteration, Counter::kAvgIterations);
          state.counters["factorizations"] = Counter(factorizations, Counter::kAvgIterations);
          // Means per iteration over every iteration of every run.
          steps = std::max(1.0, steps);
          state.counters["assembly_ms"] = Counter(assembly / steps);
          state.counters["factorization_ms"] = Counter(factorization / steps);
          state.counters["solve_ms"] = Counter(solve / steps);
          state.counters["pcg_solves"] = Counter(pcg, Counter::kAvgIterations);
          state.counters["alternating_alpha_sum"] = Counter(alternating, Counter::kAvgIterations);
          state.counters["hard_residual"] = Counter(hard);
          state.counters["hard_max"] = Counter(hardMax);
          state.counters["handle_residual"] = Counter(handle);
        })
            ->Unit(benchmark::kMillisecond)
            ->Iterations(1)
            ->Repetitions(3)
            ->ReportAggregatesOnly(true);
      }
}

/// What an editing session computes for every streamed composite iterate besides the solver
/// (Session::geometryJson, ARCHITECTURE §7's drag latency): the quality metrics, the streamed
/// geometry (12 samples per span, as SessionSettings::compositeSamplesPerSpan) and its JSON text.
/// Each repetition moves one free variable by 1e-12 first, so nothing remembered from the last
/// state is reused (a real iterate moves every variable).
void registerIterateOutput() {
  struct Size {
    int strips, spans;
  };
  for (const Size s : std::vector<Size>{{10, 40}, {40, 40}}) {
    const std::string key = "CompositeIterateOutput/" + std::to_string(s.strips) + "x" + std::to_string(s.spans);
    benchmark::RegisterBenchmark(key.c_str(), [s, key](benchmark::State& state) {
      Fixture& f = fixture(key, [s]() { return parallelCreaseSheet(s.strips, s.spans); }, composite::CompositeOptions{},
                           engine::SolverOptions{});
      if (!f.model) {
        state.SkipWithError(f.error.c_str());
        for (auto _ : state) {
        }
        return;
      }
      composite::CompositeModel& model = *f.model;
      const Eigen::Index moved = model.problem().x().size() - 1;  // the far corner's handle side
      double qualityMs = 0, geometryMs = 0, textMs = 0;
      using Clock = std::chrono::steady_clock;
      auto ms = [](Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); };
      for (auto _ : state) {
        model.problem().x()[moved] += 1e-12;
        const Clock::time_point t0 = Clock::now();
        const composite::CompositeQuality q = model.quality();
        const Clock::time_point t1 = Clock::now();
        const nlohmann::json geometry = proto::compositeGeometryJson(model, q, 12);
        const Clock::time_point t2 = Clock::now();
        benchmark::DoNotOptimize(proto::wireText(geometry));  // what Session::broadcast sends
        const Clock::time_point t3 = Clock::now();
        qualityMs += ms(t0, t1);
        geometryMs += ms(t1, t2);
        textMs += ms(t2, t3);
      }
      model.problem().x() = f.x0;
      using benchmark::Counter;
      state.counters["unknowns"] = Counter(model.numUnknowns());
      state.counters["quality_ms"] = Counter(qualityMs, Counter::kAvgIterations);
      state.counters["geometry_ms"] = Counter(geometryMs, Counter::kAvgIterations);
      state.counters["json_text_ms"] = Counter(textMs, Counter::kAvgIterations);
    })
        ->Unit(benchmark::kMillisecond)
        ->MinTime(0.5)
        ->Repetitions(5)
        ->ReportAggregatesOnly(true);
  }
}

}  // namespace

int main(int argc, char** argv) {
  registerPresets();
  registerScaled();
  registerTenIterations();
  registerIterateOutput();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
