// IGES exports of the issue-6 presets (and a strip and a composite) read back by OpenCascade: every
// entity-128 surface matches the model at sample points to 1e-9 relative, in the scene's units.

#include <gtest/gtest.h>

#include <BRep_Tool.hxx>
#include <Geom_BSplineSurface.hxx>
#include <IGESControl_Reader.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>

#include <fstream>
#include <functional>
#include <string>

#include "devsurf/proto/Scene.h"
#include "devsurf/server/SceneSolver.h"
#include "support/TempDir.h"

namespace devsurf::server {
namespace {

using nlohmann::json;

json readExample(const std::string& name) {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/" + name);
  return json::parse(file);
}

/// The B-spline surfaces of an IGES file as OpenCascade reads them (lengths in OpenCascade's
/// default unit, millimetres: the header's unit flag scales them).
std::vector<Handle(Geom_BSplineSurface)> readSurfaces(const std::string& content, const std::string& path) {
  std::ofstream(path) << content;
  IGESControl_Reader reader;
  EXPECT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone);
  reader.TransferRoots();
  std::vector<Handle(Geom_BSplineSurface)> surfaces;
  for (TopExp_Explorer it(reader.OneShape(), TopAbs_FACE); it.More(); it.Next()) {
    const Handle(Geom_BSplineSurface) s =
        Handle(Geom_BSplineSurface)::DownCast(BRep_Tool::Surface(TopoDS::Face(it.Current())));
    EXPECT_FALSE(s.IsNull());
    if (!s.IsNull()) surfaces.push_back(s);
  }
  return surfaces;
}

/// Largest distance between the surface read back (scaled back to design units) and the model's
/// point at (u, v) over a 41 × 5 grid of [u0, u1] × [0, 1].
double worstDistance(const Handle(Geom_BSplineSurface)& s, double mmPerUnit, double u0, double u1,
                     const std::function<Eigen::Vector3d(double, double)>& ours) {
  double worst = 0.0;
  for (int i = 0; i <= 40; ++i)
    for (int j = 0; j <= 4; ++j) {
      const double u = u0 + (u1 - u0) * i / 40.0, v = j / 4.0;
      const gp_Pnt p = s->Value(u, v);
      worst = std::max(worst, (Eigen::Vector3d(p.X(), p.Y(), p.Z()) / mmPerUnit - ours(u, v)).norm());
    }
  return worst;
}

class StripBetweenCurvesIges : public ::testing::TestWithParam<std::string> {};

TEST_P(StripBetweenCurvesIges, SurfacesReadBackByOpenCascadeMatchTheModel) {
  const proto::Scene scene = proto::sceneFromJson(readExample(GetParam()));
  SceneSolver solver(scene);
  solver.solve();
  const ExportedFile file = solver.exportAs("iges");
  EXPECT_EQ(file.mediaType, "model/iges");
  devsurf::testing::TempDir dir;
  const auto surfaces = readSurfaces(file.content, (dir.path() / "strip.igs").string());
  const double mmPerUnit = proto::millimetresPerUnit(scene.units);
  double size = 1.0;  // relative to the largest coordinate of the design
  if (std::holds_alternative<proto::QuasiStripScene>(scene.model)) {
    const models::quasi_strip::QuasiStripModel& model = solver.quasiStripModel();
    const models::quasi_strip::QuasiStripResults& r = model.results();
    size = std::max({size, model.design().c1.points.cwiseAbs().maxCoeff(), model.design().c2.points.cwiseAbs().maxCoeff()});
    ASSERT_EQ(surfaces.size(), 1u);
    // u is C1's parameter over the trimmed range, v across: the ruled surface (1 − v) C1(u) + v C2(σ(u)).
    EXPECT_LE(worstDistance(surfaces[0], mmPerUnit, r.trimBegin, r.trimEnd,
                            [&model](double u, double v) { return model.ruledSurfacePoint(v, u); }),
              1e-9 * size);
  } else if (std::holds_alternative<models::conical_strip::ConicalStripDesign>(scene.model)) {
    const auto& patches = solver.conicalStripModel().result().patches;
    ASSERT_EQ(surfaces.size(), patches.size());
    for (std::size_t k = 0; k < patches.size(); ++k) {
      const auto& p = patches[k];
      size = std::max({size, p.a.cwiseAbs().maxCoeff(), p.b.cwiseAbs().maxCoeff()});
      EXPECT_LE(worstDistance(surfaces[k], mmPerUnit, 0.0, 1.0,
                              [&p](double u, double v) { return ((1.0 - v) * p.pointA(u) + v * p.pointB(u)).eval(); }),
                1e-9 * size)
          << "patch " << k;
    }
  } else if (solver.isStrip()) {
    const models::strip::StripDesign d = solver.stripModel().design();
    size = std::max({size, d.a.points.cwiseAbs().maxCoeff(), d.b.points.cwiseAbs().maxCoeff()});
    ASSERT_EQ(surfaces.size(), 1u);
    EXPECT_LE(worstDistance(surfaces[0], mmPerUnit, d.a.knots.domainBegin(), d.a.knots.domainEnd(),
                            [&d](double u, double v) {
                              return ((1.0 - v) * d.a.evaluate(u, 0) + v * d.b.evaluate(u, 0)).eval();
                            }),
              1e-9 * size);
  } else {
    models::composite::CompositeModel& model = solver.compositeModel();
    int strips = 0;
    for (int f = 0; f < model.topology().numFaces(); ++f)
      if (model.topology().face(f).type != models::composite::FaceType::Planar) ++strips;
    EXPECT_GE(surfaces.size(), static_cast<std::size_t>(strips));
    if (strips == model.topology().numFaces()) {
      ASSERT_EQ(surfaces.size(), static_cast<std::size_t>(strips));
      for (int f = 0; f < strips; ++f) {
        const auto [a, b] = model.faceCurves(f);
        size = std::max({size, a.points.cwiseAbs().maxCoeff(), b.points.cwiseAbs().maxCoeff()});
        EXPECT_LE(worstDistance(surfaces[static_cast<std::size_t>(f)], mmPerUnit, a.knots.domainBegin(),
                                a.knots.domainEnd(),
                                [&a = a, &b = b](double u, double v) {
                                  return ((1.0 - v) * a.evaluate(u, 0) + v * b.evaluate(u, 0)).eval();
                                }),
                  1e-9 * size)
            << "face " << f;
      }
    }
  }
}

TEST(StripBetweenCurvesIges, TheScenesUnitsAreTheIgesUnits) {
  // Same design, unit cm: OpenCascade (millimetres) reads it back ten times larger.
  json scene = readExample("quasi-strip-twisted.json");
  scene["units"] = "cm";
  SceneSolver cm(proto::sceneFromJson(scene));
  cm.solve();
  scene["units"] = "mm";
  SceneSolver mm(proto::sceneFromJson(scene));
  mm.solve();
  devsurf::testing::TempDir dir;
  const auto inCm = readSurfaces(cm.exportAs("iges").content, (dir.path() / "cm.igs").string());
  const auto inMm = readSurfaces(mm.exportAs("iges").content, (dir.path() / "mm.igs").string());
  ASSERT_EQ(inCm.size(), 1u);
  ASSERT_EQ(inMm.size(), 1u);
  Standard_Real u0, u1, v0, v1;
  inMm[0]->Bounds(u0, u1, v0, v1);
  const gp_Pnt a = inCm[0]->Value(0.5 * (u0 + u1), 0.5), b = inMm[0]->Value(0.5 * (u0 + u1), 0.5);
  EXPECT_NEAR(a.X(), 10.0 * b.X(), 1e-9 * std::abs(a.X()) + 1e-12);
  EXPECT_NEAR(a.Z(), 10.0 * b.Z(), 1e-9 * std::abs(a.Z()) + 1e-12);
}

INSTANTIATE_TEST_SUITE_P(Examples, StripBetweenCurvesIges,
                         ::testing::Values("quasi-strip-hull.json", "quasi-strip-brim.json",
                                           "quasi-strip-twisted.json", "conical-strip-hull.json",
                                           "conical-strip-brim.json", "conical-strip-twisted.json",
                                           "strip-twisted.json", "composite-curved-fold.json"),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param.substr(0, info.param.size() - 5);
                           for (char& c : name)
                             if (c == '-') c = '_';
                           return name;
                         });

}  // namespace
}  // namespace devsurf::server
