// IGES export (entity 128 B-spline surfaces, 126 B-spline curves) read back by an independent
// reader, OpenCascade's IGESControl_Reader: the surfaces and curves it builds agree with ours at
// sample points to 1e-9 relative.

#include <gtest/gtest.h>

#include <BRep_Tool.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_Curve.hxx>
#include <Geom_Surface.hxx>
#include <IGESControl_Reader.hxx>
#include <Interface_Static.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "devsurf/io/IgesWriter.h"
#include "devsurf/spline/Basis.h"
#include "devsurf/spline/BSplineCurve.h"
#include "support/TempDir.h"

namespace devsurf::io {
namespace {

/// A degree 1 × 3 ruled surface between two cubic curves with non-uniform knots (the shape of a
/// strip converted by Bo et al.'s Algorithm 1), 2 × 6 control points.
IgesSurface ruledSurface() {
  IgesSurface s;
  s.degreeU = 3;
  s.degreeV = 1;
  s.nu = 6;
  s.nv = 2;
  s.knotsU = {0, 0, 0, 0, 0.3, 0.55, 1, 1, 1, 1};
  s.knotsV = {0, 0, 1, 1};
  s.points.resize(12, 3);
  for (int i = 0; i < 6; ++i) {
    s.points.row(i) << i * 20.0, 3.0 * std::sin(i), 0.5 * i * i;                 // a(u): v = 0
    s.points.row(6 + i) << i * 19.0 + 4.0, 30.0 + 2.0 * std::cos(i), 10.0 - i;  // b(u): v = 1
  }
  s.label = "STRIP";
  return s;
}

/// S(u, v) of an IgesSurface, evaluated with our own basis functions.
Eigen::Vector3d evaluate(const IgesSurface& s, double u, double v) {
  const spline::KnotVector ku = spline::KnotVector::clamped(s.degreeU, s.knotsU, s.nu);
  const spline::KnotVector kv = spline::KnotVector::clamped(s.degreeV, s.knotsV, s.nv);
  const spline::EvaluationMatrix Nu = spline::evaluationMatrix(ku, {u}, 0);
  const spline::EvaluationMatrix Nv = spline::evaluationMatrix(kv, {v}, 0);
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (spline::EvaluationMatrix::InnerIterator a(Nu, 0); a; ++a)
    for (spline::EvaluationMatrix::InnerIterator b(Nv, 0); b; ++b)
      p += a.value() * b.value() * s.points.row(a.col() + s.nu * b.col()).transpose();
  return p;
}

TEST(IgesWriter, OpenCascadeReadsBackTheSurfaceAndCurvesExactly) {
  const IgesSurface surface = ruledSurface();
  IgesCurve a;
  a.degree = 3;
  a.knots = surface.knotsU;
  a.points = surface.points.topRows(6);
  a.label = "C1";
  IgesCurve b = a;
  b.points = surface.points.bottomRows(6);
  b.weights = Eigen::VectorXd::Constant(6, 1.0);
  b.weights[2] = 2.0;  // rational: written with PROP3 = 0
  b.label = "C2";
  testing::TempDir dir;
  const std::string path = (dir.path() / "strip.igs").string();
  IgesHeader header;
  header.units = "mm";
  header.timestamp = "20261122.120000";
  writeIges(path, {surface}, {a, b}, header);

  IGESControl_Reader reader;
  ASSERT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone);
  reader.SetReadVisible(Standard_False);
  EXPECT_EQ(reader.NbRootsForTransfer(), 3);
  reader.TransferRoots();
  const TopoDS_Shape shape = reader.OneShape();

  // The surface.
  int faces = 0;
  for (TopExp_Explorer it(shape, TopAbs_FACE); it.More(); it.Next()) {
    ++faces;
    const Handle(Geom_Surface) g = BRep_Tool::Surface(TopoDS::Face(it.Current()));
    const Handle(Geom_BSplineSurface) bs = Handle(Geom_BSplineSurface)::DownCast(g);
    ASSERT_FALSE(bs.IsNull()) << "an entity 128 comes back as a B-spline surface";
    EXPECT_EQ(bs->UDegree(), 3);
    EXPECT_EQ(bs->VDegree(), 1);
    const double size = surface.points.cwiseAbs().maxCoeff();
    double worst = 0.0;
    for (int i = 0; i <= 20; ++i)
      for (int j = 0; j <= 4; ++j) {
        const double u = i / 20.0, v = j / 4.0;
        const gp_Pnt p = bs->Value(u, v);
        const Eigen::Vector3d ours = evaluate(surface, u, v);
        worst = std::max(worst, (Eigen::Vector3d(p.X(), p.Y(), p.Z()) - ours).norm() / size);
      }
    EXPECT_LT(worst, 1e-9);
  }
  EXPECT_EQ(faces, 1);

  // The curves, polynomial and rational.
  std::vector<IgesCurve> expected = {a, b};
  int edges = 0;
  for (TopExp_Explorer it(shape, TopAbs_EDGE, TopAbs_FACE); it.More(); it.Next()) {
    Standard_Real first = 0, last = 0;
    const Handle(Geom_Curve) g = BRep_Tool::Curve(TopoDS::Edge(it.Current()), first, last);
    ASSERT_FALSE(g.IsNull());
    ASSERT_LT(edges, 2);
    const IgesCurve& c = expected[static_cast<std::size_t>(edges)];
    spline::BSplineCurve ours;
    ours.knots = spline::KnotVector::clamped(c.degree, c.knots, static_cast<int>(c.points.rows()));
    ours.points = c.points;
    double worst = 0.0;
    for (int i = 0; i <= 40; ++i) {
      const double t = first + (last - first) * i / 40.0;
      const gp_Pnt p = g->Value(t);
      Eigen::Vector3d q;
      if (c.weights.size() == 0) {
        q = ours.evaluate(t, 0);
      } else {  // rational: evaluate the homogeneous curve
        spline::BSplineCurve h;
        h.knots = ours.knots;
        h.points.resize(c.points.rows(), 4);
        for (Eigen::Index k = 0; k < c.points.rows(); ++k) {
          h.points.row(k).head<3>() = c.weights[k] * c.points.row(k);
          h.points(k, 3) = c.weights[k];
        }
        const Eigen::VectorXd w = h.evaluate(t, 0);
        q = w.head<3>() / w[3];
      }
      worst = std::max(worst, (Eigen::Vector3d(p.X(), p.Y(), p.Z()) - q).norm() / c.points.cwiseAbs().maxCoeff());
    }
    EXPECT_LT(worst, 1e-9) << "curve " << edges;
    ++edges;
  }
  EXPECT_EQ(edges, 2);
}

TEST(IgesWriter, FollowsTheFixedColumnLayout) {
  const std::string text = igesDocument({ruledSurface()}, {}, IgesHeader{"x.igs", "a", "o", "20261122.120000", "in"});
  std::size_t start = 0;
  int lines = 0;
  while (start < text.size()) {
    const std::size_t end = text.find('\n', start);
    ASSERT_NE(end, std::string::npos);
    EXPECT_EQ(end - start, 80u) << "line " << lines;
    const char section = text[start + 72];
    EXPECT_NE(std::string("SGDPT").find(section), std::string::npos);
    start = end + 1;
    ++lines;
  }
  EXPECT_NE(text.find("4HINCH"), std::string::npos);
  EXPECT_NE(text.find("     128"), std::string::npos);
}

// A scene's name in UTF-8 ("40 × 40 sheet") reaches the global section as ASCII, one character
// per character, so that the Hollerith counts and the 80 columns stay counts of bytes.
TEST(IgesWriter, WritesNonAsciiNamesAsAscii) {
  const std::string text = igesDocument({ruledSurface()}, {},
                                        IgesHeader{"40 \xC3\x97 40 sheet \xE2\x80\x94 n\xC2\xB0 1.igs", "Jos\xC3\xA9", "o",
                                                   "20261122.120000", "mm"});
  for (const char c : text) EXPECT_TRUE(static_cast<unsigned char>(c) < 0x80) << "byte " << static_cast<int>(static_cast<unsigned char>(c));
  EXPECT_NE(text.find("24H40 x 40 sheet ? n? 1.igs"), std::string::npos);
  EXPECT_NE(text.find("4HJos?"), std::string::npos);
  std::size_t start = 0;
  while (start < text.size()) {
    const std::size_t end = text.find('\n', start);
    ASSERT_NE(end, std::string::npos);
    EXPECT_EQ(end - start, 80u);
    start = end + 1;
  }
}

TEST(IgesWriter, RejectsInconsistentEntitiesNamingThem) {
  IgesSurface s = ruledSurface();
  s.knotsU.pop_back();
  try {
    igesDocument({s}, {});
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("surfaces[0].knotsU"), std::string::npos) << e.what();
  }
  IgesCurve c;
  c.degree = 3;
  c.knots = {0, 0, 0, 0, 1, 1, 1, 1};
  c.points = Eigen::MatrixX3d::Zero(4, 3);
  c.points(2, 1) = std::nan("");
  EXPECT_THROW(igesDocument({}, {c}), std::invalid_argument);
}

}  // namespace
}  // namespace devsurf::io
