// A composite exported as IGES (faces as entity 128, S edges as 126) and read back by
// OpenCascade: every face surface agrees with the model's ruled faces (1 − v)·a(u) + v·b(u).

#include <gtest/gtest.h>

#include <BRep_Tool.hxx>
#include <Geom_BSplineSurface.hxx>
#include <IGESControl_Reader.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>

#include <string>

#include "devsurf/io/IgesWriter.h"
#include "devsurf/models/composite/CompositeModel.h"
#include "solver/models/composite/CompositeFixtures.h"
#include "support/TempDir.h"

namespace devsurf::models::composite {
namespace {

TEST(CompositeIges, FoldedSheetFacesReadBackAsTheModelsRuledSurfaces) {
  CompositeDesign design = fixtures::foldedCylinders(35.0);
  CompositeModel model(design);
  std::vector<io::IgesSurface> surfaces;
  std::vector<io::IgesCurve> curves;
  model.igesEntities(surfaces, curves);
  ASSERT_EQ(surfaces.size(), static_cast<std::size_t>(model.topology().numFaces()));
  EXPECT_GE(curves.size(), 1u);
  devsurf::testing::TempDir dir;
  const std::string path = (dir.path() / "composite.igs").string();
  io::writeIges(path, surfaces, curves);

  IGESControl_Reader reader;
  ASSERT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone);
  reader.TransferRoots();
  const TopoDS_Shape shape = reader.OneShape();
  int f = 0;
  for (TopExp_Explorer it(shape, TopAbs_FACE); it.More(); it.Next(), ++f) {
    const Handle(Geom_BSplineSurface) s =
        Handle(Geom_BSplineSurface)::DownCast(BRep_Tool::Surface(TopoDS::Face(it.Current())));
    ASSERT_FALSE(s.IsNull());
    const auto [a, b] = model.faceCurves(f);
    const double u0 = a.knots.domainBegin(), u1 = a.knots.domainEnd();
    double worst = 0.0;
    for (int i = 0; i <= 30; ++i)
      for (int j = 0; j <= 2; ++j) {
        const double u = u0 + (u1 - u0) * i / 30.0, v = j / 2.0;
        const gp_Pnt p = s->Value(u, v);
        const Eigen::Vector3d ours = (1.0 - v) * a.evaluate(u, 0) + v * b.evaluate(u, 0);
        worst = std::max(worst, (Eigen::Vector3d(p.X(), p.Y(), p.Z()) - ours).norm());
      }
    EXPECT_LT(worst, 1e-9 * std::max(1.0, a.points.cwiseAbs().maxCoeff())) << "face " << f;
  }
  EXPECT_EQ(f, model.topology().numFaces());
}

}  // namespace
}  // namespace devsurf::models::composite
