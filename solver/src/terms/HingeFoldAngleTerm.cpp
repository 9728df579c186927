#include "devsurf/terms/HingeFoldAngleTerm.h"

#include <cmath>
#include <stdexcept>

#include <Eigen/Geometry>

namespace devsurf::terms {

namespace {

constexpr double kPi = 3.14159265358979323846;

double wrappedAngle(double angle) {
  while (angle > kPi) angle -= 2.0 * kPi;
  while (angle <= -kPi) angle += 2.0 * kPi;
  return angle;
}

}  // namespace

double hingeFoldAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                      const Eigen::Vector3d& d) {
  const Eigen::Vector3d e = b - a;
  const Eigen::Vector3d nL = e.cross(c - a), nR = (d - a).cross(e);
  const double length = e.norm();
  if (!(length > 0.0)) return 0.0;
  return std::atan2(nR.cross(nL).dot(e) / length, nR.dot(nL));
}

HingeFoldAngleTerm::HingeFoldAngleTerm(std::string name, std::vector<std::array<int, 4>> hinges, std::vector<double> targets)
    : Term(std::move(name)), hinges_(std::move(hinges)) {
  for (std::size_t h = 0; h < hinges_.size(); ++h) {
    const auto& p = hinges_[h];
    for (int i = 0; i < 4; ++i) {
      if (p[i] < 0) throw std::invalid_argument("HingeFoldAngleTerm: hinge " + std::to_string(h) + " has a negative offset");
      for (int j = 0; j < i; ++j)
        if (p[i] == p[j]) throw std::invalid_argument("HingeFoldAngleTerm: hinge " + std::to_string(h) + " uses one point twice");
    }
  }
  targets_.resize(hinges_.size());
  setTargets(targets);
}

void HingeFoldAngleTerm::setTargets(const std::vector<double>& targets) {
  if (targets.size() != hinges_.size())
    throw std::invalid_argument("HingeFoldAngleTerm: " + std::to_string(targets.size()) + " targets for " +
                                std::to_string(hinges_.size()) + " hinges");
  for (double t : targets)
    if (!std::isfinite(t)) throw std::invalid_argument("HingeFoldAngleTerm: a target is not finite");
  targets_ = targets;
}

void HingeFoldAngleTerm::jacobianStructure(std::vector<engine::JacobianEntry>& entries) const {
  for (std::size_t h = 0; h < hinges_.size(); ++h)
    for (int p = 0; p < 4; ++p)
      for (int k = 0; k < 3; ++k) entries.push_back({static_cast<int>(h), hinges_[h][p] + k});
}

void HingeFoldAngleTerm::evaluate(const Eigen::VectorXd& x, double* residuals, double* jacobian) const {
  double* J = jacobian;
  for (std::size_t h = 0; h < hinges_.size(); ++h) {
    const auto& o = hinges_[h];
    const Eigen::Vector3d a = x.segment<3>(o[0]), b = x.segment<3>(o[1]), c = x.segment<3>(o[2]), d = x.segment<3>(o[3]);
    const Eigen::Vector3d e = b - a, ca = c - a, da = d - a;
    const Eigen::Vector3d nL = e.cross(ca), nR = da.cross(e);
    const double length = e.norm();
    const Eigen::Vector3d unit = length > 0.0 ? Eigen::Vector3d(e / length) : Eigen::Vector3d::Zero();
    const Eigen::Vector3d m = nR.cross(nL);
    const double s = m.dot(unit), t = nR.dot(nL);  // θ = atan2(s, t)
    residuals[h] = wrappedAngle(std::atan2(s, t) - targets_[h]);
    if (!J) continue;
    const double denominator = s * s + t * t;
    if (!(denominator > 0.0) || !(length > 0.0)) {
      for (int i = 0; i < 12; ++i) *J++ = 0.0;
      continue;
    }
    // dθ = (t ds − s dt)/(s² + t²), each coordinate of a, b, c, d in turn.
    for (int p = 0; p < 4; ++p)
      for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d dA = Eigen::Vector3d::Zero(), dB = dA, dC = dA, dD = dA;
        (p == 0 ? dA : p == 1 ? dB : p == 2 ? dC : dD)[k] = 1.0;
        const Eigen::Vector3d dE = dB - dA;
        const Eigen::Vector3d dNL = dE.cross(ca) + e.cross(dC - dA);
        const Eigen::Vector3d dNR = (dD - dA).cross(e) + da.cross(dE);
        const Eigen::Vector3d dUnit = (dE - unit * unit.dot(dE)) / length;
        const double ds = (dNR.cross(nL) + nR.cross(dNL)).dot(unit) + m.dot(dUnit);
        const double dt = dNR.dot(nL) + nR.dot(dNL);
        *J++ = (t * ds - s * dt) / denominator;
      }
  }
}

}  // namespace devsurf::terms
