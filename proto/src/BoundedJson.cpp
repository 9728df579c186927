#include "devsurf/proto/BoundedJson.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>

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

namespace {

/// Whether nlohmann's compact dump writes `text` unchanged between its quotes: printable ASCII
/// other than the quote and the backslash (8 bytes at a time; a long base64 array is one such
/// string).
bool writtenVerbatim(const std::string& text) {
  const char* p = text.data();
  std::size_t n = text.size(), i = 0;
  for (; i + 8 <= n; i += 8) {
    std::uint64_t w;
    std::memcpy(&w, p + i, 8);
    constexpr std::uint64_t ones = 0x0101010101010101ULL, highs = 0x8080808080808080ULL;
    // A byte < 0x20 or ≥ 0x7f, or equal to '"' (0x22) or '\\' (0x5c), stops the fast scan.
    const std::uint64_t below = (w - ones * 0x20) & ~w & highs;
    const std::uint64_t above = (w + ones * 0x01) & highs;  // 0x7f + 1 and ≥ 0x80 set the high bit
    const std::uint64_t quote = ((w ^ (ones * 0x22)) - ones) & ~(w ^ (ones * 0x22)) & highs;
    const std::uint64_t slash = ((w ^ (ones * 0x5c)) - ones) & ~(w ^ (ones * 0x5c)) & highs;
    if ((below | above | (w & highs) | quote | slash) != 0) return false;
  }
  for (; i < n; ++i) {
    const unsigned char c = static_cast<unsigned char>(p[i]);
    if (c < 0x20 || c >= 0x7f || c == '"' || c == '\\') return false;
  }
  return true;
}

using Serializer = nlohmann::detail::serializer<nlohmann::json>;

/// value.dump(-1, ' ', false, replace) into `out`, with strings that need no escaping copied as
/// they are instead of character by character (nlohmann's dump_escaped was 5–6 % of a daemon
/// streaming a 10 000-unknown composite: its base64 arrays).
void writeWireText(const nlohmann::json& value, std::string& out, Serializer& scalars) {
  switch (value.type()) {
    case nlohmann::json::value_t::object: {
      out += '{';
      bool first = true;
      for (auto it = value.cbegin(); it != value.cend(); ++it) {
        if (!first) out += ',';
        first = false;
        const std::string& key = it.key();
        if (writtenVerbatim(key)) {
          out += '"';
          out += key;
          out += '"';
        } else {
          scalars.dump(nlohmann::json(key), false, false, 0);
        }
        out += ':';
        writeWireText(it.value(), out, scalars);
      }
      out += '}';
      return;
    }
    case nlohmann::json::value_t::array: {
      out += '[';
      bool first = true;
      for (const nlohmann::json& element : value) {
        if (!first) out += ',';
        first = false;
        writeWireText(element, out, scalars);
      }
      out += ']';
      return;
    }
    case nlohmann::json::value_t::string: {
      const std::string& text = value.get_ref<const std::string&>();
      if (writtenVerbatim(text)) {
        out += '"';
        out += text;
        out += '"';
        return;
      }
      break;
    }
    default: break;
  }
  scalars.dump(value, false, false, 0);
}

}  // namespace

std::string wireText(const nlohmann::json& value) {
  std::string out;
  Serializer scalars(nlohmann::detail::output_adapter<char>(out), ' ', nlohmann::json::error_handler_t::replace);
  writeWireText(value, out, scalars);
  return out;
}

nlohmann::json echoableId(const nlohmann::json& id) {
  if (id.is_number_integer()) return id;
  if (id.is_string() && id.get_ref<const std::string&>().size() <= 64) return id;
  return nullptr;
}

}  // namespace devsurf::proto
