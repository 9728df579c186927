// Reading a shape sent as a request body, and the query parameters of the routes that bring one
// (issue 15): POST /api/approximations, /api/references, /api/fits, /api/covers.
#include "devsurf/server/ShapeUpload.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include <unistd.h>

#include "devsurf/proto/Scene.h"

namespace devsurf::server {

long integerParameter(const std::string& field, const std::string& value, long lo, long hi) {
  std::size_t used = 0;
  long v = 0;
  try {
    v = std::stol(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (value.empty() || used != value.size() || v < lo || v > hi)
    throw ApproximationInputError(field, field + ": expected an integer " + std::to_string(lo) + " … " +
                                             std::to_string(hi) + ", got \"" + value + "\"");
  return v;
}

double numberParameter(const std::string& field, const std::string& value, double lo, double hi, bool positive) {
  std::size_t used = 0;
  double v = NAN;
  try {
    v = std::stod(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (value.empty() || used != value.size() || !std::isfinite(v) || v < lo || v > hi || (positive && !(v > 0.0))) {
    std::ostringstream range;
    range << (positive ? "a number > " : "a number ") << lo << " … " << hi;
    throw ApproximationInputError(field, field + ": expected " + range.str() + ", got \"" + value + "\"");
  }
  return v;
}

std::string nameParameter(const std::string& field, const std::string& value) {
  if (value.size() > 200) throw ApproximationInputError(field, field + ": at most 200 characters");
  return value;
}

std::string unitsParameter(const std::string& field, const std::string& value) {
  try {
    proto::millimetresPerUnit(value);
  } catch (const std::invalid_argument&) {
    throw ApproximationInputError(field, field + ": expected mm, cm, m or in, got \"" + value + "\"");
  }
  return value;
}

reference::ReferenceShape readUploadedShape(const std::string& body, const std::string& format,
                                            const std::vector<std::string>& formats,
                                            const reference::ReferenceLimits& limits) {
  if (std::find(formats.begin(), formats.end(), format) == formats.end()) {
    std::string list;
    for (std::size_t k = 0; k < formats.size(); ++k) list += (k ? (k + 1 == formats.size() ? " or " : ", ") : "") + formats[k];
    throw ApproximationInputError("format", "format: expected " + list + ", got \"" + format + "\"");
  }
  if (body.empty()) throw ApproximationInputError("body", "body: empty; send the shape's file as the request body");
  if (body.size() > limits.maxFileBytes)
    throw ApproximationInputError("body", "body: " + std::to_string(body.size()) + " bytes; the limit is " +
                                              std::to_string(limits.maxFileBytes), true);
  // The readers take a path: a private file under the temporary directory, removed on return.
  static std::atomic<unsigned long> counter{0};
  std::random_device entropy;
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      ("devsurf-upload-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-" + std::to_string(entropy()) +
       "." + format);
  struct Removal {
    std::filesystem::path path;
    ~Removal() {
      std::error_code ignored;
      std::filesystem::remove(path, ignored);
    }
  } removal{path};
  {
    std::ofstream file(path, std::ios::binary | std::ios::trunc);
    std::filesystem::permissions(path, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
    if (!(file << body) || !file.flush()) throw std::runtime_error("cannot write the upload to a temporary file");
  }
  try {
    return reference::readReferenceShape(path.string(), limits);
  } catch (const std::invalid_argument& e) {
    std::string message = e.what();
    const std::string name = path.string();
    for (std::size_t at = message.find(name); at != std::string::npos; at = message.find(name))
      message.replace(at, name.size(), "body");
    const bool tooLarge = message.find("limit") != std::string::npos;
    throw ApproximationInputError("body", message, tooLarge);
  }
}

}  // namespace devsurf::server
