#pragma once

// The presets of examples/, discovered (a new preset is covered by every suite that uses this
// without editing it).

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace devsurf::testing {

/// File names (e.g. "strip-twisted.json") of every devsurf scene in examples/, sorted.
inline std::vector<std::string> presetFiles() {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(DEVSURF_SOURCE_DIR) + "/examples")) {
    if (entry.path().extension() != ".json") continue;
    std::ifstream file(entry.path());
    const nlohmann::json doc = nlohmann::json::parse(file, nullptr, false);
    if (doc.is_object() && doc.value("format", "") == "devsurf-scene") names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

/// The scene document of examples/`name`.
inline nlohmann::json readPreset(const std::string& name) {
  std::ifstream file(std::string(DEVSURF_SOURCE_DIR) + "/examples/" + name);
  return nlohmann::json::parse(file);
}

/// A parameterized test's name for a preset file: "composite-curved-fold.json" → "composite_curved_fold".
/// Use as INSTANTIATE_TEST_SUITE_P(…, ValuesIn(presetFiles()), presetTestName).
template <class Info>
std::string presetTestName(const Info& info) {
  std::string n = info.param.substr(0, info.param.size() - 5);
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
}

}  // namespace devsurf::testing
