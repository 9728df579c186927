#include "devsurf/engine/VariableLayout.h"

#include <stdexcept>

namespace devsurf::engine {

int VariableLayout::addBlock(const std::string& name, int size) {
  if (size < 0) throw std::invalid_argument("variable block '" + name + "': negative size");
  for (const VariableBlock& b : blocks_)
    if (b.name == name) throw std::invalid_argument("variable block '" + name + "' exists already");
  blocks_.push_back({name, numVariables(), size, 1.0, VariableBlock::kAutoElimination, false});
  fixed_.resize(fixed_.size() + static_cast<std::size_t>(size), 0);
  blockOf_.resize(fixed_.size(), numBlocks() - 1);
  return numBlocks() - 1;
}

int VariableLayout::blockId(const std::string& name) const {
  for (int i = 0; i < numBlocks(); ++i)
    if (blocks_[i].name == name) return i;
  throw std::out_of_range("no variable block named '" + name + "'");
}

void VariableLayout::setFixed(int block, int first, int count, bool fixed) {
  const VariableBlock& b = blocks_.at(block);
  if (first < 0 || count < 0 || first + count > b.size)
    throw std::out_of_range("variable block '" + b.name + "': fixed range out of bounds");
  for (int i = 0; i < count; ++i) fixed_[b.offset + first + i] = fixed ? 1 : 0;
}

void VariableLayout::setRegularizationScale(int block, double scale) {
  if (!(scale >= 0.0)) throw std::invalid_argument("regularization scale must be ≥ 0");
  blocks_.at(block).regularizationScale = scale;
}

void VariableLayout::setEliminable(int block, int groupSize) {
  VariableBlock& b = blocks_.at(block);
  if (groupSize < VariableBlock::kAutoElimination)
    throw std::invalid_argument("variable block '" + b.name + "': elimination group size < -1");
  if (groupSize > 0 && b.size % groupSize != 0)
    throw std::invalid_argument("variable block '" + b.name + "': elimination group size " +
                                std::to_string(groupSize) + " does not divide the block size " +
                                std::to_string(b.size));
  b.eliminationGroupSize = groupSize;
}

void VariableLayout::setBlockFixed(int block, bool fixed) {
  setFixed(block, 0, blocks_.at(block).size, fixed);
}

void VariableLayout::setAlternating(int block, bool alternating) { blocks_.at(block).alternating = alternating; }

bool VariableLayout::hasAlternation() const {
  for (std::size_t i = 0; i < fixed_.size(); ++i)
    if (!fixed_[i] && blocks_[static_cast<std::size_t>(blockOf_[i])].alternating) return true;
  return false;
}

bool VariableLayout::inPart(int variable, VariablePart part) const {
  if (part == VariablePart::All) return true;
  const bool alternating = blocks_[static_cast<std::size_t>(blockOf_[static_cast<std::size_t>(variable)])].alternating;
  return alternating == (part == VariablePart::Alternating);
}

std::vector<int> VariableLayout::freeIndex(VariablePart part) const {
  std::vector<int> index(fixed_.size(), -1);
  int column = 0;
  for (std::size_t i = 0; i < fixed_.size(); ++i)
    if (!fixed_[i] && inPart(static_cast<int>(i), part)) index[i] = column++;
  return index;
}

int VariableLayout::numFree(VariablePart part) const {
  int n = 0;
  for (std::size_t i = 0; i < fixed_.size(); ++i) n += !fixed_[i] && inPart(static_cast<int>(i), part) ? 1 : 0;
  return n;
}

}  // namespace devsurf::engine
