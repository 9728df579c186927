// The CAD output of developable spline surfaces (issue 14): every preset with a control net,
// solved, exported as STEP (OpenCascade's writer) and IGES (our entity-128 writer), and read back
// by OpenCascade's STEP and IGES readers: the same bicubic patches with the solved control points
// to 1e-9, and a watertight model as one shell whose shared sides are shared edges.
#include <gtest/gtest.h>

#include <BRepMesh_IncrementalMesh.hxx>
#include <BRep_Tool.hxx>
#include <Geom_BSplineSurface.hxx>
#include <IGESControl_Reader.hxx>
#include <Interface_Static.hxx>
#include <STEPControl_Reader.hxx>
#include <StlAPI_Writer.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>

#include <fstream>
#include <iostream>
#include <string>

#include "devsurf/models/quad_mesh/SplineSurface.h"
#include "devsurf/proto/Scene.h"
#include "devsurf/server/SceneSolver.h"
#include "support/Presets.h"
#include "support/TempDir.h"

namespace devsurf::server {
namespace {

using nlohmann::json;
namespace qm = models::quad_mesh;

std::vector<std::string> splinePresets() {
  std::vector<std::string> out;
  for (const std::string& name : devsurf::testing::presetFiles()) {
    const json doc = devsurf::testing::readPreset(name);
    if (doc["model"].value("kind", "") == "quad_mesh" && doc["model"].contains("control")) out.push_back(name);
  }
  return out;
}

struct ReadBack {
  TopoDS_Shape shape;
  std::vector<Handle(Geom_BSplineSurface)> surfaces;
};

ReadBack collect(const TopoDS_Shape& shape) {
  ReadBack r;
  r.shape = shape;
  for (TopExp_Explorer it(shape, TopAbs_FACE); it.More(); it.Next()) {
    const Handle(Geom_BSplineSurface) s =
        Handle(Geom_BSplineSurface)::DownCast(BRep_Tool::Surface(TopoDS::Face(it.Current())));
    EXPECT_FALSE(s.IsNull());
    if (!s.IsNull()) r.surfaces.push_back(s);
  }
  return r;
}

ReadBack readStep(const std::string& content, const std::string& path) {
  std::ofstream(path) << content;
  Interface_Static::SetCVal("xstep.cascade.unit", "MM");
  STEPControl_Reader reader;
  EXPECT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone);
  reader.TransferRoots();
  return collect(reader.OneShape());
}

ReadBack readIges(const std::string& content, const std::string& path) {
  std::ofstream(path) << content;
  Interface_Static::SetCVal("xstep.cascade.unit", "MM");
  IGESControl_Reader reader;
  EXPECT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone);
  reader.TransferRoots();
  return collect(reader.OneShape());
}

/// Largest distance (design units) between a surface read back (in mm) and the patch's control
/// points, matched by position in the file.
double poleDistance(const qm::SplinePatchSurface& patch, const Handle(Geom_BSplineSurface)& s, double mmPerUnit) {
  EXPECT_EQ(s->UDegree(), 3);
  EXPECT_EQ(s->VDegree(), 3);
  if (s->NbUPoles() != patch.nu || s->NbVPoles() != patch.nv) return 1e300;
  double worst = 0.0;
  for (int j = 0; j < patch.nv; ++j)
    for (int i = 0; i < patch.nu; ++i) {
      const gp_Pnt p = s->Pole(i + 1, j + 1);
      worst = std::max(worst, (Eigen::Vector3d(p.X(), p.Y(), p.Z()) / mmPerUnit -
                               patch.points.row(i + patch.nu * j).transpose()).norm());
    }
  return worst;
}

class SplineSurfaceCad : public ::testing::TestWithParam<std::string> {};

TEST_P(SplineSurfaceCad, StepAndIgesReadBackByOpenCascadeCarryTheSolvedControlPoints) {
  const proto::Scene scene = proto::sceneFromJson(devsurf::testing::readPreset(GetParam()));
  SceneSolver solver(scene);
  solver.solve();
  const qm::QuadMeshModel& model = solver.quadMeshModel();
  const qm::ControlNet net = *model.design().control;
  const std::vector<qm::SplinePatchSurface> patches = qm::splinePatchSurfaces(net, model.controlPoints());
  const double mm = proto::millimetresPerUnit(scene.units);
  const double size = model.controlPoints().cwiseAbs().maxCoeff();
  devsurf::testing::TempDir dir;

  const ExportedFile step = solver.exportAs("step");
  EXPECT_EQ(step.mediaType, "model/step");
  const ReadBack s = readStep(step.content, (dir.path() / "model.step").string());
  ASSERT_EQ(s.surfaces.size(), patches.size());
  for (std::size_t k = 0; k < patches.size(); ++k)
    EXPECT_LT(poleDistance(patches[k], s.surfaces[k], mm), 1e-9 * size) << "STEP patch " << k;

  const ExportedFile iges = solver.exportAs("iges");
  EXPECT_EQ(iges.mediaType, "model/iges");
  const ReadBack g = readIges(iges.content, (dir.path() / "model.igs").string());
  ASSERT_EQ(g.surfaces.size(), patches.size());
  for (std::size_t k = 0; k < patches.size(); ++k)
    EXPECT_LT(poleDistance(patches[k], g.surfaces[k], mm), 1e-9 * size) << "IGES patch " << k;

  // Watertight: the STEP model is one shell, and each side two patches share is one edge of both.
  int shells = 0;
  for (TopExp_Explorer it(s.shape, TopAbs_SHELL); it.More(); it.Next()) ++shells;
  TopTools_IndexedDataMapOfShapeListOfShape facesOfEdge;
  TopExp::MapShapesAndAncestors(s.shape, TopAbs_EDGE, TopAbs_FACE, facesOfEdge);
  int shared = 0;
  for (int e = 1; e <= facesOfEdge.Extent(); ++e) shared += facesOfEdge(e).Extent() == 2 ? 1 : 0;
  const int sharedSides = static_cast<int>(qm::splineSharedSides(net).size());
  std::cout << GetParam() << ": " << patches.size() << " patches, " << shells << " shell(s), " << shared
            << " shared edges (" << sharedSides << " shared sides); STEP " << step.content.size() << " bytes, IGES "
            << iges.content.size() << " bytes\n";
  if (patches.size() > 1) {
    EXPECT_EQ(shells, 1);
  }
  EXPECT_EQ(shared, sharedSides);
  // For a look (scripts/render_mesh.mjs → docs/): the solved model as STEP, and the shape
  // OpenCascade imported from it, tessellated by OpenCascade, as STL.
  if (const char* out = std::getenv("DEVSURF_STEP_OUT")) {
    const std::string base = std::string(out) + "/" + GetParam().substr(0, GetParam().size() - 5);
    std::ofstream(base + ".step") << step.content;
    BRepMesh_IncrementalMesh mesher(s.shape, 1e-3 * size * mm);
    StlAPI_Writer stl;
    EXPECT_TRUE(stl.Write(s.shape, (base + ".imported.stl").c_str()));
  }
}

INSTANTIATE_TEST_SUITE_P(Presets, SplineSurfaceCad, ::testing::ValuesIn(splinePresets()),
                         devsurf::testing::presetTestName<::testing::TestParamInfo<std::string>>);

TEST(SplineSurfaceCad, AMeshWithoutAControlNetHasNoBSplineExport) {
  const proto::Scene scene = proto::sceneFromJson(devsurf::testing::readPreset("quad-bend-sheet.json"));
  SceneSolver solver(scene);
  EXPECT_THROW(solver.exportAs("step"), ExportUnavailable);
  EXPECT_THROW(solver.exportAs("iges"), ExportUnavailable);
}

}  // namespace
}  // namespace devsurf::server
