#include "devsurf/proto/Geometry.h"

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <vector>

#include <Eigen/Geometry>

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
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < size; i += 3) {
    const std::uint32_t v = (bytes[i] << 16) | (bytes[i + 1] << 8) | bytes[i + 2];
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i + 1 == size) {
    const std::uint32_t v = bytes[i] << 16;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == size) {
    const std::uint32_t v = (bytes[i] << 16) | (bytes[i + 1] << 8);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += '=';
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

}  // namespace devsurf::proto
