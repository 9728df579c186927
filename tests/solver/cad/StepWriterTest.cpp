// STEP files written by cad::stepDocument read back by OpenCascade's STEPControl_Reader: the
// surfaces come back with the same control points, knots and weights (1e-9), in the file's
// unit; sewn patches sharing a side come back as one shell with that side as one shared edge.
#include <gtest/gtest.h>

#include <BRep_Tool.hxx>
#include <Geom_BSplineSurface.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <STEPControl_Reader.hxx>
#include <TopAbs_ShapeEnum.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>

#include <cmath>
#include <fstream>
#include <stdexcept>

#include "devsurf/cad/StepWriter.h"
#include "support/TempDir.h"

namespace devsurf::cad {
namespace {

std::vector<double> clampedKnots(int n) {
  std::vector<double> k(4, 0.0);
  for (int i = 1; i <= n - 4; ++i) k.push_back(i);
  for (int i = 0; i < 4; ++i) k.push_back(n - 3);
  return k;
}

/// A bicubic nu × nv patch over [x0, x0 + 1] × [0, 1], wavy in z.
io::IgesSurface patch(int nu, int nv, double x0, double wave) {
  io::IgesSurface s;
  s.degreeU = s.degreeV = 3;
  s.nu = nu;
  s.nv = nv;
  s.knotsU = clampedKnots(nu);
  s.knotsV = clampedKnots(nv);
  s.points.resize(nu * nv, 3);
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i)
      s.points.row(i + nu * j) << x0 + i / (nu - 1.0), j / (nv - 1.0), wave * std::sin(3.1 * i + 1.7 * j) + 0.123456789012;
  return s;
}

struct ReadBack {
  TopoDS_Shape shape;
  std::vector<Handle(Geom_BSplineSurface)> surfaces;
};

ReadBack readStep(const std::string& content, const std::string& path, const char* cascadeUnit = "MM") {
  std::ofstream(path) << content;
  Interface_Static::SetCVal("xstep.cascade.unit", cascadeUnit);
  STEPControl_Reader reader;
  EXPECT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone);
  reader.TransferRoots();
  ReadBack r;
  r.shape = reader.OneShape();
  for (TopExp_Explorer it(r.shape, TopAbs_FACE); it.More(); it.Next()) {
    const Handle(Geom_BSplineSurface) s =
        Handle(Geom_BSplineSurface)::DownCast(BRep_Tool::Surface(TopoDS::Face(it.Current())));
    EXPECT_FALSE(s.IsNull());
    if (!s.IsNull()) r.surfaces.push_back(s);
  }
  return r;
}

/// Largest difference of control points, knots and weights between what was written and read.
double difference(const io::IgesSurface& written, const Handle(Geom_BSplineSurface)& read, double scale = 1.0) {
  EXPECT_EQ(read->NbUPoles(), written.nu);
  EXPECT_EQ(read->NbVPoles(), written.nv);
  EXPECT_EQ(read->UDegree(), written.degreeU);
  EXPECT_EQ(read->VDegree(), written.degreeV);
  if (read->NbUPoles() != written.nu || read->NbVPoles() != written.nv) return 1e300;
  double worst = 0.0;
  for (int j = 0; j < written.nv; ++j)
    for (int i = 0; i < written.nu; ++i) {
      const gp_Pnt p = read->Pole(i + 1, j + 1);
      worst = std::max(worst, (Eigen::Vector3d(p.X(), p.Y(), p.Z()) * scale -
                               written.points.row(i + written.nu * j).transpose()).norm());
      if (written.weights.size()) worst = std::max(worst, std::abs(read->Weight(i + 1, j + 1) - written.weights[i + written.nu * j]));
    }
  TColStd_Array1OfReal uKnots(1, read->NbUPoles() + read->UDegree() + 1);
  read->UKnotSequence(uKnots);
  for (int k = 0; k < uKnots.Length(); ++k) worst = std::max(worst, std::abs(uKnots(k + 1) - written.knotsU[k]));
  TColStd_Array1OfReal vKnots(1, read->NbVPoles() + read->VDegree() + 1);
  read->VKnotSequence(vKnots);
  for (int k = 0; k < vKnots.Length(); ++k) worst = std::max(worst, std::abs(vKnots(k + 1) - written.knotsV[k]));
  return worst;
}

TEST(StepWriter, SurfacesReadBackByOpenCascadeHaveTheWrittenControlPointsKnotsAndWeights) {
  std::vector<io::IgesSurface> surfaces = {patch(7, 5, 0.0, 0.2), patch(4, 9, 2.0, 0.05)};
  io::IgesSurface rational = patch(5, 5, 4.0, 0.1);
  rational.weights = Eigen::VectorXd::LinSpaced(25, 0.5, 2.0);
  surfaces.push_back(rational);
  devsurf::testing::TempDir dir;
  const std::string text = stepDocument(surfaces);
  EXPECT_NE(text.find("ISO-10303-21"), std::string::npos);
  EXPECT_NE(text.find("AUTOMOTIVE_DESIGN"), std::string::npos) << "AP214";
  EXPECT_NE(text.find("B_SPLINE_SURFACE_WITH_KNOTS"), std::string::npos);
  const ReadBack r = readStep(text, (dir.path() / "three.step").string());
  ASSERT_EQ(r.surfaces.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_LT(difference(surfaces[k], r.surfaces[k]), 1e-9) << "surface " << k;
}

TEST(StepWriter, TheFileUnitIsTheScenesAndOpenCascadeConvertsFromIt) {
  const std::vector<io::IgesSurface> surfaces = {patch(5, 5, 0.0, 0.2)};
  StepOptions options;
  options.units = "cm";
  devsurf::testing::TempDir dir;
  const std::string text = stepDocument(surfaces, options);
  // Read in millimetres: every coordinate ten times the written one.
  const ReadBack r = readStep(text, (dir.path() / "cm.step").string(), "MM");
  ASSERT_EQ(r.surfaces.size(), 1u);
  EXPECT_LT(difference(surfaces[0], r.surfaces[0], 0.1), 1e-9);
}

TEST(StepWriter, SewnPatchesSharingASideReadBackAsOneShellWithThatSideSharedByBoth) {
  // Two 6 × 6 patches: A's last column of points is B's first.
  io::IgesSurface a = patch(6, 6, 0.0, 0.1), b = patch(6, 6, 1.0, 0.1);
  for (int j = 0; j < 6; ++j) b.points.row(0 + 6 * j) = a.points.row(5 + 6 * j);
  StepOptions options;
  options.sew = true;
  devsurf::testing::TempDir dir;
  const ReadBack r = readStep(stepDocument({a, b}, options), (dir.path() / "sewn.step").string());
  ASSERT_EQ(r.surfaces.size(), 2u);
  EXPECT_LT(difference(a, r.surfaces[0]), 1e-9);
  EXPECT_LT(difference(b, r.surfaces[1]), 1e-9);
  int shells = 0;
  for (TopExp_Explorer it(r.shape, TopAbs_SHELL); it.More(); it.Next()) ++shells;
  EXPECT_EQ(shells, 1);
  TopTools_IndexedDataMapOfShapeListOfShape facesOfEdge;
  TopExp::MapShapesAndAncestors(r.shape, TopAbs_EDGE, TopAbs_FACE, facesOfEdge);
  int shared = 0, free = 0;
  for (int e = 1; e <= facesOfEdge.Extent(); ++e) (facesOfEdge(e).Extent() == 2 ? shared : free) += 1;
  EXPECT_EQ(shared, 1);
  EXPECT_EQ(free, 6);
}

TEST(StepWriter, MalformedSurfacesAreRefusedNamingTheSurface) {
  io::IgesSurface s = patch(5, 5, 0.0, 0.1);
  s.knotsU.pop_back();
  try {
    stepDocument({patch(5, 5, 0.0, 0.1), s});
    FAIL() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("surfaces[1].knotsU"), std::string::npos) << e.what();
  }
  s = patch(5, 5, 0.0, 0.1);
  s.points(3, 2) = std::nan("");
  EXPECT_THROW(stepDocument({s}), std::invalid_argument);
  StepOptions options;
  options.units = "furlong";
  EXPECT_THROW(stepDocument({patch(5, 5, 0.0, 0.1)}, options), std::invalid_argument);
  EXPECT_THROW(stepDocument({}), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::cad
