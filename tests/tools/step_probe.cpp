// step_probe FILE.step — reads a STEP file with OpenCascade's STEPControl_Reader (code that shares
// nothing with devsurf's writer) and prints what it found as JSON on one line:
//   {"roots": n, "faces": n, "area": A, "bbox": [[x0,y0,z0],[x1,y1,z1]]}
// in the file's own length unit. Exit 1 when the file does not read. Used by the browser tests to
// check the STEP the web app's export menu downloads.
#include <BRepBndLib.hxx>
#include <BRepGProp.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <Interface_Static.hxx>
#include <STEPControl_Reader.hxx>
#include <TopAbs_ShapeEnum.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS_Shape.hxx>

#include <cstdio>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: step_probe FILE.step\n");
    return 2;
  }
  Interface_Static::SetCVal("xstep.cascade.unit", "MM");
  STEPControl_Reader reader;
  if (reader.ReadFile(argv[1]) != IFSelect_RetDone) {
    std::fprintf(stderr, "step_probe: %s does not read as STEP\n", argv[1]);
    return 1;
  }
  const int roots = reader.TransferRoots();
  const TopoDS_Shape shape = reader.OneShape();
  int faces = 0;
  for (TopExp_Explorer e(shape, TopAbs_FACE); e.More(); e.Next()) ++faces;
  GProp_GProps props;
  BRepGProp::SurfaceProperties(shape, props);
  Bnd_Box box;
  BRepBndLib::Add(shape, box);
  double x0 = 0, y0 = 0, z0 = 0, x1 = 0, y1 = 0, z1 = 0;
  if (!box.IsVoid()) box.Get(x0, y0, z0, x1, y1, z1);
  std::printf("{\"roots\": %d, \"faces\": %d, \"area\": %.9g, \"bbox\": [[%.9g, %.9g, %.9g], [%.9g, %.9g, %.9g]]}\n", roots,
              faces, props.Mass(), x0, y0, z0, x1, y1, z1);
  return 0;
}
