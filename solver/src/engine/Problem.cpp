#include "devsurf/engine/Problem.h"

#include <stdexcept>

namespace devsurf::engine {

int Problem::addBlock(const std::string& name, int size) {
  const int id = layout_.addBlock(name, size);
  x_.conservativeResize(layout_.numVariables());
  x_.tail(size).setZero();
  return id;
}

Eigen::Map<Eigen::VectorXd> Problem::blockValues(int block) {
  const VariableBlock& b = layout_.block(block);
  return Eigen::Map<Eigen::VectorXd>(x_.data() + b.offset, b.size);
}

Eigen::Map<const Eigen::VectorXd> Problem::blockValues(int block) const {
  const VariableBlock& b = layout_.block(block);
  return Eigen::Map<const Eigen::VectorXd>(x_.data() + b.offset, b.size);
}

int Problem::addTerm(std::unique_ptr<Term> term, double weight, Strength strength,
                     WeightSchedule schedule) {
  if (!term) throw std::invalid_argument("Problem::addTerm: null term");
  terms_.push_back({std::move(term), weight, strength, schedule});
  return numTerms() - 1;
}

int Problem::numResiduals() const {
  int n = 0;
  for (const TermSlot& t : terms_) n += t.term->numResiduals();
  return n;
}

}  // namespace devsurf::engine
