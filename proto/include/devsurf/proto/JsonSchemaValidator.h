#pragma once

#include <cstddef>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <utility>
#include <vector>

namespace devsurf::proto {

/// One violation of a schema by an instance document.
struct SchemaError {
  /// Where in the instance: object members joined by '.', array indices as [i], e.g.
  /// `model.a.points[3]`, `solver.iterations`; "" is the root. A member name that is empty or
  /// contains one of `.[]"` or whitespace is written as a quoted index: `metrics["a.b"]`.
  std::string path;
  /// The schema keyword that was broken: "type", "required", "minimum", "enum", ...
  /// (plus "depth" when the instance is nested too deeply).
  std::string rule;
  /// For humans: "expected a number, got string", "must be ≥ 0, got -3", "is required".
  std::string message;

  /// `path + ": " + message`, with "(root)" for the empty path.
  std::string toString() const;
};

/// Holds JSON Schemas (draft 2020-12) by name and validates documents against them.
///
/// This is a small interpreter of the subset of JSON Schema our schemas use (no C++ JSON
/// Schema library is packaged in Debian). Supported keywords:
///  - type (string or array of names). "number" also requires the value to be finite (nlohmann
///    parses 1e999 to infinity); "integer" accepts any finite number with an integral value,
///    so 3 and 3.0 are integers, 3.5 is not.
///  - enum, const (numbers compare by value: 1 == 1.0)
///  - minimum, maximum, exclusiveMinimum, exclusiveMaximum
///  - minLength, maxLength (in Unicode code points), pattern (std::regex ECMAScript, search
///    semantics: the pattern may match anywhere unless anchored; not tried on a string that
///    already breaks maxLength)
///  - items (one schema for all items, or for the items after prefixItems), prefixItems,
///    minItems, maxItems
///  - properties, required, additionalProperties (false or a schema), minProperties,
///    maxProperties
///  - allOf, anyOf, oneOf, not, if/then/else
///  - $ref: "#/json/pointer" inside the same document, "other.schema.json#/json/pointer" or
///    "other.schema.json" across documents (looked up by registered name or "$id"); sibling
///    keywords next to $ref are applied too, as in 2020-12.
///  - $defs; boolean schemas true/false.
///  - annotations, ignored: $schema, $id, $comment, title, description, default, examples,
///    deprecated, readOnly, writeOnly, format; and any other keyword starting with "x-".
/// Any other keyword is rejected by add() rather than silently ignored.
///
/// Two extensions:
///  - `"x-error": "expected 3 numbers"` on any schema: when the instance fails that schema,
///    ONE error is reported at the instance path with this message (its rule is the first
///    keyword of that schema that failed, e.g. "minItems") instead of the errors underneath.
///  - `"discriminator": {"propertyName": "kind"}` next to `oneOf` (as in OpenAPI / ajv): every
///    branch (inline or via $ref) must declare `properties.kind.const` (or a one-value enum).
///    The branch whose constant equals the instance's "kind" is the only one validated and
///    only its errors are reported. A missing "kind" gives `<path>.kind: is required` (rule
///    "required"); a value no branch has gives, at `<path>.kind` with rule "enum",
///    `unknown kind "sphere" (expected one of: strip)`; a non-object gives a "type" error.
///    Adding a branch is one more oneOf item.
///
/// Errors without a discriminator: oneOf/anyOf with no matching branch report the errors of
/// the branch that got furthest into the instance (deepest error path) or, when every branch
/// fails at the instance itself, one error listing each branch's complaint.
///
/// Limits: instances nested more than kMaxDepth levels below the validated root give a
/// "depth" error instead of a stack overflow; a $ref cycle that does not descend into the
/// instance throws std::logic_error.
///
/// Thread safety: after the last add(), any number of threads may call the const members
/// concurrently. A registry may be copied; copies share the (immutable) schemas.
class SchemaRegistry {
 public:
  /// Instance nesting depth (below the validated root) that validation descends into.
  static constexpr int kMaxDepth = 64;

  /// Registers `schema` under `name` (e.g. "scene.schema.json") and, if it has a string
  /// "$id", under that too. Replaces an earlier schema of the same name.
  /// @throws std::invalid_argument if the schema uses a keyword this validator does not
  ///   support, a keyword value is malformed, a pattern does not compile, a local "#..." $ref
  ///   does not resolve, or a discriminator branch has no constant. (Cross-document $refs are
  ///   resolved when used, so documents may be added in any order.)
  void add(const std::string& name, nlohmann::json schema);

  /// True if a schema is registered under `name` (or has it as "$id").
  bool contains(const std::string& name) const;

  /// @throws std::out_of_range naming the schema if none is registered under `name`.
  const nlohmann::json& get(const std::string& name) const;

  /// Validates `instance` against the schema registered as `schemaName`.
  /// @returns all errors found, in document order, at most `maxErrors` (a value of 0 is
  ///   treated as 1); empty means valid. The first error is the most specific one available
  ///   (see the discriminator and oneOf notes above).
  /// @throws std::out_of_range if `schemaName` or a $ref target used is not registered or
  ///   does not resolve; std::logic_error on a $ref cycle.
  std::vector<SchemaError> validate(const nlohmann::json& instance, const std::string& schemaName,
                                    std::size_t maxErrors = 20) const;

  /// Same, against a sub-schema given as "<name>#<json pointer>", e.g.
  /// "scene.schema.json#/$defs/curve" ("<name>" or "<name>#" is the whole schema). Error paths
  /// are relative to `instance`.
  /// @throws std::out_of_range if the reference does not resolve.
  std::vector<SchemaError> validateRef(const nlohmann::json& instance, const std::string& ref,
                                       std::size_t maxErrors = 20) const;

 private:
  class Validator;
  struct Index;  ///< every registered schema node in a pre-parsed form (defined in the .cpp)
  using Document = std::shared_ptr<const nlohmann::json>;

  /// The document registered under `name`, or nullptr.
  const nlohmann::json* findDocument(const std::string& name) const;
  /// Resolves a $ref string relative to `document` (its root schema) and returns the target
  /// schema and its document. @throws std::out_of_range if it does not resolve.
  std::pair<const nlohmann::json*, const nlohmann::json*> resolve(
      const std::string& ref, const nlohmann::json& document) const;

  std::map<std::string, Document> documents_;                       ///< by name and by $id
  std::map<std::string, std::shared_ptr<const std::regex>> regex_;  ///< compiled patterns
  std::shared_ptr<const Index> index_;                              ///< rebuilt by add()
};

}  // namespace devsurf::proto
