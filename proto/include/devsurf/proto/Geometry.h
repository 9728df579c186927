#pragma once

#include <string>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

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

}  // namespace devsurf::proto
