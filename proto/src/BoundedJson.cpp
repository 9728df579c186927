#include "devsurf/proto/BoundedJson.h"

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
  return nlohmann::json::parse(text);
}

nlohmann::json echoableId(const nlohmann::json& id) {
  if (id.is_number_integer()) return id;
  if (id.is_string() && id.get_ref<const std::string&>().size() <= 64) return id;
  return nullptr;
}

}  // namespace devsurf::proto
