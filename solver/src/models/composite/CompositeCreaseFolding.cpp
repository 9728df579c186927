// CompositeModel's fold-angle targets (the fold slider, issue 16 item 2): the soft "fold_angle"
// rows and what the session asks of them.

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/terms/HingeFoldAngleTerm.h"

namespace devsurf::models::composite {

namespace {
constexpr double kDegreesPerRadian = 57.29577951308232;
/// A hinge folded by less than this is flat to captureFoldTargets (the first fold's threshold).
constexpr double kFoldedHingeDeg = 0.5;
}  // namespace

void CompositeModel::addFoldAngleTerm() {
  hinges_ = foldHinges(*topology_, [this](const PointSlot& s) { return pointValue(s); });
  foldTargetHinge_.clear();
  foldTerm_ = -1;
  if (design_.foldAngles.empty()) return;
  std::vector<std::array<int, 4>> offsets;
  std::vector<double> targets;
  for (std::size_t i = 0; i < design_.foldAngles.size(); ++i) {
    const FoldAngleTarget& t = design_.foldAngles[i];
    int found = -1;
    for (std::size_t h = 0; h < hinges_.size() && found < 0; ++h)
      if (hinges_[h].edge == t.edge && hinges_[h].end == t.end) found = static_cast<int>(h);
    if (found < 0)
      throw std::invalid_argument("fold_angles[" + std::to_string(i) + "]: edge " + std::to_string(t.edge) +
                                  " has no hinge there (its faces are degenerate at that end)");
    foldTargetHinge_.push_back(found);
    const FoldHinge& h = hinges_[static_cast<std::size_t>(found)];
    offsets.push_back({3 * pointIndex(h.a), 3 * pointIndex(h.b), 3 * pointIndex(h.c), 3 * pointIndex(h.d)});
    targets.push_back(design_.foldAmount * t.angleDeg / kDegreesPerRadian);
  }
  foldTerm_ = problem_.addTerm(std::make_unique<terms::HingeFoldAngleTerm>("fold_angle", std::move(offsets), std::move(targets)),
                               options_.foldWeight, engine::Strength::Soft);
  // Like a handle: step control may shorten the pull, so a slider moved far in one message folds
  // the sheet over several steps instead of tearing it (GuidedProjectionSolver, StepControlOptions).
  problem_.term(foldTerm_).relaxable = true;
  problem_.term(foldTerm_).heldInProjection = true;  // the slider's position holds through a release
}

std::vector<CompositeModel::HingeAngle> CompositeModel::hingeAngles() const {
  std::vector<HingeAngle> angles;
  for (const FoldHinge& h : hinges_)
    angles.push_back({h.edge, h.end,
                      kDegreesPerRadian * terms::hingeFoldAngle(pointValue(h.a), pointValue(h.b), pointValue(h.c), pointValue(h.d))});
  return angles;
}

void CompositeModel::setFoldAmount(double amount) {
  if (!(amount >= 0.0 && amount <= 1.0)) throw std::invalid_argument("fold_amount: must lie in [0, 1]");
  design_.foldAmount = amount;
  if (foldTerm_ < 0) return;
  std::vector<double> targets;
  for (const FoldAngleTarget& t : design_.foldAngles) targets.push_back(amount * t.angleDeg / kDegreesPerRadian);
  static_cast<terms::HingeFoldAngleTerm*>(problem_.term(foldTerm_).term.get())->setTargets(targets);
}

bool CompositeModel::captureFoldTargets() {
  if (foldTerm_ < 0) return false;
  auto hingeAngleDeg = [this](std::size_t i) {
    const FoldHinge& h = hinges_[static_cast<std::size_t>(foldTargetHinge_[i])];
    return kDegreesPerRadian * terms::hingeFoldAngle(pointValue(h.a), pointValue(h.b), pointValue(h.c), pointValue(h.d));
  };
  bool changed = false;
  if (!(design_.foldAmount > 0.0)) {
    // A flat design (the slider at 0 %) that a drag folded: the slider moves to the amount the
    // drag folded, the hinge folded furthest toward its target setting it.
    double folded = 0.0;
    for (std::size_t i = 0; i < design_.foldAngles.size() && i < foldTargetHinge_.size(); ++i) {
      const double angle = hingeAngleDeg(i), target = design_.foldAngles[i].angleDeg;
      if (std::abs(angle) >= kFoldedHingeDeg && angle * target > 0.0) folded = std::max(folded, angle / target);
    }
    if (!(folded > 0.0)) return false;
    design_.foldAmount = std::min(1.0, folded);
    changed = true;
  }
  for (std::size_t i = 0; i < design_.foldAngles.size() && i < foldTargetHinge_.size(); ++i) {
    const FoldHinge& h = hinges_[static_cast<std::size_t>(foldTargetHinge_[i])];
    const double angle = kDegreesPerRadian * terms::hingeFoldAngle(pointValue(h.a), pointValue(h.b), pointValue(h.c), pointValue(h.d));
    // A hinge left flat or folded against its target keeps the target: a drag does not erase a
    // crease's fold or turn a valley into a mountain (its letter says which way it folds; a new
    // user's drag of a sheet stuck near flat did both, without a word).
    const double target = design_.foldAngles[i].angleDeg;
    if (std::abs(angle) < kFoldedHingeDeg || (target != 0.0 && angle * target < 0.0)) continue;
    const double captured = std::clamp(angle / design_.foldAmount, -180.0, 180.0);
    changed = changed || captured != design_.foldAngles[i].angleDeg;
    design_.foldAngles[i].angleDeg = captured;
  }
  setFoldAmount(design_.foldAmount);
  return changed;
}

void CompositeModel::holdFoldTargets(bool held) {
  if (foldTerm_ >= 0) problem_.term(foldTerm_).weight = held ? options_.foldWeight : 0.0;
}

double CompositeModel::foldAngleErrorMaxDeg() const {
  double worst = 0.0;
  for (std::size_t i = 0; i < design_.foldAngles.size() && i < foldTargetHinge_.size(); ++i) {
    const FoldHinge& h = hinges_[static_cast<std::size_t>(foldTargetHinge_[i])];
    const double angle = kDegreesPerRadian * terms::hingeFoldAngle(pointValue(h.a), pointValue(h.b), pointValue(h.c), pointValue(h.d));
    double error = std::abs(angle - design_.foldAmount * design_.foldAngles[i].angleDeg);
    if (error > 180.0) error = 360.0 - error;
    worst = std::max(worst, error);
  }
  return worst;
}

}  // namespace devsurf::models::composite
