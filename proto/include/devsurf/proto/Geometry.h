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

/// Sampled strip geometry for drawing: surface grid, boundary curves, control points, rulings,
/// per-vertex warp angle (deg) for colouring. Sizes documented in docs/protocol.md.
nlohmann::json stripGeometryJson(const models::strip::StripModel& model, int uSamples = 96,
                                 int vSamples = 2, int rulings = 32);

}  // namespace devsurf::proto
