#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

namespace devsurf::proto {

/// Deepest nesting of arrays and objects any document devsurf reads may have. The deepest valid
/// scene nests 5 levels (model.edges[e].points[k][i]); 64 leaves room and keeps every recursive
/// walk (parse, schema validation, dump, destruction) far from the stack's end: 80 000 levels of
/// `[` in one WebSocket frame had overflowed it while the error reply serialized the echo.
inline constexpr int kMaxJsonDepth = 64;

/// A document that nests deeper than allowed (checked before it is parsed).
class JsonTooDeep : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// Largest nesting depth of `text` as JSON, counting [ and { outside strings; stops counting (and
/// returns limit + 1) as soon as the depth passes `limit`. Does not validate the syntax.
int jsonNestingDepth(std::string_view text, int limit = kMaxJsonDepth);

/// nlohmann::json::parse after the depth check: throws JsonTooDeep (naming the limit) for a
/// document nested deeper than `maxDepth`, nlohmann::json::parse_error for invalid JSON.
nlohmann::json parseBoundedJson(std::string_view text, int maxDepth = kMaxJsonDepth);

/// An identifier the client chose (a message's `op`) as it may be echoed back: integers and strings
/// of at most 64 characters as they are, anything else null — never an unbounded echo of input.
nlohmann::json echoableId(const nlohmann::json& id);

}  // namespace devsurf::proto
