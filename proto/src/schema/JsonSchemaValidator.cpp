#include "devsurf/proto/JsonSchemaValidator.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>
#include <stdexcept>
#include <tuple>
#include <unordered_map>
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

std::string dumpSafe(const json& v) {
  return v.dump(-1, ' ', false, json::error_handler_t::replace);
}

/// A value as quoted in a message: JSON text (strings in quotes), shortened.
std::string brief(const json& v) {
  if (v.is_string())
    return dumpSafe(json(utf8Truncate(v.get_ref<const std::string&>(), kMaxQuoted)));
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
    case json::value_t::null:
      return "null";
    case json::value_t::boolean:
      return "boolean";
    case json::value_t::object:
      return "object";
    case json::value_t::array:
      return "array";
    case json::value_t::string:
      return "string";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
    case json::value_t::number_float:
      return "number";
    default:
      return "unknown";
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

const std::set<std::string>& typeNames() {
  static const std::set<std::string> names{"null",   "boolean", "object", "array",
                                           "string", "number",  "integer"};
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
      if (c == '\\')
        ++i;
      else if (c == '"')
        quoted = false;
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
    if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
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
        // any value
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
        checkDiscriminator(schema, v, where, at);
      } else {
        fail(at, "unsupported keyword \"" + key + "\"");
      }
    }
  }

 private:
  static bool isAnnotation(const std::string& key) {
    static const std::set<std::string> keys{"$schema",     "$id",       "$comment", "title",
                                            "description", "default",   "examples", "deprecated",
                                            "readOnly",    "writeOnly", "format"};
    return keys.count(key) != 0;
  }

  static std::string escape(const std::string& key) {
    std::string out;
    for (char c : key) {
      if (c == '~') {
        out += "~0";
      } else if (c == '/') {
        out += "~1";
      } else {
        out += c;
      }
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

  void checkDiscriminator(const json& schema, const json& v, const std::string& where,
                          const std::string& at) const {
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
      const std::string branchAt = where + "/oneOf/" + std::to_string(i);
      int hops = 0;
      while (branch != nullptr && branch->is_object() && branchConstant(*branch, prop) == nullptr &&
             branch->contains("$ref") && ++hops <= kMaxRefHops) {
        branch = local((*branch)["$ref"], branchAt);
      }
      if (branch == nullptr) continue;  // cross-document: checked when used
      const json* c = branchConstant(*branch, prop);
      if (c == nullptr)
        fail(branchAt, "discriminator branch without properties." + prop + ".const");
      if (!seen.insert(dumpSafe(*c)).second)
        fail(branchAt, "duplicate " + prop + " " + dumpSafe(*c));
    }
  }

  const std::string& name_;
  const json& root_;
  std::map<std::string, std::shared_ptr<const std::regex>>& regex_;
};

/// Calls `f(schema)` for `schema` and every subschema inside it.
template <class F>
void forEachSchema(const json& schema, F&& f) {
  f(schema);
  if (!schema.is_object()) return;
  for (auto it = schema.begin(); it != schema.end(); ++it) {
    const std::string& key = it.key();
    const json& v = it.value();
    if (key == "properties" || key == "$defs") {
      if (v.is_object()) {
        for (const auto& s : v) forEachSchema(s, f);
      }
    } else if (key == "additionalProperties" || key == "items" || key == "not" || key == "if" ||
               key == "then" || key == "else") {
      forEachSchema(v, f);
    } else if (key == "prefixItems" || key == "allOf" || key == "anyOf" || key == "oneOf") {
      if (v.is_array()) {
        for (const auto& s : v) forEachSchema(s, f);
      }
    }
  }
}

// Instance type bits, for "type".
enum : unsigned {
  kNull = 1,
  kBoolean = 2,
  kObject = 4,
  kArray = 8,
  kString = 16,
  kNumber = 32,
  kInteger = 64
};

unsigned typeBit(const std::string& t) {
  if (t == "null") return kNull;
  if (t == "boolean") return kBoolean;
  if (t == "object") return kObject;
  if (t == "array") return kArray;
  if (t == "string") return kString;
  if (t == "number") return kNumber;
  if (t == "integer") return kInteger;
  return 0;
}

unsigned instanceBits(const json& v) {
  switch (v.type()) {
    case json::value_t::null:
      return kNull;
    case json::value_t::boolean:
      return kBoolean;
    case json::value_t::object:
      return kObject;
    case json::value_t::array:
      return kArray;
    case json::value_t::string:
      return kString;
    case json::value_t::number_integer:
    case json::value_t::number_unsigned:
      return kNumber | kInteger;
    case json::value_t::number_float: {
      const double d = v.get<double>();
      if (!std::isfinite(d)) return 0;
      return std::floor(d) == d ? (kNumber | kInteger) : kNumber;
    }
    default:
      return 0;
  }
}

constexpr std::size_t kNoLimit = static_cast<std::size_t>(-1);

}  // namespace

// ---------------------------------------------------------------------------------------------
// Index: every schema node pre-parsed, so validation does no keyword lookups by name
// ---------------------------------------------------------------------------------------------

namespace {

/// One schema (object or boolean) with its keywords looked up once.
struct Compiled {
  bool isBoolean = false;
  bool booleanValue = true;
  bool trivial = false;  ///< true or {}: accepts everything

  const json* ref = nullptr;        ///< the $ref string
  const json* refSchema = nullptr;  ///< its target, if it resolved when indexed
  const json* refDocument = nullptr;
  const json* type = nullptr;
  unsigned typeMask = 0;
  const json* enumValues = nullptr;
  const json* constValue = nullptr;
  const json* minimum = nullptr;
  const json* maximum = nullptr;
  const json* exclusiveMinimum = nullptr;
  const json* exclusiveMaximum = nullptr;
  std::size_t minLength = 0, maxLength = kNoLimit;
  std::size_t minItems = 0, maxItems = kNoLimit;
  std::size_t minProperties = 0, maxProperties = kNoLimit;
  const json* pattern = nullptr;
  std::shared_ptr<const std::regex> regex;
  const json* required = nullptr;
  const json* properties = nullptr;
  const json* additional = nullptr;
  const json* items = nullptr;
  const json* prefixItems = nullptr;
  const json* allOf = nullptr;
  const json* anyOf = nullptr;
  const json* oneOf = nullptr;
  const json* notSchema = nullptr;
  const json* ifSchema = nullptr;
  const json* thenSchema = nullptr;
  const json* elseSchema = nullptr;
  const std::string* discriminator = nullptr;
  const std::string* xError = nullptr;
};

Compiled compile(const json& schema,
                 const std::map<std::string, std::shared_ptr<const std::regex>>& regexes) {
  static const std::map<std::string, const json * Compiled::*> kSchemaValued{
      {"$ref", &Compiled::ref},
      {"enum", &Compiled::enumValues},
      {"const", &Compiled::constValue},
      {"minimum", &Compiled::minimum},
      {"maximum", &Compiled::maximum},
      {"exclusiveMinimum", &Compiled::exclusiveMinimum},
      {"exclusiveMaximum", &Compiled::exclusiveMaximum},
      {"pattern", &Compiled::pattern},
      {"required", &Compiled::required},
      {"properties", &Compiled::properties},
      {"additionalProperties", &Compiled::additional},
      {"items", &Compiled::items},
      {"prefixItems", &Compiled::prefixItems},
      {"allOf", &Compiled::allOf},
      {"anyOf", &Compiled::anyOf},
      {"oneOf", &Compiled::oneOf},
      {"not", &Compiled::notSchema},
      {"if", &Compiled::ifSchema},
      {"then", &Compiled::thenSchema},
      {"else", &Compiled::elseSchema},
  };
  static const std::map<std::string, std::size_t Compiled::*> kCounts{
      {"minLength", &Compiled::minLength},         {"maxLength", &Compiled::maxLength},
      {"minItems", &Compiled::minItems},           {"maxItems", &Compiled::maxItems},
      {"minProperties", &Compiled::minProperties}, {"maxProperties", &Compiled::maxProperties},
  };

  Compiled c;
  if (schema.is_boolean()) {
    c.isBoolean = true;
    c.booleanValue = schema.get<bool>();
    c.trivial = c.booleanValue;
    return c;
  }
  if (!schema.is_object()) return c;
  c.trivial = schema.empty();
  // add() checked every indexed node; anything else (validateRef into an odd place) is read
  // defensively: malformed keyword values are ignored.
  for (auto it = schema.begin(); it != schema.end(); ++it) {
    const json& v = it.value();
    if (const auto p = kSchemaValued.find(it.key()); p != kSchemaValued.end()) {
      c.*(p->second) = &v;
    } else if (const auto n = kCounts.find(it.key()); n != kCounts.end()) {
      if (isIntegral(v) && v.get<double>() >= 0) c.*(n->second) = v.get<std::size_t>();
    } else if (it.key() == "type") {
      c.type = &v;
      if (v.is_string()) c.typeMask = typeBit(v.get<std::string>());
      for (const auto& t : v.is_array() ? v : json::array()) {
        if (t.is_string()) c.typeMask |= typeBit(t.get<std::string>());
      }
    } else if (it.key() == "discriminator") {
      if (v.is_object() && v.contains("propertyName") && v["propertyName"].is_string()) {
        c.discriminator = &v["propertyName"].get_ref<const std::string&>();
      }
    } else if (it.key() == "x-error" && v.is_string()) {
      c.xError = &v.get_ref<const std::string&>();
    }
  }
  if (c.pattern != nullptr && c.pattern->is_string()) {
    const auto r = regexes.find(c.pattern->get<std::string>());
    if (r != regexes.end()) c.regex = r->second;
  }
  if (c.ref != nullptr && !c.ref->is_string()) c.ref = nullptr;
  return c;
}

}  // namespace

struct SchemaRegistry::Index {
  std::vector<Document> documents;  ///< keeps every indexed node alive
  std::unordered_map<const json*, Compiled> nodes;
};

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
    Compiled local;
    const Compiled& c = compiled(schema, local);
    if (c.xError != nullptr) {
      Sink probe(1);
      const char* failed = "x-error";
      if (keywords(inst, c, doc, path, depth, hops, probe, &failed)) return true;
      out.add(path, failed, *c.xError);
      return false;
    }
    return keywords(inst, c, doc, path, depth, hops, out, nullptr);
  }

 private:
  /// The pre-parsed form of `schema`; `local` holds it for a node outside the index.
  const Compiled& compiled(const json& schema, Compiled& local) const {
    if (reg_.index_) {
      const auto it = reg_.index_->nodes.find(&schema);
      if (it != reg_.index_->nodes.end()) return it->second;
    }
    local = compile(schema, reg_.regex_);
    return local;
  }

  bool trivial(const json& schema) const {
    Compiled local;
    return compiled(schema, local).trivial;
  }

  /// Validates a member/item of the current instance; `path` already points at it.
  bool descend(const json& inst, const json& schema, const json& doc, std::string& path, int depth,
               Sink& out) {
    if (depth + 1 > kMaxDepth) {
      if (trivial(schema)) return true;
      out.add(path, "depth",
              "nested too deeply (more than " + std::to_string(kMaxDepth) + " levels)");
      return false;
    }
    return node(inst, schema, doc, path, depth + 1, 0, out);
  }

  std::pair<const json*, const json*> target(const Compiled& c, const json& doc) const {
    if (c.refSchema != nullptr) return {c.refSchema, c.refDocument};
    return reg_.resolve(c.ref->get<std::string>(), doc);
  }

  bool keywords(const json& inst, const Compiled& c, const json& doc, std::string& path, int depth,
                int hops, Sink& out, const char** failed) {
    if (c.trivial) return true;
    if (c.isBoolean) {
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

    // --- $ref ------------------------------------------------------------------------------
    if (c.ref != nullptr) {
      if (hops + 1 > kMaxRefHops) {
        throw std::logic_error("JSON Schema: $ref cycle at " + c.ref->get<std::string>() +
                               " (instance path \"" + path + "\")");
      }
      const auto [refSchema, refDoc] = target(c, doc);
      if (!node(inst, *refSchema, *refDoc, path, depth, hops + 1, out) && fail("$ref")) {
        return false;
      }
    }

    // --- type ------------------------------------------------------------------------------
    if (c.type != nullptr && (c.typeMask & instanceBits(inst)) == 0) {
      typeError(inst, *c.type, c.typeMask, path, out);
      fail("type");
      return false;  // the remaining keywords would only add noise
    }

    // --- enum / const ----------------------------------------------------------------------
    if (c.enumValues != nullptr &&
        std::find(c.enumValues->begin(), c.enumValues->end(), inst) == c.enumValues->end()) {
      std::string allowed;
      for (const auto& v : *c.enumValues) allowed += (allowed.empty() ? "" : ", ") + listed(v);
      out.add(path, "enum", "must be one of: " + allowed);
      if (fail("enum")) return false;
    }
    if (c.constValue != nullptr && inst != *c.constValue) {
      out.add(path, "const", "must be " + brief(*c.constValue) + ", got " + brief(inst));
      if (fail("const")) return false;
    }

    // --- numbers ---------------------------------------------------------------------------
    if (inst.is_number()) {
      auto bound = [&](const json* limit, const char* keyword, const char* op, auto okFor) {
        if (limit == nullptr || okFor(compareNumbers(inst, *limit))) return false;
        out.add(path, keyword,
                std::string("must be ") + op + " " + dumpSafe(*limit) + ", got " + dumpSafe(inst));
        return fail(keyword);
      };
      if (bound(c.minimum, "minimum", "≥", [](int r) { return r >= 0; })) return false;
      if (bound(c.maximum, "maximum", "≤", [](int r) { return r <= 0; })) return false;
      if (bound(c.exclusiveMinimum, "exclusiveMinimum", ">", [](int r) { return r > 0; }))
        return false;
      if (bound(c.exclusiveMaximum, "exclusiveMaximum", "<", [](int r) { return r < 0; }))
        return false;
    }

    // --- strings ---------------------------------------------------------------------------
    if (inst.is_string() && (c.minLength > 0 || c.maxLength != kNoLimit || c.pattern != nullptr)) {
      const std::string& s = inst.get_ref<const std::string&>();
      const std::size_t length = utf8Length(s);
      if (length < c.minLength) {
        out.add(path, "minLength",
                "expected at least " + plural(c.minLength, "character") + ", got " +
                    std::to_string(length));
        if (fail("minLength")) return false;
      }
      const bool tooLong = length > c.maxLength;
      if (tooLong) {
        out.add(path, "maxLength",
                "expected at most " + plural(c.maxLength, "character") + ", got " +
                    std::to_string(length));
        if (fail("maxLength")) return false;
      }
      if (c.pattern != nullptr && !tooLong) {
        if (!c.regex)
          throw std::logic_error("JSON Schema: pattern not compiled: " + c.pattern->dump());
        if (!std::regex_search(s, *c.regex)) {
          out.add(path, "pattern", "does not match the pattern " + dumpSafe(*c.pattern));
          if (fail("pattern")) return false;
        }
      }
    }

    // --- arrays ----------------------------------------------------------------------------
    if (inst.is_array()) {
      const std::size_t n = inst.size();
      if (n < c.minItems) {
        out.add(path, "minItems",
                "expected at least " + plural(c.minItems, "item") + ", got " + std::to_string(n));
        if (fail("minItems")) return false;
      }
      const bool tooMany = n > c.maxItems;  // then do not walk a huge array item by item
      if (tooMany) {
        out.add(path, "maxItems",
                "expected at most " + plural(c.maxItems, "item") + ", got " + std::to_string(n));
        if (fail("maxItems")) return false;
      }
      if (!tooMany) {
        std::size_t first = 0;
        const std::size_t base = path.size();
        if (c.prefixItems != nullptr) {
          first = c.prefixItems->size();
          for (std::size_t i = 0; i < std::min(n, first); ++i) {
            appendIndex(path, i);
            const bool itemOk = descend(inst[i], (*c.prefixItems)[i], doc, path, depth, out);
            path.resize(base);
            if (!itemOk && fail("prefixItems")) return false;
          }
        }
        if (c.items != nullptr && !trivial(*c.items)) {
          for (std::size_t i = first; i < n; ++i) {
            appendIndex(path, i);
            const bool itemOk = descend(inst[i], *c.items, doc, path, depth, out);
            path.resize(base);
            if (!itemOk && fail("items")) return false;
          }
        }
      }
    }

    // --- objects ---------------------------------------------------------------------------
    if (inst.is_object()) {
      if (c.required != nullptr) {
        for (const auto& r : *c.required) {
          const std::string& name = r.get_ref<const std::string&>();
          if (!inst.contains(name)) {
            out.add(memberPath(path, name), "required", "is required");
            if (fail("required")) return false;
          }
        }
      }
      if (c.properties != nullptr || c.additional != nullptr) {
        const std::size_t base = path.size();
        for (auto it = inst.begin(); it != inst.end(); ++it) {
          const json* sub = nullptr;
          if (c.properties != nullptr) {
            const auto p = c.properties->find(it.key());
            if (p != c.properties->end()) sub = &*p;
          }
          const bool extra = sub == nullptr;
          if (extra) sub = c.additional;
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
          if (!memberOk && fail(extra ? "additionalProperties" : "properties")) return false;
        }
      }
      if (inst.size() < c.minProperties) {
        out.add(path, "minProperties",
                "expected at least " + plural(c.minProperties, "member") + ", got " +
                    std::to_string(inst.size()));
        if (fail("minProperties")) return false;
      }
      if (inst.size() > c.maxProperties) {
        out.add(path, "maxProperties",
                "expected at most " + plural(c.maxProperties, "member") + ", got " +
                    std::to_string(inst.size()));
        if (fail("maxProperties")) return false;
      }
    }

    // --- combinators -----------------------------------------------------------------------
    if (c.allOf != nullptr) {
      for (const auto& s : *c.allOf) {
        if (!node(inst, s, doc, path, depth, hops, out) && fail("allOf")) return false;
      }
    }
    if (c.anyOf != nullptr && !alternatives(inst, *c.anyOf, false, doc, path, depth, hops, out) &&
        fail("anyOf")) {
      return false;
    }
    if (c.oneOf != nullptr) {
      const bool oneOk =
          c.discriminator != nullptr
              ? discriminated(inst, *c.oneOf, *c.discriminator, doc, path, depth, hops, out)
              : alternatives(inst, *c.oneOf, true, doc, path, depth, hops, out);
      if (!oneOk && fail("oneOf")) return false;
    }
    if (c.notSchema != nullptr) {
      Sink probe(1);
      if (node(inst, *c.notSchema, doc, path, depth, hops, probe)) {
        out.add(path, "not", "must not match the excluded schema");
        if (fail("not")) return false;
      }
    }
    if (c.ifSchema != nullptr) {
      Sink probe(1);
      const bool holds = node(inst, *c.ifSchema, doc, path, depth, hops, probe);
      const json* branch = holds ? c.thenSchema : c.elseSchema;
      if (branch != nullptr && !node(inst, *branch, doc, path, depth, hops, out) &&
          fail(holds ? "then" : "else")) {
        return false;
      }
    }
    return ok;
  }

  static void typeError(const json& inst, const json& type, unsigned mask, const std::string& path,
                        Sink& out) {
    const bool wantsNumber = (mask & (kNumber | kInteger)) != 0;
    if (wantsNumber && inst.is_number_float() && !std::isfinite(inst.get<double>())) {
      out.add(path, "type", "expected a finite number");
      return;
    }
    std::vector<std::string> allowed;
    if (type.is_array()) {
      for (const auto& t : type) allowed.push_back(t.get<std::string>());
    } else {
      allowed.push_back(type.get<std::string>());
    }
    std::string expected;
    for (std::size_t i = 0; i < allowed.size(); ++i) {
      if (i > 0) expected += i + 1 == allowed.size() ? " or " : ", ";
      expected += withArticle(allowed[i]);
    }
    const std::string got = wantsNumber && inst.is_number() ? dumpSafe(inst) : typeName(inst);
    out.add(path, "type", "expected " + expected + ", got " + got);
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
      out.add(path, rule,
              "matches more than one alternative (#" + std::to_string(valid[0] + 1) + " and #" +
                  std::to_string(valid[1] + 1) + ")");
      return false;
    }
    // No branch matched: report the one that got deepest into the instance (a missing member
    // counts as no progress).
    const int here = pathDepth(path);
    int bestDepth = here;
    std::size_t best = results.size();
    for (std::size_t i = 0; i < results.size(); ++i) {
      int d = here;
      for (const auto& e : results[i].errors) {
        d = std::max(d, pathDepth(e.path) - (e.rule == "required" ? 1 : 0));
      }
      if (d > bestDepth || (d == bestDepth && best < results.size() &&
                            results[i].errors.size() < results[best].errors.size())) {
        bestDepth = d;
        best = i;
      }
    }
    if (best < results.size()) {
      for (auto& e : results[best].errors) out.add(e.path, e.rule.c_str(), std::move(e.message));
      return false;
    }
    // Every branch failed at the instance itself: one error listing each complaint.
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
      Compiled local;
      const Compiled& c = compiled(*s, local);
      if (c.ref == nullptr) break;
      std::tie(s, d) = target(c, *d);
    }
    throw std::logic_error("JSON Schema: discriminator branch without properties." + prop +
                           ".const");
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

  // Re-index everything: a new document may resolve other documents' cross-document $refs.
  auto index = std::make_shared<Index>();
  for (const auto& entry : documents_) {
    const Document& d = entry.second;
    if (std::find(index->documents.begin(), index->documents.end(), d) != index->documents.end()) {
      continue;
    }
    index->documents.push_back(d);
    forEachSchema(*d, [&](const json& s) {
      Compiled c = compile(s, regex_);
      if (c.ref != nullptr) {
        try {
          std::tie(c.refSchema, c.refDocument) = resolve(c.ref->get<std::string>(), *d);
        } catch (const std::out_of_range&) {
          // cross-document target not registered (yet): resolved, or reported, when used
        }
      }
      index->nodes.emplace(&s, std::move(c));
    });
  }
  index_ = std::move(index);
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

std::pair<const json*, const json*> SchemaRegistry::resolve(const std::string& ref,
                                                            const json& document) const {
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
  if (schema == nullptr)
    throw std::out_of_range("JSON Schema $ref \"" + ref + "\" does not resolve");
  return {schema, doc};
}

std::vector<SchemaError> SchemaRegistry::validate(const json& instance,
                                                  const std::string& schemaName,
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
  const auto [schema, schemaDoc] = resolve("#" + fragment, doc);
  Validator::Sink out(maxErrors);
  std::string path;
  Validator(*this).node(instance, *schema, *schemaDoc, path, 0, 0, out);
  return std::move(out.errors);
}

}  // namespace devsurf::proto
