// Closed-form curved folds (003_… Part I) as exact solutions of the composite model (issue 5,
// "What it must show", first bullet): residuals at the start, then after a 1% perturbation of
// every free control point and 20 iterations (fairness 0).
//
// Measured (see the issue note): the planar fold is exact in B-splines (1e-15) and returns to
// ~1e-11 after the perturbation. The cylinder crease is fitted (degree 7, 16 spans: 3.5e-10);
// after the perturbation every one of 100 seeds returns below 5e-7 (the test runs 10 of them, and
// 10 each of the 32- and 4-span fits). Five iterations from the 32-span fit reach round-off.

#include "devsurf/models/composite/ClosedFormDesigns.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/proto/Scene.h"

namespace devsurf::models::composite {
namespace {

engine::SolverOptions iterationsWithoutFairness(int iterations) {
  engine::SolverOptions o;
  o.maxIterations = iterations;
  o.fairness = 0.0;
  o.regularization = 0.01;
  o.residualTolerance = 0.0;        // run every iteration: the test measures what 20 of them do
  o.relativeChangeTolerance = 0.0;
  return o;
}

/// Largest |r| of every term (by name) at the model's current variables, rows as the solver sees
/// them (row scales of this state, weights not applied).
std::map<std::string, double> termResidualMax(CompositeModel& model) {
  std::map<std::string, double> out;
  engine::Problem& problem = model.problem();
  const Eigen::VectorXd& x = problem.x();
  for (int t = 0; t < problem.numTerms(); ++t) {
    engine::Term& term = *problem.term(t).term;
    term.linearizeAt(x);
    Eigen::VectorXd r(term.numResiduals());
    term.evaluate(x, r.data(), nullptr);
    double& m = out[term.name()];
    if (r.size() > 0) m = std::max(m, r.cwiseAbs().maxCoeff());
  }
  return out;
}

/// Hard rows of the composite: developability, unit normals held hard, the curved fold.
double hardResidualMax(const std::map<std::string, double>& r) {
  double m = 0.0;
  for (const char* name : {"developability", "unit_normal_hard", "crease_fold"}) m = std::max(m, r.at(name));
  return m;
}

/// Diagonal of the bounding box of every vertex and control point.
double designSize(const CompositeDesign& d) {
  Eigen::Vector3d lo = d.vertices.colwise().minCoeff().transpose(), hi = d.vertices.colwise().maxCoeff().transpose();
  for (const CompositeEdge& e : d.edges) {
    if (e.curve.points.rows() == 0) continue;
    lo = lo.cwiseMin(e.curve.points.colwise().minCoeff().transpose());
    hi = hi.cwiseMax(e.curve.points.colwise().maxCoeff().transpose());
  }
  return (hi - lo).norm();
}

/// Largest move of any vertex or control point between two designs of the same combinatorics.
double designDistance(const CompositeDesign& a, const CompositeDesign& b) {
  double m = (a.vertices - b.vertices).rowwise().norm().maxCoeff();
  for (std::size_t e = 0; e < a.edges.size(); ++e)
    if (a.edges[e].curve.points.rows() > 0)
      m = std::max(m, (a.edges[e].curve.points - b.edges[e].curve.points).rowwise().norm().maxCoeff());
  return m;
}

/// Moves every vertex and control point by a smooth random displacement field of space,
/// δ(p) = Σ_k a_k sin(⟨w_k, p⟩ + φ_k) (three modes, wavelengths between the design's size and half
/// of it; deterministic seed), scaled so that the largest move is exactly `fraction`·size. A
/// field of space moves a vertex and the curve ends at it alike and keeps the curves smooth (a
/// designer's drag, not white noise on the control polygon).
///
/// Held points move too and are then held where the field put them. Moving only the free ones
/// is not a smooth perturbation: next to a held curve end the first control-point leg of the
/// 16-span fit is 0.027 long, shorter than 1% of the size (0.03), and moving the second control
/// point but not the first reversed c′ near the end (a cusp that no fold can follow; measured:
/// 16-span fits then ended between 1e-6 and 5e-3 after 20 iterations).
CompositeDesign perturbed(CompositeDesign d, double fraction, unsigned seed) {
  const double size = designSize(d);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  struct Mode {
    Eigen::Vector3d amplitude, wave;
    double phase;
  };
  std::vector<Mode> modes;
  for (int k = 0; k < 3; ++k) {
    Mode m;
    m.amplitude = Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    m.wave = Eigen::Vector3d(unit(rng), unit(rng), unit(rng)).normalized() * (2.0 * M_PI / size) * (1.0 + 0.5 * (k + unit(rng)));
    m.phase = M_PI * unit(rng);
    modes.push_back(m);
  }
  auto field = [&modes](const Eigen::RowVector3d& p) {
    Eigen::Vector3d v = Eigen::Vector3d::Zero();
    for (const Mode& m : modes) v += m.amplitude * std::sin(m.wave.dot(p.transpose()) + m.phase);
    return Eigen::RowVector3d(v.transpose());
  };
  double largest = 0.0;
  Eigen::MatrixX3d vertexMove = Eigen::MatrixX3d::Zero(d.vertices.rows(), 3);
  for (int v = 0; v < d.vertices.rows(); ++v) {
    vertexMove.row(v) = field(d.vertices.row(v));
    largest = std::max(largest, vertexMove.row(v).norm());
  }
  std::vector<Eigen::MatrixXd> edgeMove(d.edges.size());
  for (std::size_t e = 0; e < d.edges.size(); ++e) {
    const Eigen::MatrixXd& p = d.edges[e].curve.points;
    edgeMove[e] = Eigen::MatrixXd::Zero(p.rows(), 3);
    for (Eigen::Index k = 1; k + 1 < p.rows(); ++k) {
      edgeMove[e].row(k) = field(p.row(k));
      largest = std::max(largest, edgeMove[e].row(k).norm());
    }
  }
  const double scale = fraction * size / largest;
  d.vertices += scale * vertexMove;
  for (std::size_t e = 0; e < d.edges.size(); ++e) {
    Eigen::MatrixXd& p = d.edges[e].curve.points;
    if (p.rows() == 0) continue;
    p += scale * edgeMove[e];
    p.row(0) = d.vertices.row(d.edges[e].v0);
    p.row(p.rows() - 1) = d.vertices.row(d.edges[e].v1);
  }
  return d;
}

struct Residuals {
  CompositeQuality quality;
  std::map<std::string, double> terms;
};

Residuals measure(CompositeModel& model, const std::string& label) {
  Residuals r{model.quality(), termResidualMax(model)};
  std::cout << label << ": crease_fold_residual_max " << r.quality.creaseFoldResidualMax << ", warp_angle_max_deg "
            << r.quality.warpAngleMaxDeg << ", face_flatness_max " << r.quality.faceFlatnessMax
            << ", vertex_curvature_max " << r.quality.vertexCurvatureMax << "; term |r| max:";
  for (const auto& [name, value] : r.terms) std::cout << " " << name << " " << value;
  std::cout << "\n";
  return r;
}

/// The two folds, each with the crease's ends and one far corner of the first sheet held (no
/// rigid motion left).
CompositeDesign heldPlanarFold() {
  CompositeDesign d = planarFoldDesign();
  d.fixed = {PointRef::ofVertex(0), PointRef::ofVertex(1), PointRef::ofVertex(3)};
  return d;
}

CompositeDesign heldCylinderCrease(const ClosedFormFit& fit) {
  CompositeDesign d = cylinderCatenaryCreaseDesign(defaultCylinderCatenaryCrease(), fit);
  d.fixed = {PointRef::ofVertex(0), PointRef::ofVertex(1), PointRef::ofVertex(3)};
  return d;
}

/// The fit of the exactness test: degree 7, 16 spans (hard rows ≈ 3.5e-10, see the table test).
ClosedFormFit fineFit() {
  ClosedFormFit fit;
  fit.degree = 7;
  fit.spans = 16;
  return fit;
}

/// 20 iterations without fairness: 5 with ε_reg = 0.03 (robust far from the solution), then 15
/// with ε_reg = 1e-3 (close to Gauss–Newton near it). Measured on the 16-span cylinder crease,
/// 100 seeds: this schedule brings all of them below 5e-7; 10 + 10 leaves one at 1.6e-6 (the
/// crease ends creep back at ~10% per iteration once ε_reg is small); 20 at the default
/// ε_reg = 0.01 stall at 1e-6…1e-5; 1e-3 from the start is not robust.
int recover(CompositeModel& model) {
  engine::SolverOptions o = iterationsWithoutFairness(5);
  o.regularization = 0.03;
  int steps = model.solve(o).stepsTaken();
  o.maxIterations = 15;
  o.regularization = 1e-3;
  steps += model.solve(o).stepsTaken();
  return steps;
}

TEST(ClosedFormCrease, PlanarFoldByReflectionIsExactAtRoundOff) {
  const CompositeDesign in = heldPlanarFold();
  CompositeModel model(in);
  const Residuals r = measure(model, "planar fold");
  EXPECT_LT(r.quality.creaseFoldResidualMax, 1e-12);
  EXPECT_LT(r.quality.warpAngleMaxDeg, 1e-9);
  EXPECT_LT(r.quality.faceFlatnessMax, 1e-12);  // both sheets are cylinders: sampled quads are planar
  EXPECT_LT(r.quality.vertexCurvatureMax, 1e-12);
  EXPECT_GT(r.quality.foldAngleMaxDeg, 30.0);  // it is folded
  EXPECT_LT(hardResidualMax(r.terms), 1e-12);
  // An exact solution stays put.
  model.solve(iterationsWithoutFairness(20));
  EXPECT_LT(hardResidualMax(termResidualMax(model)), 1e-12);
  EXPECT_LT(designDistance(in, model.design()), 1e-12);
}

TEST(ClosedFormCrease, PlanarFoldRecoversAfterAOnePercentPerturbation) {
  const CompositeDesign start = perturbed(heldPlanarFold(), 0.01, 2016);
  CompositeModel model(start);
  const Residuals before = measure(model, "planar fold, perturbed by 1%");
  EXPECT_GT(hardResidualMax(before.terms), 1e-3);
  const int iterations = recover(model);
  EXPECT_EQ(iterations, 20);
  const Residuals after = measure(model, "planar fold, 20 iterations later");
  EXPECT_LE(after.terms.at("developability"), 1e-10);
  EXPECT_LE(after.terms.at("crease_fold"), 1e-10);
  EXPECT_LE(after.quality.creaseFoldResidualMax, 1e-9);
  EXPECT_LE(after.quality.warpAngleMaxDeg, 1e-7);
  EXPECT_LE(after.quality.faceFlatnessMax, 1e-9);  // still two cylinders
  EXPECT_GT(designDistance(start, model.design()), 1e-3);  // it did move
}

TEST(ClosedFormCrease, CylinderCatenaryResidualsFallWithTheNumberOfSpans) {
  const creases::CylinderCatenaryCrease crease = defaultCylinderCatenaryCrease();
  for (int degree : {3, 5, 7}) {
    double previousFit = 1e300, previousRows = 1e300;
    for (int spans : {2, 4, 8, 16, 32}) {
      ClosedFormFit fit;
      fit.degree = degree;
      fit.spans = spans;
      const CompositeDesign d = cylinderCatenaryCreaseDesign(crease, fit);
      CompositeModel model(d);
      const CompositeQuality q = model.quality();
      const std::map<std::string, double> t = termResidualMax(model);
      const double fitError = cylinderCatenaryFitError(crease, d);
      std::cout << "degree " << degree << ", " << spans << " spans: fit " << fitError << ", developability rows "
                << t.at("developability") << ", crease_fold rows " << t.at("crease_fold") << ", crease_fold_residual_max "
                << q.creaseFoldResidualMax << ", warp_angle_max_deg " << q.warpAngleMaxDeg << ", face_flatness_max "
                << q.faceFlatnessMax << "\n";
      EXPECT_LT(fitError, previousFit) << degree << " " << spans;
      if (fitError > 1e-12) {
        EXPECT_LT(hardResidualMax(t), previousRows) << degree << " " << spans;
      }
      previousFit = fitError;
      previousRows = hardResidualMax(t);
    }
  }
}

TEST(ClosedFormCrease, CylinderCatenaryCreaseIsExactToTheFit) {
  const creases::CylinderCatenaryCrease crease = defaultCylinderCatenaryCrease();
  CompositeModel model(heldCylinderCrease(fineFit()));
  const Residuals r = measure(model, "cylinder crease, degree 7, 16 spans");
  EXPECT_LT(cylinderCatenaryFitError(crease, model.design()), 1e-10);
  EXPECT_LT(hardResidualMax(r.terms), 1e-9);
  EXPECT_LT(r.quality.creaseFoldResidualMax, 1e-9);
  EXPECT_LT(r.quality.warpAngleMaxDeg, 1e-6);
  // The second sheet is neither a cylinder nor a cone: its sampled quads are planar only to
  // O(h²) (10 samples per span), unlike the exact per-ruling warp above.
  EXPECT_LT(r.quality.faceFlatnessMax, 1e-5);
  EXPECT_GT(r.quality.foldAngleMaxDeg, 30.0);
}

TEST(ClosedFormCrease, CylinderCatenaryCreaseProjectsToRoundOffWithoutLeavingTheClosedForm) {
  // The fit's rows are limited by the fit itself (16 spans: 3.5e-10 and 5 iterations leave them
  // there; 32 spans: 1e-10). Five Gauss–Newton iterations from the 32-span fit reach the
  // composite's own exact solution: rows at round-off (measured 2.2e-12) while the design moves
  // by 3e-9 and stays on the closed form to 2.5e-9.
  ClosedFormFit fit;
  fit.degree = 7;
  fit.spans = 32;
  const CompositeDesign in = heldCylinderCrease(fit);
  CompositeModel model(in);
  EXPECT_GT(hardResidualMax(termResidualMax(model)), 1e-11);  // the fit alone is not there
  engine::SolverOptions o = iterationsWithoutFairness(5);
  o.regularization = 1e-3;
  model.solve(o);
  const Residuals r = measure(model, "cylinder crease, degree 7, 32 spans, 5 iterations");
  EXPECT_LT(hardResidualMax(r.terms), 1e-11);
  EXPECT_LT(r.quality.creaseFoldResidualMax, 1e-11);
  EXPECT_LT(r.quality.warpAngleMaxDeg * M_PI / 180.0, 1e-11);
  EXPECT_LT(designDistance(in, model.design()), 1e-8);
  EXPECT_LT(cylinderCatenaryFitError(defaultCylinderCatenaryCrease(), model.design()), 1e-8);
}

/// The cylinder crease fitted with `spans` spans of degree 7, perturbed by 1% (seeds 1…10), and
/// 20 iterations later.
class CylinderCreaseRecovery : public ::testing::TestWithParam<int> {};

TEST_P(CylinderCreaseRecovery, TwentyIterationsBringEveryResidualBelowOneInAMillion) {
  ClosedFormFit fit;
  fit.degree = 7;
  fit.spans = GetParam();
  for (unsigned seed = 1; seed <= 10; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const CompositeDesign start = perturbed(heldCylinderCrease(fit), 0.01, seed);
    CompositeModel model(start);
    const Residuals before = measure(model, "cylinder crease (" + std::to_string(fit.spans) + " spans, seed " +
                                                std::to_string(seed) + "), perturbed by 1%");
    EXPECT_GT(hardResidualMax(before.terms), 1e-2);
    EXPECT_EQ(recover(model), 20);
    const Residuals after = measure(model, "20 iterations later");
    EXPECT_LE(after.terms.at("developability"), 1e-6);
    EXPECT_LE(after.terms.at("crease_fold"), 1e-6);
    EXPECT_LE(after.terms.at("unit_normal_hard"), 1e-6);
    EXPECT_LE(after.quality.creaseFoldResidualMax, 1e-6);
    EXPECT_LE(after.quality.warpAngleMaxDeg * M_PI / 180.0, 1e-6);
    // It came back to a fold near the start, not to something else that satisfies the rows
    // (measured: at most 1.7% of the size away, folded by ~115°).
    const double moved = designDistance(start, model.design()) / designSize(start);
    EXPECT_GT(moved, 1e-4);
    EXPECT_LT(moved, 0.05);
    EXPECT_GT(after.quality.foldAngleMaxDeg, 90.0);
  }
}

INSTANTIATE_TEST_SUITE_P(ClosedFormCrease, CylinderCreaseRecovery, ::testing::Values(32, 16, 4),
                         [](const ::testing::TestParamInfo<int>& info) {
                           return std::to_string(info.param) + "Spans";
                         });

/// The preset examples/composite-cylinder-crease.json: the fine fit (degree 7, 16 spans), the
/// crease's ends and the cylinder sheet's far corner held, development management on.
proto::Scene cylinderCreasePreset() {
  proto::Scene scene;
  scene.name = "cylinder crease (catenary)";
  scene.summary = "A cylinder folded along a crease that keeps one angle all along; flat, the crease is a catenary.";
  scene.description =
      "Curved crease of constant angle 1 rad on the unit cylinder (Mundilova, Part I §3.1.3): the crease develops "
      "to a catenary; the second sheet reflects the cylinder's tangent planes in the crease's osculating planes. "
      "Closed form fitted with degree-7 B-splines, 16 spans (residuals ~1e-10). Written by "
      "DEVSURF_WRITE_PRESETS=1 test_composite --gtest_filter=ClosedFormCrease.CylinderCreasePresetIsTheBuilderOutput";
  CompositeDesign d = heldCylinderCrease(fineFit());
  d.developmentSamples = 4;
  scene.model = d;
  scene.solver.fairness = 0.0;  // an exact solution: nothing to smooth, it should stay put
  return scene;
}

TEST(ClosedFormCrease, CylinderCreasePresetIsTheBuilderOutput) {
  const nlohmann::json built = proto::sceneToJson(cylinderCreasePreset());
  const std::string path = std::string(DEVSURF_SOURCE_DIR) + "/examples/composite-cylinder-crease.json";
  if (std::getenv("DEVSURF_WRITE_PRESETS") != nullptr) {
    std::ofstream out(path);
    out << built.dump(2) << "\n";
  }
  std::ifstream file(path);
  ASSERT_TRUE(file.good()) << path;
  std::stringstream text;
  text << file.rdbuf();
  EXPECT_EQ(nlohmann::json::parse(text.str()), built) << "regenerate with DEVSURF_WRITE_PRESETS=1";
}

TEST(CompositePresets, CylinderCatenaryCreaseMeetsThePaperQualityAfterTenIterations) {
  // As `devsurf solve examples/composite-cylinder-crease.json --iterations 10` does.
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/composite-cylinder-crease.json");
  std::stringstream text;
  text << file.rdbuf();
  const proto::Scene scene = proto::sceneFromText(text.str());
  CompositeModel model(std::get<CompositeDesign>(scene.model), scene.solver.compositeOptions());
  ASSERT_TRUE(model.hasDevelopment());
  engine::SolverOptions o = scene.solver.solverOptions();
  o.maxIterations = 10;
  model.solve(o);
  const CompositeQuality q = model.quality();
  const double lengthError = model.developmentLengthError();
  std::cout << "composite-cylinder-crease.json: face_flatness_max " << q.faceFlatnessMax << ", face_flatness_mean "
            << q.faceFlatnessMean << ", vertex_curvature_max " << q.vertexCurvatureMax << ", development_length_error "
            << lengthError << ", crease_fold_residual_max " << q.creaseFoldResidualMax << ", fold angle max "
            << q.foldAngleMaxDeg << " deg\n";
  EXPECT_LE(q.faceFlatnessMax, 1e-3);
  EXPECT_LE(q.faceFlatnessMean, 2e-4);
  EXPECT_LE(q.vertexCurvatureMax, 1e-3);
  EXPECT_LE(lengthError, 0.005);
  EXPECT_LT(q.creaseFoldResidualMax, 1e-8);
  EXPECT_GT(q.foldAngleMaxDeg, 30.0);
}

}  // namespace
}  // namespace devsurf::models::composite

