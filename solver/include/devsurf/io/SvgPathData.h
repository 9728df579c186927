#pragma once
// SVG geometry below the element level, for io::importSvgText: path data (SVG 1.1 §8.3), the
// transform attribute, number lists.

#include <string>
#include <vector>

#include <Eigen/Core>

namespace devsurf::io::svg {

inline constexpr double kPi = 3.14159265358979323846;

/// @throws std::invalid_argument "SVG: " + message
[[noreturn]] void refuseSvg(const std::string& message);

/// 2D affine map [a c e; b d f] (SVG's matrix(a b c d e f)).
using Affine = Eigen::Matrix<double, 2, 3>;
Affine identityAffine();
Affine compose(const Affine& outer, const Affine& inner);  ///< outer ∘ inner
Eigen::Vector2d applyAffine(const Affine& m, const Eigen::Vector2d& p);

/// The transform attribute: matrix, translate, scale, rotate (about a point), skewX, skewY, composed
/// left to right. @throws std::invalid_argument naming `element` for anything else
Affine parseTransform(const std::string& text, const std::string& element);

/// One drawn piece: a straight segment (2 points) or a sampled curve.
struct Piece {
  std::vector<Eigen::Vector2d> points;
  bool curved = false;
};
/// The pieces from one M to the next (closed by Z).
struct Subpath {
  std::vector<Piece> pieces;
  bool closed = false;
};

/// An elliptical arc from its end points (SVG 1.1 F.6.5: radii scaled up when too small), sampled
/// with perHalfTurn points per half turn (≥ 4) into `piece`.
void sampleArc(const Eigen::Vector2d& p0, const Eigen::Vector2d& p1, double rx, double ry, double phiDeg, int largeArc,
               int sweep, int perHalfTurn, Piece& piece);

/// Path data (M L H V C S Q T A Z, absolute and relative, implicit repeats) as subpaths in user
/// units; Bézier pieces sampled with `samples` points. @throws std::invalid_argument naming
/// `element` and the character position
std::vector<Subpath> parsePathData(const std::string& d, const std::string& element, int samples);

/// Numbers separated by white space or commas. @throws std::invalid_argument naming element and attribute
std::vector<double> numbersOf(const std::string& text, const std::string& element, const std::string& attribute);

}  // namespace devsurf::io::svg
