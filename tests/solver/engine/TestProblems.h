#pragma once

// Small problems shared by the engine tests.

#include <memory>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Problem.h"
#include "solver/engine/TestTerms.h"

namespace devsurf::engine::testing {

/// A problem shaped like the developable strip (Tang et al. 2016): control points (block
/// "points", 3 scalars each, the first held fixed) and one free normal per sample (block
/// "normals"). Sample k of span s couples its normal to the span's 4 control points through
/// three DotTerm rows; every normal also has a soft unit-length row, and the points a soft
/// second-difference fairness term.
/// With `oneRowCoversTheSpan` the first row of a sample involves all 4 points (as the strip's
/// ⟨b − a, n⟩ does), so eliminating the normal creates no fill-in; without it each row involves
/// only 2 of the 4 points.
inline void buildStripLike(Problem& problem, int spans, int samplesPerSpan, unsigned seed,
                           bool oneRowCoversTheSpan = true) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  const int numPoints = spans + 3;
  const int numSamples = spans * samplesPerSpan;
  const int points = problem.addBlock("points", 3 * numPoints);
  const int normals = problem.addBlock("normals", 3 * numSamples);
  problem.layout().setRegularizationScale(normals, 1e-2);
  problem.layout().setFixed(points, 0, 3);
  const int offP = problem.layout().block(points).offset;
  const int offN = problem.layout().block(normals).offset;
  for (int i = 0; i < 3 * numPoints; ++i) problem.x()[offP + i] = i / 3 + 0.3 * uni(rng);
  for (int k = 0; k < numSamples; ++k) {
    Eigen::Vector3d n(uni(rng), uni(rng), 1.0);
    problem.x().segment<3>(offN + 3 * k) = n.normalized();
  }
  auto pointScalars = [&](int first, int count) {
    std::vector<int> s;
    for (int p = first; p < first + count; ++p)
      for (int c = 0; c < 3; ++c) s.push_back(offP + 3 * p + c);
    return s;
  };
  auto randomWeights = [&](std::size_t cols) {
    Eigen::Matrix3Xd w(3, static_cast<Eigen::Index>(cols));
    for (Eigen::Index i = 0; i < w.size(); ++i) w.data()[i] = uni(rng);
    return w;
  };
  std::vector<DotTerm::Row> rows;
  for (int s = 0; s < spans; ++s) {
    for (int j = 0; j < samplesPerSpan; ++j) {
      const int normal = offN + 3 * (s * samplesPerSpan + j);
      const std::vector<std::pair<int, int>> ranges =
          oneRowCoversTheSpan ? std::vector<std::pair<int, int>>{{s, 4}, {s, 2}, {s + 2, 2}}
                              : std::vector<std::pair<int, int>>{{s, 2}, {s + 2, 2}, {s + 1, 2}};
      for (const auto& [first, count] : ranges) {
        DotTerm::Row row;
        row.scalars = pointScalars(first, count);
        row.weights = randomWeights(row.scalars.size());
        row.normal = normal;
        row.target = 0.1 * uni(rng);
        rows.push_back(std::move(row));
      }
    }
  }
  problem.addTerm(std::make_unique<DotTerm>("developability", std::move(rows)), 1.0,
                  Strength::Hard);
  std::vector<int> offsets;
  for (int k = 0; k < numSamples; ++k) offsets.push_back(offN + 3 * k);
  problem.addTerm(std::make_unique<SquaredNormTerm>("unit_normal", offsets), 0.1, Strength::Soft);
  std::vector<SparseLinearTerm::Row> fair;
  for (int p = 0; p + 2 < numPoints; ++p) {
    for (int c = 0; c < 3; ++c) {
      SparseLinearTerm::Row row;
      row.coefficients = {{offP + 3 * p + c, 1.0}, {offP + 3 * (p + 1) + c, -2.0},
                          {offP + 3 * (p + 2) + c, 1.0}};
      fair.push_back(std::move(row));
    }
  }
  problem.addTerm(std::make_unique<SparseLinearTerm>("fairness", std::move(fair)), 1.0,
                  Strength::Soft, WeightSchedule::Fairness);
}

}  // namespace devsurf::engine::testing
