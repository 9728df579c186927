#pragma once

// What CompositeModel.cpp and CompositeEdgeTerms.cpp (the problem) and CompositeMeasurement.cpp
// (metrics and sampling of the current state) share; private to the composite model's sources.

#include <array>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/spline/BasisTable.h"

namespace devsurf::models::composite {

/// Newell's normal of a polygon (not normalized; zero for a degenerate one).
inline Eigen::Vector3d newellNormal(const std::vector<Eigen::Vector3d>& poly) {
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < poly.size(); ++i) n += poly[i].cross(poly[(i + 1) % poly.size()]);
  return n;
}

/// Per-topology tables and per-state results a model remembers between calls (see quality()).
struct CompositeModel::StateCache {
  /// Per strip-like face, the basis of its first curve at the dense warp metric's 1 000 rulings
  /// (metrics::stripQuality's parameters): depends on the topology only, built on first use.
  std::once_flag warpOnce;
  std::vector<spline::BasisTable> warpRulings;

  /// The basis at computeCreases' samples of one interior S edge, for one samples-per-span: of
  /// the edge's own curve (up to the second derivative) and of each adjacent face's curves at the
  /// face's parameters of those samples (up to the first). Depends on the topology only.
  struct CreaseEdgeTables {
    spline::BasisTable curve;
    std::array<spline::BasisTable, 2> sides;
  };
  std::mutex creaseTablesMutex;
  std::map<int, std::shared_ptr<const std::vector<CreaseEdgeTables>>> creaseTables;  ///< per samples per span

  std::mutex mutex;
  Eigen::VectorXd x;  ///< the variables every entry below was computed from
  std::map<int, CompositeQuality> quality;
  std::map<int, CreaseSamples> creases;

  /// The entry for `key` in `entries` if it was computed from `now`; drops everything when the
  /// variables moved. Entries are copied out: the lock is not held while computing.
  template <class Value>
  std::optional<Value> find(const Eigen::VectorXd& now, std::map<int, Value>& entries, int key) {
    std::lock_guard<std::mutex> lock(mutex);
    if (x.size() != now.size() || x != now) {
      quality.clear();
      creases.clear();
      x = now;
      return std::nullopt;
    }
    const auto it = entries.find(key);
    if (it == entries.end()) return std::nullopt;
    return it->second;
  }
  template <class Value>
  void store(const Eigen::VectorXd& from, std::map<int, Value>& entries, int key, const Value& value) {
    std::lock_guard<std::mutex> lock(mutex);
    if (x.size() == from.size() && x == from) entries[key] = value;
  }
};

}  // namespace devsurf::models::composite
