#pragma once

#include <string>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "devsurf/models/composite/CompositeModel.h"
#include "devsurf/models/conical_strip/ConicalStripModel.h"
#include "devsurf/models/quad_mesh/QuadMeshModel.h"
#include "devsurf/models/quasi_strip/QuasiStripModel.h"
#include "devsurf/models/strip/StripModel.h"

namespace devsurf::proto {

/// Standard base64 (RFC 4648, with padding) of raw bytes.
std::string base64Encode(const void* data, std::size_t size);
/// Decodes standard base64; throws std::invalid_argument on malformed input.
std::string base64Decode(const std::string& text);

/// A float array as it travels on the wire: {"dtype":"float32","shape":[rows,cols],"data":BASE64}
/// (little-endian IEEE float32, row-major).
nlohmann::json float32Array(const Eigen::MatrixXd& m);
/// Same for int32 index arrays (quads).
nlohmann::json int32Array(const Eigen::MatrixXi& m);
/// Decodes a float32Array (tests, clients written in C++).
Eigen::MatrixXd decodeFloat32Array(const nlohmann::json& j);

/// Unrolls a strip sampled along its rulings into the plane, quad after quad (000_… §5
/// "Conversion of surfaces to meshes"): rows 2i and 2i+1 of the result are the images of a_i and
/// b_i. Exact (an isometry of every quad) when the quads are planar, i.e. the strip developable.
/// @param[in] a, b  the rulings' end points, U×3 each
Eigen::MatrixXd unrollRulingGrid(const Eigen::MatrixX3d& a, const Eigen::MatrixX3d& b);

/// Sampled strip geometry for drawing: surface grid, boundary curves, control points, rulings,
/// per-vertex warp angle (deg) for colouring. Sizes documented in docs/protocol.md.
nlohmann::json stripGeometryJson(const models::strip::StripModel& model, int uSamples = 96,
                                 int vSamples = 2, int rulings = 32);

/// Sampled composite geometry for drawing and editing (docs/protocol.md, "Composite geometry"):
///  * "surface": every face sampled (CompositeModel::geometry(samplesPerSpan, vSamples)) and
///    concatenated face after face, vertices [N,3], quads [Q,4] (int32), "quad_face" [Q,1] (int32,
///    the composite face of each quad), and two per-vertex scalars for colouring:
///    "face_flatness" [N,1] (quality.faceFlatness of the vertex's face, δ of 000_… Fig. 17) and
///    "vertex_curvature" [N,1] (|angle sum − 2π| in rad of the composite vertices, spread over
///    the surface as max_v K_v·max(0, 1 − |p − v|/r_v), r_v = 0.35 × the shortest chord of v's
///    edges, so each defect shows as a spot around its vertex);
///  * "vertices" [V,3] and "vertex_curvature" [V,1] per composite vertex; "face_flatness" [F,1]
///    per face;
///  * "edges": one object per composite edge {"edge", "v":[v0,v1], "type":"S"|"R",
///    "crease":"none"|"fold"|"geodesic"|"smooth", "interior", "assignment":"M"|"V"|"F"|"B",
///    "polyline":[k,3], "fold_angle_deg":[k,1] (interior edges; FOLD sign: valley > 0),
///    "control_points":[n,3] (S edges: the full control polygon, v0 first)};
///  * "points": every draggable point, "positions" [P,3] and "refs" [P,3] (int32 rows
///    (vertex, edge, index): (v, −1, −1) for vertex v, (−1, e, k) for interior control point k of
///    S edge e) — the vertices first, then the S edges' interior control points in edge order;
///  * "development": null without development management, otherwise the crease pattern of
///    CompositeModel::creasePattern(): "vertices" [M,2] (design units), "triangles" [T,3] (the
///    development's polygons fanned), "triangle_face" [T,1], "edges" [E,2] (int32) with
///    "assignment" (one letter B/M/V/F/C per edge, a string) and "rulings" [R,4] (x0,y0,x1,y1).
nlohmann::json compositeGeometryJson(const models::composite::CompositeModel& model,
                                     const models::composite::CompositeQuality& quality,
                                     int samplesPerSpan = 12, int vSamples = 3);

/// Sampled quasi_strip geometry (Bo et al.) for drawing and editing (docs/protocol.md,
/// "quasi_strip geometry"), from the model's current results (before a solve: σ(t) = t):
///  * "surface": the converted ruled surface over the trimmed range [trimBegin, trimEnd] sampled
///    U × 2 (vertex i·2 + j: s = j on ruling i), "quads", "grid", "warp_angle_deg" [U·2,1] (the
///    warp of the vertex's ruling, metrics::warpAngleDeg);
///  * "rulings" [R,6] (C1 end, C2 end); "curves" {"c1","c2"} [C,3] sampled over each curve's
///    domain; "control_points" {"c1","c2"} [n,3] (row k is target {"curve":"c1","index":k});
///  * "mapping": {"sigma" [M,2] rows (t, σ(t)) over σ's domain, "initial" [M,2] rows (t, σ0(t))
///    with σ0 the affine map of C1's domain onto C2's (T = t in the curves' normalized
///    parameters: the solver's starting point), "samples" [K,2] rows (t_i, warp_i in degrees),
///    "trim" [t0, t1], "domain_c1", "domain_c2" [begin, end]};
///  * "development": the sampled quads unrolled (unrollRulingGrid), {"vertices","quads"}.
nlohmann::json quasiStripGeometryJson(const models::quasi_strip::QuasiStripModel& model, int uSamples = 96,
                                      int rulings = 32, int mappingSamples = 101, int curveSamples = 128);

/// Sampled conical_strip geometry (Chu et al.) for drawing and editing (docs/protocol.md,
/// "conical_strip geometry"); a model not solved yet has only its curves and control points:
///  * "surface": every patch sampled at `samplesPerPatch`+1 rulings × 2 (vertex rows 2i: a(u_i),
///    2i+1: b(u_i)), concatenated in patch order; "quads" [Q,4], "quad_patch" [Q,1] int32,
///    per-vertex "patch_type" [N,1] (3 triangular, 4 quadrilateral) and "normal_jump_deg" [N,1]
///    (the angle between the normals of the neighbouring patches across the patch's end rulings,
///    interpolated linearly along the patch: 0 everywhere on a G1 strip);
///  * "patches": {"type" [P,1] int32 (3|4), "base" (one letter P|Q per patch, a string),
///    "normal_jump_deg" [P,1] (larger of its two end rulings), "projection_points" [P,3] (O of eq. 3;
///    non-finite for a cylindrical patch, f = 1)};
///  * "rulings" [P+1,6] (the patch boundaries, P side first); "curves" {"p","q"} [C,3];
///    "control_points" {"p","q"} [n,3]; "samples" {"p" [np,3], "q" [nq,3]} (Step 1's points);
///  * "development": {"vertices" [2·P·(S+1),2] (each unfolded patch's boundary images, rows 2i
///    on P and 2i+1 on Q), "quads", "quad_patch"} from ConicalStripResult::unfolded, or null.
nlohmann::json conicalStripGeometryJson(const models::conical_strip::ConicalStripModel& model,
                                        int samplesPerPatch = 8, int curveSamples = 128);

/// quad_mesh geometry (Jiang et al. 2020) for drawing and editing (docs/protocol.md, "quad_mesh
/// geometry"), design units:
///  * "kind": "quad_mesh";
///  * "mesh" [V,3] (M), "unfolding" [V,3] (M′; z = 0 when "planar"), "faces" [F,4] int32 (ccw;
///    a triangle has −1 in column 3), "edges" [E,2] int32 (each once, i < j), "edge_boundary"
///    [E,1] int32 (1 on the boundary), "edge_length_error" [E,1] ((l′ − l)/l per edge: L-Err's
///    parts), "face_area_error" [F,1] ((A′ − A)/A per face);
///  * "glue" [G,2] int32 vertex pairs glued on M, "glue_unfolding" [G′,2] on M′;
///  * "variable" ("mesh" | "unfolding" | "both"), "planar" (bool), "conformal" (bool);
///  * "curvature": null unless the design asks for the Gauss image, else per face "gauss" [F,1],
///    "mean" [F,1], "kappa1", "kappa2" [F,1] and "rulings" [F,6] (a segment through the face's
///    centre along its ruling direction, half the face's size each way; where |K| is not small
///    against κ1² the segment has zero length);
///  * "spline" (only with a control net): splineGeometryJson of the current control points.
nlohmann::json quadMeshGeometryJson(const models::quad_mesh::QuadMeshModel& model,
                                    const models::quad_mesh::QuadMeshQuality& quality);

/// The spline surface M^∞ of a control net (issue 14) for the browser: "control" [P,3] float32
/// control points, "control_edges" [E,2] int32 (the patches' grid edges, each once), "rounds",
/// "patches" (per patch "rows", "columns" and row-major float32 "points" [rows·columns,3] of M^∞
/// sampled 6 per span, "gauss_scaled" [rows·columns,1] K · diameter²), "rulings" (float32
/// polylines [n,3] where M^∞ is developable and curved), "gauss_max_scaled", "gauss_mean_scaled",
/// "shared_sides", "normal_jump_max_deg" (models::quad_mesh::analyzeSplineSurface).
nlohmann::json splineGeometryJson(const models::quad_mesh::ControlNet& net, const Eigen::MatrixX3d& points);

}  // namespace devsurf::proto
