#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "devsurf/reference/ReferenceShape.h"

namespace devsurf::server {

/// A bad field of a request that brings a user's shape (a query parameter, the body, a CLI
/// option): the route answers 400 naming `field` (413 when `tooLarge`).
class ApproximationInputError : public std::invalid_argument {
 public:
  ApproximationInputError(std::string field, const std::string& message, bool tooLarge = false)
      : std::invalid_argument(message), field_(std::move(field)), tooLarge_(tooLarge) {}
  const std::string& field() const { return field_; }
  bool tooLarge() const { return tooLarge_; }

 private:
  std::string field_;
  bool tooLarge_;
};

/// An integer query parameter in [lo, hi]. @throws ApproximationInputError naming it
long integerParameter(const std::string& field, const std::string& value, long lo, long hi);
/// A finite number in [lo, hi] (> 0 when `positive`). @throws ApproximationInputError naming it
double numberParameter(const std::string& field, const std::string& value, double lo, double hi, bool positive);

/// A scene name (at most 200 characters). @throws ApproximationInputError naming it
std::string nameParameter(const std::string& field, const std::string& value);
/// Scene units: mm, cm, m or in. @throws ApproximationInputError naming it
std::string unitsParameter(const std::string& field, const std::string& value);

/// A shape sent as a request body: `format` is the file's extension (one of `formats`: "off",
/// "obj", "ply", "stl", "xyz", "pwn"), read through reference::readReferenceShape from a private
/// temporary file (removed on return) within `limits`; messages name "body" instead of the file.
/// @throws ApproximationInputError naming "format" or "body"
reference::ReferenceShape readUploadedShape(const std::string& body, const std::string& format,
                                            const std::vector<std::string>& formats,
                                            const reference::ReferenceLimits& limits);

}  // namespace devsurf::server
