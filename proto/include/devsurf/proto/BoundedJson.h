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

/// A document that is not JSON (syntax, or a string that is not UTF-8). what() is short and
/// plain ASCII: it says where and why, and never repeats the input (nlohmann's own message
/// quotes the token it read last, which may be megabytes of the client's bytes).
class JsonSyntaxError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// nlohmann::json::parse after the depth check: throws JsonTooDeep (naming the limit) for a
/// document nested deeper than `maxDepth`, JsonSyntaxError for invalid JSON.
nlohmann::json parseBoundedJson(std::string_view text, int maxDepth = kMaxJsonDepth);

/// The JSON path (`model.b.points[3][2]`; `prefix` first) of the first number in `value` that
/// is NaN or infinite (nlohmann keeps them as doubles and writes them as null), or "" if none.
std::string nonFinitePath(const nlohmann::json& value, const std::string& prefix = "");

/// `value` serialized for the wire: compact, and any invalid UTF-8 in its strings replaced by
/// U+FFFD instead of throwing (an error message may quote what a client sent).
std::string wireText(const nlohmann::json& value);

/// An identifier the client chose (a message's `op`) as it may be echoed back: integers and strings
/// of at most 64 characters as they are, anything else null — never an unbounded echo of input.
nlohmann::json echoableId(const nlohmann::json& id);

}  // namespace devsurf::proto
