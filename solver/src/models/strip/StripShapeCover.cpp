// A whole shape covered region by region (000_… Fig. 10e).
#include "devsurf/models/strip/StripShapeCover.h"

#include <algorithm>
#include <limits>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>
#include <utility>

#include "devsurf/reference/PointThinning.h"
#include "devsurf/spline/BSplineCurve.h"
#include "devsurf/reference/SurfaceSegmentation.h"
#include "devsurf/spatial/DisjointSets.h"
#include "devsurf/spatial/MatrixRowsKdTree.h"

namespace devsurf::models::strip {

namespace {

/// Neighbours per point in the graph whose connected parts split the clusters.
constexpr int kRegionGraphNeighbours = 12;

/// k-means clusters of normals need not be connected (two flanks facing one way); a region must
/// be one piece of surface for its bands to describe it. Splits every cluster into its connected
/// parts in the graph of each point's 12 nearest points within `reach` (12 per point, whatever
/// the cloud's density), gives parts under `minimumShare` of their cluster to the label most of
/// their neighbours carry, a part with no other neighbour to the label most of its points' 32
/// nearest labelled points within three reaches carry (stray points of a sparse cloud), and numbers
/// the labels 0 … by first point.
std::vector<int> connectedRegionLabels(const Eigen::MatrixX3d& points, std::vector<int> label, double reach,
                                       double minimumShare) {
  const auto n = static_cast<std::size_t>(points.rows());
  const spatial::MatrixRows rows{points};
  const spatial::MatrixRowsKdTree tree(3, rows, nanoflann::KDTreeSingleIndexAdaptorParams(16));
  constexpr int K = kRegionGraphNeighbours;
  std::vector<int> neighbours(n * K, -1);  // row j: its nearest points within reach, −1 padded
  spatial::DisjointSets parts(n);
  {
    std::size_t found[K + 1];
    double squared[K + 1];
    for (std::size_t j = 0; j < n; ++j) {
      const Eigen::Vector3d p = points.row(static_cast<Eigen::Index>(j)).transpose();
      const std::size_t count = tree.knnSearch(p.data(), K + 1, found, squared);
      int slot = 0;
      for (std::size_t k = 0; k < count && slot < K; ++k) {
        if (found[k] == j || squared[k] > reach * reach) continue;
        neighbours[j * K + static_cast<std::size_t>(slot++)] = static_cast<int>(found[k]);
        if (label[found[k]] == label[j]) parts.join(static_cast<int>(j), static_cast<int>(found[k]));
      }
    }
  }
  std::map<int, int> clusterSize, partSize;
  for (std::size_t j = 0; j < n; ++j) ++clusterSize[label[j]], ++partSize[parts.find(static_cast<int>(j))];
  // The largest part of each cluster keeps the cluster; other parts become clusters of their own
  // or, when small, join the label around them.
  std::map<int, int> largestPart;
  for (std::size_t j = 0; j < n; ++j) {
    const int part = parts.find(static_cast<int>(j));
    auto [it, inserted] = largestPart.emplace(label[j], part);
    if (!inserted && partSize[part] > partSize[it->second]) it->second = part;
  }
  int nextLabel = 0;
  for (const auto& [l, size] : clusterSize) nextLabel = std::max(nextLabel, l + 1);
  std::map<int, int> newLabelOfPart;
  std::vector<char> small(n, 0);
  for (std::size_t j = 0; j < n; ++j) {
    const int part = parts.find(static_cast<int>(j));
    if (largestPart[label[j]] == part) continue;
    if (partSize[part] < minimumShare * clusterSize[label[j]]) {
      small[j] = 1;
      continue;
    }
    auto [it, inserted] = newLabelOfPart.emplace(part, nextLabel);
    if (inserted) ++nextLabel;
    label[j] = it->second;
  }
  // Each small part takes the label most votes give it; `votesOf` lists a point's voters.
  const auto settleByVotes = [&small, &label, &parts, n](const auto& votesOf) {
    bool changed = false;
    std::map<int, std::map<int, int>> votes;  // part → label → count
    for (std::size_t j = 0; j < n; ++j)
      if (small[j]) votesOf(j, votes[parts.find(static_cast<int>(j))]);
    for (std::size_t j = 0; j < n; ++j) {
      if (!small[j]) continue;
      const std::map<int, int>& ballot = votes[parts.find(static_cast<int>(j))];
      if (ballot.empty()) continue;
      label[j] = std::max_element(ballot.begin(), ballot.end(),
                                  [](const auto& x, const auto& y) { return x.second < y.second; })->first;
      small[j] = 2;  // settled this pass: not a voter until the pass ends
      changed = true;
    }
    for (char& s : small)
      if (s == 2) s = 0;
    return changed;
  };
  // Small parts next to labelled points (repeated while some part borders only other small parts).
  const auto graphVotes = [&neighbours, &small, &label](std::size_t j, std::map<int, int>& ballot) {
    for (int k = 0; k < K; ++k) {
      const int other = neighbours[j * K + static_cast<std::size_t>(k)];
      if (other >= 0 && !small[static_cast<std::size_t>(other)]) ++ballot[label[static_cast<std::size_t>(other)]];
    }
  };
  while (settleByVotes(graphVotes)) {
  }
  // Parts with no labelled neighbour in the graph: their points' 32 nearest labelled points within
  // three reaches vote.
  const auto strayVotes = [&tree, &points, &small, &label, reach](std::size_t j, std::map<int, int>& ballot) {
    std::size_t found[32];
    double squared[32];
    const Eigen::Vector3d p = points.row(static_cast<Eigen::Index>(j)).transpose();
    const std::size_t count = tree.knnSearch(p.data(), 32, found, squared);
    for (std::size_t k = 0; k < count; ++k)
      if (!small[found[k]] && squared[k] <= 9.0 * reach * reach) ++ballot[label[found[k]]];
  };
  settleByVotes(strayVotes);
  // The rest keep a label of their own.
  for (std::size_t j = 0; j < n; ++j)
    if (small[j]) {
      auto [it, inserted] = newLabelOfPart.emplace(parts.find(static_cast<int>(j)), nextLabel);
      if (inserted) ++nextLabel;
      label[j] = it->second;
    }
  std::map<int, int> renumber;
  for (int& l : label) l = renumber.emplace(l, static_cast<int>(renumber.size())).first->second;
  return label;
}

}  // namespace

void trimToRegion(RegionCover& cover, const Eigen::MatrixX3d& points) {
  std::vector<StripDesign>& strips = cover.paired.strips;
  if (strips.empty() || strips.size() != cover.layout.bands.size()) return;
  constexpr int U = 160, W = 16;  // samples along and across each strip
  double uLow = std::numeric_limits<double>::infinity(), uHigh = -uLow, vFirst = 1.0, vLast = 0.0;
  const double begin = strips.front().a.knots.domainBegin(), end = strips.front().a.knots.domainEnd();
  for (std::size_t k = 0; k < strips.size(); ++k) {
    const StripDesign& s = strips[k];
    Eigen::MatrixX3d samples((U + 1) * (W + 1), 3);
    for (int i = 0; i <= U; ++i) {
      const double u = begin + (end - begin) * i / U;
      const Eigen::Vector3d a = s.a.evaluate(u), b = s.b.evaluate(u);
      for (int j = 0; j <= W; ++j) samples.row(i * (W + 1) + j) = ((1.0 - double(j) / W) * a + double(j) / W * b).transpose();
    }
    const spatial::MatrixRows rows{samples};
    const spatial::MatrixRowsKdTree tree(3, rows, nanoflann::KDTreeSingleIndexAdaptorParams(16));
    for (const int j : cover.layout.bands[k]) {
      std::size_t nearest = 0;
      double squared = 0.0;
      const Eigen::Vector3d p = points.row(j).transpose();
      tree.knnSearch(p.data(), 1, &nearest, &squared);
      const int i = static_cast<int>(nearest) / (W + 1), w = static_cast<int>(nearest) % (W + 1);
      const double u = begin + (end - begin) * i / U, v = double(w) / W;
      uLow = std::min(uLow, u);
      uHigh = std::max(uHigh, u);
      if (k == 0) vFirst = std::min(vFirst, v);
      if (k + 1 == strips.size()) vLast = std::max(vLast, v);
    }
  }
  // One sample of margin; nothing to cut when the points reach (nearly) both ends.
  const double step = (end - begin) / U;
  uLow = std::max(begin, uLow - step);
  uHigh = std::min(end, uHigh + step);
  if (uHigh - uLow < 4.0 * step) return;  // points on one ruling: nothing sensible to keep
  for (StripDesign& s : strips) {
    s.a = spline::restrictToInterval(s.a, uLow, uHigh);
    s.b = spline::restrictToInterval(s.b, uLow, uHigh);
  }
  vFirst = std::max(0.0, vFirst - 1.0 / W);
  vLast = std::min(1.0, vLast + 1.0 / W);
  if (vFirst > 0.0 && vFirst < vLast) {
    StripDesign& s = strips.front();
    s.a.points = (1.0 - vFirst) * s.a.points + vFirst * s.b.points;
  }
  if (vLast < 1.0 && (strips.size() > 1 || vFirst < vLast)) {
    StripDesign& s = strips.back();
    // For a single strip, a moved already: v is measured on the strip as it was.
    const double v = strips.size() > 1 ? vLast : (vLast - vFirst) / (1.0 - vFirst);
    s.b.points = (1.0 - v) * s.a.points + v * s.b.points;
  }
}

ShapeCover coverShapeByRegions(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& normals,
                               const ShapeCoverOptions& options) {
  if (options.regions < 1) throw std::invalid_argument("regions: at least one");
  if (normals.rows() != points.rows()) throw std::invalid_argument("normals: one per point is needed");
  reference::NormalSegmentationOptions segmentation;
  segmentation.patches = options.regions;
  segmentation.positionWeight = options.positionWeight;
  segmentation.seed = options.seed;
  ShapeCover out;
  out.label = reference::segmentPointsByNormals(points, normals, segmentation);
  const double reach = options.connectionReach > 0.0 ? options.connectionReach
                                                      : reference::suggestedThinningRadius(points, false);
  if (reach > 0.0) out.label = connectedRegionLabels(points, std::move(out.label), reach, options.minimumPartShare);
  int count = 0;
  for (const int l : out.label) count = std::max(count, l + 1);
  out.regions.resize(static_cast<std::size_t>(count));
  for (std::size_t j = 0; j < out.label.size(); ++j)
    out.regions[static_cast<std::size_t>(out.label[j])].points.push_back(static_cast<int>(j));
  for (std::size_t r = 0; r < out.regions.size(); ++r) {
    ShapeRegionCover& region = out.regions[r];
    const auto size = static_cast<Eigen::Index>(region.points.size());
    Eigen::MatrixX3d regionPoints(size, 3), regionNormals(size, 3);
    for (Eigen::Index j = 0; j < size; ++j) {
      regionPoints.row(j) = points.row(region.points[static_cast<std::size_t>(j)]);
      regionNormals.row(j) = normals.row(region.points[static_cast<std::size_t>(j)]);
    }
    options.deadline.check();
    try {
      region.cover = coverRegion(regionPoints, regionNormals, options.region);
      if (options.trim) trimToRegion(region.cover, regionPoints);
      region.covered = true;
    } catch (const std::invalid_argument& e) {
      // Too few points for the strips, points on a line, a band thinned to nothing: the region
      // stays uncovered and says why; the others go on.
      region.skipped = e.what();
    }
  }
  return out;
}

}  // namespace devsurf::models::strip
