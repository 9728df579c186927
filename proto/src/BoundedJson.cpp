#include "devsurf/proto/BoundedJson.h"

#include <cmath>

namespace devsurf::proto {

int jsonNestingDepth(std::string_view text, int limit) {
  int depth = 0, deepest = 0;
  bool inString = false, escaped = false;
  for (const char ch : text) {
    if (inString) {
      if (escaped) escaped = false;
      else if (ch == '\\') escaped = true;
      else if (ch == '"') inString = false;
      continue;
    }
    switch (ch) {
      case '"': inString = true; break;
      case '[':
      case '{':
        if (++depth > deepest) {
          deepest = depth;
          if (deepest > limit) return limit + 1;
        }
        break;
      case ']':
      case '}':
        if (depth > 0) --depth;
        break;
      default: break;
    }
  }
  return deepest;
}

nlohmann::json parseBoundedJson(std::string_view text, int maxDepth) {
  if (jsonNestingDepth(text, maxDepth) > maxDepth)
    throw JsonTooDeep("the document nests deeper than " + std::to_string(maxDepth) + " levels of arrays and objects");
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::out_of_range& e) {
    // A number too large for a double (1e999): nlohmann reports it as out_of_range.406, quoting
    // the number; repeated only when short.
    const std::string what = e.what();
    const auto open = what.find("parsing '");
    const auto close = open == std::string::npos ? open : what.find('\'', open + 9);
    std::string number;
    if (close != std::string::npos && close - open - 9 <= 40) number = what.substr(open + 9, close - open - 9) + " ";
    throw JsonSyntaxError("the number " + number + "is out of the range of a double");
  } catch (const nlohmann::json::parse_error& e) {
    // "[json.exception.parse_error.101] parse error at line 1, column 9: syntax error while
    // parsing value - invalid string: ill-formed UTF-8 byte; last read: '…'": keep the reason,
    // drop the prefix and the quoted input.
    std::string why = e.what();
    if (const auto colon = why.find(": "); colon != std::string::npos) why.erase(0, colon + 2);
    if (const auto quoted = why.find("; last read"); quoted != std::string::npos) why.erase(quoted);
    std::string clean;
    for (const char ch : why)
      if (ch >= 0x20 && ch < 0x7f) clean += ch;
    if (clean.size() > 200) clean.resize(200);
    throw JsonSyntaxError("at byte " + std::to_string(e.byte) + ": " + clean);
  }
}

std::string nonFinitePath(const nlohmann::json& value, const std::string& prefix) {
  if (value.is_number_float()) return std::isfinite(value.get<double>()) ? std::string() : (prefix.empty() ? "(root)" : prefix);
  if (value.is_array()) {
    for (std::size_t i = 0; i < value.size(); ++i)
      if (std::string p = nonFinitePath(value[i], prefix + "[" + std::to_string(i) + "]"); !p.empty()) return p;
  } else if (value.is_object()) {
    for (const auto& [key, v] : value.items())
      if (std::string p = nonFinitePath(v, prefix.empty() ? key : prefix + "." + key); !p.empty()) return p;
  }
  return {};
}

std::string wireText(const nlohmann::json& value) {
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

nlohmann::json echoableId(const nlohmann::json& id) {
  if (id.is_number_integer()) return id;
  if (id.is_string() && id.get_ref<const std::string&>().size() <= 64) return id;
  return nullptr;
}

}  // namespace devsurf::proto
