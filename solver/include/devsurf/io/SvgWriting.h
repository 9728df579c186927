#pragma once

#include <string>

#include <Eigen/Core>

namespace devsurf::io {

// Pieces shared by the SVG writers (svgFoldPattern, cuttingPatternSvg): number formatting, XML
// escaping, option checks, the page geometry in millimetres, the document head and the file write.

/// Locale-independent fixed-point number for SVG: `decimals` digits after the point
/// (std::to_chars), then trailing zeros and a trailing point removed, "-0" written "0"
/// (1.2500 → "1.25", 3.000 → "3", -0.00001 at 4 decimals → "0"). A value std::to_chars cannot
/// write is written "0".
class SvgNumberFormat {
 public:
  explicit SvgNumberFormat(int decimals) : decimals_(decimals) {}
  std::string operator()(double value) const;

 private:
  int decimals_;
};

/// What xmlEscape does with the characters on which the writers' established outputs differ.
struct XmlEscapeOptions {
  bool escapeApostrophe = true;    ///< ' → &apos; (else kept: valid in text and "…" attributes)
  bool keepCarriageReturn = true;  ///< keep '\r' (else dropped with the other control characters)
};

/// Text or attribute value for XML 1.0: & < > " escaped; control characters below 0x20 other than
/// tab and newline (and carriage return, when kept) dropped; everything else copied byte for byte.
std::string xmlEscape(const std::string& text, const XmlEscapeOptions& options = {});

/// Checks an option length in millimetres.
/// @throws std::invalid_argument "<optionsName>: <field> must be finite and > 0" (">= 0" when
///         allowZero) unless `value` is finite and positive (or zero when allowZero).
void checkSvgLength(double value, const char* optionsName, const char* field, bool allowZero);

/// Bounding box of a drawing's points (rows of a matrix whose columns 0 and 1 are x and y, in
/// drawing units); all zero for no points.
struct SvgBounds {
  double xmin = 0, xmax = 0, ymin = 0, ymax = 0;
};
SvgBounds svgBounds(const Eigen::Ref<const Eigen::MatrixXd>& points);

/// A drawing placed on paper: `marginMm` of blank border around its bounding box, scaled by
/// `mmPerUnit`. SVG's y axis points down, so y is flipped and the drawing is not mirrored.
struct SvgPage {
  SvgBounds bounds;
  double mmPerUnit = 1.0;
  double marginMm = 0.0;

  /// (xmax − xmin)·mmPerUnit + 2·margin
  double widthMm() const { return (bounds.xmax - bounds.xmin) * mmPerUnit + 2 * marginMm; }
  /// (ymax − ymin)·mmPerUnit + 2·margin
  double heightMm() const { return (bounds.ymax - bounds.ymin) * mmPerUnit + 2 * marginMm; }
  /// Paper x (mm from the left) of drawing x: margin + (x − xmin)·mmPerUnit.
  double x(double x) const { return marginMm + (x - bounds.xmin) * mmPerUnit; }
  /// Paper y (mm from the top) of drawing y: margin + (ymax − y)·mmPerUnit.
  double y(double y) const { return marginMm + (bounds.ymax - y) * mmPerUnit; }
};

/// The head of an SVG 1.1 document sized width × height millimetres with viewBox "0 0 W H" (one
/// user unit is one millimetre): the XML declaration, the <svg> start tag and the <title> and
/// <desc> elements (their text escaped with `escape`), each on its own line. The caller adds the
/// content and "</svg>\n".
std::string svgDocumentHead(double widthMm, double heightMm, const SvgNumberFormat& num,
                            const std::string& title, const std::string& description,
                            const XmlEscapeOptions& escape = {});

/// Writes `text` to `path` (binary, truncating).
/// @throws std::runtime_error "cannot write SVG file <path>" when opening or writing fails.
void writeSvgFile(const std::string& path, const std::string& text);

}  // namespace devsurf::io
