#include "devsurf/io/SvgWriting.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <stdexcept>

namespace devsurf::io {

std::string SvgNumberFormat::operator()(double value) const {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof buf, value, std::chars_format::fixed, decimals_);
  std::string s = res.ec == std::errc() ? std::string(buf, res.ptr) : std::string("0");
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  return s;
}

std::string xmlEscape(const std::string& text, const XmlEscapeOptions& options) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    switch (ch) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += options.escapeApostrophe ? "&apos;" : "'"; break;
      default: {
        const bool allowedControl = ch == '\t' || ch == '\n' || (ch == '\r' && options.keepCarriageReturn);
        if (static_cast<unsigned char>(ch) >= 0x20 || allowedControl) out += ch;
      }
    }
  }
  return out;
}

void checkSvgLength(double value, const char* optionsName, const char* field, bool allowZero) {
  if (!std::isfinite(value) || value < 0.0 || (!allowZero && value == 0.0))
    throw std::invalid_argument(std::string(optionsName) + ": " + field +
                                (allowZero ? " must be finite and >= 0" : " must be finite and > 0"));
}

SvgBounds svgBounds(const Eigen::Ref<const Eigen::MatrixXd>& points) {
  SvgBounds b;
  if (points.rows() > 0) {
    b.xmin = points.col(0).minCoeff();
    b.xmax = points.col(0).maxCoeff();
    b.ymin = points.col(1).minCoeff();
    b.ymax = points.col(1).maxCoeff();
  }
  return b;
}

std::string svgDocumentHead(double widthMm, double heightMm, const SvgNumberFormat& num,
                            const std::string& title, const std::string& description,
                            const XmlEscapeOptions& escape) {
  const std::string W = num(widthMm), H = num(heightMm);
  std::string out;
  out += "<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"no\"?>\n";
  out += "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" + W + "mm\" height=\"" +
         H + "mm\" viewBox=\"0 0 " + W + " " + H + "\">\n";
  out += "  <title>" + xmlEscape(title, escape) + "</title>\n";
  out += "  <desc>" + xmlEscape(description, escape) + "</desc>\n";
  return out;
}

void writeSvgFile(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error("cannot write SVG file " + path);
  out << text;
  out.flush();
  if (!out) throw std::runtime_error("cannot write SVG file " + path);
}

}  // namespace devsurf::io
