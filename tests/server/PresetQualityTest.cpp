// Every preset in examples/ as shipped — discovered, so a new preset is covered without editing
// this file — solved as `devsurf solve` solves it (SceneSolver with the scene's own settings,
// handles held), must meet the quality thresholds of issue 5: the model's verdict, and the same
// numbers recomputed independently from the OBJ and FOLD exports.

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "devsurf/server/SceneSolver.h"
#include "support/ExportChecks.h"
#include "support/Presets.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
namespace checks = devsurf::testing;

using devsurf::testing::presetFiles;

class PresetAsShipped : public ::testing::TestWithParam<std::string> {};

TEST_P(PresetAsShipped, SolvedAsDevsurfSolveSolvesItMeetsTheQualityThresholds) {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/" + GetParam());
  SceneSolver solver(proto::sceneFromJson(json::parse(file)));
  const engine::SolveSummary summary = solver.solve();
  EXPECT_NE(summary.reason, engine::TerminationReason::Diverged);
  const proto::Metrics metrics = solver.metrics();
  for (const auto& [name, value] : metrics) EXPECT_TRUE(std::isfinite(value)) << name;
  const QualityVerdict verdict = solver.quality();
  std::cout << GetParam() << ": " << summary.stepsTaken() << " iterations, "
            << engine::terminationReasonName(summary.reason) << ", quality " << verdict.toJson().dump() << "\n";
  for (const QualityCheck& c : verdict.checks) EXPECT_TRUE(c.ok) << c.metric << " = " << c.value << ", limit " << c.limit;
  EXPECT_TRUE(verdict.met);

  if (solver.keepsInputGeometry()) return;
  // Independently, from what a user downloads.
  const checks::ObjMesh mesh = checks::parseObj(solver.exportAs("obj").content);
  ASSERT_FALSE(mesh.faces.empty());
  if (solver.isQuadMesh()) {
    const double l = checks::objEdgeLengthError(mesh, checks::parseObj(solver.exportAs("unfolding_obj").content));
    EXPECT_NEAR(l, metrics.at("length_error"), 1e-9 + 1e-6 * l) << "L-Err recomputed from the OBJ exports of M and M′";
  }
  if (solver.isComposite()) {
    const checks::FlatnessStats flat = checks::objFlatness(mesh);
    EXPECT_LE(flat.max, 1e-3) << "face flatness recomputed from the OBJ export";
    // FOLD: the development's crease pattern, or the pieces of a composite cut along its seams.
    std::string foldText;
    try {
      foldText = solver.exportAs("fold").content;
    } catch (const ExportUnavailable& e) {
      EXPECT_EQ(metrics.count("development_length_error"), 0u) << "a development exports as FOLD: " << e.what();
    }
    if (!foldText.empty()) {
      const checks::FoldDevelopmentCheck fold = checks::checkFoldDevelopment(json::parse(foldText));
      EXPECT_EQ(fold.flippedFaces, 0) << "faces of the FOLD crease pattern that are not counterclockwise";
      EXPECT_LE(fold.lengthError, 5e-3) << "edge lengths of the FOLD crease pattern against its folded frame";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Examples, PresetAsShipped, ::testing::ValuesIn(presetFiles()),
                         devsurf::testing::presetTestName<::testing::TestParamInfo<std::string>>);

/// Every composite preset with the solver's normal splines switched on (the designer's "normals:
/// spline" in the Solver panel, or `"normal_splines": true`): still solved to the same quality
/// thresholds, with far fewer unknowns (Tang et al. §7: "this did not impair quality").
class CompositePresetWithNormalSplines : public ::testing::TestWithParam<std::string> {};

std::vector<std::string> compositePresetFiles() {
  std::vector<std::string> out;
  for (const std::string& name : presetFiles()) {
    std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/" + name);
    if (json::parse(file)["model"]["kind"] == "composite") out.push_back(name);
  }
  return out;
}

TEST_P(CompositePresetWithNormalSplines, SolvedWithNormalSplinesItStillMeetsTheQualityThresholds) {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/" + GetParam());
  json scene = json::parse(file);
  const bool shippedWithSplines = scene.value("solver", json::object()).value("normal_splines", false);
  scene["solver"]["normal_splines"] = false;
  const double freeNormalUnknowns = SceneSolver(proto::sceneFromJson(scene)).metrics().at("unknowns");
  scene["solver"]["normal_splines"] = true;
  SceneSolver solver(proto::sceneFromJson(scene));
  EXPECT_LT(solver.metrics().at("unknowns"), 0.8 * freeNormalUnknowns) << "normal splines have fewer unknowns";
  const engine::SolveSummary summary = solver.solve();
  EXPECT_NE(summary.reason, engine::TerminationReason::Diverged);
  const proto::Metrics metrics = solver.metrics();
  for (const auto& [name, value] : metrics) EXPECT_TRUE(std::isfinite(value)) << name;
  const QualityVerdict verdict = solver.quality();
  std::cout << GetParam() << (shippedWithSplines ? " (shipped with normal splines)" : "") << ": "
            << summary.stepsTaken() << " iterations, quality " << verdict.toJson().dump() << "\n";
  for (const QualityCheck& c : verdict.checks) EXPECT_TRUE(c.ok) << c.metric << " = " << c.value << ", limit " << c.limit;
  EXPECT_LT(metrics.at("warp_angle_max_deg"), 0.05);
  const checks::FlatnessStats flat = checks::objFlatness(checks::parseObj(solver.exportAs("obj").content));
  EXPECT_LE(flat.max, 1e-3) << "face flatness recomputed from the OBJ export";
}

INSTANTIATE_TEST_SUITE_P(Examples, CompositePresetWithNormalSplines, ::testing::ValuesIn(compositePresetFiles()),
                         devsurf::testing::presetTestName<::testing::TestParamInfo<std::string>>);

/// Every composite preset with the crease rows on the faces' rulings (`"crease_normals":
/// "ruling"`; `auto` takes them from 5 000 unknowns on, above every preset): still solved to the
/// same quality thresholds, checked again from the OBJ export, with fewer unknowns factorized.
class CompositePresetWithRulingCreases : public ::testing::TestWithParam<std::string> {};

TEST_P(CompositePresetWithRulingCreases, SolvedWithTheRulingCreaseRowsItStillMeetsTheQualityThresholds) {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/" + GetParam());
  json scene = json::parse(file);
  scene["solver"]["crease_normals"] = "ruling";
  SceneSolver solver(proto::sceneFromJson(scene));
  EXPECT_TRUE(solver.compositeModel().rulingCreases());
  const engine::SolveSummary summary = solver.solve();
  EXPECT_NE(summary.reason, engine::TerminationReason::Diverged);
  const proto::Metrics metrics = solver.metrics();
  for (const auto& [name, value] : metrics) EXPECT_TRUE(std::isfinite(value)) << name;
  const QualityVerdict verdict = solver.quality();
  std::cout << GetParam() << " with ruling crease rows: " << summary.stepsTaken() << " iterations, quality "
            << verdict.toJson().dump() << "\n";
  for (const QualityCheck& c : verdict.checks) EXPECT_TRUE(c.ok) << c.metric << " = " << c.value << ", limit " << c.limit;
  EXPECT_LT(metrics.at("warp_angle_max_deg"), 0.05);
  const checks::FlatnessStats flat = checks::objFlatness(checks::parseObj(solver.exportAs("obj").content));
  EXPECT_LE(flat.max, 1e-3) << "face flatness recomputed from the OBJ export";
}

INSTANTIATE_TEST_SUITE_P(Examples, CompositePresetWithRulingCreases, ::testing::ValuesIn(compositePresetFiles()),
                         devsurf::testing::presetTestName<::testing::TestParamInfo<std::string>>);

/// Every composite preset with a development, its development solved apart (`"development_solve":
/// "alternating"`): still solved to the same quality thresholds, its FOLD crease pattern — the
/// development itself — checked again against its folded frame by the independent reader, and
/// the design's intent kept: its handles reached and its folds folded as the coupled solve does.
class CompositePresetWithAlternatingDevelopment : public ::testing::TestWithParam<std::string> {};

std::vector<std::string> developedCompositePresetFiles() {
  std::vector<std::string> out;
  for (const std::string& name : compositePresetFiles()) {
    std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/" + name);
    if (json::parse(file)["model"].contains("development")) out.push_back(name);
  }
  return out;
}

TEST_P(CompositePresetWithAlternatingDevelopment, SolvedWithTheDevelopmentApartItStillMeetsTheQualityThresholds) {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/" + GetParam());
  json scene = json::parse(file);
  SceneSolver coupled(proto::sceneFromJson(scene));
  EXPECT_FALSE(coupled.compositeModel().solver().alternates());
  coupled.solve();
  scene["solver"]["development_solve"] = "alternating";
  SceneSolver solver(proto::sceneFromJson(scene));
  EXPECT_TRUE(solver.compositeModel().solver().alternates());
  const engine::SolveSummary summary = solver.solve();
  EXPECT_NE(summary.reason, engine::TerminationReason::Diverged);
  const proto::Metrics metrics = solver.metrics();
  for (const auto& [name, value] : metrics) EXPECT_TRUE(std::isfinite(value)) << name;
  const QualityVerdict verdict = solver.quality();
  std::cout << GetParam() << " with the development apart: " << summary.stepsTaken() << " iterations, quality "
            << verdict.toJson().dump() << "; coupled: " << coupled.quality().toJson().dump() << "\n";
  for (const QualityCheck& c : verdict.checks) EXPECT_TRUE(c.ok) << c.metric << " = " << c.value << ", limit " << c.limit;
  EXPECT_LE(metrics.at("development_length_error"), 5e-3);
  const checks::FlatnessStats flat = checks::objFlatness(checks::parseObj(solver.exportAs("obj").content));
  EXPECT_LE(flat.max, 1e-3) << "face flatness recomputed from the OBJ export";
  const checks::FoldDevelopmentCheck pattern =
      checks::checkFoldDevelopment(json::parse(solver.exportAs("fold").content));
  EXPECT_EQ(pattern.flippedFaces, 0) << "faces of the FOLD crease pattern that are not counterclockwise";
  EXPECT_LE(pattern.lengthError, 5e-3) << "edge lengths of the FOLD crease pattern against its folded frame";
  const proto::Metrics reference = coupled.metrics();
  const double handle = metrics.count("handle_distance_max") ? metrics.at("handle_distance_max") : 0.0;
  const double coupledHandle = reference.count("handle_distance_max") ? reference.at("handle_distance_max") : 0.0;
  const double fold = metrics.at("crease_fold_angle_max_deg"), coupledFold = reference.at("crease_fold_angle_max_deg");
  std::cout << "  handle distance " << handle << " (coupled " << coupledHandle << "), largest fold " << fold
            << "° (coupled " << coupledFold << "°)\n";
  EXPECT_LE(handle, std::max(1e-3, 10.0 * coupledHandle)) << "the handles are reached";
  if (GetParam() == "composite-pleated-sheet.json") {
    // Known (DevelopmentSolve::Alternating): the flat sheet pulled into its pleat shrinks in its
    // plane instead of folding — the surface's steps are held to the development's rigid quads,
    // the development then follows the surface. It reaches its handles unfolded.
    EXPECT_LT(fold, 1.0) << "the pleat now folds with the development apart: update DevelopmentSolve's note";
    return;
  }
  EXPECT_NEAR(fold, coupledFold, 0.1 * coupledFold + 0.5) << "the folds fold as the coupled solve folds them";
}

INSTANTIATE_TEST_SUITE_P(Examples, CompositePresetWithAlternatingDevelopment,
                         ::testing::ValuesIn(developedCompositePresetFiles()),
                         devsurf::testing::presetTestName<::testing::TestParamInfo<std::string>>);

/// The evaluation that judged a step serves the next assembly (SolverOptions::keepEvaluations,
/// Term::evaluatesFromXAlone): every preset whose model runs guided projection takes the same
/// iterates bit for bit with it on and off.
class PresetWithKeptEvaluations : public ::testing::TestWithParam<std::string> {};

/// The presets whose model is solved by guided projection (strip, composite, quad_mesh).
std::vector<std::string> guidedProjectionPresetFiles() {
  std::vector<std::string> out;
  for (const std::string& name : presetFiles()) {
    const std::string kind = devsurf::testing::readPreset(name)["model"].value("kind", "");
    if (kind == "strip" || kind == "composite" || kind == "quad_mesh") out.push_back(name);
  }
  return out;
}

TEST_P(PresetWithKeptEvaluations, TakesTheSameIteratesBitForBitAsWithoutThem) {
  const json scene = devsurf::testing::readPreset(GetParam());
  SceneSolver kept(proto::sceneFromJson(scene)), plain(proto::sceneFromJson(scene));
  engine::SolverOptions options;
  options.maxIterations = 6;        // twelve until stop 52 (CI time); kept evaluations from the second on
  options.residualTolerance = 0.0;  // all six, also on a preset that ships solved
  options.relativeChangeTolerance = 0.0;
  engine::SolverOptions without = options;
  without.keepEvaluations = false;
  auto run = [](SceneSolver& solver, const engine::SolverOptions& o, engine::SolveSummary& summary) -> Eigen::VectorXd {
    if (solver.isComposite()) {
      summary = solver.compositeModel().solve(o);
      return solver.compositeModel().problem().x();
    }
    if (solver.isStrip()) {
      summary = solver.stripModel().solve(o);
      return solver.stripModel().problem().x();
    }
    summary = solver.quadMeshModel().solve(o).summary;
    return solver.quadMeshModel().problem().x();
  };
  engine::SolveSummary sa, sb;
  const Eigen::VectorXd a = run(kept, options, sa), b = run(plain, without, sb);
  EXPECT_GT(sa.keptEvaluations, 0) << "no assembly took a kept evaluation";
  EXPECT_EQ(sb.keptEvaluations, 0);
  ASSERT_EQ(sa.iterations.size(), sb.iterations.size());
  for (std::size_t k = 0; k < sa.iterations.size(); ++k)
    EXPECT_EQ(sa.iterations[k].termResiduals, sb.iterations[k].termResiduals) << "the record of iteration " << k;
  ASSERT_EQ(a.size(), b.size());
  EXPECT_TRUE(a.allFinite());
  EXPECT_EQ(std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())), 0)
      << "largest difference " << (a - b).cwiseAbs().maxCoeff();
}

/// What a term that says it evaluates from x alone evaluates at x does not change when every term
/// of the model is linearized elsewhere (shared foot points, row scales): the declaration holds.
TEST_P(PresetWithKeptEvaluations, ATermThatSaysItEvaluatesFromXAloneDoes) {
  SceneSolver solver(proto::sceneFromJson(devsurf::testing::readPreset(GetParam())));
  engine::Problem& problem = solver.isComposite() ? solver.compositeModel().problem()
                             : solver.isStrip()   ? solver.stripModel().problem()
                                                  : solver.quadMeshModel().problem();
  const Eigen::VectorXd x = problem.x();
  Eigen::VectorXd elsewhere = x;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 1e-2 * (1.0 + x.cwiseAbs().maxCoeff()));
  for (Eigen::Index i = 0; i < elsewhere.size(); ++i) elsewhere[i] += noise(rng);
  struct Evaluation {
    std::vector<double> r, J;
  };
  auto evaluateAt = [](const engine::Term& term, const Eigen::VectorXd& at) {
    std::vector<engine::JacobianEntry> entries;
    term.jacobianStructure(entries);
    Evaluation e{std::vector<double>(static_cast<std::size_t>(term.numResiduals())), std::vector<double>(entries.size())};
    term.evaluate(at, e.r.data(), e.J.data());
    return e;
  };
  int declared = 0;
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<Evaluation> before;
    for (int t = 0; t < problem.numTerms(); ++t) {
      const engine::Term& term = *problem.term(t).term;
      before.push_back(term.evaluatesFromXAlone() ? evaluateAt(term, x) : Evaluation{});
    }
    for (int t = 0; t < problem.numTerms(); ++t) problem.term(t).term->linearizeAt(pass == 0 ? elsewhere : x);
    for (int t = 0; t < problem.numTerms(); ++t) {
      const engine::Term& term = *problem.term(t).term;
      if (!term.evaluatesFromXAlone()) continue;
      declared += pass == 0 ? 1 : 0;
      const Evaluation after = evaluateAt(term, x);
      EXPECT_EQ(after.r, before[static_cast<std::size_t>(t)].r) << term.name();
      EXPECT_EQ(after.J, before[static_cast<std::size_t>(t)].J) << term.name();
    }
  }
  EXPECT_GT(declared, 0) << "no term of the model says it evaluates from x alone";
}

INSTANTIATE_TEST_SUITE_P(Examples, PresetWithKeptEvaluations, ::testing::ValuesIn(guidedProjectionPresetFiles()),
                         [](const auto& info) { return devsurf::testing::presetTestName(info); });

TEST(PresetAsShipped, EveryKindHasAPreset) {
  std::set<std::string> kinds;
  for (const std::string& name : presetFiles()) {
    std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/" + name);
    kinds.insert(json::parse(file)["model"]["kind"].get<std::string>());
  }
  EXPECT_EQ(kinds, (std::set<std::string>{"strip", "composite", "quasi_strip", "conical_strip", "quad_mesh"}));
}

}  // namespace
}  // namespace devsurf::server
