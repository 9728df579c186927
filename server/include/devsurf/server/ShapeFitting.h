#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "devsurf/models/composite/CompositeDesign.h"
#include "devsurf/models/strip/StripFromRegion.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/reference/ReferenceShape.h"
#include "devsurf/server/ShapeUpload.h"

namespace devsurf::server {

/// A region of a user's shape and what to place on it (issue 15, 000_… §4.2): `devsurf fit`,
/// `devsurf cover`, POST /api/fits and /api/covers.
struct RegionFitRequest {
  std::optional<Eigen::Vector3d> centre;  ///< with radius: a ball (a brush stroke); else all of the shape
  double radius = 0.0;
  double thin = 0.0;          ///< thinning radius; 0 = reference::suggestedThinningRadius
  std::uint32_t seed = 1;     ///< thinning order
  int controlPoints = 8;      ///< per curve
  int iterations = 60;        ///< fit: the scene's solver.iterations (Fig. 17 row 10)
  models::strip::RegionStripOptions::Rulings rulings = models::strip::RegionStripOptions::Rulings::Auto;  ///< fit
  bool flat = false;          ///< fit: leave the start flat (the paper's Fig. 10a)
  /// ApproximationTarget::overhangWeight of the fitted strip(s); 0 (the default) = the paper's
  /// eq. 9–11 alone, under which a strip grows over all it can reach (Fig. 11) — what merging
  /// strips fitted to neighbouring regions needs (Fig. 10c). 0.001 keeps a single strip over its
  /// region: on the bunny's back (ball 0.3) the strip's farthest point from the region went from
  /// 0.37 to 0.14 and the RMS from 4.5 % to 3.5 % of the region. In a cover it slowed the sweeps.
  double overhang = 0.0;
  int strips = 4;             ///< cover: bands, one strip each
  int rounds = 8;             ///< cover: sweeps
  /// cover: regions the shape (or the ball) is segmented into, each covered by `strips` strips
  /// (000_… Fig. 10e: the bunny as six composites); 1 = the whole region as one set of bands.
  int regions = 1;
  models::composite::CreaseKind crease = models::composite::CreaseKind::None;  ///< cover: shared edges
  /// Wall-clock limit of a cover in ms (0 = none, the CLI's); POST /api/covers sets 60 000 — the
  /// work runs in the request's thread. Running out is an ApproximationInputError (413 "limit").
  double timeLimitMs = 0.0;
  std::string name;           ///< the scene's name ("" = from the source)
  std::string units = "mm";
};

/// A scene made over a region, what was built (as JSON) and warnings for the user.
struct RegionFitResult {
  proto::Scene scene;
  nlohmann::json summary;
  std::vector<std::string> warnings;
  Eigen::MatrixX3d covered;  ///< cover: the points of the bands (the region as covered)
};

/// The request from query parameters: centre ("x,y,z"), radius, thin, seed, control_points,
/// iterations, rulings (auto|across|along), flat (true|false), name, units; for a cover also
/// strips, rounds, crease (none|fold), regions (1–32), overhang (weight in [0, 10]), with strips × rounds ≤ 400 and
/// regions × strips × rounds ≤ 1600. Unknown ones are refused.
/// @throws ApproximationInputError naming the parameter
RegionFitRequest regionFitRequestFromQuery(const std::multimap<std::string, std::string>& params, bool cover);

/// A strip scene approximating the region (000_… §4.2, Fig. 10a–b): the region thinned with a
/// normal per point, a strip placed by PCA over it, eq. (9)–(11) as its approximation target.
/// @param[in] source  names the input in the scene's name and description (a file name)
/// @throws ApproximationInputError (field "radius", "thin", …) for a region too small to fit
RegionFitResult fitStripToShape(const reference::ReferenceShape& shape, const std::string& source,
                                const RegionFitRequest& request);

/// A composite scene of strips side by side covering the region (000_… Fig. 10d–e;
/// models::strip::coverRegion, models::composite::compositeFromStrips). Its summary lists the
/// pairings and each sweep's gap and warp; warnings when the region wraps around the shape or the
/// strips end far from developable. With request.regions > 1 the region is first segmented
/// (models::strip::coverShapeByRegions, normals from reference::orientedPointNormals) and the
/// composite has one part per covered region; the summary lists every region, and a region that
/// could not be covered is a warning, not an error, unless none could.
/// @throws ApproximationInputError naming the parameter the region fails on
RegionFitResult coverShapeWithStrips(const reference::ReferenceShape& shape, const std::string& source,
                                     const RegionFitRequest& request);

/// What the browser draws of an uploaded shape before a region is chosen: at most `maxPoints`
/// of its points (a seeded thinning when there are more), its bounding box and diagonal, counts.
nlohmann::json referencePreview(const reference::ReferenceShape& shape, int maxPoints);

}  // namespace devsurf::server
