#include "devsurf/models/quasi_strip/QuasiStripModel.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include <Eigen/Eigenvalues>

#include "devsurf/metrics/StripQuality.h"
#include "devsurf/models/CurvePairWidth.h"
#include "devsurf/terms/MappingDevelopabilityTerm.h"
#include "devsurf/terms/MappingEndPointTerm.h"
#include "devsurf/terms/UnitNormalTerm.h"

namespace devsurf::models::quasi_strip {

const char* optimizerName(Optimizer optimizer) {
  return optimizer == Optimizer::GuidedProjection ? "guided_projection" : "lbfgs";
}

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

void validateCurve(const spline::BSplineCurve& c, const std::string& name) {
  try {
    c.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(name + ": " + e.what());
  }
  if (c.isRational()) throw std::invalid_argument(name + ".weights: rational curves are not supported");
  if (c.knots.kind() != spline::KnotKind::Clamped) {
    throw std::invalid_argument(name + ".knots: only clamped (open) curves are supported");
  }
  if (c.dimension() != 3) {
    throw std::invalid_argument(name + ".points: expected 3 coordinates per control point");
  }
}

void requireNonNegative(double v, const std::string& name) {
  if (!(std::isfinite(v) && v >= 0.0)) throw std::invalid_argument(name + ": must be a finite number >= 0");
}

/// Σ w²‖r‖² and its gradient over all terms of a problem (the objective eq. 9 in the form the
/// engine minimizes), for L-BFGS.
class ProblemObjective {
 public:
  explicit ProblemObjective(engine::Problem& problem) : problem_(problem) {
    for (int id = 0; id < problem.numTerms(); ++id) {
      std::vector<engine::JacobianEntry> entries;
      problem.term(id).term->jacobianStructure(entries);
      structures_.push_back(std::move(entries));
      residuals_.emplace_back(problem.term(id).term->numResiduals());
      jacobians_.emplace_back(structures_.back().size());
    }
  }

  double operator()(const Eigen::VectorXd& x, Eigen::VectorXd& gradient) {
    gradient.setZero();
    double value = 0.0;
    for (int id = 0; id < problem_.numTerms(); ++id) {
      engine::TermSlot& slot = problem_.term(id);
      slot.term->linearizeAt(x);
      slot.term->evaluate(x, residuals_[id].data(), jacobians_[id].data());
      const double w2 = slot.weight * slot.weight;
      value += w2 * residuals_[id].squaredNorm();
      const std::vector<engine::JacobianEntry>& entries = structures_[id];
      for (size_t e = 0; e < entries.size(); ++e) {
        gradient[entries[e].variable] += 2.0 * w2 * residuals_[id][entries[e].row] * jacobians_[id][e];
      }
    }
    return value;
  }

 private:
  engine::Problem& problem_;
  std::vector<std::vector<engine::JacobianEntry>> structures_;
  std::vector<Eigen::VectorXd> residuals_, jacobians_;
};

/// Arc length of an extended curve between parameters a and b (either order; beyond the domain
/// the end polynomial is continued): 5-point Gauss–Legendre on 32 equal pieces.
double arcLength(const terms::ExtendedCurve& curve, double a, double b) {
  static const double nodes[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831,
                                  0.9061798459386640};
  static const double weights[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889,
                                    0.4786286704993665, 0.2369268850561891};
  if (a > b) std::swap(a, b);
  const int pieces = 32;
  const double h = (b - a) / pieces;
  double length = 0.0;
  for (int k = 0; k < pieces; ++k) {
    const double mid = a + (k + 0.5) * h;
    for (int q = 0; q < 5; ++q) length += weights[q] * 0.5 * h * curve.evaluate(mid + 0.5 * h * nodes[q]).d1.norm();
  }
  return length;
}

}  // namespace

/// A state solve() may return: the extension it was solved with and the problem's x.
struct QuasiStripModel::Candidate {
  int round = 0;            ///< 0 = the initial mapping, k = the result of round k
  std::string termination;  ///< the optimizer's reason (empty for the initial mapping)
  bool converged = false;
  bool polished = true;     ///< false: the L-BFGS state before the guided-projection polish
  int iterate = -1;         ///< ≥ 0: an L-BFGS iterate before the optimizer stopped (not converged)
  bool fixedEndPoints = false;  ///< solved with end-point fixing (the design's, or the retry's)
  CurveExtension extension;
  Eigen::VectorXd x;
  double warpMaxDense = 0.0;  ///< the score: largest warp over the dense rulings
  /// How far the strip's end rulings are from C2's ends along C2 (past its end or short of its
  /// ends; fraction of C2's domain or arc length)
  double reach = 0.0;
  bool finite = false;        ///< σ, the normals and the warp are finite
  bool eligible = false;      ///< finite and reach ≤ extension.maxLength
};

/// Everything rebuilt per extension round: working curves (normalized, extended, on [0,1]), the
/// problem and the engine.
struct QuasiStripModel::Working {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double scale = 1.0;
  spline::BSplineCurve compatible1, compatible2;  ///< design curves after §4 (design coordinates)
  double t0 = 0, t1 = 1, T0 = 0, T1 = 1;          ///< extended domains in the design parameters
  spline::BSplineCurve w1, w2;                    ///< working curves
  std::shared_ptr<const terms::ExtendedCurve> e1, e2;
  double length1 = 1.0, length2 = 1.0;            ///< arc lengths of C1, C2 over their design domains
  std::vector<double> samples;                    ///< working t_i
  spline::KnotVector mappingKnots;                ///< B-spline method
  engine::Problem problem;
  int shapeBlock = -1, normalBlock = -1;
  std::unique_ptr<engine::GuidedProjectionSolver> engine;

  Eigen::Vector3d toDesign(const Eigen::Vector3d& p) const { return p * scale + centre; }
};

QuasiStripModel::QuasiStripModel(QuasiStripDesign design, QuasiStripOptions options)
    : design_(std::move(design)), options_(std::move(options)) {
  validateCurve(design_.c1, "c1");
  validateCurve(design_.c2, "c2");
  requireCurvePairWidth(design_.c1, design_.c2, "c1", "c2");
  if (design_.mapping.degree < 1) throw std::invalid_argument("mapping.degree: must be >= 1");
  if (design_.mapping.coefficients < design_.mapping.degree + 1) {
    throw std::invalid_argument("mapping.coefficients: must be >= mapping.degree + 1");
  }
  if (design_.samples < 2) throw std::invalid_argument("samples: must be >= 2");
  if (!(std::isfinite(design_.endPoints.weight) && design_.endPoints.weight > 0.0)) {
    throw std::invalid_argument("endPoints.weight: must be a finite number > 0");
  }
  const CurveExtension& x = design_.extension;
  requireNonNegative(x.c1Begin, "extension.c1Begin");
  requireNonNegative(x.c1End, "extension.c1End");
  requireNonNegative(x.c2Begin, "extension.c2Begin");
  requireNonNegative(x.c2End, "extension.c2End");
  requireNonNegative(x.tolerance, "extension.tolerance");
  requireNonNegative(x.maxLength, "extension.maxLength");
  if (x.maxRounds < 0) throw std::invalid_argument("extension.maxRounds: must be >= 0");
  if (!(options_.lambda1 > 0.0) || !(options_.lambda2 > 0.0)) {
    throw std::invalid_argument("options.lambda1/lambda2: must be > 0");
  }
  extension_ = design_.extension;
  build();
  computeResults();
}

QuasiStripModel::~QuasiStripModel() = default;

int QuasiStripModel::numUnknowns() const { return working_->problem.layout().numFree(); }

void QuasiStripModel::build() {
  auto w = std::make_unique<Working>();
  // §4: one degree and one knot vector where the domains agree.
  const bool sameDomain =
      std::abs(design_.c1.knots.domainBegin() - design_.c2.knots.domainBegin()) <= 1e-12 &&
      std::abs(design_.c1.knots.domainEnd() - design_.c2.knots.domainEnd()) <= 1e-12;
  if (sameDomain) {
    std::tie(w->compatible1, w->compatible2) = makeCompatible(design_.c1, design_.c2);
  } else {
    w->compatible1 = design_.c1;
    w->compatible2 = design_.c2;
  }
  // Unit box: centre of the control points' bounding box, scaled by its largest side.
  Eigen::MatrixXd all(design_.c1.points.rows() + design_.c2.points.rows(), 3);
  all << design_.c1.points, design_.c2.points;
  const Eigen::Vector3d lo = all.colwise().minCoeff().transpose(), hi = all.colwise().maxCoeff().transpose();
  w->centre = 0.5 * (lo + hi);
  w->scale = (hi - lo).maxCoeff() > 0.0 ? (hi - lo).maxCoeff() : 1.0;

  auto working = [&w](const spline::BSplineCurve& c, double begin, double end, double& a, double& b) {
    const double u0 = c.knots.domainBegin(), u1 = c.knots.domainEnd(), len = u1 - u0;
    spline::BSplineCurve n = c;
    for (int i = 0; i < n.points.rows(); ++i)
      n.points.row(i) = (n.points.row(i) - w->centre.transpose()) / w->scale;
    a = u0 - begin * len;
    b = u1 + end * len;
    return reparametrizeToUnit(extendCurve(n, begin * len, end * len));
  };
  w->w1 = working(w->compatible1, extension_.c1Begin, extension_.c1End, w->t0, w->t1);
  w->w2 = working(w->compatible2, extension_.c2Begin, extension_.c2End, w->T0, w->T1);
  w->e1 = std::make_shared<const terms::ExtendedCurve>(w->w1);
  w->e2 = std::make_shared<const terms::ExtendedCurve>(w->w2);
  w->length1 = arcLength(*w->e1, (design_.c1.knots.domainBegin() - w->t0) / (w->t1 - w->t0),
                         (design_.c1.knots.domainEnd() - w->t0) / (w->t1 - w->t0));
  w->length2 = arcLength(*w->e2, (design_.c2.knots.domainBegin() - w->T0) / (w->T1 - w->T0),
                         (design_.c2.knots.domainEnd() - w->T0) / (w->T1 - w->T0));

  const int K = design_.samples;
  for (int i = 0; i < K; ++i) w->samples.push_back(static_cast<double>(i) / (K - 1));

  // Shape parameters and their tail sums S (σ_i = Σ_k S(i,k) ε_k²), initialized to T = t.
  spline::EvaluationMatrix tails;
  Eigen::VectorXd shape;
  if (options_.method == MappingMethod::BSpline) {
    w->mappingKnots = spline::KnotVector::clampedUniform(design_.mapping.degree, design_.mapping.coefficients);
    tails = tailSumMatrix(w->mappingKnots, w->samples);
    shape = shapeParameters(identityCoefficients(w->mappingKnots));
  } else {
    std::vector<Eigen::Triplet<double>> entries;
    for (int i = 0; i < K; ++i)
      for (int k = 0; k <= i; ++k) entries.emplace_back(i, k, 1.0);
    tails.resize(K, K);
    tails.setFromTriplets(entries.begin(), entries.end());
    tails.makeCompressed();
    shape = shapeParameters(Eigen::Map<const Eigen::VectorXd>(w->samples.data(), K));
  }

  engine::Problem& problem = w->problem;
  w->shapeBlock = problem.addBlock("mapping shape", static_cast<int>(shape.size()));
  w->normalBlock = problem.addBlock("normals", 3 * K);
  problem.layout().setEliminable(w->normalBlock, 3);
  problem.layout().setRegularizationScale(w->normalBlock, options_.normalRegularizationScale);
  problem.blockValues(w->shapeBlock) = shape;

  const int shapeOffset = problem.layout().block(w->shapeBlock).offset;
  const int normalOffset = problem.layout().block(w->normalBlock).offset;
  Eigen::MatrixX3d points(K, 3), tangents(K, 3);
  std::vector<int> normalOffsets;
  for (int i = 0; i < K; ++i) {
    if (i % 256 == 0) options_.deadline.check();
    const terms::CurveJet a = w->e1->evaluate(w->samples[i]);
    points.row(i) = a.point.transpose();
    tangents.row(i) = a.d1.transpose();
    normalOffsets.push_back(normalOffset + 3 * i);
    // N_i: the unit vector closest to orthogonal to C1′, C2′ and the ruling at T = t.
    const terms::CurveJet b = w->e2->evaluate(w->samples[i]);
    const Eigen::Vector3d ruling = a.point - b.point;
    const Eigen::Matrix3d m = a.d1 * a.d1.transpose() + b.d1 * b.d1.transpose() + ruling * ruling.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(m);
    problem.x().segment<3>(normalOffset + 3 * i) = eig.eigenvectors().col(0).normalized();
  }
  auto development = std::make_unique<terms::MappingDevelopabilityTerm>(
      "developability", shapeOffset, tails, normalOffsets, points, tangents, w->e2);
  problem.addTerm(std::move(development), std::sqrt(options_.lambda1), engine::Strength::Soft);
  problem.addTerm(std::make_unique<terms::UnitNormalTerm>("unit_normal", normalOffsets),
                  std::sqrt(options_.lambda2), engine::Strength::Soft);
  if (design_.endPoints.enabled || fixEndPoints_) {
    // Targets: C2's own end points (its design domain, in working parameters).
    const double len2 = w->T1 - w->T0;
    const double begin2 = (design_.c2.knots.domainBegin() - w->T0) / len2;
    const double end2 = (design_.c2.knots.domainEnd() - w->T0) / len2;
    for (int e = 0; e < 2; ++e) {
      const int sample = e == 0 ? 0 : K - 1;
      std::vector<std::pair<int, double>> weights;
      for (spline::EvaluationMatrix::InnerIterator it(tails, sample); it; ++it)
        weights.emplace_back(static_cast<int>(it.col()), it.value());
      problem.addTerm(std::make_unique<terms::MappingEndPointTerm>(
                          "end_point", shapeOffset, weights, w->e2,
                          w->e2->evaluate(e == 0 ? begin2 : end2).point),
                      std::sqrt(design_.endPoints.weight), engine::Strength::Soft);
    }
  }
  options_.deadline.check();
  if (options_.optimizer == Optimizer::GuidedProjection || options_.polishIterations > 0)
    w->engine = std::make_unique<engine::GuidedProjectionSolver>(problem);
  working_ = std::move(w);
}

namespace {

/// The working mapping (parameters [0,1] of the working curves) from the shape parameters.
Mapping workingMapping(MappingMethod method, const spline::KnotVector& knots, int degree,
                       const std::vector<double>& samples, const Eigen::VectorXd& shape) {
  Mapping m;
  m.coefficients = mappingCoefficients(shape);
  if (method == MappingMethod::BSpline) {
    m.degree = degree;
    m.knots = knots.knots();
  } else {
    // Piecewise-linear interpolation of (t_i, T_i) (monotone).
    m.degree = 1;
    m.knots = {samples.front()};
    m.knots.insert(m.knots.end(), samples.begin(), samples.end());
    m.knots.push_back(samples.back());
  }
  return m;
}

/// Warp angle (metrics::warpAngleDeg) of the working ruling C1(t)–C2(σ(t)).
double warpAtDeg(const terms::ExtendedCurve& e1, const terms::ExtendedCurve& e2, const spline::BSplineCurve& sigma,
                 double t) {
  const terms::CurveJet a = e1.evaluate(t);
  const terms::CurveJet b = e2.evaluate(sigma.evaluate(t)[0]);
  return metrics::warpAngleDeg(a.point, a.d1, b.point, b.d1);
}

/// Largest and mean warp over `rulings` rulings equally spaced over the working domain [0, 1].
std::pair<double, double> denseWarpDeg(const terms::ExtendedCurve& e1, const terms::ExtendedCurve& e2,
                                       const spline::BSplineCurve& sigma, int rulings,
                                       const engine::Deadline& deadline) {
  const int n = std::max(2, rulings);
  double worst = 0.0, sum = 0.0;
  for (int i = 0; i < n; ++i) {
    if (i % 256 == 0) deadline.check();
    const double warp = warpAtDeg(e1, e2, sigma, static_cast<double>(i) / (n - 1));
    // A NaN warp makes the state unusable: keep it visible to the caller.
    if (!(warp <= worst)) worst = warp;
    sum += warp;
  }
  return {worst, sum / n};
}

}  // namespace

double QuasiStripModel::guidedProjectionSteps(int round, QuasiStripSummary& summary, int maxIterations,
                                              bool recordStart, std::chrono::steady_clock::time_point start) {
  Working& w = *working_;
  // Guided projection one step at a time with Levenberg–Marquardt control of ε_reg: a step
  // that raises eq. 9 (or diverges) is undone and retried with 10× ε_reg; an accepted one lets
  // ε_reg fall back by 3× towards options.regularization. (The engine itself has no line
  // search; without this a strongly twisted start overshoots σ far out of C2's domain.)
  engine::SolverOptions o;
  o.maxIterations = 1;
  o.fairness = 0.0;
  o.residualTolerance = options_.residualTolerance;
  o.relativeChangeTolerance = 0.0;
  double regularization = options_.regularization;
  Eigen::VectorXd saved;
  double objective = 0.0;
  summary.termination = engine::terminationReasonName(engine::TerminationReason::MaxIterations);
  summary.converged = false;
  int accepted = 0;
  o.deadline = options_.deadline;
  for (int k = 0; k < maxIterations; ++k) {
    options_.deadline.check();
    if (options_.timeBudgetMs > 0.0 && msSince(start) > options_.timeBudgetMs) {
      summary.termination = engine::terminationReasonName(engine::TerminationReason::TimeBudget);
      break;
    }
    saved = w.problem.x();
    o.regularization = regularization;
    const engine::SolveSummary s = w.engine->solve(o);
    const double before = s.iterations.front().objective;
    if (k == 0) {
      objective = before;
      if (recordStart) summary.iterations.push_back({0, before, 0.0, 0.0, msSince(start), round});
    }
    if (s.reason == engine::TerminationReason::ResidualTolerance && s.stepsTaken() == 0) {
      summary.termination = engine::terminationReasonName(s.reason);
      summary.converged = true;
      break;
    }
    const double after = s.iterations.back().objective;
    // Fraction to the boundary: a step may not shrink a shape parameter |ε_k| below a tenth
    // of its value. At ε_k = 0 the derivative 2ε_k(…) vanishes and σ′ stays 0 there for good;
    // full Gauss–Newton steps on a twisted start drove whole runs of ε to 0 (σ flat over
    // t ∈ [0.4, 0.55], 8° left).
    bool collapses = false;
    {
      const auto shapeNew = w.problem.blockValues(w.shapeBlock);
      const int offset = w.problem.layout().block(w.shapeBlock).offset;
      for (Eigen::Index k = 0; k < shapeNew.size() && !collapses; ++k)
        collapses = std::abs(shapeNew[k]) < 0.1 * std::abs(saved[offset + k]);
    }
    if (collapses || s.reason == engine::TerminationReason::Diverged || !(after < before)) {
      w.problem.x() = saved;
      regularization *= 10.0;
      if (regularization > 1e8) {
        summary.termination = "step_rejected";
        summary.converged = true;  // no step of any length decreases eq. 9: a local minimum
        break;
      }
      continue;
    }
    regularization = std::max(options_.regularization, regularization / 3.0);
    objective = after;
    summary.iterations.push_back(
        {++accepted, after, s.iterations.back().stepNorm, 0.0, msSince(start), round});
    if (after <= options_.residualTolerance) {
      summary.termination = engine::terminationReasonName(engine::TerminationReason::ResidualTolerance);
      summary.converged = true;
      break;
    }
    if (before - after <= options_.relativeChangeTolerance * before) {
      summary.termination = engine::terminationReasonName(engine::TerminationReason::RelativeChange);
      summary.converged = true;
      break;
    }
  }
  return objective;
}

void QuasiStripModel::solveRound(int round, QuasiStripSummary& summary, std::vector<Candidate>& candidates) {
  Working& w = *working_;
  const auto start = Clock::now();
  if (options_.optimizer == Optimizer::GuidedProjection) {
    guidedProjectionSteps(round, summary, options_.maxIterations, true, start);
    candidates.push_back(capture(round + 1, summary.termination, summary.converged));
    return;
  }
  ProblemObjective objective(w.problem);
  Eigen::VectorXd gradient(w.problem.x().size());
  const double f0 = objective(w.problem.x(), gradient);
  summary.iterations.push_back({0, f0, 0.0, gradient.cwiseAbs().maxCoeff(), msSince(start), round});
  LbfgsOptions lo = options_.lbfgs;
  if (options_.timeBudgetMs > 0.0) lo.timeBudgetMs = options_.timeBudgetMs;
  Eigen::VectorXd x = w.problem.x();
  // Geometric stops: the largest and the mean warp angle over the sample rulings at x (what the
  // user sees).
  const engine::VariableBlock& shape = w.problem.layout().block(w.shapeBlock);
  auto sampleWarpDeg = [this, &w, &shape](const Eigen::VectorXd& v) {
    const Mapping m = workingMapping(options_.method, w.mappingKnots, design_.mapping.degree, w.samples,
                                     v.segment(shape.offset, shape.size));
    const spline::BSplineCurve sigma = m.curve();
    double worst = 0.0, sum = 0.0;
    for (double t : w.samples) {
      if (options_.deadline.expired()) break;  // (inside libLBFGS' callback: no throw; checked after it)
      const double warp = warpAtDeg(*w.e1, *w.e2, sigma, t);
      worst = std::max(worst, warp);
      sum += warp;
    }
    return std::make_pair(worst, sum / static_cast<double>(w.samples.size()));
  };
  bool warpReached = false, warpStalled = false;
  // The iterate with the smallest largest sample warp (checked every 10 iterations) is kept as a
  // fallback: eq. 9 sums over the samples and may keep falling while the worst ruling gets worse.
  std::pair<double, double> warp = sampleWarpDeg(x);
  double bestMax = warp.first, bestMean = warp.second;
  int bestIterate = 0;
  Eigen::VectorXd bestX = x;
  std::vector<std::pair<double, double>> progress{{bestMax, bestMean}};  // smallest so far, every 10 iterations
  const int stallChecks = options_.warpStallIterations / 10;
  const double keep = 1.0 - options_.warpStallDecrease;
  const LbfgsResult r = minimizeLbfgs(
      [&objective](const Eigen::VectorXd& v, Eigen::VectorXd& g) { return objective(v, g); }, x, lo,
      [&](int k, double f, double g) {
        // No exception may cross libLBFGS (C): stop here, throw below.
        if (options_.deadline.expired()) return false;
        summary.iterations.push_back({k, f, 0.0, g, msSince(start), round});
        if (k % 10 != 0) return true;
        warp = sampleWarpDeg(x);
        if (warp.first < bestMax) {
          bestMax = warp.first;
          bestIterate = k;
          bestX = x;
        }
        bestMean = std::min(bestMean, warp.second);
        progress.emplace_back(bestMax, bestMean);
        if (options_.warpToleranceDeg > 0.0 && warp.first <= options_.warpToleranceDeg) {
          warpReached = true;
          return false;
        }
        const int checks = static_cast<int>(progress.size()) - 1;
        if (stallChecks > 0 && checks >= stallChecks) {
          const std::pair<double, double>& before = progress[static_cast<std::size_t>(checks - stallChecks)];
          if (!(bestMax < keep * before.first) && !(bestMean < keep * before.second)) {
            warpStalled = true;
            return false;
          }
        }
        return true;
      });
  options_.deadline.check();
  summary.termination = warpReached ? "warp_tolerance" : warpStalled ? "warp_stalled" : lbfgsTerminationName(r.reason);
  summary.converged = warpReached || warpStalled || r.reason == LbfgsTermination::GradientTolerance ||
                      r.reason == LbfgsTermination::RelativeDecrease ||
                      r.reason == LbfgsTermination::AbsoluteTolerance;
  if (bestIterate > 0 && bestIterate < r.iterations) {
    w.problem.x() = bestX;
    candidates.push_back(capture(round + 1, summary.termination, false));
    candidates.back().iterate = bestIterate;
  }
  w.problem.x() = x;
  // The polish lowers eq. 9 but may raise the largest warp: the state before it is a candidate too.
  candidates.push_back(capture(round + 1, summary.termination, summary.converged));
  if (options_.polishIterations <= 0) return;
  candidates.back().polished = false;
  // Gauss–Newton converges quadratically once L-BFGS has brought σ near the solution.
  const std::string first = summary.termination;
  const bool firstConverged = summary.converged;
  guidedProjectionSteps(round, summary, options_.polishIterations, false, start);
  summary.termination = first + ", then guided projection: " + summary.termination;
  summary.converged = summary.converged || firstConverged;
  candidates.push_back(capture(round + 1, summary.termination, summary.converged));
}

QuasiStripModel::Candidate QuasiStripModel::capture(int round, std::string termination, bool converged) const {
  const Working& w = *working_;
  Candidate c;
  c.round = round;
  c.termination = std::move(termination);
  c.converged = converged;
  c.extension = extension_;
  c.fixedEndPoints = design_.endPoints.enabled || fixEndPoints_;
  c.x = w.problem.x();
  const Mapping m = workingMapping(options_.method, w.mappingKnots, design_.mapping.degree, w.samples,
                                   w.problem.blockValues(w.shapeBlock));
  c.warpMaxDense = denseWarpDeg(*w.e1, *w.e2, m.curve(), options_.denseRulings, options_.deadline).first;
  // How far the end rulings are from C2's ends along C2: past the working end (the design's end
  // plus its explicit extension; σ ≥ 0 keeps the begin), or short of the design's ends (beyond
  // extension.tolerance), as fractions of C2's domain or arc length, whichever is larger.
  const double len2 = design_.c2.knots.domainEnd() - design_.c2.knots.domainBegin();
  const double a2 = (design_.c2.knots.domainBegin() - w.T0) / (w.T1 - w.T0);
  const double b2 = (design_.c2.knots.domainEnd() - w.T0) / (w.T1 - w.T0);
  const double tol = extension_.tolerance * len2 / (w.T1 - w.T0);
  const double begin = m.evaluate(0.0), end = m.evaluate(1.0);
  auto along = [&](double from, double to) {
    return std::max((to - from) * (w.T1 - w.T0) / len2, arcLength(*w.e2, from, to) / w.length2);
  };
  if (std::isfinite(begin) && std::isfinite(end)) {
    if (end > 1.0) c.reach = std::max(c.reach, along(1.0, end));
    if (end < b2 - tol) c.reach = std::max(c.reach, along(end, b2 - tol));
    if (begin > a2 + tol) c.reach = std::max(c.reach, along(a2 + tol, begin));
  }
  c.finite = std::isfinite(c.warpMaxDense) && c.x.allFinite() && std::isfinite(begin) && std::isfinite(end);
  c.eligible = c.finite && c.reach <= extension_.maxLength;
  return c;
}

void QuasiStripModel::restore(const Candidate& c) {
  const CurveExtension& x = c.extension;
  const bool fix = c.fixedEndPoints && !design_.endPoints.enabled;
  if (x.c1Begin != extension_.c1Begin || x.c1End != extension_.c1End || x.c2Begin != extension_.c2Begin ||
      x.c2End != extension_.c2End || fix != fixEndPoints_) {
    extension_ = x;
    fixEndPoints_ = fix;
    build();
  }
  working_->problem.x() = c.x;
}

bool QuasiStripModel::extendForNextRound() {
  // Case 1 of §3.4: σ leaves an end part of C2 uncovered → extend C1 there, by 1.25× the missing
  // length estimated with σ′, at most extension.maxLength of C1's domain and arc length in all.
  const Working& w = *working_;
  const Mapping m = workingMapping(options_.method, w.mappingKnots, design_.mapping.degree,
                                   w.samples, w.problem.blockValues(w.shapeBlock));
  const double len1 = design_.c1.knots.domainEnd() - design_.c1.knots.domainBegin();
  const double len2 = design_.c2.knots.domainEnd() - design_.c2.knots.domainBegin();
  const double a2 = (design_.c2.knots.domainBegin() - w.T0) / (w.T1 - w.T0);
  const double b2 = (design_.c2.knots.domainEnd() - w.T0) / (w.T1 - w.T0);
  const double tol = extension_.tolerance * len2 / (w.T1 - w.T0);
  const double toC1Fraction = (w.t1 - w.t0) / len1;
  const double workingPerFraction = len1 / (w.t1 - w.t0);  // working parameter per fraction of C1's domain
  // The largest automatic fraction at one end: bisection on the arc length of the continuation
  // beyond the explicit extension (monotone in the fraction).
  auto cap = [&](double wanted, bool atEnd) {
    const double automatic = atEnd ? extension_.c1End - design_.extension.c1End
                                   : extension_.c1Begin - design_.extension.c1Begin;
    // The working domain [0, 1] includes the automatic part: measure from the explicit end.
    const double origin = atEnd ? 1.0 - automatic * workingPerFraction : automatic * workingPerFraction;
    const double limit = extension_.maxLength * w.length1;
    auto lengthOf = [&](double fraction) {
      const double reach = fraction * workingPerFraction;
      return arcLength(*w.e1, origin, atEnd ? origin + reach : origin - reach);
    };
    double total = std::min(automatic + wanted, extension_.maxLength);
    if (lengthOf(total) > limit) {
      double lo = automatic, hi = total;
      for (int k = 0; k < 50; ++k) {
        const double mid = 0.5 * (lo + hi);
        (lengthOf(mid) > limit ? hi : lo) = mid;
      }
      total = lo;
    }
    return std::max(0.0, total - automatic);
  };
  bool extended = false;
  const double missingEnd = b2 - m.evaluate(1.0);
  if (missingEnd > tol) {
    const double add = cap(1.25 * missingEnd / std::max(m.evaluate(1.0, 1), 1e-3) * toC1Fraction, true);
    if (add > extension_.tolerance) {
      extension_.c1End += add;
      extended = true;
    }
  }
  const double missingBegin = m.evaluate(0.0) - a2;
  if (missingBegin > tol) {
    const double add = cap(1.25 * missingBegin / std::max(m.evaluate(0.0, 1), 1e-3) * toC1Fraction, false);
    if (add > extension_.tolerance) {
      extension_.c1Begin += add;
      extended = true;
    }
  }
  return extended;
}

QuasiStripSummary QuasiStripModel::solve() {
  const auto start = Clock::now();
  if (!pristine_) {
    extension_ = design_.extension;
    fixEndPoints_ = false;
    build();
  }
  pristine_ = false;
  QuasiStripSummary summary;
  summary.optimizer = options_.optimizer;
  std::vector<Candidate> candidates{capture(0, "", false)};
  // A state may be returned if it reaches C2's ends within extension.maxLength and its largest
  // dense warp is no worse than the initial mapping's.
  const double initialWarp = candidates.front().warpMaxDense;
  auto acceptable = [initialWarp](const Candidate& c) { return c.eligible && c.warpMaxDense <= initialWarp; };
  // A round's result: its final state if acceptable, else its state before the polish, else its
  // best L-BFGS iterate (solveRound appends them in the reverse order); 0 = none.
  auto roundResult = [&candidates, &acceptable](std::size_t first) -> std::size_t {
    for (std::size_t k = candidates.size(); k-- > first;)
      if (acceptable(candidates[k])) return k;
    return 0;
  };
  std::size_t best = 0;
  for (int round = 1;; ++round) {
    options_.deadline.check();
    const std::size_t first = candidates.size();
    solveRound(round - 1, summary, candidates);
    summary.rounds = round;
    // An extension round is kept only if its result is no worse than the round before (up to
    // round-off; warps at or below options.warpToleranceDeg count as equal).
    const std::size_t result = roundResult(first);
    const bool improves =
        result != 0 && (best == 0 || candidates[result].warpMaxDense <=
                                         std::max(candidates[best].warpMaxDense * (1.0 + 1e-9), options_.warpToleranceDeg));
    if (improves) best = result;
    // Extend from an improving round, or from a first round whose strip only falls short of C2's
    // ends (what extension is for); never from a state worse than the initial mapping.
    const Candidate& final = candidates.back();
    const bool extendable = improves || (best == 0 && final.finite && final.warpMaxDense <= initialWarp);
    if (!extendable || !extension_.automatic || round > extension_.maxRounds) break;
    if (improves) restore(candidates[best]);
    if (!extendForNextRound()) break;
    build();
  }
  // No free round beat the start: once more with the end rulings pulled onto C2's end points
  // (§5.4) and the design's own extension. The strip then keeps the initial mapping's end rulings
  // and its reach, and the optimizer can only improve the rulings between them.
  if (best == 0 && options_.fixEndPointsRetry && !design_.endPoints.enabled) {
    extension_ = design_.extension;
    fixEndPoints_ = true;
    build();
    const std::size_t first = candidates.size();
    solveRound(summary.rounds, summary, candidates);
    ++summary.rounds;
    best = roundResult(first);
  }
  const Candidate& chosen = candidates[best];
  const Candidate& last = candidates.back();
  restore(chosen);
  summary.selectedRound = chosen.round;
  std::ostringstream why;
  why.precision(4);
  const bool retried = !design_.endPoints.enabled;
  auto name = [&why, retried](const Candidate& c) {
    why << "round " << c.round << (c.fixedEndPoints && retried ? " (end points fixed)" : "");
    if (c.iterate >= 0)
      why << ", L-BFGS iterate " << c.iterate;
    else if (!c.polished)
      why << ", before the guided-projection polish";
    why << " (" << c.termination << ")";
  };
  auto describe = [&why, this](const Candidate& c) {
    why << "largest warp over " << options_.denseRulings << " rulings " << c.warpMaxDense << "°";
    if (!c.eligible) {
      if (c.reach > extension_.maxLength)
        why << ", but its end rulings are " << c.reach << " of c2 from c2's ends (more than extension.maxLength)";
      else
        why << ", but it is not finite";
    }
  };
  if (chosen.round == 0) {
    summary.termination = kIdentityFallback;
    summary.converged = false;
    why << "the initial mapping, " ;
    describe(chosen);
    why << "; the last optimized state: ";
    name(last);
    why << ", ";
    describe(last);
  } else {
    summary.termination = chosen.termination;
    summary.converged = chosen.converged && chosen.iterate < 0;
    if (best + 1 == candidates.size()) {
      why << "last round";
    } else {
      name(chosen);
      why << ", ";
      describe(chosen);
      why << "; the last state: ";
      name(last);
      why << ", ";
      describe(last);
    }
  }
  summary.selection = why.str();
  computeResults();
  summary.totalMs = msSince(start);
  return summary;
}

Eigen::Vector3d QuasiStripModel::ruledSurfacePoint(double s, double t) const {
  const Working& w = *working_;
  const double tw = (t - w.t0) / (w.t1 - w.t0);
  const double Tw = (results_.mapping.evaluate(t) - w.T0) / (w.T1 - w.T0);
  const Eigen::Vector3d a = w.e1->evaluate(tw).point, b = w.e2->evaluate(Tw).point;
  return w.toDesign((1.0 - s) * a + s * b);
}

void QuasiStripModel::computeResults() {
  Working& w = *working_;
  QuasiStripResults r;
  const Mapping m = workingMapping(options_.method, w.mappingKnots, design_.mapping.degree,
                                   w.samples, w.problem.blockValues(w.shapeBlock));
  // Objective at the current x.
  {
    ProblemObjective objective(w.problem);
    Eigen::VectorXd g(w.problem.x().size());
    r.objective = objective(w.problem.x(), g);
  }
  const spline::BSplineCurve sigma = m.curve();
  const int K = static_cast<int>(w.samples.size());
  r.normals.resize(K, 3);
  const int normalOffset = w.problem.layout().block(w.normalBlock).offset;
  double sum = 0.0;
  for (int i = 0; i < K; ++i) {
    if (i % 256 == 0) options_.deadline.check();
    const double warp = warpAtDeg(*w.e1, *w.e2, sigma, w.samples[i]);
    r.sampleParameters.push_back(w.t0 + w.samples[i] * (w.t1 - w.t0));
    r.sampleWarpDeg.push_back(warp);
    r.warpAngleMaxDeg = std::max(r.warpAngleMaxDeg, warp);
    sum += warp;
    const Eigen::Vector3d n = w.problem.x().segment<3>(normalOffset + 3 * i);
    r.normals.row(i) = (n.norm() > 0 ? n.normalized() : n).transpose();
  }
  r.warpAngleMeanDeg = sum / K;
  std::tie(r.warpAngleMaxDegDense, r.warpAngleMeanDegDense) = denseWarpDeg(*w.e1, *w.e2, sigma, options_.denseRulings, options_.deadline);

  // σ in the design's parameters: t = t0 + t̃ (t1 − t0), T = T0 + T̃ (T1 − T0).
  r.mapping = m;
  for (double& k : r.mapping.knots) k = w.t0 + k * (w.t1 - w.t0);
  r.mapping.coefficients = (w.T0 + m.coefficients.array() * (w.T1 - w.T0)).matrix();
  r.extension = extension_;

  // Trim by end rulings: keep all of C1 and every t whose ruling ends on C2's design domain.
  const double a1 = (design_.c1.knots.domainBegin() - w.t0) / (w.t1 - w.t0);
  const double b1 = (design_.c1.knots.domainEnd() - w.t0) / (w.t1 - w.t0);
  const double a2 = (design_.c2.knots.domainBegin() - w.T0) / (w.T1 - w.T0);
  const double b2 = (design_.c2.knots.domainEnd() - w.T0) / (w.T1 - w.T0);
  const double trimBegin = std::min(a1, m.inverse(a2));
  double trimEnd = std::max(b1, m.inverse(b2));
  if (!(trimEnd > trimBegin)) trimEnd = 1.0;
  r.trimBegin = w.t0 + trimBegin * (w.t1 - w.t0);
  r.trimEnd = w.t0 + trimEnd * (w.t1 - w.t0);

  // Algorithm 1 on the working curves, then back to design parameters and coordinates.
  options_.deadline.check();
  r.surface = convertRuledSurface(w.w1, w.w2, m, trimBegin, trimEnd);
  for (double& k : r.surface.knots) k = w.t0 + k * (w.t1 - w.t0);
  for (int i = 0; i < r.surface.side0.rows(); ++i) {
    r.surface.side0.row(i) = w.toDesign(r.surface.side0.row(i).transpose()).transpose();
    r.surface.side1.row(i) = w.toDesign(r.surface.side1.row(i).transpose()).transpose();
  }
  results_ = std::move(r);
}

}  // namespace devsurf::models::quasi_strip
