// Writes the quad-mesh exports of one case for test_quad_exports.py, which reads them back with
// independent parsers (python3's xml.etree and json).
//
// Usage: write_quad_exports CASE.json OUTDIR
// CASE.json: {"unfolding": [[x, y]…], "mesh": [[x, y, z]…] (optional), "faces": [[a, b, c(, d)]…],
//             "glue": [[i, j]…], "mm_per_unit": s, "margin_mm": m (optional), "draw_mesh": bool
//             (optional)}
// Writes OUTDIR/mesh.obj (when there is a mesh), unfolding.obj, pattern.svg, model.fold; exits 1
// with the message on stderr when an export throws.
#include <fstream>
#include <iostream>
#include <string>

#include <nlohmann/json.hpp>

#include "devsurf/io/CuttingPatternSvg.h"
#include "devsurf/io/PolygonMesh.h"
#include "devsurf/io/QuadMeshFold.h"

namespace {

Eigen::MatrixXd points(const nlohmann::json& list) {
  if (list.empty()) return Eigen::MatrixXd(0, 3);
  Eigen::MatrixXd out(static_cast<Eigen::Index>(list.size()), static_cast<Eigen::Index>(list[0].size()));
  for (std::size_t i = 0; i < list.size(); ++i)
    for (std::size_t d = 0; d < list[i].size(); ++d)
      out(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(d)) = list[i][d].get<double>();
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: write_quad_exports CASE.json OUTDIR\n";
    return 2;
  }
  try {
    std::ifstream in(argv[1]);
    const nlohmann::json c = nlohmann::json::parse(in);
    const std::string dir = argv[2];
    const Eigen::MatrixXd unfolding = points(c.at("unfolding"));
    const Eigen::MatrixXd mesh = c.contains("mesh") ? points(c["mesh"]) : Eigen::MatrixXd(0, 3);
    std::vector<devsurf::io::PolygonFace> faces;
    for (const auto& f : c.at("faces"))
      faces.push_back({f[0].get<int>(), f[1].get<int>(), f[2].get<int>(), f.size() > 3 ? f[3].get<int>() : -1});
    std::vector<std::array<int, 2>> glue;
    for (const auto& p : c.value("glue", nlohmann::json::array())) glue.push_back({p[0].get<int>(), p[1].get<int>()});
    const double scale = c.at("mm_per_unit").get<double>();

    if (mesh.rows() > 0) devsurf::io::writeObj(mesh, faces, dir + "/mesh.obj", "M");
    devsurf::io::writeObj(unfolding, faces, dir + "/unfolding.obj", "M'\nunfolding");
    devsurf::io::CuttingPatternOptions svg;
    svg.marginMm = c.value("margin_mm", svg.marginMm);
    svg.drawMesh = c.value("draw_mesh", svg.drawMesh);
    devsurf::io::writeCuttingPatternSvg(unfolding, faces, glue, scale, dir + "/pattern.svg", svg);
    devsurf::io::QuadMeshFoldOptions fold;
    fold.unitToMm = scale;
    fold.title = "test case";
    devsurf::io::writeQuadMeshFold(unfolding, mesh, faces, glue, dir + "/model.fold", fold);
  } catch (const std::exception& e) {
    std::cerr << e.what() << "\n";
    return 1;
  }
  return 0;
}
