#pragma once

#include <nlohmann/json.hpp>

#include "devsurf/models/quad_mesh/QuadMeshDesign.h"

namespace devsurf::proto {

/// The "quad_mesh" model object of a scene (scene.schema.json "quad_mesh_model"), already
/// validated against the schema, as a design. Indices are checked here (SceneError naming
/// "model.glue[0].pairs[3]", "model.faces[7]"); the model's own checks follow in sceneFromJson.
/// @throws SceneError
models::quad_mesh::QuadMeshDesign quadMeshFromJson(const nlohmann::json& model);

/// The design as the scene's model object (sceneFromJson reads it back to the same design).
nlohmann::json quadMeshToJson(const models::quad_mesh::QuadMeshDesign& design);

}  // namespace devsurf::proto
