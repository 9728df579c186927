#pragma once

// Independent checks on exported files: the numbers are recomputed from the bytes a user gets
// (OBJ, FOLD), with code that shares nothing with the solver's own metrics.

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

namespace devsurf::testing {

/// A polygon mesh read from OBJ text: `v x y z` and `f i j k …` (1-based, `i/t/n` accepted).
struct ObjMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<std::vector<int>> faces;  ///< 0-based
};

inline ObjMesh parseObj(const std::string& text) {
  ObjMesh mesh;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream l(line);
    std::string tag;
    l >> tag;
    if (tag == "v") {
      Eigen::Vector3d p;
      l >> p.x() >> p.y() >> p.z();
      mesh.vertices.push_back(p);
    } else if (tag == "f") {
      std::vector<int> f;
      std::string item;
      while (l >> item) f.push_back(std::stoi(item.substr(0, item.find('/'))) - 1);
      mesh.faces.push_back(f);
    }
  }
  return mesh;
}

/// L-Err of Jiang et al. 2020 (Fig. 22), recomputed from two OBJ files of the same faces (a
/// quad_mesh's M and its unfolding M′): ‖L′ − L‖ / ‖L‖ over every edge of the faces (each once).
inline double objEdgeLengthError(const ObjMesh& mesh, const ObjMesh& unfolding) {
  if (mesh.faces != unfolding.faces || mesh.vertices.size() != unfolding.vertices.size())
    throw std::runtime_error("objEdgeLengthError: the two OBJ files have different faces");
  std::set<std::pair<int, int>> edges;
  for (const auto& f : mesh.faces)
    for (std::size_t k = 0; k < f.size(); ++k) {
      const int a = f[k], b = f[(k + 1) % f.size()];
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  double diff = 0.0, norm = 0.0;
  for (const auto& [a, b] : edges) {
    const double l = (mesh.vertices[a] - mesh.vertices[b]).norm();
    const double lp = (unfolding.vertices[a] - unfolding.vertices[b]).norm();
    diff += (lp - l) * (lp - l);
    norm += l * l;
  }
  return std::sqrt(diff / norm);
}

/// The largest |l′ − l| / l of one edge, recomputed from the same two OBJ files.
inline double objEdgeLengthErrorMax(const ObjMesh& mesh, const ObjMesh& unfolding) {
  if (mesh.faces != unfolding.faces || mesh.vertices.size() != unfolding.vertices.size())
    throw std::runtime_error("objEdgeLengthErrorMax: the two OBJ files have different faces");
  double worst = 0.0;
  for (const auto& f : mesh.faces)
    for (std::size_t k = 0; k < f.size(); ++k) {
      const int a = f[k], b = f[(k + 1) % f.size()];
      const double l = (mesh.vertices[a] - mesh.vertices[b]).norm();
      const double lp = (unfolding.vertices[a] - unfolding.vertices[b]).norm();
      if (l > 0.0) worst = std::max(worst, std::abs(lp - l) / l);
    }
  return worst;
}

/// Tang et al. 2016 Fig. 17 face flatness of one quad: distance of the lines of its diagonals over
/// the mean of its two shortest edges; 0 for a quad with a (near) zero-length edge (a triangle) or
/// parallel diagonals (two parallel lines share a plane).
inline double quadFlatness(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2,
                           const Eigen::Vector3d& p3) {
  std::array<double, 4> edges = {(p1 - p0).norm(), (p2 - p1).norm(), (p3 - p2).norm(), (p0 - p3).norm()};
  std::sort(edges.begin(), edges.end());
  const double scale = 0.5 * (edges[0] + edges[1]);
  if (edges[0] <= 1e-12 * edges[3] || scale <= 0.0) return 0.0;
  const Eigen::Vector3d u = p2 - p0, v = p3 - p1, w = p1 - p0;
  const Eigen::Vector3d n = u.cross(v);
  if (n.norm() <= 1e-14 * u.norm() * v.norm()) return 0.0;  // parallel diagonals: in one plane
  return std::abs(w.dot(n)) / n.norm() / scale;
}

struct FlatnessStats {
  double max = 0.0, mean = 0.0;
  int quads = 0;
};

/// δ over every quad of an OBJ mesh.
inline FlatnessStats objFlatness(const ObjMesh& mesh) {
  FlatnessStats s;
  double sum = 0.0;
  for (const auto& f : mesh.faces) {
    if (f.size() != 4) continue;
    const double d = quadFlatness(mesh.vertices.at(f[0]), mesh.vertices.at(f[1]), mesh.vertices.at(f[2]),
                                  mesh.vertices.at(f[3]));
    s.max = std::max(s.max, d);
    sum += d;
    ++s.quads;
  }
  s.mean = s.quads ? sum / s.quads : 0.0;
  return s;
}

/// What a FOLD 1.2 crease pattern says about its development, recomputed from the file: faces of
/// the crease-pattern frame (2D) that are not counterclockwise, and the relative length error of
/// its edges against the folded frame (3D), sqrt(Σ(l3 − l2)²)/sqrt(Σ l3²).
struct FoldDevelopmentCheck {
  int faces = 0;
  int flippedFaces = 0;
  double lengthError = 0.0;
};

inline FoldDevelopmentCheck checkFoldDevelopment(const nlohmann::json& fold) {
  FoldDevelopmentCheck c;
  const auto& cp = fold.at("vertices_coords");
  const nlohmann::json* folded = nullptr;
  if (fold.contains("file_frames"))
    for (const auto& frame : fold["file_frames"])
      if (frame.contains("vertices_coords") && frame["vertices_coords"].size() == cp.size()) folded = &frame["vertices_coords"];
  if (!folded) throw std::runtime_error("FOLD file has no folded frame with the crease pattern's vertices");
  auto p2 = [&cp](int i) { return Eigen::Vector2d(cp[i][0].get<double>(), cp[i][1].get<double>()); };
  auto p3 = [folded](int i) {
    const auto& v = (*folded)[i];
    return Eigen::Vector3d(v[0].get<double>(), v[1].get<double>(), v.size() > 2 ? v[2].get<double>() : 0.0);
  };
  for (const auto& f : fold.at("faces_vertices")) {
    double area = 0.0;
    for (std::size_t k = 0; k < f.size(); ++k) {
      const Eigen::Vector2d a = p2(f[k].get<int>()), b = p2(f[(k + 1) % f.size()].get<int>());
      area += a.x() * b.y() - a.y() * b.x();
    }
    ++c.faces;
    if (area <= 0.0) ++c.flippedFaces;
  }
  double num = 0.0, den = 0.0;
  for (const auto& e : fold.at("edges_vertices")) {
    const int i = e[0].get<int>(), j = e[1].get<int>();
    const double l2 = (p2(i) - p2(j)).norm(), l3 = (p3(i) - p3(j)).norm();
    num += (l3 - l2) * (l3 - l2);
    den += l3 * l3;
  }
  c.lengthError = den > 0.0 ? std::sqrt(num / den) : 0.0;
  return c;
}

/// The development of a strip exported as a U × V grid (ruling i = vertices V·i … V·i + V − 1, a
/// first), unfolded here triangle after triangle from the 3D distances alone: the triangles
/// (a_i, b_i, a_{i+1}) and (b_i, b_{i+1}, a_{i+1}), each new vertex placed on the side away from the
/// triangle before. Returns how many triangles turn the other way than the first (0 for a strip
/// whose development does not fold over or cross itself locally); triangles with a side shorter
/// than 1e-12 of the strip's size are skipped.
inline int stripDevelopmentFlips(const ObjMesh& mesh, int V) {
  const int U = static_cast<int>(mesh.vertices.size()) / V;
  if (U < 2) return 0;
  std::vector<Eigen::Vector3d> a, b;
  for (int i = 0; i < U; ++i) {
    a.push_back(mesh.vertices[static_cast<std::size_t>(V * i)]);
    b.push_back(mesh.vertices[static_cast<std::size_t>(V * i + V - 1)]);
  }
  double size = 0.0;
  for (int i = 0; i < U; ++i) size = std::max(size, (a[i] - a[0]).norm() + (b[i] - a[i]).norm());
  // Places r with |r − p| = dp, |r − q| = dq on the side of pq opposite to `away`.
  auto place = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, double dp, double dq, const Eigen::Vector2d& away) {
    const Eigen::Vector2d e = q - p;
    const double L = e.norm();
    const double x = (dp * dp - dq * dq + L * L) / (2.0 * L);
    const double y = std::sqrt(std::max(0.0, dp * dp - x * x));
    const Eigen::Vector2d ex = e / L, ey(-ex.y(), ex.x());
    const double side = (away - p).dot(ey) > 0.0 ? -1.0 : 1.0;
    return Eigen::Vector2d(p + x * ex + side * y * ey);
  };
  auto area = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r) {
    return 0.5 * ((q - p).x() * (r - p).y() - (r - p).x() * (q - p).y());
  };
  std::vector<Eigen::Vector2d> a2(U), b2(U);
  a2[0] = Eigen::Vector2d::Zero();
  b2[0] = Eigen::Vector2d((b[0] - a[0]).norm(), 0.0);
  Eigen::Vector2d previousThird(0.0, -1.0);  // the first triangle goes to +y
  int flips = 0;
  double firstSign = 0.0;
  auto check = [&](const Eigen::Vector2d& p, const Eigen::Vector2d& q, const Eigen::Vector2d& r, double shortest) {
    if (shortest < 1e-12 * size) return;
    const double s = area(p, q, r);
    if (firstSign == 0.0) firstSign = s > 0 ? 1.0 : -1.0;
    else if (s * firstSign < 0.0) ++flips;
  };
  for (int i = 0; i + 1 < U; ++i) {
    // (a_i, b_i, a_{i+1}): a_{i+1} away from the third vertex of the triangle before.
    const double ra = (a[i + 1] - a[i]).norm(), rb = (a[i + 1] - b[i]).norm();
    const double ab = (b[i] - a[i]).norm();
    if (ab < 1e-12 * size) {  // a pinched ruling: the unfolding cannot go on from here
      ++flips;
      break;
    }
    a2[i + 1] = place(a2[i], b2[i], ra, rb, previousThird);
    check(a2[i], b2[i], a2[i + 1], std::min({ra, rb, ab}));
    // (b_i, b_{i+1}, a_{i+1}): b_{i+1} away from a_i across the side b_i a_{i+1}.
    const double sb = (b[i + 1] - b[i]).norm(), sa = (b[i + 1] - a[i + 1]).norm();
    if (rb < 1e-12 * size) {
      previousThird = a2[i];
      b2[i + 1] = b2[i];
      continue;
    }
    b2[i + 1] = place(b2[i], a2[i + 1], sb, sa, a2[i]);
    check(b2[i], b2[i + 1], a2[i + 1], std::min({sb, sa, rb}));
    previousThird = b2[i];
  }
  return flips;
}

}  // namespace devsurf::testing
