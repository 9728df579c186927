#pragma once

#include <nlohmann/json.hpp>

#include "devsurf/models/quad_mesh/QuadMeshDesign.h"

namespace devsurf::proto {

/// The "quad_mesh" model object of a scene (scene.schema.json "quad_mesh_model"), already
/// validated against the schema, as a design. Indices are checked here (SceneError naming
/// "model.glue[0][1]", "model.mesh.faces[7][2]"); the model's own checks follow in sceneFromJson.
/// @throws SceneError
models::quad_mesh::QuadMeshDesign quadMeshFromJson(const nlohmann::json& model);

/// Rewrites a "quad_mesh" model object written in the spelling devsurf wrote before issue 13's
/// contract into the contract's, in place, before validation: `faces` + `mesh: [points]` →
/// `mesh: {vertices, faces}`; `unfolding: [points]` → `unfolding: {vertices}`; `unfolding_planar`
/// → `unfolding.planar`; `variable` → `variables`; `reference.triangles` → `reference.faces`.
/// (`fixed` as {vertex} objects and `glue` as {on, pairs} objects are valid contract items.) A
/// model already in the contract's spelling is left as it is; anything else is left for the
/// schema to name.
void acceptLegacyQuadMeshSpelling(nlohmann::json& model);

/// The design as the scene's model object in the contract's spelling (sceneFromJson reads it
/// back to the same design): `mesh: {vertices, faces}`, `unfolding: {vertices, planar: false
/// only when not planar}`, `variables`, `fixed` as indices of M (objects for M′ and control
/// points), `glue` as pairs of M then one {on: "unfolding", pairs}, `reference: {vertices, faces}`.
nlohmann::json quadMeshToJson(const models::quad_mesh::QuadMeshDesign& design);

}  // namespace devsurf::proto
