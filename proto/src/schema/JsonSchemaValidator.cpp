#include "devsurf/proto/JsonSchemaValidator.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <stdexcept>
#include <utility>

namespace devsurf::proto {

using nlohmann::json;

namespace {

/// $ref hops allowed without descending into the instance; more means a $ref cycle.
constexpr int kMaxRefHops = 32;
/// Longest excerpt of an instance value quoted in a message (code points).
constexpr std::size_t kMaxQuoted = 40;

// ---------------------------------------------------------------------------------------------
// Small helpers
// ---------------------------------------------------------------------------------------------

std::string plural(std::size_t n, const char* word) {
  std::string s = std::to_string(n) + " " + word;
  if (n != 1) s += "s";
  return s;
}

std::size_t utf8Length(const std::string& s) {
  std::size_t n = 0;
  for (unsigned char c : s) {
    if ((c & 0xC0) != 0x80) ++n;
  }
  return n;
}

/// Cuts `s` to at most `max` code points, appending "…" if it was cut.
std::string utf8Truncate(const std::string& s, std::size_t max) {
  std::size_t count = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if ((static_cast<unsigned char>(s[i]) & 0xC0) != 0x80) {
      if (count == max) return s.substr(0, i) + "…";
      ++count;
    }
  }
  return s;
}

std::string dumpSafe(const json& v) { return v.dump(-1, ' ', false, json::error_handler_t::replace); }

/// A value as quoted in a message: JSON text (strings in quotes), shortened.
std::string brief(const json& v) {
  if (v.is_string()) return dumpSafe(json(utf8Truncate(v.get_ref<const std::string&>(), kMaxQuoted)));
  if (v.is_object()) return v.empty() ? "{}" : "an object";
  if (v.is_array()) return v.empty() ? "[]" : "an array";
  return dumpSafe(v);
}

/// A value as listed among allowed ones ("must be one of: vectors, spline"): strings bare.
std::string listed(const json& v) {
  if (v.is_string()) return v.get<std::string>();
  return dumpSafe(v);
}

std::string typeName(const json& v) {
  switch (v.type()) {
    case json::value_t::null: return "null";
    case json::value_t::boolean: return "boolean";
    case json::value_t::object: return "object";
    case json::value_t::array: return "array";
    case json::value_t::string: return "string";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float: return "number";
    default: return "unknown";
  }
}

std::string withArticle(const std::string& type) {
  if (type == "null") return "null";
  if (type == "object" || type == "array" || type == "integer") return "an " + type;
  return "a " + type;
}

bool isFiniteNumber(const json& v) {
  return v.is_number() && (!v.is_number_float() || std::isfinite(v.get<double>()));
}

bool isIntegral(const json& v) {
  if (v.is_number_integer()) return true;  // also true for number_unsigned
  if (!v.is_number_float()) return false;
  const double d = v.get<double>();
  return std::isfinite(d) && std::floor(d) == d;
}

bool typeMatches(const json& v, const std::string& t) {
  if (t == "number") return isFiniteNumber(v);
  if (t == "integer") return isIntegral(v);
  if (t == "string") return v.is_string();
  if (t == "object") return v.is_object();
  if (t == "array") return v.is_array();
  if (t == "boolean") return v.is_boolean();
  if (t == "null") return v.is_null();
  return false;
}

const std::set<std::string>& typeNames() {
  static const std::set<std::string> names{"null", "boolean", "object", "array",
                                           "string", "number", "integer"};
  return names;
}

long double asLongDouble(const json& v) {
  if (v.is_number_unsigned()) return static_cast<long double>(v.get<std::uint64_t>());
  if (v.is_number_integer()) return static_cast<long double>(v.get<std::int64_t>());
  return static_cast<long double>(v.get<double>());
}

/// <0, 0, >0 like a - b (exact for any mix of int64, uint64 and double).
int compareNumbers(const json& a, const json& b) {
  const long double x = asLongDouble(a), y = asLongDouble(b);
  return x < y ? -1 : (x > y ? 1 : 0);
}

bool plainKey(const std::string& key) {
  if (key.empty()) return false;
  for (unsigned char c : key) {
    if (c == '.' || c == '[' || c == ']' || c == '"' || c <= ' ') return false;
  }
  return true;
}

/// Appends a member segment to `path`.
void appendMember(std::string& path, const std::string& key) {
  if (plainKey(key)) {
    if (!path.empty()) path += '.';
    path += key;
  } else {
    path += '[';
    path += dumpSafe(json(key));
    path += ']';
  }
}

std::string memberPath(const std::string& path, const std::string& key) {
  std::string p = path;
  appendMember(p, key);
  return p;
}

void appendIndex(std::string& path, std::size_t i) {
  path += '[';
  path += std::to_string(i);
  path += ']';
}

/// Number of segments in an error path (how deep into the instance it points).
int pathDepth(const std::string& path) {
  if (path.empty()) return 0;
  int n = path[0] == '[' ? 0 : 1;
  bool quoted = false;
  for (std::size_t i = 0; i < path.size(); ++i) {
    const char c = path[i];
    if (quoted) {
      if (c == '\\') ++i;
      else if (c == '"') quoted = false;
    } else if (c == '"') {
      quoted = true;
    } else if (c == '.' || c == '[') {
      ++n;
    }
  }
  return n;
}

std::string percentDecode(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() &&
        std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
      out += static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

/// The schema at URI fragment `fragment` ("" or "/json/pointer") of `root`, or nullptr.
const json* resolveFragment(const json& root, const std::string& fragment) {
  if (fragment.empty()) return &root;
  if (fragment[0] != '/') return nullptr;  // plain-name anchors are not supported
  try {
    const json::json_pointer ptr(percentDecode(fragment));
    if (!root.contains(ptr)) return nullptr;
    return &root.at(ptr);
  } catch (const json::exception&) {
    return nullptr;
  }
}

/// Splits "doc#fragment" into ("doc", "fragment").
std::pair<std::string, std::string> splitRef(const std::string& ref) {
  const auto hash = ref.find('#');
  if (hash == std::string::npos) return {ref, ""};
  return {ref.substr(0, hash), ref.substr(hash + 1)};
}

/// properties[prop].const (or a one-value enum) of a discriminator branch, or nullptr.
const json* branchConstant(const json& branch, const std::string& prop) {
  if (!branch.is_object()) return nullptr;
  const auto props = branch.find("properties");
  if (props == branch.end() || !props->is_object()) return nullptr;
  const auto p = props->find(prop);
  if (p == props->end() || !p->is_object()) return nullptr;
  if (const auto c = p->find("const"); c != p->end()) return &*c;
  if (const auto e = p->find("enum"); e != p->end() && e->is_array() && e->size() == 1) {
    return &(*e)[0];
  }
  return nullptr;
}

// ---------------------------------------------------------------------------------------------
// Schema checking at add()
// ---------------------------------------------------------------------------------------------

class SchemaChecker {
 public:
  SchemaChecker(const std::string& name, const json& root,
                std::map<std::string, std::shared_ptr<const std::regex>>& regex)
      : name_(name), root_(root), regex_(regex) {}

  void check(const json& schema, const std::string& where) {
    if (schema.is_boolean()) return;
    if (!schema.is_object()) fail(where, "a schema must be an object or a boolean");
    for (auto it = schema.begin(); it != schema.end(); ++it) {
      const std::string& key = it.key();
      const json& v = it.value();
      const std::string at = where + "/" + escape(key);
      if (isAnnotation(key)) continue;
      if (key.rfind("x-", 0) == 0) {
        if (key == "x-error" && !v.is_string()) fail(at, "must be a string");
        continue;
      }
      if (key == "type") {
        checkType(v, at);
      } else if (key == "enum") {
        if (!v.is_array() || v.empty()) fail(at, "must be a non-empty array");
      } else if (key == "const") {
      } else if (key == "minimum" || key == "maximum" || key == "exclusiveMinimum" ||
                 key == "exclusiveMaximum") {
        if (!isFiniteNumber(v)) fail(at, "must be a number");
      } else if (key == "minLength" || key == "maxLength" || key == "minItems" ||
                 key == "maxItems" || key == "minProperties" || key == "maxProperties") {
        if (!isIntegral(v) || v.get<double>() < 0) fail(at, "must be a non-negative integer");
      } else if (key == "pattern") {
        checkPattern(v, at);
      } else if (key == "required") {
        if (!v.is_array()) fail(at, "must be an array of strings");
        for (const auto& r : v) {
          if (!r.is_string()) fail(at, "must be an array of strings");
        }
      } else if (key == "properties" || key == "$defs") {
        if (!v.is_object()) fail(at, "must be an object of schemas");
        for (auto p = v.begin(); p != v.end(); ++p) check(p.value(), at + "/" + escape(p.key()));
      } else if (key == "additionalProperties" || key == "items" || key == "not" || key == "if" ||
                 key == "then" || key == "else") {
        check(v, at);
      } else if (key == "prefixItems" || key == "allOf" || key == "anyOf" || key == "oneOf") {
        if (!v.is_array() || v.empty()) fail(at, "must be a non-empty array of schemas");
        for (std::size_t i = 0; i < v.size(); ++i) check(v[i], at + "/" + std::to_string(i));
      } else if (key == "$ref") {
        checkRef(v, at);
      } else if (key == "discriminator") {
        checkDiscriminator(schema, v, at);
      } else {
        fail(at, "unsupported keyword \"" + key + "\"");
      }
    }
  }

 private:
  static bool isAnnotation(const std::string& key) {
    static const std::set<std::string> keys{
        "$schema", "$id",      "$comment", "title",    "description", "default",
        "examples", "deprecated", "readOnly", "writeOnly", "format"};
    return keys.count(key) != 0;
  }

  static std::string escape(const std::string& key) {
    std::string out;
    for (char c : key) {
      if (c == '~') out += "~0";
      else if (c == '/') out += "~1";
      else out += c;
    }
    return out;
  }

  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw std::invalid_argument("schema " + name_ + "#" + where + ": " + what);
  }

  void checkType(const json& v, const std::string& at) const {
    auto one = [&](const json& t) {
      if (!t.is_string() || typeNames().count(t.get<std::string>()) == 0) {
        fail(at, "unknown type " + dumpSafe(t));
      }
    };
    if (v.is_array()) {
      if (v.empty()) fail(at, "must not be empty");
      for (const auto& t : v) one(t);
    } else {
      one(v);
    }
  }

  void checkPattern(const json& v, const std::string& at) {
    if (!v.is_string()) fail(at, "must be a string");
    const std::string& p = v.get_ref<const std::string&>();
    if (regex_.count(p) != 0) return;
    try {
      regex_[p] = std::make_shared<const std::regex>(p, std::regex::ECMAScript);
    } catch (const std::regex_error& e) {
      fail(at, "invalid pattern \"" + p + "\": " + e.what());
    }
  }

  /// The local target of `ref`, nullptr for a cross-document one; fails if unresolvable.
  const json* local(const json& ref, const std::string& at) const {
    if (!ref.is_string()) fail(at, "must be a string");
    const auto [doc, fragment] = splitRef(ref.get<std::string>());
    if (!doc.empty()) return nullptr;
    const json* target = resolveFragment(root_, fragment);
    if (target == nullptr) fail(at, "cannot resolve " + dumpSafe(ref));
    return target;
  }

  void checkRef(const json& v, const std::string& at) const { local(v, at); }

  void checkDiscriminator(const json& schema, const json& v, const std::string& at) const {
    if (!v.is_object() || !v.contains("propertyName") || !v["propertyName"].is_string() ||
        v.size() != 1) {
      fail(at, "must be {\"propertyName\": \"<name>\"}");
    }
    const auto oneOf = schema.find("oneOf");
    if (oneOf == schema.end() || !oneOf->is_array()) fail(at, "needs a oneOf next to it");
    const std::string prop = v["propertyName"].get<std::string>();
    std::set<std::string> seen;
    for (std::size_t i = 0; i < oneOf->size(); ++i) {
      const json* branch = &(*oneOf)[i];
      const std::string branchAt = at + "/../oneOf/" + std::to_string(i);
      int hops = 0;
      while (branch != nullptr && branch->is_object() && branchConstant(*branch, prop) == nullptr &&
             branch->contains("$ref") && ++hops <= kMaxRefHops) {
        branch = local((*branch)["$ref"], branchAt);
      }
      if (branch == nullptr) continue;  // cross-document: checked when used
      const json* c = branchConstant(*branch, prop);
      if (c == nullptr) fail(branchAt, "discriminator branch without properties." + prop + ".const");
      if (!seen.insert(dumpSafe(*c)).second) fail(branchAt, "duplicate " + prop + " " + dumpSafe(*c));
    }
  }

  const std::string& name_;
  const json& root_;
  std::map<std::string, std::shared_ptr<const std::regex>>& regex_;
};

/// Calls `f(schema)` for every schema object holding a "$ref" inside `schema`.
template <class F>
void forEachRef(const json& schema, F&& f) {
  if (!schema.is_object()) return;
  if (schema.contains("$ref")) f(schema);
  for (auto it = schema.begin(); it != schema.end(); ++it) {
    const std::string& key = it.key();
    const json& v = it.value();
    if (key == "properties" || key == "$defs") {
      if (v.is_object()) {
        for (const auto& s : v) forEachRef(s, f);
      }
    } else if (key == "additionalProperties" || key == "items" || key == "not" || key == "if" ||
               key == "then" || key == "else") {
      forEachRef(v, f);
    } else if (key == "prefixItems" || key == "allOf" || key == "anyOf" || key == "oneOf") {
      if (v.is_array()) {
        for (const auto& s : v) forEachRef(s, f);
      }
    }
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// SchemaError
// ---------------------------------------------------------------------------------------------

std::string SchemaError::toString() const {
  return (path.empty() ? std::string("(root)") : path) + ": " + message;
}

// ---------------------------------------------------------------------------------------------
// Validator
// ---------------------------------------------------------------------------------------------

class SchemaRegistry::Validator {
 public:
  /// Collects errors up to a limit.
  struct Sink {
    explicit Sink(std::size_t limit) : limit(std::max<std::size_t>(limit, 1)) {}
    std::vector<SchemaError> errors;
    std::size_t limit;
    bool full() const { return errors.size() >= limit; }
    void add(const std::string& path, const char* rule, std::string message) {
      if (!full()) errors.push_back(SchemaError{path, rule, std::move(message)});
    }
  };

  explicit Validator(const SchemaRegistry& registry) : reg_(registry) {}

  /// Validates `inst` (at `path`, `depth` levels below the root) against `schema`, a subschema
  /// of document `doc`. Returns whether it is valid; adds errors to `out`. `path` is restored.
  bool node(const json& inst, const json& schema, const json& doc, std::string& path, int depth,
            int hops, Sink& out) {
    if (schema.is_object()) {
      const auto xerror = schema.find("x-error");
      if (xerror != schema.end() && xerror->is_string()) {
        Sink probe(1);
        const char* failed = "x-error";
        if (keywords(inst, schema, doc, path, depth, hops, probe, &failed)) return true;
        out.add(path, failed, xerror->get<std::string>());
        return false;
      }
    }
    return keywords(inst, schema, doc, path, depth, hops, out, nullptr);
  }

 private:
  static bool trivial(const json& schema) {
    return (schema.is_boolean() && schema.get<bool>()) || (schema.is_object() && schema.empty());
  }

  /// Validates a member/item of the current instance; `path` already points at it.
  bool descend(const json& inst, const json& schema, const json& doc, std::string& path,
               int depth, Sink& out) {
    if (trivial(schema)) return true;
    if (depth + 1 > kMaxDepth) {
      out.add(path, "depth", "nested too deeply (more than " + std::to_string(kMaxDepth) +
                                 " levels)");
      return false;
    }
    return node(inst, schema, doc, path, depth + 1, 0, out);
  }

  SchemaRegistry::Target target(const json& schema, const json& doc) const {
    const auto cached = reg_.refCache_.find(&schema);
    if (cached != reg_.refCache_.end()) return cached->second;
    return reg_.resolve(schema["$ref"].get<std::string>(), doc);
  }

  bool keywords(const json& inst, const json& schema, const json& doc, std::string& path,
                int depth, int hops, Sink& out, const char** failed) {
    if (schema.is_boolean()) {
      if (schema.get<bool>()) return true;
      if (failed != nullptr) *failed = "false";
      out.add(path, "false", "is not allowed");
      return false;
    }

    bool ok = true;
    // Records a failed keyword; true if validation of this schema should stop here.
    auto fail = [&](const char* keyword) {
      if (ok && failed != nullptr) *failed = keyword;
      ok = false;
      return out.full();
    };
    const auto end = schema.end();

    // --- $ref ------------------------------------------------------------------------------
    if (const auto ref = schema.find("$ref"); ref != end) {
      if (hops + 1 > kMaxRefHops) {
        throw std::logic_error("JSON Schema: $ref cycle at " + ref->get<std::string>() +
                               " (instance path \"" + path + "\")");
      }
      const auto t = target(schema, doc);
      if (!node(inst, *t.schema, *t.document, path, depth, hops + 1, out) && fail("$ref")) {
        return false;
      }
    }

    // --- type ------------------------------------------------------------------------------
    if (const auto type = schema.find("type"); type != end) {
      if (!checkType(inst, *type, path, out)) {
        fail("type");
        return false;  // the remaining keywords would only add noise
      }
    }

    // --- enum / const ----------------------------------------------------------------------
    if (const auto e = schema.find("enum"); e != end) {
      if (std::find(e->begin(), e->end(), inst) == e->end()) {
        std::string allowed;
        for (const auto& v : *e) allowed += (allowed.empty() ? "" : ", ") + listed(v);
        out.add(path, "enum", "must be one of: " + allowed);
        if (fail("enum")) return false;
      }
    }
    if (const auto c = schema.find("const"); c != end) {
      if (inst != *c) {
        out.add(path, "const", "must be " + brief(*c) + ", got " + brief(inst));
        if (fail("const")) return false;
      }
    }

    // --- numbers ---------------------------------------------------------------------------
    if (inst.is_number()) {
      struct Bound {
        const char* keyword;
        const char* op;
        bool (*okFor)(int);
      };
      static const Bound bounds[] = {
          {"minimum", "≥", [](int c) { return c >= 0; }},
          {"maximum", "≤", [](int c) { return c <= 0; }},
          {"exclusiveMinimum", ">", [](int c) { return c > 0; }},
          {"exclusiveMaximum", "<", [](int c) { return c < 0; }},
      };
      for (const auto& b : bounds) {
        const auto limit = schema.find(b.keyword);
        if (limit == end || !limit->is_number()) continue;
        if (!b.okFor(compareNumbers(inst, *limit))) {
          out.add(path, b.keyword,
                  std::string("must be ") + b.op + " " + dumpSafe(*limit) + ", got " + dumpSafe(inst));
          if (fail(b.keyword)) return false;
        }
      }
    }

    // --- strings ---------------------------------------------------------------------------
    if (inst.is_string()) {
      const std::string& s = inst.get_ref<const std::string&>();
      const std::size_t length = utf8Length(s);
      bool tooLong = false;
      if (const auto m = schema.find("minLength"); m != end && length < m->get<std::size_t>()) {
        out.add(path, "minLength", "expected at least " + plural(m->get<std::size_t>(), "character") +
                                       ", got " + std::to_string(length));
        if (fail("minLength")) return false;
      }
      if (const auto m = schema.find("maxLength"); m != end && length > m->get<std::size_t>()) {
        tooLong = true;
        out.add(path, "maxLength", "expected at most " + plural(m->get<std::size_t>(), "character") +
                                       ", got " + std::to_string(length));
        if (fail("maxLength")) return false;
      }
      if (const auto p = schema.find("pattern"); p != end && !tooLong) {
        if (!std::regex_search(s, regex(p->get_ref<const std::string&>()))) {
          out.add(path, "pattern", "does not match the pattern " + dumpSafe(*p));
          if (fail("pattern")) return false;
        }
      }
    }

    // --- arrays ----------------------------------------------------------------------------
    if (inst.is_array()) {
      const std::size_t n = inst.size();
      bool tooMany = false;
      if (const auto m = schema.find("minItems"); m != end && n < m->get<std::size_t>()) {
        out.add(path, "minItems", "expected at least " + plural(m->get<std::size_t>(), "item") +
                                      ", got " + std::to_string(n));
        if (fail("minItems")) return false;
      }
      if (const auto m = schema.find("maxItems"); m != end && n > m->get<std::size_t>()) {
        tooMany = true;  // do not walk a huge array item by item
        out.add(path, "maxItems", "expected at most " + plural(m->get<std::size_t>(), "item") +
                                      ", got " + std::to_string(n));
        if (fail("maxItems")) return false;
      }
      if (!tooMany) {
        std::size_t first = 0;
        const std::size_t base = path.size();
        if (const auto prefix = schema.find("prefixItems"); prefix != end) {
          first = prefix->size();
          for (std::size_t i = 0; i < std::min(n, first); ++i) {
            appendIndex(path, i);
            const bool itemOk = descend(inst[i], (*prefix)[i], doc, path, depth, out);
            path.resize(base);
            if (!itemOk && fail("prefixItems")) return false;
          }
        }
        if (const auto items = schema.find("items"); items != end && !trivial(*items)) {
          for (std::size_t i = first; i < n; ++i) {
            appendIndex(path, i);
            const bool itemOk = descend(inst[i], *items, doc, path, depth, out);
            path.resize(base);
            if (!itemOk && fail("items")) return false;
          }
        }
      }
    }

    // --- objects ---------------------------------------------------------------------------
    if (inst.is_object()) {
      if (const auto req = schema.find("required"); req != end) {
        for (const auto& r : *req) {
          const std::string& name = r.get_ref<const std::string&>();
          if (!inst.contains(name)) {
            out.add(memberPath(path, name), "required", "is required");
            if (fail("required")) return false;
          }
        }
      }
      const auto props = schema.find("properties");
      const auto additional = schema.find("additionalProperties");
      const std::size_t base = path.size();
      for (auto it = inst.begin(); it != inst.end(); ++it) {
        const json* sub = nullptr;
        const char* keyword = "properties";
        bool extra = false;
        if (props != end) {
          const auto p = props->find(it.key());
          if (p != props->end()) sub = &*p;
        }
        if (sub == nullptr && additional != end) {
          sub = &*additional;
          keyword = "additionalProperties";
          extra = true;
        }
        if (sub == nullptr) continue;
        appendMember(path, it.key());
        bool memberOk;
        if (extra && sub->is_boolean() && !sub->get<bool>()) {
          out.add(path, "additionalProperties", "unknown field");
          memberOk = false;
        } else {
          memberOk = descend(it.value(), *sub, doc, path, depth, out);
        }
        path.resize(base);
        if (!memberOk && fail(keyword)) return false;
      }
      if (const auto m = schema.find("minProperties"); m != end && inst.size() < m->get<std::size_t>()) {
        out.add(path, "minProperties", "expected at least " + plural(m->get<std::size_t>(), "member") +
                                           ", got " + std::to_string(inst.size()));
        if (fail("minProperties")) return false;
      }
      if (const auto m = schema.find("maxProperties"); m != end && inst.size() > m->get<std::size_t>()) {
        out.add(path, "maxProperties", "expected at most " + plural(m->get<std::size_t>(), "member") +
                                           ", got " + std::to_string(inst.size()));
        if (fail("maxProperties")) return false;
      }
    }

    // --- combinators -----------------------------------------------------------------------
    if (const auto all = schema.find("allOf"); all != end) {
      for (const auto& s : *all) {
        if (!node(inst, s, doc, path, depth, hops, out) && fail("allOf")) return false;
      }
    }
    if (const auto any = schema.find("anyOf"); any != end) {
      if (!alternatives(inst, *any, false, doc, path, depth, hops, out) && fail("anyOf")) return false;
    }
    if (const auto one = schema.find("oneOf"); one != end) {
      const auto disc = schema.find("discriminator");
      const bool oneOk =
          disc != end ? discriminated(inst, *one, (*disc)["propertyName"].get<std::string>(), doc,
                                      path, depth, hops, out)
                      : alternatives(inst, *one, true, doc, path, depth, hops, out);
      if (!oneOk && fail("oneOf")) return false;
    }
    if (const auto n = schema.find("not"); n != end) {
      Sink probe(1);
      if (node(inst, *n, doc, path, depth, hops, probe)) {
        out.add(path, "not", "must not match the excluded schema");
        if (fail("not")) return false;
      }
    }
    if (const auto cond = schema.find("if"); cond != end) {
      Sink probe(1);
      const bool holds = node(inst, *cond, doc, path, depth, hops, probe);
      const auto branch = schema.find(holds ? "then" : "else");
      if (branch != end && !node(inst, *branch, doc, path, depth, hops, out) &&
          fail(holds ? "then" : "else")) {
        return false;
      }
    }
    return ok;
  }

  bool checkType(const json& inst, const json& type, const std::string& path, Sink& out) {
    std::vector<std::string> allowed;
    if (type.is_array()) {
      for (const auto& t : type) allowed.push_back(t.get<std::string>());
    } else {
      allowed.push_back(type.get<std::string>());
    }
    for (const auto& t : allowed) {
      if (typeMatches(inst, t)) return true;
    }
    const bool wantsNumber = std::count(allowed.begin(), allowed.end(), "number") +
                                 std::count(allowed.begin(), allowed.end(), "integer") > 0;
    if (wantsNumber && inst.is_number_float() && !std::isfinite(inst.get<double>())) {
      out.add(path, "type", "expected a finite number");
      return false;
    }
    std::string expected;
    for (std::size_t i = 0; i < allowed.size(); ++i) {
      if (i > 0) expected += i + 1 == allowed.size() ? " or " : ", ";
      expected += withArticle(allowed[i]);
    }
    const std::string got = wantsNumber && inst.is_number() ? dumpSafe(inst) : typeName(inst);
    out.add(path, "type", "expected " + expected + ", got " + got);
    return false;
  }

  const std::regex& regex(const std::string& pattern) const {
    const auto it = reg_.regex_.find(pattern);
    if (it == reg_.regex_.end()) throw std::logic_error("JSON Schema: pattern not compiled: " + pattern);
    return *it->second;
  }

  /// oneOf (exactlyOne) or anyOf without a discriminator.
  bool alternatives(const json& inst, const json& branches, bool exactlyOne, const json& doc,
                    std::string& path, int depth, int hops, Sink& out) {
    const char* rule = exactlyOne ? "oneOf" : "anyOf";
    const std::size_t room = out.limit > out.errors.size() ? out.limit - out.errors.size() : 1;
    std::vector<Sink> results;
    std::vector<std::size_t> valid;
    for (std::size_t i = 0; i < branches.size(); ++i) {
      results.emplace_back(room);
      if (node(inst, branches[i], doc, path, depth, hops, results.back())) {
        valid.push_back(i);
        if (!exactlyOne || valid.size() > 1) break;
      }
    }
    if (exactlyOne ? valid.size() == 1 : !valid.empty()) return true;
    if (valid.size() > 1) {
      out.add(path, rule, "matches more than one alternative (#" + std::to_string(valid[0] + 1) +
                              " and #" + std::to_string(valid[1] + 1) + ")");
      return false;
    }
    // No branch matched: report the one that got deepest into the instance.
    const int here = pathDepth(path);
    int bestDepth = here;
    std::size_t best = results.size();
    for (std::size_t i = 0; i < results.size(); ++i) {
      int d = here;
      for (const auto& e : results[i].errors) {
        d = std::max(d, pathDepth(e.path) - (e.rule == "required" ? 1 : 0));
      }
      if (d > bestDepth ||
          (d == bestDepth && best < results.size() &&
           results[i].errors.size() < results[best].errors.size())) {
        bestDepth = d;
        best = i;
      }
    }
    if (best < results.size()) {
      for (auto& e : results[best].errors) out.add(e.path, e.rule.c_str(), std::move(e.message));
      return false;
    }
    std::string why;
    std::set<std::string> seen;
    for (const auto& r : results) {
      if (r.errors.empty()) continue;
      const auto& e = r.errors.front();
      std::string text = e.message;
      if (e.path != path) {
        std::string rel = e.path.substr(std::min(path.size(), e.path.size()));
        if (!rel.empty() && rel[0] == '.') rel.erase(0, 1);
        text = rel + ": " + text;
      }
      if (seen.insert(text).second) why += (why.empty() ? "" : "; or ") + text;
    }
    out.add(path, rule, "matches none of the alternatives: " + why);
    return false;
  }

  /// oneOf with a discriminator property.
  bool discriminated(const json& inst, const json& branches, const std::string& prop,
                     const json& doc, std::string& path, int depth, int hops, Sink& out) {
    if (!inst.is_object()) {
      out.add(path, "type", "expected an object, got " + typeName(inst));
      return false;
    }
    const auto value = inst.find(prop);
    if (value == inst.end()) {
      out.add(memberPath(path, prop), "required", "is required");
      return false;
    }
    std::string allowed;
    for (const auto& branch : branches) {
      const json* c = constantOf(branch, doc, prop);
      if (*c == *value) return node(inst, branch, doc, path, depth, hops, out);
      allowed += (allowed.empty() ? "" : ", ") + listed(*c);
    }
    out.add(memberPath(path, prop), "enum",
            "unknown " + prop + " " + brief(*value) + " (expected one of: " + allowed + ")");
    return false;
  }

  /// The discriminator constant of a branch, following $refs.
  const json* constantOf(const json& branch, const json& doc, const std::string& prop) const {
    const json* s = &branch;
    const json* d = &doc;
    for (int hops = 0; hops <= kMaxRefHops; ++hops) {
      if (const json* c = branchConstant(*s, prop)) return c;
      if (!s->is_object() || !s->contains("$ref")) break;
      const auto t = target(*s, *d);
      s = t.schema;
      d = t.document;
    }
    throw std::logic_error("JSON Schema: discriminator branch without properties." + prop + ".const");
  }

  const SchemaRegistry& reg_;
};

// ---------------------------------------------------------------------------------------------
// SchemaRegistry
// ---------------------------------------------------------------------------------------------

void SchemaRegistry::add(const std::string& name, json schema) {
  auto regex = regex_;
  SchemaChecker(name, schema, regex).check(schema, "");
  auto doc = std::make_shared<const json>(std::move(schema));
  documents_[name] = doc;
  if (doc->is_object()) {
    const auto id = doc->find("$id");
    if (id != doc->end() && id->is_string() && id->get<std::string>() != name) {
      documents_[id->get<std::string>()] = doc;
    }
  }
  regex_ = std::move(regex);
  rebuildRefCache();
}

bool SchemaRegistry::contains(const std::string& name) const { return documents_.count(name) != 0; }

const json& SchemaRegistry::get(const std::string& name) const {
  const json* doc = findDocument(name);
  if (doc == nullptr) throw std::out_of_range("no JSON Schema registered as \"" + name + "\"");
  return *doc;
}

const json* SchemaRegistry::findDocument(const std::string& name) const {
  const auto it = documents_.find(name);
  return it == documents_.end() ? nullptr : it->second.get();
}

SchemaRegistry::Target SchemaRegistry::resolve(const std::string& ref, const json& document) const {
  const auto [docName, fragment] = splitRef(ref);
  const json* doc = &document;
  if (!docName.empty()) {
    doc = findDocument(docName);
    if (doc == nullptr) {
      throw std::out_of_range("JSON Schema $ref \"" + ref + "\": no schema registered as \"" +
                              docName + "\"");
    }
  }
  const json* schema = resolveFragment(*doc, fragment);
  if (schema == nullptr) throw std::out_of_range("JSON Schema $ref \"" + ref + "\" does not resolve");
  return Target{schema, doc};
}

void SchemaRegistry::rebuildRefCache() {
  refCache_.clear();
  std::set<const json*> done;
  for (const auto& [name, doc] : documents_) {
    if (!done.insert(doc.get()).second) continue;
    forEachRef(*doc, [&](const json& s) {
      const json& ref = s["$ref"];
      if (!ref.is_string()) return;
      try {
        refCache_[&s] = resolve(ref.get<std::string>(), *doc);
      } catch (const std::out_of_range&) {
        // cross-document target not registered (yet): resolved, or reported, when used
      }
    });
  }
}

std::vector<SchemaError> SchemaRegistry::validate(const json& instance, const std::string& schemaName,
                                                  std::size_t maxErrors) const {
  const json& doc = get(schemaName);
  Validator::Sink out(maxErrors);
  std::string path;
  Validator(*this).node(instance, doc, doc, path, 0, 0, out);
  return std::move(out.errors);
}

std::vector<SchemaError> SchemaRegistry::validateRef(const json& instance, const std::string& ref,
                                                     std::size_t maxErrors) const {
  const auto [docName, fragment] = splitRef(ref);
  const json& doc = get(docName);
  const Target t = resolve("#" + fragment, doc);
  Validator::Sink out(maxErrors);
  std::string path;
  Validator(*this).node(instance, *t.schema, *t.document, path, 0, 0, out);
  return std::move(out.errors);
}

}  // namespace devsurf::proto
