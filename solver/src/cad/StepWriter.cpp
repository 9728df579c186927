// STEP output through OpenCascade (Debian's libocct-*): B-spline surfaces → faces → (sewn
// shells or a compound) → STEPControl_Writer.
#include "devsurf/cad/StepWriter.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <mutex>
#include <sstream>
#include <stdexcept>

#include <unistd.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRep_Builder.hxx>
#include <Geom_BSplineSurface.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_Printer.hxx>
#include <STEPControl_Controller.hxx>
#include <STEPControl_Writer.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Face.hxx>

namespace devsurf::cad {

namespace {

[[noreturn]] void failStep(const std::string& message) { throw std::invalid_argument(message); }

/// Distinct knot values and their multiplicities.
void splitKnots(const std::vector<double>& knots, const std::string& path, TColStd_Array1OfReal*& values,
                TColStd_Array1OfInteger*& multiplicities) {
  std::vector<double> distinct;
  std::vector<int> counts;
  for (std::size_t i = 0; i < knots.size(); ++i) {
    if (!std::isfinite(knots[i])) failStep(path + "[" + std::to_string(i) + "]: must be finite");
    if (i > 0 && knots[i] < knots[i - 1]) failStep(path + ": must be non-decreasing");
    if (!distinct.empty() && knots[i] == distinct.back())
      ++counts.back();
    else {
      distinct.push_back(knots[i]);
      counts.push_back(1);
    }
  }
  if (distinct.size() < 2) failStep(path + ": the domain is empty");
  values = new TColStd_Array1OfReal(1, static_cast<int>(distinct.size()));
  multiplicities = new TColStd_Array1OfInteger(1, static_cast<int>(distinct.size()));
  for (std::size_t i = 0; i < distinct.size(); ++i) {
    values->SetValue(static_cast<int>(i) + 1, distinct[i]);
    multiplicities->SetValue(static_cast<int>(i) + 1, counts[i]);
  }
}

Handle(Geom_BSplineSurface) surfaceOf(const io::IgesSurface& s, const std::string& path) {
  if (s.degreeU < 1 || s.degreeV < 1 || s.degreeU > 25 || s.degreeV > 25) failStep(path + ": degrees must be 1 … 25");
  if (s.nu <= s.degreeU || s.nv <= s.degreeV) failStep(path + ": needs more than degree control points in each direction");
  if (s.points.rows() != static_cast<Eigen::Index>(s.nu) * s.nv)
    failStep(path + ".points: nu × nv = " + std::to_string(s.nu * s.nv) + " expected");
  if (!s.points.allFinite()) failStep(path + ".points: every coordinate must be finite");
  if (static_cast<int>(s.knotsU.size()) != s.nu + s.degreeU + 1) failStep(path + ".knotsU: nu + degreeU + 1 values expected");
  if (static_cast<int>(s.knotsV.size()) != s.nv + s.degreeV + 1) failStep(path + ".knotsV: nv + degreeV + 1 values expected");
  if (s.weights.size() != 0 && (s.weights.size() != s.points.rows() || !(s.weights.array() > 0).all()))
    failStep(path + ".weights: one positive weight per control point expected");
  TColgp_Array2OfPnt poles(1, s.nu, 1, s.nv);
  for (int j = 0; j < s.nv; ++j)
    for (int i = 0; i < s.nu; ++i) {
      const Eigen::Index k = i + static_cast<Eigen::Index>(s.nu) * j;
      poles.SetValue(i + 1, j + 1, gp_Pnt(s.points(k, 0), s.points(k, 1), s.points(k, 2)));
    }
  TColStd_Array1OfReal *uKnots = nullptr, *vKnots = nullptr;
  TColStd_Array1OfInteger *uMults = nullptr, *vMults = nullptr;
  splitKnots(s.knotsU, path + ".knotsU", uKnots, uMults);
  std::unique_ptr<TColStd_Array1OfReal> ownU(uKnots);
  std::unique_ptr<TColStd_Array1OfInteger> ownUm(uMults);
  splitKnots(s.knotsV, path + ".knotsV", vKnots, vMults);
  std::unique_ptr<TColStd_Array1OfReal> ownV(vKnots);
  std::unique_ptr<TColStd_Array1OfInteger> ownVm(vMults);
  if (s.weights.size() == 0) return new Geom_BSplineSurface(poles, *uKnots, *vKnots, *uMults, *vMults, s.degreeU, s.degreeV);
  TColStd_Array2OfReal weights(1, s.nu, 1, s.nv);
  for (int j = 0; j < s.nv; ++j)
    for (int i = 0; i < s.nu; ++i) weights.SetValue(i + 1, j + 1, s.weights[i + static_cast<Eigen::Index>(s.nu) * j]);
  return new Geom_BSplineSurface(poles, weights, *uKnots, *vKnots, *uMults, *vMults, s.degreeU, s.degreeV);
}

const char* stepUnit(const std::string& units) {
  if (units == "mm") return "MM";
  if (units == "cm") return "CM";
  if (units == "m") return "M";
  if (units == "in") return "INCH";
  failStep("units: expected mm, cm, m or in, got \"" + units + "\"");
}

/// STEPControl_Writer's parameters are process-wide (Interface_Static): one write at a time.
std::mutex& writerMutex() {
  static std::mutex m;
  return m;
}

/// OpenCascade's default messenger prints transfer statistics to stdout on every write; the
/// daemon's output is its log. Only failures are printed.
void quietMessenger() {
  static std::once_flag once;
  std::call_once(once, [] {
    const Message_SequenceOfPrinters& printers = Message::DefaultMessenger()->Printers();
    for (int i = 1; i <= printers.Length(); ++i) printers.Value(i)->SetTraceLevel(Message_Fail);
  });
}

}  // namespace

std::string stepDocument(const std::vector<io::IgesSurface>& surfaces, const StepOptions& options) {
  if (surfaces.empty()) failStep("surfaces: at least one surface is needed");
  const char* unit = stepUnit(options.units);
  if (!std::isfinite(options.sewingTolerance) || options.sewingTolerance <= 0)
    failStep("sewingTolerance: a finite value > 0 is needed");
  std::vector<TopoDS_Face> faces;
  try {
    for (std::size_t k = 0; k < surfaces.size(); ++k) {
      const std::string path = "surfaces[" + std::to_string(k) + "]";
      const Handle(Geom_BSplineSurface) surface = surfaceOf(surfaces[k], path);
      BRepBuilderAPI_MakeFace make(surface, 1e-9);
      if (!make.IsDone()) throw std::runtime_error(path + ": OpenCascade could not make a face of it");
      faces.push_back(make.Face());
    }
    TopoDS_Shape shape;
    if (options.sew && faces.size() > 1) {
      BRepBuilderAPI_Sewing sewing(options.sewingTolerance);
      for (const TopoDS_Face& f : faces) sewing.Add(f);
      sewing.Perform();
      shape = sewing.SewedShape();
    } else {
      TopoDS_Compound compound;
      BRep_Builder builder;
      builder.MakeCompound(compound);
      for (const TopoDS_Face& f : faces) builder.Add(compound, f);
      shape = compound;
    }
    const std::lock_guard<std::mutex> lock(writerMutex());
    quietMessenger();
    // The parameters exist once the STEP controller is initialized (setting them before is ignored).
    STEPControl_Controller::Init();
    Interface_Static::SetCVal("write.step.schema", "AP214IS");
    Interface_Static::SetCVal("write.step.unit", unit);
    Interface_Static::SetCVal("xstep.cascade.unit", unit);
    STEPControl_Writer writer;
    if (writer.Transfer(shape, STEPControl_AsIs) != IFSelect_RetDone)
      throw std::runtime_error("STEP: OpenCascade could not translate the model");
    // The writer writes files only: a private temporary file, read back and removed.
    std::string name = (std::filesystem::temp_directory_path() / "devsurf-step-XXXXXX").string();
    const int fd = mkstemp(name.data());
    if (fd < 0) throw std::runtime_error("STEP: cannot create a temporary file");
    close(fd);
    struct Remove {
      std::string path;
      ~Remove() { std::remove(path.c_str()); }
    } remove{name};
    if (writer.Write(name.c_str()) != IFSelect_RetDone) throw std::runtime_error("STEP: OpenCascade could not write the file");
    std::ifstream in(name, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  } catch (const Standard_Failure& e) {
    throw std::runtime_error(std::string("STEP: OpenCascade failed: ") + e.GetMessageString());
  }
}

}  // namespace devsurf::cad
