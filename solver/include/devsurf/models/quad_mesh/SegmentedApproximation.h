#pragma once

#include <vector>

#include <Eigen/Core>

#include "devsurf/models/quad_mesh/QuadMeshDesign.h"
#include "devsurf/spatial/DiskParameterization.h"

namespace devsurf::models::quad_mesh {

/// How a segmented reference is turned into glued developable patches (004_… §5, Fig. 20–21).
struct SegmentedApproximationOptions {
  /// Quads wanted over the whole reference (about; the grid is square in the parameter plane).
  int targetFaces = 1500;
  /// Quad edge length in the reference's units; > 0 overrides targetFaces.
  double spacing = 0.0;
  /// A connected piece of a patch with fewer quads joins the neighbouring patch it shares most
  /// edges with (a segmentation's slivers would otherwise be patches of their own).
  int minPieceFaces = 8;
  /// The unfoldings are laid out as the reference's map, each moved away from the centre by this
  /// fraction of its distance (so the cutting pattern's pieces do not overlap where they met).
  double spread = 0.25;
  /// The map of the reference to the plane the quads are laid out in.
  spatial::ParameterizationMethod method = spatial::ParameterizationMethod::NearIsometric;
  /// Weights (normalized units: the model scales the mesh to diameter 1): Fig. 22 row 20b's
  /// proximity w_prox,1 = w_prox,2 = 0.01, with isometry and gluing w_iso = w_pos = 10 (row 20b:
  /// 1) and fairness w_fair = 0.01 (row 20b: 0.1). Measured on CGAL's patch-01.off in 8 patches,
  /// 40 iterations: w_iso = 1 ended at L-Err 0.022 %, 10 at 0.0035 %; w_fair = 0.1 bent the box's
  /// flat walls (RMS distance 0.42 % of the diagonal), 0.01 kept them (0.23 %).
  QuadMeshWeights weights = defaultWeights();
  /// Algorithm 1: 4 rounds of 10 iterations, w_fair ÷ 10 after each.
  IsometrySchedule schedule = {1e-12, 1e-12, 10, 4, 10};

  static QuadMeshWeights defaultWeights() {
    QuadMeshWeights w;
    w.isometry = 10.0;
    w.position = 10.0;
    w.proximityPoint = 0.01;
    w.proximityPlane = 0.01;
    w.fairnessMesh = 0.01;
    w.fairnessUnfolding = 0.01;
    return w;
  }
};

/// The start of a segmented approximation: one quad mesh M whose connected pieces are the
/// patches, each with its own planar unfolding M′, glued along shared boundaries.
struct SegmentedApproximation {
  /// faces, M on the reference, M′ (pieces laid out apart), variables both, glue pairs on M
  /// (every grid node shared by several pieces: its copies chained pairwise), the reference as
  /// Φ of E_prox, weights and schedule from the options.
  QuadMeshDesign design;
  std::vector<int> facePatch;  ///< F values: the input patch id each quad belongs to
  std::vector<int> facePiece;  ///< F values: the connected piece (0 … pieces − 1)
  int pieces = 0;              ///< connected pieces (M′ has this many components)
  double spacing = 0.0;        ///< the quad edge length used (reference units)
  int mergedPieces = 0;        ///< pieces below minPieceFaces given to a neighbour
  int droppedFaces = 0;        ///< quads of isolated slivers left out
  int bordersAligned = 0;      ///< grid nodes moved onto a border between patches
  int cornerQuadsSplit = 0;    ///< quads split in two triangles at a corner in no other face
  int piecesMappedAlone = 0;   ///< pieces whose M′ is their own map (the others are not disks)
};

/// Builds the start of 004_… §5's approximation of a segmented reference shape: the reference (a
/// triangle mesh with the topology of a disk) is mapped to the plane once
/// (spatial::parameterizeDisk, conformal and near-isometric), a square grid of spacing h is laid
/// over the map, every grid cell inside it becomes a quad of M (its corners lifted back onto the
/// reference) assigned to the patch of the triangle under its centre, and grid nodes on a border
/// between patches are split into one vertex per patch, glued together. A quad with a corner in
/// no other face is split into two triangles that cut the corner off (eq. 1 leaves such a corner
/// free to swing about the quad's diagonals). Each patch's M′ starts as
/// the patch's own near-isometric map (its part of the reference's map, scaled to its area, when
/// the patch is not a disk), so all patches and unfoldings
/// can then be optimized together (Algorithm 1 with E_prox to the reference and E_pos gluing).
/// @param[in] V              n×3 reference vertices
/// @param[in] T              t×3 reference triangles (ccw seen from the front)
/// @param[in] trianglePatch  t patch ids ≥ 0 (a segmentation: given, drawn, or from
///                           reference::segmentByNormals)
/// @throws std::invalid_argument if sizes disagree, an id is negative, the reference is not a
///         disk (parameterizeDisk's message), the grid is too coarse for any quad or finer than
///         2 000 000 nodes
SegmentedApproximation segmentedApproximation(const Eigen::MatrixX3d& V, const Eigen::MatrixX3i& T,
                                              const std::vector<int>& trianglePatch,
                                              const SegmentedApproximationOptions& options = {});

}  // namespace devsurf::models::quad_mesh
