#pragma once

#include <nlohmann/json.hpp>

#include "devsurf/models/quad_mesh/QuadMeshDesign.h"

namespace devsurf::proto {

/// The "quad_mesh" model object of a scene (scene.schema.json "quad_mesh_model"), already
/// validated against the schema, as a design. Indices are checked here (SceneError naming
/// "model.glue[0].pairs[3]", "model.faces[7]"); the model's own checks follow in sceneFromJson.
/// @throws SceneError
models::quad_mesh::QuadMeshDesign quadMeshFromJson(const nlohmann::json& model);

/// Rewrites a "quad_mesh" model object written in issue 13's spelling into the scene's own, in
/// place, before validation: `mesh: {vertices, faces}` → `mesh` + `faces`; `unfolding: {vertices}`
/// → `unfolding`; `variables` → `variable`; `fixed: [vertex…]` → `[{vertex}…]`; `glue: [[i, j]…]`
/// → `[{on: "mesh", pairs}]`; `reference.faces` → `reference.triangles`. A model already in the
/// scene's spelling is left as it is; anything else is left for the schema to name.
void acceptQuadMeshShorthand(nlohmann::json& model);

/// The design as the scene's model object (sceneFromJson reads it back to the same design).
nlohmann::json quadMeshToJson(const models::quad_mesh::QuadMeshDesign& design);

}  // namespace devsurf::proto
