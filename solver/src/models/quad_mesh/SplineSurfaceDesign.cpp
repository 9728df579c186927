// The design of a developable spline surface (004_… §4, Algorithm 2): S^k(M) of a control net.
#include <stdexcept>

#include "devsurf/models/quad_mesh/QuadMeshDesign.h"
#include "devsurf/models/quad_mesh/SplineSurface.h"

namespace devsurf::models::quad_mesh {

QuadMeshDesign splineSurfaceDesign(ControlNet net) {
  SplineRefinement refinement = splineRefinement(net);
  QuadMeshDesign d;
  d.mesh = refinement.subdivision * net.points;
  d.faces = std::move(refinement.faces);
  d.variable = VariableMeshes::Both;
  d.control = std::move(net);
  return d;
}

}  // namespace devsurf::models::quad_mesh
