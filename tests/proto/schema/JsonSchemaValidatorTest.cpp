// Unit tests of the JSON Schema subset interpreter: every keyword, the path format and the
// two extensions (x-error, discriminator).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "devsurf/proto/JsonSchemaValidator.h"

using devsurf::proto::SchemaError;
using devsurf::proto::SchemaRegistry;
using nlohmann::json;

namespace {

/// Validates `instance` against `schema` (registered as "t.json").
std::vector<SchemaError> check(const json& schema, const json& instance,
                               std::size_t maxErrors = 20) {
  SchemaRegistry reg;
  reg.add("t.json", schema);
  return reg.validate(instance, "t.json", maxErrors);
}

bool valid(const json& schema, const json& instance) { return check(schema, instance).empty(); }

std::string all(const std::vector<SchemaError>& errors) {
  std::string s;
  for (const auto& e : errors) s += e.toString() + " [" + e.rule + "]\n";
  return s;
}

/// Expects exactly one error with this path, rule and message.
void expectOne(const std::vector<SchemaError>& errors, const std::string& path,
               const std::string& rule, const std::string& message) {
  ASSERT_EQ(errors.size(), 1u) << all(errors);
  EXPECT_EQ(errors[0].path, path);
  EXPECT_EQ(errors[0].rule, rule);
  EXPECT_EQ(errors[0].message, message);
}

}  // namespace

// --- SchemaError / registry ------------------------------------------------------------------

TEST(SchemaError, ToStringUsesRootForEmptyPath) {
  EXPECT_EQ((SchemaError{"", "type", "expected an object, got array"}).toString(),
            "(root): expected an object, got array");
  EXPECT_EQ((SchemaError{"model.a.points[3]", "minItems", "expected 3 numbers"}).toString(),
            "model.a.points[3]: expected 3 numbers");
}

TEST(SchemaRegistry, GetByNameAndId) {
  SchemaRegistry reg;
  reg.add("file.json", json{{"$id", "other.json"}, {"type", "string"}});
  EXPECT_TRUE(reg.contains("file.json"));
  EXPECT_TRUE(reg.contains("other.json"));
  EXPECT_EQ(reg.get("file.json")["type"], "string");
  EXPECT_EQ(&reg.get("file.json"), &reg.get("other.json"));
  EXPECT_TRUE(reg.validate("x", "other.json").empty());
}

TEST(SchemaRegistry, UnknownNameThrowsOutOfRange) {
  SchemaRegistry reg;
  try {
    reg.get("missing.json");
    FAIL();
  } catch (const std::out_of_range& e) {
    EXPECT_NE(std::string(e.what()).find("missing.json"), std::string::npos);
  }
  EXPECT_THROW(reg.validate(1, "missing.json"), std::out_of_range);
  EXPECT_THROW(reg.validateRef(1, "missing.json#/$defs/x"), std::out_of_range);
}

TEST(SchemaRegistry, AddRejectsUnsupportedOrMalformedSchemas) {
  SchemaRegistry reg;
  EXPECT_THROW(reg.add("a", json{{"uniqueItems", true}}), std::invalid_argument);
  EXPECT_THROW(reg.add("a", json{{"properties", {{"x", {{"patternProperties", json::object()}}}}}}),
               std::invalid_argument);
  EXPECT_THROW(reg.add("a", json{{"type", "float"}}), std::invalid_argument);
  EXPECT_THROW(reg.add("a", json{{"minItems", -1}}), std::invalid_argument);
  EXPECT_THROW(reg.add("a", json{{"pattern", "("}}), std::invalid_argument);
  EXPECT_THROW(reg.add("a", json{{"$ref", "#/$defs/nope"}}), std::invalid_argument);
  EXPECT_THROW(reg.add("a", json{{"discriminator", {{"propertyName", "k"}}}}),
               std::invalid_argument);
  EXPECT_THROW(reg.add("a", json{{"discriminator", {{"propertyName", "k"}}},
                                 {"oneOf", {{{"type", "object"}}}}}),
               std::invalid_argument);
  EXPECT_THROW(reg.add("a", json::array()), std::invalid_argument);
  // annotations and x- extensions are fine
  EXPECT_NO_THROW(reg.add("a", json{{"title", "t"},
                                    {"description", "d"},
                                    {"default", 1},
                                    {"examples", {1}},
                                    {"$comment", "c"},
                                    {"x-ui", "slider"},
                                    {"$schema", "https://json-schema.org/draft/2020-12/schema"}}));
  EXPECT_FALSE(reg.contains("b"));
}

TEST(SchemaRegistry, MaxErrorsLimitsTheList) {
  const json schema = {{"type", "array"}, {"items", {{"type", "number"}}}};
  const json instance = {"a", "b", "c", "d"};
  EXPECT_EQ(check(schema, instance).size(), 4u);
  EXPECT_EQ(check(schema, instance, 2).size(), 2u);
  EXPECT_EQ(check(schema, instance, 0).size(), 1u);  // 0 is treated as 1
  EXPECT_EQ(check(schema, instance, 2)[1].path, "[1]");
}

TEST(SchemaRegistry, BooleanSchemas) {
  EXPECT_TRUE(valid(true, json{{"x", 1}}));
  expectOne(check(false, 1), "", "false", "is not allowed");
  expectOne(check({{"properties", {{"x", false}}}}, json{{"x", 1}}), "x", "false",
            "is not allowed");
}

// --- path format -----------------------------------------------------------------------------

TEST(Paths, MembersJoinedByDotsIndicesInBrackets) {
  const json schema = {
      {"properties",
       {{"model",
         {{"properties",
           {{"a",
             {{"properties", {{"points", {{"items", {{"items", {{"type", "number"}}}}}}}}}}}}}}}}}};
  const json instance = {{"model", {{"a", {{"points", {{0, 0}, {1, 1}, {2, 2}, {3, "x"}}}}}}}};
  expectOne(check(schema, instance), "model.a.points[3][1]", "type",
            "expected a number, got string");
}

TEST(Paths, RootArrayIndexHasNoLeadingDot) {
  expectOne(check({{"items", {{"type", "string"}}}}, json{"a", 1}), "[1]", "type",
            "expected a string, got number");
}

TEST(Paths, OddMemberNamesAreQuoted) {
  const json schema = {{"additionalProperties", {{"type", "number"}}}};
  expectOne(check(schema, json{{"a.b", "x"}}), "[\"a.b\"]", "type",
            "expected a number, got string");
  const json nested = {{"properties", {{"m", schema}}}};
  expectOne(check(nested, json{{"m", {{"", true}}}}), "m[\"\"]", "type",
            "expected a number, got boolean");
}

// --- type ------------------------------------------------------------------------------------

TEST(Type, EachType) {
  EXPECT_TRUE(valid({{"type", "string"}}, "s"));
  EXPECT_TRUE(valid({{"type", "number"}}, 1.5));
  EXPECT_TRUE(valid({{"type", "number"}}, -3));
  EXPECT_TRUE(valid({{"type", "boolean"}}, false));
  EXPECT_TRUE(valid({{"type", "null"}}, nullptr));
  EXPECT_TRUE(valid({{"type", "object"}}, json::object()));
  EXPECT_TRUE(valid({{"type", "array"}}, json::array()));
  expectOne(check({{"type", "number"}}, "3"), "", "type", "expected a number, got string");
  expectOne(check({{"type", "object"}}, json::array()), "", "type",
            "expected an object, got array");
  expectOne(check({{"type", "array"}}, nullptr), "", "type", "expected an array, got null");
  expectOne(check({{"type", "boolean"}}, 0), "", "type", "expected a boolean, got number");
  expectOne(check({{"type", "null"}}, true), "", "type", "expected null, got boolean");
  expectOne(check({{"type", "string"}}, json::object()), "", "type",
            "expected a string, got object");
}

TEST(Type, ArrayOfTypes) {
  const json schema = {{"type", {"string", "null"}}};
  EXPECT_TRUE(valid(schema, "x"));
  EXPECT_TRUE(valid(schema, nullptr));
  expectOne(check(schema, 1), "", "type", "expected a string or null, got number");
  expectOne(check({{"type", {"string", "array", "null"}}}, true), "", "type",
            "expected a string, an array or null, got boolean");
}

TEST(Type, IntegerAcceptsIntegralValuesOnly) {
  const json schema = {{"type", "integer"}};
  EXPECT_TRUE(valid(schema, 3));
  EXPECT_TRUE(valid(schema, -3));
  EXPECT_TRUE(valid(schema, std::numeric_limits<std::uint64_t>::max()));
  EXPECT_TRUE(valid(schema, 3.0));
  EXPECT_TRUE(valid(schema, json::parse("1e3")));
  expectOne(check(schema, 2.5), "", "type", "expected an integer, got 2.5");
  expectOne(check(schema, "3"), "", "type", "expected an integer, got string");
  expectOne(check(schema, std::numeric_limits<double>::infinity()), "", "type",
            "expected a finite number");
}

TEST(Type, NumberMustBeFinite) {
  const json schema = {{"type", "number"}};
  const double inf = std::numeric_limits<double>::infinity();
  expectOne(check(schema, inf), "", "type", "expected a finite number");
  expectOne(check(schema, -inf), "", "type", "expected a finite number");
  expectOne(check(schema, std::nan("")), "", "type", "expected a finite number");
  // Binary formats carry infinities straight through.
  const json fromCbor = json::from_cbor(json::to_cbor(json(inf)));
  ASSERT_TRUE(fromCbor.is_number_float());
  expectOne(check(schema, fromCbor), "", "type", "expected a finite number");
}

TEST(Type, TextOverflowIsAParseErrorInNlohmann) {
  // nlohmann 3.11 rejects 1e999 while parsing (it does not produce infinity); callers must treat
  // json::exception from parse() as a malformed document.
  EXPECT_THROW({ const json j = json::parse("1e999"); }, json::out_of_range);
  EXPECT_TRUE(json::parse("[1e999]", nullptr, false).is_discarded());
}

// --- enum / const ----------------------------------------------------------------------------

TEST(Enum, ListsAllowedValues) {
  const json schema = {{"enum", {"vectors", "spline"}}};
  EXPECT_TRUE(valid(schema, "spline"));
  expectOne(check(schema, "spheres"), "", "enum", "must be one of: vectors, spline");
  expectOne(check({{"enum", {1, 2, nullptr}}}, 3), "", "enum", "must be one of: 1, 2, null");
  EXPECT_TRUE(valid({{"enum", {1, 2}}}, 2.0));  // numbers compare by value
}

TEST(Const, ValueMustBeEqual) {
  EXPECT_TRUE(valid({{"const", "devsurf-scene"}}, "devsurf-scene"));
  EXPECT_TRUE(valid({{"const", 1}}, 1.0));
  expectOne(check({{"const", "devsurf-scene"}}, "devsurf-report"), "", "const",
            "must be \"devsurf-scene\", got \"devsurf-report\"");
  expectOne(check({{"const", 1}}, 2), "", "const", "must be 1, got 2");
  expectOne(check({{"const", 1}}, json{{"a", 1}}), "", "const", "must be 1, got an object");
}

// --- numeric bounds --------------------------------------------------------------------------

TEST(Numbers, MinimumAndMaximum) {
  const json schema = {{"minimum", 0}, {"maximum", 9}};
  EXPECT_TRUE(valid(schema, 0));
  EXPECT_TRUE(valid(schema, 9));
  EXPECT_TRUE(valid(schema, 4.5));
  expectOne(check(schema, -3), "", "minimum", "must be ≥ 0, got -3");
  expectOne(check(schema, 10), "", "maximum", "must be ≤ 9, got 10");
  expectOne(check(schema, 9.5), "", "maximum", "must be ≤ 9, got 9.5");
  EXPECT_TRUE(valid(schema, "not a number"));  // bounds apply to numbers only
}

TEST(Numbers, ExclusiveBounds) {
  const json schema = {{"exclusiveMinimum", 0}, {"exclusiveMaximum", 1}};
  EXPECT_TRUE(valid(schema, 0.5));
  expectOne(check(schema, 0), "", "exclusiveMinimum", "must be > 0, got 0");
  expectOne(check(schema, 1.0), "", "exclusiveMaximum", "must be < 1, got 1.0");
}

TEST(Numbers, ExactComparisonOfLargeIntegers) {
  const json schema = {{"maximum", 9007199254740992}};  // 2^53
  EXPECT_TRUE(valid(schema, 9007199254740992));
  EXPECT_FALSE(valid(schema, 9007199254740993));
  EXPECT_FALSE(valid({{"minimum", 0}}, std::numeric_limits<std::int64_t>::min()));
  EXPECT_TRUE(valid({{"minimum", 0}}, std::numeric_limits<std::uint64_t>::max()));
}

TEST(Numbers, SeveralBoundsAllReported) {
  const auto errors = check({{"minimum", 5}, {"exclusiveMinimum", 5}}, 4);
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].rule, "minimum");
  EXPECT_EQ(errors[1].rule, "exclusiveMinimum");
}

// --- strings ---------------------------------------------------------------------------------

TEST(Strings, MinAndMaxLengthCountCodePoints) {
  const json schema = {{"minLength", 2}, {"maxLength", 3}};
  EXPECT_TRUE(valid(schema, "ab"));
  EXPECT_TRUE(valid(schema, "äöü"));  // 6 bytes, 3 code points
  expectOne(check(schema, "a"), "", "minLength", "expected at least 2 characters, got 1");
  expectOne(check(schema, "abcd"), "", "maxLength", "expected at most 3 characters, got 4");
  expectOne(check({{"minLength", 1}}, ""), "", "minLength", "expected at least 1 character, got 0");
}

TEST(Strings, PatternUsesSearchSemantics) {
  EXPECT_TRUE(valid({{"pattern", "b+"}}, "abbbc"));
  EXPECT_TRUE(valid({{"pattern", "^[a-z_]+$"}}, "warp_angle"));
  expectOne(check({{"pattern", "^[a-z_]+$"}}, "Warp"), "", "pattern",
            "does not match the pattern \"^[a-z_]+$\"");
  EXPECT_TRUE(valid({{"pattern", "^a$"}}, 5));  // strings only
}

// --- arrays ----------------------------------------------------------------------------------

TEST(Arrays, MinAndMaxItems) {
  const json schema = {{"minItems", 2}, {"maxItems", 3}};
  EXPECT_TRUE(valid(schema, json{1, 2}));
  expectOne(check(schema, json{1}), "", "minItems", "expected at least 2 items, got 1");
  expectOne(check(schema, json{1, 2, 3, 4}), "", "maxItems", "expected at most 3 items, got 4");
  expectOne(check({{"minItems", 1}}, json::array()), "", "minItems",
            "expected at least 1 item, got 0");
}

TEST(Arrays, TooManyItemsAreNotWalked) {
  const json schema = {{"maxItems", 2}, {"items", {{"type", "string"}}}};
  expectOne(check(schema, json{1, 2, 3}), "", "maxItems", "expected at most 2 items, got 3");
}

TEST(Arrays, ItemsAppliesToEveryItem) {
  const json schema = {{"items", {{"type", "integer"}, {"minimum", 0}}}};
  EXPECT_TRUE(valid(schema, json::array()));
  EXPECT_TRUE(valid(schema, json{0, 1, 2}));
  const auto errors = check(schema, json{0, -1, "x"});
  ASSERT_EQ(errors.size(), 2u) << all(errors);
  EXPECT_EQ(errors[0].toString(), "[1]: must be ≥ 0, got -1");
  EXPECT_EQ(errors[1].toString(), "[2]: expected an integer, got string");
}

TEST(Arrays, PrefixItemsThenItems) {
  const json schema = {{"prefixItems", {{{"type", "string"}}, {{"type", "number"}}}},
                       {"items", {{"type", "boolean"}}}};
  EXPECT_TRUE(valid(schema, json{"a"}));
  EXPECT_TRUE(valid(schema, json{"a", 1, true, false}));
  expectOne(check(schema, json{1}), "[0]", "type", "expected a string, got number");
  expectOne(check(schema, json{"a", 1, true, 3}), "[3]", "type", "expected a boolean, got number");
  EXPECT_TRUE(valid({{"prefixItems", {{{"type", "string"}}}}}, json{"a", 1, nullptr}));
  expectOne(check({{"prefixItems", {{{"type", "string"}}}}, {"items", false}}, json{"a", 1}), "[1]",
            "false", "is not allowed");
}

// --- objects ---------------------------------------------------------------------------------

TEST(Objects, PropertiesValidateTheirMembers) {
  const json schema = {{"properties", {{"n", {{"type", "number"}}}, {"s", {{"type", "string"}}}}}};
  EXPECT_TRUE(valid(schema, json::object()));
  EXPECT_TRUE(valid(schema, json{{"n", 1}, {"other", "anything"}}));
  expectOne(check(schema, json{{"n", "1"}}), "n", "type", "expected a number, got string");
  EXPECT_TRUE(valid(schema, json::array()));  // object keywords apply to objects only
}

TEST(Objects, RequiredNamesTheMissingMember) {
  const json schema = {{"required", {"model"}},
                       {"properties", {{"model", {{"required", {"kind", "a"}}}}}}};
  expectOne(check(schema, json::object()), "model", "required", "is required");
  const auto errors = check(schema, json{{"model", json::object()}});
  ASSERT_EQ(errors.size(), 2u);
  EXPECT_EQ(errors[0].toString(), "model.kind: is required");
  EXPECT_EQ(errors[0].rule, "required");
  EXPECT_EQ(errors[1].toString(), "model.a: is required");
}

TEST(Objects, AdditionalPropertiesFalse) {
  const json schema = {{"properties", {{"iterations", {{"type", "integer"}}}}},
                       {"additionalProperties", false}};
  EXPECT_TRUE(valid(schema, json{{"iterations", 3}}));
  expectOne(check(schema, json{{"iteratons", 3}}), "iteratons", "additionalProperties",
            "unknown field");
  const json nested = {{"properties", {{"solver", schema}}}};
  expectOne(check(nested, json{{"solver", {{"foo", 1}}}}), "solver.foo", "additionalProperties",
            "unknown field");
}

TEST(Objects, AdditionalPropertiesSchema) {
  const json schema = {{"properties", {{"name", {{"type", "string"}}}}},
                       {"additionalProperties", {{"type", "number"}}}};
  EXPECT_TRUE(valid(schema, json{{"name", "x"}, {"warp_angle_max_deg", 1.5}}));
  expectOne(check(schema, json{{"name", "x"}, {"y", "z"}}), "y", "type",
            "expected a number, got string");
}

TEST(Objects, MinAndMaxProperties) {
  const json schema = {{"minProperties", 1}, {"maxProperties", 2}};
  EXPECT_TRUE(valid(schema, json{{"a", 1}}));
  expectOne(check(schema, json::object()), "", "minProperties",
            "expected at least 1 member, got 0");
  expectOne(check(schema, json{{"a", 1}, {"b", 2}, {"c", 3}}), "", "maxProperties",
            "expected at most 2 members, got 3");
}

// --- combinators -----------------------------------------------------------------------------

TEST(Combinators, AllOfReportsEveryBranch) {
  const json schema = {{"allOf", {{{"minimum", 0}}, {{"multipleOfNot", 1}}}}};
  EXPECT_THROW(check(schema, 1), std::invalid_argument);  // unknown keyword inside allOf
  const json ok = {{"allOf", {{{"minimum", 0}}, {{"maximum", 1}}, {{"type", "integer"}}}}};
  EXPECT_TRUE(valid(ok, 1));
  const auto errors = check(ok, 1.5);
  ASSERT_EQ(errors.size(), 2u) << all(errors);
  EXPECT_EQ(errors[0].rule, "maximum");
  EXPECT_EQ(errors[1].rule, "type");
}

TEST(Combinators, AnyOf) {
  const json schema = {{"anyOf", {{{"type", "string"}}, {{"type", "integer"}, {"minimum", 0}}}}};
  EXPECT_TRUE(valid(schema, "x"));
  EXPECT_TRUE(valid(schema, 3));
  expectOne(
      check(schema, -1), "", "anyOf",
      "matches none of the alternatives: expected a string, got number; or must be ≥ 0, got -1");
}

TEST(Combinators, OneOfExactlyOne) {
  const json schema = {{"oneOf", {{{"type", "integer"}}, {{"minimum", 2}}}}};
  EXPECT_TRUE(valid(schema, 1));
  EXPECT_TRUE(valid(schema, 2.5));
  expectOne(check(schema, 3), "", "oneOf", "matches more than one alternative (#1 and #2)");
  expectOne(
      check(schema, 0.5), "", "oneOf",
      "matches none of the alternatives: expected an integer, got 0.5; or must be ≥ 2, got 0.5");
}

TEST(Combinators, OneOfReportsTheBranchThatGotFurthest) {
  const json pointBranch = {
      {"type", "object"},
      {"required", {"x"}},
      {"properties", {{"x", {{"type", "number"}}}, {"y", {{"type", "number"}}}}}};
  const json schema = {{"oneOf", {{{"type", "string"}}, pointBranch}}};
  expectOne(check(schema, json{{"x", 1}, {"y", "2"}}), "y", "type",
            "expected a number, got string");
  // a missing member is no progress: both branches fail at the instance itself
  expectOne(check(schema, json::object()), "", "oneOf",
            "matches none of the alternatives: expected a string, got object; or x: is required");
}

TEST(Combinators, Not) {
  const json schema = {{"not", {{"type", "string"}}}};
  EXPECT_TRUE(valid(schema, 1));
  expectOne(check(schema, "x"), "", "not", "must not match the excluded schema");
}

TEST(Combinators, IfThenElse) {
  const json schema = {{"if", {{"properties", {{"type", {{"const", "spline"}}}}}}},
                       {"then", {{"required", {"degree"}}}},
                       {"else", {{"properties", {{"degree", false}}}}}};
  EXPECT_TRUE(valid(schema, json{{"type", "spline"}, {"degree", 3}}));
  EXPECT_TRUE(valid(schema, json{{"type", "vectors"}}));
  expectOne(check(schema, json{{"type", "spline"}}), "degree", "required", "is required");
  expectOne(check(schema, json{{"type", "vectors"}, {"degree", 3}}), "degree", "false",
            "is not allowed");
  EXPECT_TRUE(valid({{"if", {{"type", "string"}}}}, 1));  // if alone constrains nothing
}

// --- $ref ------------------------------------------------------------------------------------

TEST(Ref, LocalDefs) {
  const json schema = {{"type", "object"},
                       {"properties", {{"p", {{"$ref", "#/$defs/pos"}}}}},
                       {"$defs", {{"pos", {{"type", "number"}, {"minimum", 0}}}}}};
  EXPECT_TRUE(valid(schema, json{{"p", 1}}));
  expectOne(check(schema, json{{"p", -1}}), "p", "minimum", "must be ≥ 0, got -1");
}

TEST(Ref, SiblingKeywordsApplyToo) {
  const json schema = {
      {"$defs", {{"n", {{"type", "number"}}}}}, {"$ref", "#/$defs/n"}, {"maximum", 5}};
  EXPECT_TRUE(valid(schema, 5));
  expectOne(check(schema, 6), "", "maximum", "must be ≤ 5, got 6");
  expectOne(check(schema, "x"), "", "type", "expected a number, got string");
}

TEST(Ref, RecursiveSchemaAndDepthLimit) {
  // a tree: {"children": [tree...]}
  const json schema = {
      {"$defs",
       {{"tree",
         {{"type", "object"},
          {"additionalProperties", false},
          {"properties",
           {{"children", {{"type", "array"}, {"items", {{"$ref", "#/$defs/tree"}}}}}}}}}}},
      {"$ref", "#/$defs/tree"}};
  json shallow = json::object();
  for (int i = 0; i < 10; ++i) shallow = json{{"children", {shallow}}};
  EXPECT_TRUE(valid(schema, shallow));

  json deep = json::object();
  for (int i = 0; i < 1000; ++i) deep = json{{"children", {deep}}};
  const auto errors = check(schema, deep);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].rule, "depth");
  EXPECT_EQ(errors[0].path.rfind("children[0].children[0]", 0), 0u);
  EXPECT_NE(errors[0].message.find("64"), std::string::npos);
}

TEST(Ref, CycleWithoutProgressThrows) {
  const json schema = {{"$defs", {{"a", {{"$ref", "#/$defs/b"}}}, {"b", {{"$ref", "#/$defs/a"}}}}},
                       {"$ref", "#/$defs/a"}};
  EXPECT_THROW(check(schema, 1), std::logic_error);
}

TEST(Ref, CrossDocumentByNameAndId) {
  SchemaRegistry reg;
  // the referencing document may be added before its target
  reg.add("outer.json",
          json{{"type", "object"},
               {"properties",
                {{"p", {{"$ref", "common.json#/$defs/point3"}}}, {"q", {{"$ref", "urn:inner"}}}}}});
  EXPECT_THROW(reg.validate(json{{"p", {1, 2, 3}}}, "outer.json"), std::out_of_range);
  reg.add(
      "common.json",
      json{{"$defs",
            {{"point3", {{"type", "array"}, {"items", {{"$ref", "#/$defs/num"}}}, {"minItems", 3}}},
             {"num", {{"type", "number"}}}}}});
  reg.add("inner-file.json", json{{"$id", "urn:inner"}, {"type", "string"}});
  EXPECT_TRUE(reg.validate(json{{"p", {1, 2, 3}}, {"q", "x"}}, "outer.json").empty());
  // "#/$defs/num" inside common.json resolves in common.json, not in outer.json
  auto errors = reg.validate(json{{"p", {1, 2, "3"}}}, "outer.json");
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].toString(), "p[2]: expected a number, got string");
  errors = reg.validate(json{{"q", 1}}, "outer.json");
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].toString(), "q: expected a string, got number");
}

TEST(Ref, ValidateRefSelectsASubschema) {
  SchemaRegistry reg;
  reg.add("s.json",
          json{{"$defs", {{"pos", {{"type", "number"}, {"minimum", 0}}}}}, {"type", "object"}});
  EXPECT_TRUE(reg.validateRef(1, "s.json#/$defs/pos").empty());
  EXPECT_TRUE(reg.validateRef(1, "s.json#/%24defs/pos").empty());  // percent-encoded
  expectOne(reg.validateRef(-1, "s.json#/$defs/pos"), "", "minimum", "must be ≥ 0, got -1");
  expectOne(reg.validateRef(1, "s.json"), "", "type", "expected an object, got number");
  expectOne(reg.validateRef(1, "s.json#"), "", "type", "expected an object, got number");
  EXPECT_THROW(reg.validateRef(1, "s.json#/$defs/nope"), std::out_of_range);
}

// --- x-error ---------------------------------------------------------------------------------

TEST(XError, ReplacesErrorsUnderneathWithOneMessage) {
  const json point3 = {{"type", "array"},
                       {"items", {{"type", "number"}}},
                       {"minItems", 3},
                       {"maxItems", 3},
                       {"x-error", "expected 3 numbers"}};
  const json schema = {{"items", point3}};
  EXPECT_TRUE(valid(schema, json{{1, 2, 3}}));
  expectOne(check(schema, json{{1, 2, 3}, {1, 2}}), "[1]", "minItems", "expected 3 numbers");
  expectOne(check(schema, json{{1, 2, 3, 4}}), "[0]", "maxItems", "expected 3 numbers");
  expectOne(check(schema, json{{1, "2", "3"}}), "[0]", "items", "expected 3 numbers");
  expectOne(check(schema, json{"p"}), "[0]", "type", "expected 3 numbers");
  expectOne(check(schema, json{{1, 2, std::numeric_limits<double>::infinity()}}), "[0]", "items",
            "expected 3 numbers");
}

TEST(XError, WorksThroughRef) {
  const json schema = {
      {"$defs",
       {{"pos", {{"type", "number"}, {"minimum", 0}, {"x-error", "expected a position ≥ 0"}}}}},
      {"properties", {{"p", {{"$ref", "#/$defs/pos"}}}}}};
  expectOne(check(schema, json{{"p", -2}}), "p", "minimum", "expected a position ≥ 0");
}

// --- discriminator ---------------------------------------------------------------------------

namespace {
json discriminated() {
  return {{"$defs",
           {{"strip",
             {{"type", "object"},
              {"required", {"kind", "a"}},
              {"additionalProperties", false},
              {"properties", {{"kind", {{"const", "strip"}}}, {"a", {{"type", "number"}}}}}}},
            {"mesh",
             {{"type", "object"},
              {"required", {"kind", "faces"}},
              {"additionalProperties", false},
              {"properties", {{"kind", {{"const", "mesh"}}}, {"faces", {{"type", "array"}}}}}}}}},
          {"properties",
           {{"model",
             {{"discriminator", {{"propertyName", "kind"}}},
              {"oneOf", {{{"$ref", "#/$defs/strip"}}, {{"$ref", "#/$defs/mesh"}}}}}}}}};
}
}  // namespace

TEST(Discriminator, SelectsTheBranchByItsConstant) {
  EXPECT_TRUE(valid(discriminated(), json{{"model", {{"kind", "strip"}, {"a", 1}}}}));
  EXPECT_TRUE(
      valid(discriminated(), json{{"model", {{"kind", "mesh"}, {"faces", json::array()}}}}));
  // only the chosen branch's errors
  const auto errors = check(discriminated(), json{{"model", {{"kind", "mesh"}, {"a", 1}}}});
  ASSERT_EQ(errors.size(), 2u) << all(errors);
  EXPECT_EQ(errors[0].toString(), "model.faces: is required");
  EXPECT_EQ(errors[1].toString(), "model.a: unknown field");
  expectOne(check(discriminated(), json{{"model", {{"kind", "strip"}, {"a", "1"}}}}), "model.a",
            "type", "expected a number, got string");
}

TEST(Discriminator, MissingProperty) {
  expectOne(check(discriminated(), json{{"model", {{"a", 1}}}}), "model.kind", "required",
            "is required");
}

TEST(Discriminator, UnknownValueListsTheAllowedOnes) {
  expectOne(check(discriminated(), json{{"model", {{"kind", "sphere"}}}}), "model.kind", "enum",
            "unknown kind \"sphere\" (expected one of: strip, mesh)");
  expectOne(check(discriminated(), json{{"model", {{"kind", 3}}}}), "model.kind", "enum",
            "unknown kind 3 (expected one of: strip, mesh)");
}

TEST(Discriminator, NonObject) {
  expectOne(check(discriminated(), json{{"model", {1, 2}}}), "model", "type",
            "expected an object, got array");
}

TEST(Discriminator, InlineBranchesAndCrossDocumentBranches) {
  SchemaRegistry reg;
  reg.add("models.json",
          json{{"$defs",
                {{"quad_mesh",
                  {{"required", {"faces"}},
                   {"properties",
                    {{"kind", {{"const", "quad_mesh"}}}, {"faces", {{"type", "array"}}}}}}}}}});
  reg.add("t.json", json{{"discriminator", {{"propertyName", "kind"}}},
                         {"oneOf",
                          {{{"properties", {{"kind", {{"enum", {"strip"}}}}}}},
                           {{"$ref", "models.json#/$defs/quad_mesh"}}}}});
  EXPECT_TRUE(reg.validate(json{{"kind", "strip"}}, "t.json").empty());
  expectOne(reg.validate(json{{"kind", "quad_mesh"}}, "t.json"), "faces", "required",
            "is required");
  expectOne(reg.validate(json{{"kind", "x"}}, "t.json"), "kind", "enum",
            "unknown kind \"x\" (expected one of: strip, quad_mesh)");
}
