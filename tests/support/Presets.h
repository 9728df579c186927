#pragma once

// The presets of examples/, discovered (a new preset is covered by every suite that uses this
// without editing it).

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace devsurf::testing {

/// Every devsurf scene document in examples/ by file name, read and parsed once per process: the
/// parameterized suites ask for the presets at static initialization, in every process CTest
/// starts for one test (parsing the 1.4 MB of examples once per suite: test_server started in 0.41 s,
/// now in 0.18 s).
inline const std::map<std::string, nlohmann::json>& presetDocuments() {
  static const std::map<std::string, nlohmann::json> documents = [] {
    std::map<std::string, nlohmann::json> out;
    for (const auto& entry : std::filesystem::directory_iterator(std::string(DEVSURF_SOURCE_DIR) + "/examples")) {
      if (entry.path().extension() != ".json") continue;
      std::ifstream file(entry.path());
      std::ostringstream text;  // from memory: parsing from the stream reads it a character at a time
      text << file.rdbuf();
      nlohmann::json doc = nlohmann::json::parse(text.str(), nullptr, false);
      if (doc.is_object() && doc.value("format", "") == "devsurf-scene")
        out.emplace(entry.path().filename().string(), std::move(doc));
    }
    return out;
  }();
  return documents;
}

/// File names (e.g. "strip-twisted.json") of every devsurf scene in examples/, sorted.
inline std::vector<std::string> presetFiles() {
  std::vector<std::string> names;
  for (const auto& [name, doc] : presetDocuments()) names.push_back(name);
  return names;
}

/// The scene document of examples/`name` (a copy: callers edit it).
inline nlohmann::json readPreset(const std::string& name) {
  const auto found = presetDocuments().find(name);
  if (found != presetDocuments().end()) return found->second;
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
