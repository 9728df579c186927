#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "devsurf/engine/Deadline.h"
#include "devsurf/models/strip/StripCover.h"

namespace devsurf::models::strip {

/// Cuts a region's strips back to the part of them over its points: every strip's curves
/// restricted to one parameter interval (the least and greatest u of the band points' nearest
/// samples, over all strips; exact, spline::restrictToInterval), and the region's two outer
/// curves moved along the rulings to the least / greatest v of their strip's band points
/// (a ← (1 − v₀) a + v₀ b: the same ruled surface). Neighbouring strips share their curve's
/// parametrization, so the shared curves stay shared. Corners of the band rectangle outside a
/// round region are not cut (a strip's ends are rulings).
/// @param[in] points  the region's points (the layout's bands index them)
void trimToRegion(RegionCover& cover, const Eigen::MatrixX3d& points);

/// Options of coverShapeByRegions.
struct ShapeCoverOptions {
  int regions = 6;              ///< clusters of the segmentation (Fig. 10e: six composites on the bunny)
  /// Segmentation: weight of position against normal (reference::NormalSegmentationOptions); 2
  /// keeps the regions compact enough that each is one piece of surface on CGAL's bunny and kitten.
  double positionWeight = 2.0;
  std::uint32_t seed = 1;       ///< segmentation's k-means++ seeding
  /// Points closer than this are neighbours when clusters are split into connected parts; 0 =
  /// reference::suggestedThinningRadius of the points (without normals).
  double connectionReach = 0.0;
  /// A connected part smaller than this share of its cluster joins the region around it; larger
  /// ones become regions of their own.
  double minimumPartShare = 0.25;
  /// Each region's cover: strips, thinning, placement, sweeps. Its rectangle spans the whole
  /// region (keep = 1): the regions meet, so a margin left by each would be a gap between them
  /// (a closed can in 6 regions: 57 % of its points within 1 % of its size at keep = 0.7, 91 % at
  /// 0.9, all at 1).
  RegionCoverOptions region = wholeRegion();
  /// Each covered region's strips cut back to its points (trimToRegion): without, a rectangle of
  /// bands over a region that is not one leaves blades beyond the shape.
  bool trim = true;
  /// When to give up (checked between regions; each region's sweeps check region.pairing's).
  engine::Deadline deadline;

  static RegionCoverOptions wholeRegion() {
    RegionCoverOptions options;
    options.keep = 1.0;
    return options;
  }
};

/// One region of the shape and its cover, or why it has none.
struct ShapeRegionCover {
  std::vector<int> points;      ///< indices into the shape's points
  bool covered = false;
  RegionCover cover;            ///< when covered
  std::string skipped;          ///< why not, when not covered
};

/// A whole shape cut into regions, each covered by strips side by side.
struct ShapeCover {
  std::vector<int> label;                 ///< per point its region
  std::vector<ShapeRegionCover> regions;  ///< in label order
};

/// 000_… Fig. 10e on a whole shape: "the bunny is approximated by 6 composite surfaces". The paper
/// leaves the layout to the user ("if one already guesses at the final strip layout…"); here the
/// points are segmented by normal and position (reference::segmentPointsByNormals), so that each
/// region is close to a height field over its own plane; each cluster is split into its connected
/// parts (two flanks facing one way are two regions; small parts join the region around them);
/// and each region is covered by
/// coverRegion (Fig. 10b–d). A region too small or too thin for its strips is reported as skipped,
/// not thrown: the rest of the shape is still covered.
/// @param[in] points   n×3
/// @param[in] normals  n×3, oriented consistently (reference::orientedPointNormals)
/// @throws std::invalid_argument for regions < 1, sizes that disagree or non-finite values
ShapeCover coverShapeByRegions(const Eigen::MatrixX3d& points, const Eigen::MatrixX3d& normals,
                               const ShapeCoverOptions& options = {});

}  // namespace devsurf::models::strip
