#include "devsurf/io/IgesWriter.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <stdexcept>

namespace devsurf::io {
namespace {

/// IGES text is ASCII (its columns are counted in bytes, and readers take bytes for characters):
/// a UTF-8 character of a scene's name becomes one ASCII character, "×" an "x", others "?";
/// control characters become spaces.
std::string asciiText(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size();) {
    const unsigned char c = static_cast<unsigned char>(s[i]);
    if (c < 0x80) {
      out += c < 0x20 || c == 0x7F ? ' ' : static_cast<char>(c);
      ++i;
      continue;
    }
    const std::size_t length = c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : c >= 0xC0 ? 2 : 1;
    out += s.compare(i, 2, "\xC3\x97") == 0 ? 'x' : '?';
    i += std::min(length, s.size() - i);
  }
  return out;
}

std::string hollerith(const std::string& text) {
  const std::string s = asciiText(text);
  return std::to_string(s.size()) + "H" + s;
}

std::string igesNumber(double v) {
  if (v == 0.0) return "0.0";
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17G", v);
  std::string s(buf);
  // IGES reals need a decimal point or an exponent marker "D"/"E"; plain integers get ".0".
  if (s.find_first_of(".E") == std::string::npos) s += ".0";
  return s;
}

/// Splits a parameter record into lines of at most `width` characters, breaking only after a
/// delimiter (so no number is cut).
std::vector<std::string> wrap(const std::vector<std::string>& tokens, char delimiter, char terminator,
                              std::size_t width) {
  std::vector<std::string> lines;
  std::string line;
  for (std::size_t i = 0; i < tokens.size(); ++i) {
    const std::string t = tokens[i] + (i + 1 < tokens.size() ? delimiter : terminator);
    if (t.size() > width) throw std::invalid_argument("IGES: a parameter is longer than a line");
    if (line.size() + t.size() > width) {
      lines.push_back(line);
      line.clear();
    }
    line += t;
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

std::string padded(const std::string& s, std::size_t width) {
  std::string out = s.substr(0, width);
  out.resize(width, ' ');
  return out;
}

std::string field(long v, int width = 8) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%*ld", width, v);
  return buf;
}

std::string sequenced(const std::string& data72, char section, int seq) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%c%7d", section, seq);
  return padded(data72, 72) + buf + "\n";
}

void checkKnots(const std::vector<double>& knots, std::size_t expected, const std::string& path) {
  if (knots.size() != expected)
    throw std::invalid_argument(path + ": expected " + std::to_string(expected) + " knots, got " +
                                std::to_string(knots.size()));
  for (std::size_t i = 0; i < knots.size(); ++i) {
    if (!std::isfinite(knots[i])) throw std::invalid_argument(path + ": knots must be finite");
    if (i > 0 && knots[i] < knots[i - 1]) throw std::invalid_argument(path + ": knots must not decrease");
  }
}

int unitsFlag(const std::string& units) {
  if (units == "mm") return 2;
  if (units == "cm") return 10;
  if (units == "m") return 6;
  if (units == "in") return 1;
  throw std::invalid_argument("units: expected mm, cm, m or in, got \"" + units + "\"");
}

std::string unitsName(const std::string& units) {
  if (units == "mm") return "MM";
  if (units == "cm") return "CM";
  if (units == "m") return "M";
  return "INCH";
}

struct Entity {
  int type = 0;
  int form = 0;
  std::string label;
  std::vector<std::string> parameters;  ///< including the type number first
};

Entity surfaceEntity(const IgesSurface& s, std::size_t index) {
  const std::string path = "surfaces[" + std::to_string(index) + "]";
  if (s.degreeU < 1 || s.degreeV < 1) throw std::invalid_argument(path + ": degrees must be ≥ 1");
  if (s.nu <= s.degreeU || s.nv <= s.degreeV)
    throw std::invalid_argument(path + ": needs more than degree control points in each direction");
  if (s.points.rows() != static_cast<Eigen::Index>(s.nu) * s.nv)
    throw std::invalid_argument(path + ".points: expected nu·nv = " + std::to_string(s.nu * s.nv) + " rows");
  if (!s.points.allFinite()) throw std::invalid_argument(path + ".points: coordinates must be finite");
  if (s.weights.size() != 0 && s.weights.size() != s.points.rows())
    throw std::invalid_argument(path + ".weights: expected one weight per control point");
  if (s.weights.size() != 0 && !(s.weights.array() > 0.0).all())
    throw std::invalid_argument(path + ".weights: must be positive");
  checkKnots(s.knotsU, static_cast<std::size_t>(s.nu + s.degreeU + 1), path + ".knotsU");
  checkKnots(s.knotsV, static_cast<std::size_t>(s.nv + s.degreeV + 1), path + ".knotsV");
  Entity e;
  e.type = 128;
  e.label = s.label;
  auto& p = e.parameters;
  const bool rational = s.weights.size() != 0 && (s.weights.array() != s.weights[0]).any();
  for (long v : {128L, long(s.nu - 1), long(s.nv - 1), long(s.degreeU), long(s.degreeV), 0L, 0L,
                 rational ? 0L : 1L, 0L, 0L})
    p.push_back(std::to_string(v));
  for (double k : s.knotsU) p.push_back(igesNumber(k));
  for (double k : s.knotsV) p.push_back(igesNumber(k));
  for (Eigen::Index i = 0; i < s.points.rows(); ++i) p.push_back(igesNumber(s.weights.size() ? s.weights[i] : 1.0));
  for (Eigen::Index i = 0; i < s.points.rows(); ++i)
    for (int c = 0; c < 3; ++c) p.push_back(igesNumber(s.points(i, c)));
  p.push_back(igesNumber(s.knotsU[static_cast<std::size_t>(s.degreeU)]));
  p.push_back(igesNumber(s.knotsU[static_cast<std::size_t>(s.nu)]));
  p.push_back(igesNumber(s.knotsV[static_cast<std::size_t>(s.degreeV)]));
  p.push_back(igesNumber(s.knotsV[static_cast<std::size_t>(s.nv)]));
  return e;
}

Entity curveEntity(const IgesCurve& c, std::size_t index) {
  const std::string path = "curves[" + std::to_string(index) + "]";
  const Eigen::Index n = c.points.rows();
  if (c.degree < 1) throw std::invalid_argument(path + ".degree: must be ≥ 1");
  if (n <= c.degree) throw std::invalid_argument(path + ".points: needs more than degree control points");
  if (!c.points.allFinite()) throw std::invalid_argument(path + ".points: coordinates must be finite");
  if (c.weights.size() != 0 && c.weights.size() != n)
    throw std::invalid_argument(path + ".weights: expected one weight per control point");
  if (c.weights.size() != 0 && !(c.weights.array() > 0.0).all())
    throw std::invalid_argument(path + ".weights: must be positive");
  checkKnots(c.knots, static_cast<std::size_t>(n + c.degree + 1), path + ".knots");
  Entity e;
  e.type = 126;
  e.label = c.label;
  auto& p = e.parameters;
  const bool rational = c.weights.size() != 0 && (c.weights.array() != c.weights[0]).any();
  // Planar when all control points lie in one plane (PROP1 and the normal at the end).
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  bool planar = false;
  {
    const Eigen::RowVector3d centre = c.points.colwise().mean();
    const Eigen::MatrixX3d centred = c.points.rowwise() - centre;
    Eigen::Matrix3d cov = centred.transpose() * centred;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    const double extent = std::max(1e-300, eig.eigenvalues()[2]);
    if (eig.eigenvalues()[0] <= 1e-24 * extent && eig.eigenvalues()[1] > 1e-24 * extent) {
      planar = true;
      normal = eig.eigenvectors().col(0).normalized();
    }
  }
  for (long v : {126L, long(n - 1), long(c.degree), planar ? 1L : 0L, 0L, rational ? 0L : 1L, 0L})
    p.push_back(std::to_string(v));
  for (double k : c.knots) p.push_back(igesNumber(k));
  for (Eigen::Index i = 0; i < n; ++i) p.push_back(igesNumber(c.weights.size() ? c.weights[i] : 1.0));
  for (Eigen::Index i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) p.push_back(igesNumber(c.points(i, k)));
  p.push_back(igesNumber(c.knots[static_cast<std::size_t>(c.degree)]));
  p.push_back(igesNumber(c.knots[static_cast<std::size_t>(n)]));
  for (int k = 0; k < 3; ++k) p.push_back(igesNumber(normal[k]));
  return e;
}

std::string nowStamp() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y%m%d.%H%M%S", &tm);
  return buf;
}

}  // namespace

std::string igesDocument(const std::vector<IgesSurface>& surfaces, const std::vector<IgesCurve>& curves,
                         const IgesHeader& header) {
  std::vector<Entity> entities;
  for (std::size_t i = 0; i < surfaces.size(); ++i) entities.push_back(surfaceEntity(surfaces[i], i));
  for (std::size_t i = 0; i < curves.size(); ++i) entities.push_back(curveEntity(curves[i], i));

  std::string out;
  // Start section.
  out += sequenced("devsurf: developable surfaces (B-spline surfaces 128, curves 126)", 'S', 1);
  // Global section.
  double maxCoordinate = 0.0;
  for (const IgesSurface& s : surfaces) maxCoordinate = std::max(maxCoordinate, s.points.cwiseAbs().maxCoeff());
  for (const IgesCurve& c : curves) maxCoordinate = std::max(maxCoordinate, c.points.cwiseAbs().maxCoeff());
  const std::string stamp = header.timestamp.empty() ? nowStamp() : header.timestamp;
  const std::vector<std::string> global = {
      "1H,", "1H;", hollerith("devsurf"), hollerith(header.fileName), hollerith("devsurf"), hollerith("devsurf 1"),
      "32", "38", "6", "308", "15", hollerith("devsurf"), "1.0", std::to_string(unitsFlag(header.units)),
      hollerith(unitsName(header.units)), "1", "1.0", hollerith(stamp), igesNumber(1e-9 * std::max(1.0, maxCoordinate)),
      igesNumber(std::max(1.0, maxCoordinate)), hollerith(header.author), hollerith(header.organization), "11", "0",
      hollerith(stamp)};
  int g = 0;
  for (const std::string& line : wrap(global, ',', ';', 72)) out += sequenced(line, 'G', ++g);
  // Parameter data first (the directory needs its line numbers), then assemble.
  std::vector<std::string> parameterLines;
  std::vector<int> firstLine, lineCount;
  for (std::size_t k = 0; k < entities.size(); ++k) {
    const int de = 2 * static_cast<int>(k) + 1;
    const std::vector<std::string> lines = wrap(entities[k].parameters, ',', ';', 64);
    firstLine.push_back(static_cast<int>(parameterLines.size()) + 1);
    lineCount.push_back(static_cast<int>(lines.size()));
    for (const std::string& l : lines) parameterLines.push_back(padded(l, 64) + " " + field(de, 7));
  }
  int d = 0;
  for (std::size_t k = 0; k < entities.size(); ++k) {
    const Entity& e = entities[k];
    const std::string line1 = field(e.type) + field(firstLine[k]) + field(0) + field(0) + field(0) + field(0) +
                              field(0) + field(0) + "00000000";
    const std::string line2 = field(e.type) + field(0) + field(0) + field(lineCount[k]) + field(e.form) +
                              std::string(8, ' ') + std::string(8, ' ') + padded(e.label, 8) + field(0);
    out += sequenced(line1, 'D', ++d);
    out += sequenced(line2, 'D', ++d);
  }
  int p = 0;
  for (const std::string& l : parameterLines) out += sequenced(l, 'P', ++p);
  char terminate[80];
  std::snprintf(terminate, sizeof terminate, "S%7dG%7dD%7dP%7d", 1, g, d, p);
  out += sequenced(terminate, 'T', 1);
  return out;
}

void writeIges(const std::string& path, const std::vector<IgesSurface>& surfaces, const std::vector<IgesCurve>& curves,
               const IgesHeader& header) {
  const std::string text = igesDocument(surfaces, curves, header);
  std::ofstream file(path, std::ios::binary);
  if (!file) throw std::runtime_error("cannot write " + path);
  file << text;
  if (!file) throw std::runtime_error("cannot write " + path);
}

}  // namespace devsurf::io
