#include "devsurf/proto/Geometry.h"

#include "devsurf/metrics/QuadFlatness.h"

#include <algorithm>
#include <cmath>
#include <array>
#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

#include "devsurf/io/CreasePattern.h"
#include "devsurf/models/composite/CompositeFoldConflicts.h"
#include "devsurf/metrics/StripQuality.h"

namespace devsurf::proto {
namespace {

constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

int decodeChar(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+') return 62;
  if (c == '/') return 63;
  return -1;
}

}  // namespace

std::string base64Encode(const void* data, std::size_t size) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  std::string out((size + 2) / 3 * 4, '=');
  char* o = out.data();
  std::size_t i = 0;
  for (; i + 2 < size; i += 3, o += 4) {
    const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (std::uint32_t{bytes[i + 1]} << 8) | bytes[i + 2];
    o[0] = kAlphabet[(v >> 18) & 63];
    o[1] = kAlphabet[(v >> 12) & 63];
    o[2] = kAlphabet[(v >> 6) & 63];
    o[3] = kAlphabet[v & 63];
  }
  if (i < size) {  // one or two bytes left: the padding '=' is already in place
    const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (i + 1 < size ? std::uint32_t{bytes[i + 1]} << 8 : 0u);
    o[0] = kAlphabet[(v >> 18) & 63];
    o[1] = kAlphabet[(v >> 12) & 63];
    if (i + 1 < size) o[2] = kAlphabet[(v >> 6) & 63];
  }
  return out;
}

std::string base64Decode(const std::string& text) {
  if (text.size() % 4 != 0) throw std::invalid_argument("base64: length is not a multiple of 4");
  std::string out;
  out.reserve(text.size() / 4 * 3);
  for (std::size_t i = 0; i < text.size(); i += 4) {
    int v[4];
    int pad = 0;
    for (int k = 0; k < 4; ++k) {
      const char c = text[i + k];
      if (c == '=' && i + 4 == text.size() && k >= 2) {
        v[k] = 0;
        ++pad;
      } else if (pad > 0 || (v[k] = decodeChar(c)) < 0) {
        throw std::invalid_argument("base64: invalid character");
      }
    }
    const std::uint32_t word = (v[0] << 18) | (v[1] << 12) | (v[2] << 6) | v[3];
    out += static_cast<char>((word >> 16) & 255);
    if (pad < 2) out += static_cast<char>((word >> 8) & 255);
    if (pad < 1) out += static_cast<char>(word & 255);
  }
  return out;
}

nlohmann::json float32Array(const Eigen::MatrixXd& m) {
  std::vector<float> values(static_cast<std::size_t>(m.size()));
  std::size_t k = 0;
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) values[k++] = static_cast<float>(m(i, j));
  static_assert(sizeof(float) == 4, "float32");
  return {{"dtype", "float32"},
          {"shape", {m.rows(), m.cols()}},
          {"data", base64Encode(values.data(), values.size() * sizeof(float))}};
}

nlohmann::json int32Array(const Eigen::MatrixXi& m) {
  std::vector<std::int32_t> values(static_cast<std::size_t>(m.size()));
  std::size_t k = 0;
  for (Eigen::Index i = 0; i < m.rows(); ++i)
    for (Eigen::Index j = 0; j < m.cols(); ++j) values[k++] = m(i, j);
  return {{"dtype", "int32"},
          {"shape", {m.rows(), m.cols()}},
          {"data", base64Encode(values.data(), values.size() * sizeof(std::int32_t))}};
}

Eigen::MatrixXd decodeFloat32Array(const nlohmann::json& j) {
  if (j.at("dtype") != "float32") throw std::invalid_argument("expected a float32 array");
  const Eigen::Index rows = j.at("shape").at(0).get<Eigen::Index>();
  const Eigen::Index cols = j.at("shape").at(1).get<Eigen::Index>();
  const std::string bytes = base64Decode(j.at("data").get<std::string>());
  if (bytes.size() != static_cast<std::size_t>(rows * cols) * sizeof(float))
    throw std::invalid_argument("float32 array: data does not match its shape");
  Eigen::MatrixXd m(rows, cols);
  std::size_t k = 0;
  for (Eigen::Index i = 0; i < rows; ++i)
    for (Eigen::Index c = 0; c < cols; ++c, ++k) {
      float f;
      std::memcpy(&f, bytes.data() + k * sizeof(float), sizeof(float));
      m(i, c) = f;
    }
  return m;
}

Eigen::MatrixXd unrollRulingGrid(const Eigen::MatrixX3d& a, const Eigen::MatrixX3d& b) {
  const Eigen::Index n = a.rows();
  Eigen::MatrixXd out(2 * n, 2);  // rows 2i: a_i, 2i+1: b_i
  if (n == 0) return out;
  Eigen::Vector2d A(0.0, 0.0), B(0.0, (b.row(0) - a.row(0)).norm());
  out.row(0) = A.transpose();
  out.row(1) = B.transpose();
  for (Eigen::Index i = 0; i + 1 < n; ++i) {
    const Eigen::Vector3d ai = a.row(i), bi = b.row(i), an = a.row(i + 1), bn = b.row(i + 1);
    // A frame of the quad (a_i, a_{i+1}, b_{i+1}, b_i): e1 along the ruling, e2 in the quad's plane
    // pointing to where the strip continues.
    Eigen::Vector3d e1 = bi - ai;
    const double len = e1.norm();
    e1 = len > 0 ? Eigen::Vector3d(e1 / len) : Eigen::Vector3d::UnitY();
    Eigen::Vector3d step = 0.5 * ((an - ai) + (bn - bi));
    Eigen::Vector3d e2 = step - step.dot(e1) * e1;
    if (e2.norm() < 1e-300) e2 = e1.unitOrthogonal();
    e2.normalize();
    // The 2D frame at the unrolled ruling: d1 along B − A, d2 perpendicular to it on the side
    // the strip advances to (+x at the start).
    Eigen::Vector2d d1 = B - A;
    const double l2 = d1.norm();
    d1 = l2 > 0 ? Eigen::Vector2d(d1 / l2) : Eigen::Vector2d(0.0, 1.0);
    const Eigen::Vector2d d2(d1.y(), -d1.x());
    auto place = [&](const Eigen::Vector3d& p) -> Eigen::Vector2d {
      const Eigen::Vector3d q = p - ai;
      return A + q.dot(e1) * d1 + q.dot(e2) * d2;
    };
    const Eigen::Vector2d nextA = place(an), nextB = place(bn);
    A = nextA;
    B = nextB;
    out.row(2 * (i + 1)) = A.transpose();
    out.row(2 * (i + 1) + 1) = B.transpose();
  }
  return out;
}

nlohmann::json stripGeometryJson(const models::strip::StripModel& model, int uSamples,
                                 int vSamples, int rulings) {
  const models::strip::StripGeometry g = model.geometry(uSamples, vSamples, rulings);
  const models::strip::StripDesign d = model.design();
  // Warp angle per u sample, as a per-vertex scalar field for colouring.
  const double u0 = d.a.knots.domainBegin(), u1 = d.a.knots.domainEnd();
  const bool closed = d.a.knots.kind() == spline::KnotKind::Periodic;
  Eigen::MatrixXd warp(g.surface.vertices.rows(), 1);
  for (int i = 0; i < uSamples; ++i) {
    const double u = u0 + (u1 - u0) * i / (closed ? uSamples : uSamples - 1);
    const double w = metrics::warpAngleDeg(d.a.evaluate(u, 0), d.a.evaluate(u, 1),
                                           d.b.evaluate(u, 0), d.b.evaluate(u, 1));
    for (int j = 0; j < vSamples; ++j) warp(i * vSamples + j, 0) = w;
  }
  Eigen::MatrixXd rulingSegments(g.rulingStart.rows(), 6);
  rulingSegments << g.rulingStart, g.rulingEnd;
  // The development: the sampled quads unrolled face after face (000_… §5); interior samples of a
  // ruling are interpolated along its unrolled image.
  const Eigen::MatrixXd ends = unrollRulingGrid(g.curveA, g.curveB);
  Eigen::MatrixXd flat(static_cast<Eigen::Index>(uSamples) * vSamples, 2);
  for (int i = 0; i < uSamples; ++i)
    for (int j = 0; j < vSamples; ++j) {
      const double v = static_cast<double>(j) / (vSamples - 1);
      flat.row(i * vSamples + j) = (1.0 - v) * ends.row(2 * i) + v * ends.row(2 * i + 1);
    }
  Eigen::MatrixXi flatQuads((uSamples - 1) * (vSamples - 1), 4);
  for (int i = 0, f = 0; i + 1 < uSamples; ++i)
    for (int j = 0; j + 1 < vSamples; ++j)
      flatQuads.row(f++) << i * vSamples + j, (i + 1) * vSamples + j, (i + 1) * vSamples + j + 1, i * vSamples + j + 1;
  return {{"kind", "strip"},
          {"surface",
           {{"vertices", float32Array(g.surface.vertices)},
            {"quads", int32Array(g.surface.quads)},
            {"grid", {uSamples, vSamples}},
            {"closed", closed},
            {"warp_angle_deg", float32Array(warp)}}},
          {"curves", {{"a", float32Array(g.curveA)}, {"b", float32Array(g.curveB)}}},
          {"control_points", {{"a", float32Array(d.a.points)}, {"b", float32Array(d.b.points)}}},
          {"rulings", float32Array(rulingSegments)},
          {"development", {{"vertices", float32Array(flat)}, {"quads", int32Array(flatQuads)}}},
          {"normals", float32Array(g.normals)}};
}

nlohmann::json compositeGeometryJson(const models::composite::CompositeModel& model,
                                     const models::composite::CompositeQuality& quality,
                                     int samplesPerSpan, int vSamples) {
  namespace composite = models::composite;
  const composite::CompositeDesign d = model.design();
  const composite::CompositeGeometry g = model.geometry(samplesPerSpan, vSamples);
  const int numFaces = static_cast<int>(d.faces.size());
  const int numVertices = static_cast<int>(d.vertices.rows());
  auto faceValue = [](const std::vector<double>& values, std::size_t i) { return i < values.size() ? values[i] : 0.0; };

  // The surface: faces concatenated in face order.
  Eigen::Index nv = 0, nq = 0;
  for (const io::QuadMesh& f : g.faces) {
    nv += f.vertices.rows();
    nq += f.quads.rows();
  }
  Eigen::MatrixXd vertices(nv, 3), flatness(nv, 1), curvature(nv, 1);
  Eigen::MatrixXi quads(nq, 4), quadFace(nq, 1);
  // Radius of each composite vertex's curvature spot: 0.35 × its shortest edge chord.
  std::vector<double> radius(static_cast<std::size_t>(numVertices), 0.0);
  for (const composite::CompositeEdge& e : d.edges) {
    const double chord = (d.vertices.row(e.v0) - d.vertices.row(e.v1)).norm();
    for (int v : {e.v0, e.v1}) {
      double& r = radius[static_cast<std::size_t>(v)];
      r = r == 0.0 ? 0.35 * chord : std::min(r, 0.35 * chord);
    }
  }
  // Only vertices with a defect make a spot (on a developable design, none or a few).
  struct Spot {
    Eigen::Vector3d centre;
    double curvature, radius;
  };
  std::vector<Spot> spots;
  for (int v = 0; v < numVertices; ++v) {
    const double kv = faceValue(quality.vertexCurvature, static_cast<std::size_t>(v));
    const double r = radius[static_cast<std::size_t>(v)];
    if (kv > 0.0 && r > 0.0) spots.push_back({d.vertices.row(v).transpose(), kv, r});
  }
  Eigen::Index vOffset = 0, qOffset = 0;
  for (std::size_t f = 0; f < g.faces.size(); ++f) {
    const io::QuadMesh& m = g.faces[f];
    for (Eigen::Index i = 0; i < m.vertices.rows(); ++i) {
      const Eigen::Vector3d p = m.vertices.row(i).transpose();
      vertices.row(vOffset + i) = p.transpose();
      flatness(vOffset + i, 0) = 0.0;
      double k = 0.0;
      for (const Spot& spot : spots) {
        const double dist = (p - spot.centre).norm();
        k = std::max(k, spot.curvature * std::max(0.0, 1.0 - dist / spot.radius));
      }
      curvature(vOffset + i, 0) = k;
    }
    // Flatness per sampled quad (δ of Tang Fig. 17), each vertex showing the largest of its quads.
    const double tiny = 1e-12 * std::max(1.0, m.vertices.cwiseAbs().maxCoeff());
    for (Eigen::Index q = 0; q < m.quads.rows(); ++q) {
      const Eigen::Vector4i c = m.quads.row(q).transpose();
      const double delta = metrics::quadFlatness(m.vertices.row(c[0]).transpose(), m.vertices.row(c[1]).transpose(),
                                                 m.vertices.row(c[2]).transpose(), m.vertices.row(c[3]).transpose(), tiny);
      for (int k = 0; k < 4; ++k) flatness(vOffset + c[k], 0) = std::max(flatness(vOffset + c[k], 0), delta);
    }
    for (Eigen::Index q = 0; q < m.quads.rows(); ++q) {
      quads.row(qOffset + q) = m.quads.row(q).array() + static_cast<int>(vOffset);
      quadFace(qOffset + q, 0) = static_cast<int>(f);
    }
    vOffset += m.vertices.rows();
    qOffset += m.quads.rows();
  }

  Eigen::MatrixXd vertexCurvature(numVertices, 1), faceFlatness(numFaces, 1);
  for (int v = 0; v < numVertices; ++v) vertexCurvature(v, 0) = faceValue(quality.vertexCurvature, static_cast<std::size_t>(v));
  for (int f = 0; f < numFaces; ++f) faceFlatness(f, 0) = faceValue(quality.faceFlatness, static_cast<std::size_t>(f));

  // Edges: interior ones with their fold angles (CompositeModel::creases), boundary ones sampled.
  std::vector<const composite::CreaseGeometry*> creaseOf(d.edges.size(), nullptr);
  for (const composite::CreaseGeometry& c : g.creases)
    if (c.edge >= 0 && static_cast<std::size_t>(c.edge) < creaseOf.size()) creaseOf[static_cast<std::size_t>(c.edge)] = &c;
  nlohmann::json edges = nlohmann::json::array();
  std::vector<std::array<int, 3>> refs;
  std::vector<Eigen::Vector3d> positions;
  for (int v = 0; v < numVertices; ++v) {
    refs.push_back({v, -1, -1});
    positions.push_back(d.vertices.row(v).transpose());
  }
  for (std::size_t e = 0; e < d.edges.size(); ++e) {
    const composite::CompositeEdge& edge = d.edges[e];
    const bool spline = edge.type == composite::EdgeType::Spline;
    nlohmann::json je{{"edge", e},
                      {"v", {edge.v0, edge.v1}},
                      {"type", composite::edgeTypeName(edge.type)},
                      {"crease", composite::creaseKindName(edge.crease)}};
    if (const composite::CreaseGeometry* c = creaseOf[e]) {
      je["interior"] = true;
      je["assignment"] = std::string(1, c->assignment);
      je["polyline"] = float32Array(c->polyline);
      je["fold_angle_deg"] = float32Array(c->foldAngleDeg);
    } else {
      je["interior"] = false;
      je["assignment"] = "B";
      Eigen::MatrixXd polyline;
      if (spline) {
        const int count = std::max(2, edge.curve.knots.numSpans() * samplesPerSpan + 1);
        polyline = edge.curve.evaluate(edge.curve.knots.uniformSamples(count), 0);
      } else {
        polyline.resize(2, 3);
        polyline << d.vertices.row(edge.v0), d.vertices.row(edge.v1);
      }
      je["polyline"] = float32Array(polyline);
    }
    if (spline) {
      je["control_points"] = float32Array(edge.curve.points);
      for (Eigen::Index k = 1; k + 1 < edge.curve.points.rows(); ++k) {
        refs.push_back({-1, static_cast<int>(e), static_cast<int>(k)});
        positions.push_back(edge.curve.points.row(k).transpose());
      }
    }
    edges.push_back(std::move(je));
  }
  Eigen::MatrixXd pointPositions(static_cast<Eigen::Index>(positions.size()), 3);
  Eigen::MatrixXi pointRefs(static_cast<Eigen::Index>(refs.size()), 3);
  for (std::size_t i = 0; i < refs.size(); ++i) {
    pointPositions.row(static_cast<Eigen::Index>(i)) = positions[i].transpose();
    pointRefs.row(static_cast<Eigen::Index>(i)) << refs[i][0], refs[i][1], refs[i][2];
  }

  // Points whose creases cannot all fold (a crossing of two straight folds, …): where they are in
  // 3D and, with a development, on the flat sheet.
  nlohmann::json foldConflicts = nlohmann::json::array();
  const std::vector<composite::FoldConflict> conflicts = composite::foldConflicts(d, model.topology());
  nlohmann::json development = nullptr;
  if (!conflicts.empty()) {
    std::vector<int> flatOf(static_cast<std::size_t>(numVertices), -1);
    Eigen::MatrixX2d flat;
    if (model.hasDevelopment()) {
      const composite::CompositeDevelopment dev = model.development();
      flat = dev.vertices2d;
      for (std::size_t i = 0; i < dev.vertexSource.size(); ++i)
        if (const int v = dev.vertexSource[i]; v >= 0 && v < numVertices && flatOf[static_cast<std::size_t>(v)] < 0)
          flatOf[static_cast<std::size_t>(v)] = static_cast<int>(i);
    }
    for (const composite::FoldConflict& c : conflicts) {
      nlohmann::json jc{{"vertex", c.vertex},
                        {"reason", c.reason},
                        {"position", {d.vertices(c.vertex, 0), d.vertices(c.vertex, 1), d.vertices(c.vertex, 2)}}};
      if (const int i = flatOf[static_cast<std::size_t>(c.vertex)]; i >= 0) jc["flat"] = {flat(i, 0), flat(i, 1)};
      foldConflicts.push_back(std::move(jc));
    }
  }
  if (model.hasDevelopment()) {
    const composite::CompositeDevelopment dev = model.development();
    // The crease pattern validates the development (e.g. every face counterclockwise); while a
    // solve passes through a state it rejects, draw the development's own edges instead: sampled
    // S and R edges with their composite edge's assignment (B on the boundary), interior rulings F.
    io::CreasePattern cp;
    try {
      cp = model.creasePattern();
    } catch (const std::exception&) {
      cp.vertices2d = dev.vertices2d;
      std::vector<char> letter(d.edges.size(), 'B');
      for (const composite::CreaseGeometry& c : g.creases)
        if (c.edge >= 0 && static_cast<std::size_t>(c.edge) < letter.size()) letter[static_cast<std::size_t>(c.edge)] = c.assignment;
      std::vector<double> rulings;
      for (const composite::CompositeDevelopment::Pair& pair : dev.pairs) {
        using Kind = composite::CompositeDevelopment::PairKind;
        if (pair.kind == Kind::Interior) {
          for (int v : {pair.v0, pair.v1}) {
            rulings.push_back(dev.vertices2d(v, 0));
            rulings.push_back(dev.vertices2d(v, 1));
          }
        } else if (pair.kind != Kind::Diagonal) {
          io::CreaseEdge edge;
          edge.v0 = pair.v0;
          edge.v1 = pair.v1;
          const char a = pair.edge >= 0 ? letter[static_cast<std::size_t>(pair.edge)] : 'F';
          edge.assignment = io::parseFoldAssignment(std::string(1, a));
          cp.edges.push_back(edge);
        }
      }
      cp.rulings.resize(static_cast<Eigen::Index>(rulings.size() / 4), 4);
      for (std::size_t k = 0; k < rulings.size(); ++k) cp.rulings(static_cast<Eigen::Index>(k / 4), static_cast<Eigen::Index>(k % 4)) = rulings[k];
    }
    std::vector<std::array<int, 4>> triangles;  // three corners and the face
    for (std::size_t p = 0; p < dev.polygons.size(); ++p) {
      const std::vector<int>& poly = dev.polygons[p];
      const int face = p < dev.polygonFace.size() ? dev.polygonFace[p] : -1;
      for (std::size_t k = 1; k + 1 < poly.size(); ++k) triangles.push_back({poly[0], poly[k], poly[k + 1], face});
    }
    Eigen::MatrixXi tri(static_cast<Eigen::Index>(triangles.size()), 3), triFace(static_cast<Eigen::Index>(triangles.size()), 1);
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      tri.row(static_cast<Eigen::Index>(t)) << triangles[t][0], triangles[t][1], triangles[t][2];
      triFace(static_cast<Eigen::Index>(t), 0) = triangles[t][3];
    }
    Eigen::MatrixXi cpEdges(static_cast<Eigen::Index>(cp.edges.size()), 2);
    std::string assignment;
    for (std::size_t k = 0; k < cp.edges.size(); ++k) {
      cpEdges.row(static_cast<Eigen::Index>(k)) << cp.edges[k].v0, cp.edges[k].v1;
      assignment += io::foldAssignmentLetter(cp.edges[k].assignment);
    }
    development = {{"vertices", float32Array(cp.vertices2d)},
                   {"triangles", int32Array(tri)},
                   {"triangle_face", int32Array(triFace)},
                   {"edges", int32Array(cpEdges)},
                   {"assignment", assignment},
                   {"rulings", float32Array(cp.rulings)}};
  }

  return {{"kind", "composite"},
          {"surface",
           {{"vertices", float32Array(vertices)},
            {"quads", int32Array(quads)},
            {"quad_face", int32Array(quadFace)},
            {"face_flatness", float32Array(flatness)},
            {"vertex_curvature", float32Array(curvature)}}},
          {"vertices", float32Array(d.vertices)},
          {"vertex_curvature", float32Array(vertexCurvature)},
          {"face_flatness", float32Array(faceFlatness)},
          {"edges", std::move(edges)},
          {"points", {{"positions", float32Array(pointPositions)}, {"refs", int32Array(pointRefs)}}},
          {"fold_conflicts", std::move(foldConflicts)},
          {"development", std::move(development)}};
}

namespace {

/// A curve sampled at n parameters equally spaced over its domain.
Eigen::MatrixXd sampleCurve(const spline::BSplineCurve& c, int n) {
  const double u0 = c.knots.domainBegin(), u1 = c.knots.domainEnd();
  Eigen::MatrixXd out(n, 3);
  for (int i = 0; i < n; ++i) out.row(i) = c.evaluate(u0 + (u1 - u0) * i / (n - 1), 0).head<3>().transpose();
  return out;
}

Eigen::MatrixXd controlPoints3(const spline::BSplineCurve& c) { return c.points.leftCols(3); }

/// Quads of a grid of U × 2 vertices (vertex 2i + j), offset by `base`.
void ladderQuads(Eigen::MatrixXi& quads, Eigen::Index& row, int rungs, int base) {
  for (int i = 0; i + 1 < rungs; ++i) quads.row(row++) << base + 2 * i, base + 2 * (i + 1), base + 2 * (i + 1) + 1, base + 2 * i + 1;
}

double angleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double na = a.norm(), nb = b.norm();
  if (na == 0.0 || nb == 0.0) return 0.0;
  return std::acos(std::clamp(a.dot(b) / (na * nb), -1.0, 1.0)) * 180.0 / 3.14159265358979323846;
}

}  // namespace

nlohmann::json quasiStripGeometryJson(const models::quasi_strip::QuasiStripModel& model, int uSamples, int rulings,
                                      int mappingSamples, int curveSamples) {
  namespace quasi = models::quasi_strip;
  const quasi::QuasiStripDesign& d = model.design();
  const quasi::QuasiStripResults& r = model.results();
  const quasi::RuledBSplineSurface& surface = r.surface;
  const double t0 = surface.knots.front(), t1 = surface.knots.back();
  const spline::BSplineCurve side0 = surface.boundary(0), side1 = surface.boundary(1);
  auto at = [&](int i, int n) { return t0 + (t1 - t0) * i / (n - 1); };

  Eigen::MatrixXd vertices(2 * uSamples, 3), warp(2 * uSamples, 1), ends0(uSamples, 3), ends1(uSamples, 3);
  for (int i = 0; i < uSamples; ++i) {
    const double t = at(i, uSamples);
    const Eigen::Vector3d a = side0.evaluate(t, 0).head<3>(), b = side1.evaluate(t, 0).head<3>();
    const double w = metrics::warpAngleDeg(a, side0.evaluate(t, 1).head<3>(), b, side1.evaluate(t, 1).head<3>());
    vertices.row(2 * i) = a.transpose();
    vertices.row(2 * i + 1) = b.transpose();
    ends0.row(i) = a.transpose();
    ends1.row(i) = b.transpose();
    warp(2 * i, 0) = warp(2 * i + 1, 0) = w;
  }
  Eigen::MatrixXi quads(uSamples - 1, 4);
  Eigen::Index row = 0;
  ladderQuads(quads, row, uSamples, 0);
  Eigen::MatrixXd rulingSegments(rulings, 6);
  for (int i = 0; i < rulings; ++i) {
    const double t = at(i, rulings);
    rulingSegments.row(i) << side0.evaluate(t, 0).head<3>().transpose(), side1.evaluate(t, 0).head<3>().transpose();
  }
  // σ over its domain, and the solver's starting point T = t (affine between the curves' domains).
  const double m0 = r.mapping.domainBegin(), m1 = r.mapping.domainEnd();
  const double a0 = d.c1.knots.domainBegin(), a1 = d.c1.knots.domainEnd();
  const double b0 = d.c2.knots.domainBegin(), b1 = d.c2.knots.domainEnd();
  Eigen::MatrixXd sigma(mappingSamples, 2), initial(mappingSamples, 2);
  for (int i = 0; i < mappingSamples; ++i) {
    const double t = m0 + (m1 - m0) * i / (mappingSamples - 1);
    sigma.row(i) << t, r.mapping.evaluate(t);
    initial.row(i) << t, b0 + (b1 - b0) * (t - a0) / (a1 - a0);
  }
  Eigen::MatrixXd samples(static_cast<Eigen::Index>(r.sampleParameters.size()), 2);
  for (std::size_t i = 0; i < r.sampleParameters.size(); ++i)
    samples.row(static_cast<Eigen::Index>(i)) << r.sampleParameters[i],
        i < r.sampleWarpDeg.size() ? r.sampleWarpDeg[i] : 0.0;
  const Eigen::MatrixXd flat = unrollRulingGrid(ends0, ends1);
  return {{"kind", "quasi_strip"},
          {"surface",
           {{"vertices", float32Array(vertices)},
            {"quads", int32Array(quads)},
            {"grid", {uSamples, 2}},
            {"closed", false},
            {"warp_angle_deg", float32Array(warp)}}},
          {"rulings", float32Array(rulingSegments)},
          {"curves", {{"c1", float32Array(sampleCurve(d.c1, curveSamples))}, {"c2", float32Array(sampleCurve(d.c2, curveSamples))}}},
          {"control_points", {{"c1", float32Array(controlPoints3(d.c1))}, {"c2", float32Array(controlPoints3(d.c2))}}},
          {"mapping",
           {{"sigma", float32Array(sigma)},
            {"initial", float32Array(initial)},
            {"samples", float32Array(samples)},
            {"trim", {r.trimBegin, r.trimEnd}},
            {"domain_c1", {a0, a1}},
            {"domain_c2", {b0, b1}}}},
          {"development", {{"vertices", float32Array(flat)}, {"quads", int32Array(quads)}}}};
}

nlohmann::json conicalStripGeometryJson(const models::conical_strip::ConicalStripModel& model, int samplesPerPatch,
                                        int curveSamples) {
  namespace conical = models::conical_strip;
  const conical::ConicalStripDesign& d = model.design();
  nlohmann::json out{{"kind", "conical_strip"},
                     {"curves", {{"p", float32Array(sampleCurve(d.p, curveSamples))}, {"q", float32Array(sampleCurve(d.q, curveSamples))}}},
                     {"control_points", {{"p", float32Array(controlPoints3(d.p))}, {"q", float32Array(controlPoints3(d.q))}}},
                     {"surface", nullptr},
                     {"patches", nullptr},
                     {"rulings", nullptr},
                     {"samples", nullptr},
                     {"development", nullptr}};
  if (!model.solved()) return out;
  const conical::ConicalStripResult& r = model.result();
  const int P = static_cast<int>(r.patches.size());
  const int S = samplesPerPatch;
  // Normal jump across the ruling between patches k−1 and k (k = 0 and P: strip ends, no jump).
  std::vector<double> jump(static_cast<std::size_t>(P + 1), 0.0);
  for (int k = 1; k < P; ++k)
    jump[static_cast<std::size_t>(k)] = angleDeg(r.patches[static_cast<std::size_t>(k - 1)].normal(1.0),
                                                 r.patches[static_cast<std::size_t>(k)].normal(0.0));
  Eigen::MatrixXd vertices(2 * P * (S + 1), 3), type(2 * P * (S + 1), 1), vertexJump(2 * P * (S + 1), 1);
  Eigen::MatrixXi quads(P * S, 4), quadPatch(P * S, 1), patchType(P, 1);
  Eigen::MatrixXd patchJump(P, 1), projection(P, 3), rulingSegments(P + 1, 6);
  std::string base;
  Eigen::Index row = 0;
  for (int k = 0; k < P; ++k) {
    const conical::ConicalPatch& patch = r.patches[static_cast<std::size_t>(k)];
    const bool quad = patch.type == conical::PatchType::Quadrilateral;
    const double j0 = jump[static_cast<std::size_t>(k)], j1 = jump[static_cast<std::size_t>(k + 1)];
    for (int i = 0; i <= S; ++i) {
      const double u = static_cast<double>(i) / S;
      const int v = 2 * (k * (S + 1) + i);
      vertices.row(v) = patch.pointA(u).transpose();
      vertices.row(v + 1) = patch.pointB(u).transpose();
      type(v, 0) = type(v + 1, 0) = quad ? 4 : 3;
      vertexJump(v, 0) = vertexJump(v + 1, 0) = (1.0 - u) * j0 + u * j1;
    }
    const Eigen::Index first = row;
    ladderQuads(quads, row, S + 1, 2 * k * (S + 1));
    quadPatch.block(first, 0, S, 1).setConstant(k);
    patchType(k, 0) = quad ? 4 : 3;
    patchJump(k, 0) = std::max(j0, j1);
    projection.row(k) = patch.projectionPoint.transpose();
    base += patch.baseSide == conical::StripSide::P ? 'P' : 'Q';
    rulingSegments.row(k) << patch.pointA(0.0).transpose(), patch.pointB(0.0).transpose();
    if (k + 1 == P) rulingSegments.row(P) << patch.pointA(1.0).transpose(), patch.pointB(1.0).transpose();
  }
  if (P == 0) rulingSegments.resize(0, 6);
  // The development: each unfolded patch as a ladder of its boundary images.
  Eigen::Index nFlat = 0, nFlatQuads = 0;
  for (const conical::UnfoldedPatch& u : r.unfolded) {
    nFlat += 2 * u.a.rows();
    nFlatQuads += std::max<Eigen::Index>(0, u.a.rows() - 1);
  }
  Eigen::MatrixXd flat(nFlat, 2);
  Eigen::MatrixXi flatQuads(nFlatQuads, 4), flatQuadPatch(nFlatQuads, 1);
  Eigen::Index fv = 0, fq = 0;
  for (std::size_t k = 0; k < r.unfolded.size(); ++k) {
    const conical::UnfoldedPatch& u = r.unfolded[k];
    const int rungs = static_cast<int>(u.a.rows());
    for (int i = 0; i < rungs; ++i) {
      flat.row(fv + 2 * i) = u.a.row(i);
      flat.row(fv + 2 * i + 1) = u.b.row(i);
    }
    const Eigen::Index first = fq;
    ladderQuads(flatQuads, fq, rungs, static_cast<int>(fv));
    flatQuadPatch.block(first, 0, fq - first, 1).setConstant(static_cast<int>(k));
    fv += 2 * rungs;
  }
  out["surface"] = {{"vertices", float32Array(vertices)},
                    {"quads", int32Array(quads)},
                    {"quad_patch", int32Array(quadPatch)},
                    {"patch_type", float32Array(type)},
                    {"normal_jump_deg", float32Array(vertexJump)}};
  out["patches"] = {{"type", int32Array(patchType)},
                    {"base", base},
                    {"normal_jump_deg", float32Array(patchJump)},
                    {"projection_points", float32Array(projection)}};
  out["rulings"] = float32Array(rulingSegments);
  out["samples"] = {{"p", float32Array(r.samplesP)}, {"q", float32Array(r.samplesQ)}};
  out["development"] = {{"vertices", float32Array(flat)}, {"quads", int32Array(flatQuads)},
                        {"quad_patch", int32Array(flatQuadPatch)}};
  return out;
}

}  // namespace devsurf::proto
