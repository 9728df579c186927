#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

namespace devsurf::io {

/// A B-spline (or NURBS) curve for IGES entity 126.
struct IgesCurve {
  int degree = 3;
  std::vector<double> knots;     ///< n + degree + 1 values (clamped or not)
  Eigen::MatrixX3d points;       ///< n control points, one per row
  Eigen::VectorXd weights;       ///< n weights, or empty for a polynomial curve
  std::string label;             ///< entity label (≤ 8 characters written)
};

/// A tensor-product B-spline (or NURBS) surface for IGES entity 128.
///
/// Control net convention: points(i + nu·j) is P_{i,j}, i along u (0 … nu−1), j along v — the
/// order IGES writes them in (u index fastest).
struct IgesSurface {
  int degreeU = 1, degreeV = 3;
  std::vector<double> knotsU;    ///< nu + degreeU + 1 values
  std::vector<double> knotsV;    ///< nv + degreeV + 1 values
  int nu = 0, nv = 0;            ///< control points along u and along v
  Eigen::MatrixX3d points;       ///< nu·nv rows, u index fastest
  Eigen::VectorXd weights;       ///< nu·nv weights (same order), or empty
  std::string label;
};

/// File-level data of the Global section.
struct IgesHeader {
  std::string fileName = "devsurf.igs";
  std::string author = "devsurf";
  std::string organization = "devsurf";
  std::string timestamp;         ///< "YYYYMMDD.HHMMSS"; empty = now (UTC)
  /// Model units: "mm", "cm", "m" or "in" (IGES unit flags 2, 10, 6, 1).
  std::string units = "mm";
};

/// IGES 5.3 document (fixed 80-column ASCII: Start, Global, Directory Entry, Parameter Data and
/// Terminate sections) holding the given surfaces as entity 128 and curves as entity 126, all
/// independent (status 00000000), in model space. Numbers are written with 17 significant
/// digits so that a reader recovers the doubles exactly.
/// @throws std::invalid_argument naming the entity ("surfaces[0].knotsU: …") when sizes disagree
std::string igesDocument(const std::vector<IgesSurface>& surfaces, const std::vector<IgesCurve>& curves,
                         const IgesHeader& header = {});

/// Writes igesDocument to path.
/// @throws std::runtime_error if the file cannot be written
void writeIges(const std::string& path, const std::vector<IgesSurface>& surfaces,
               const std::vector<IgesCurve>& curves, const IgesHeader& header = {});

}  // namespace devsurf::io
