// proto::wireText copies strings that need no escaping as they are; it must write exactly what
// nlohmann's compact dump (invalid UTF-8 replaced) writes, for every document.

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <random>
#include <string>

#include <nlohmann/json.hpp>

#include "devsurf/proto/BoundedJson.h"
#include "devsurf/proto/Geometry.h"

namespace devsurf::proto {
namespace {

std::string nlohmannText(const nlohmann::json& value) {
  return value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

/// A string of 0…40 bytes drawn from a mix meant to hit every branch of the fast scan: plain
/// printable ASCII (most of the time, so whole 8-byte words pass), quotes, backslashes, control
/// characters, DEL, valid UTF-8 (é, €, an emoji) and stray continuation or lead bytes.
std::string wireTestString(std::mt19937& rng) {
  std::uniform_int_distribution<int> length(0, 40), pick(0, 99), printable(0x20, 0x7e), control(0, 0x1f);
  const char* const utf8[] = {"\xc3\xa9", "\xe2\x82\xac", "\xf0\x9f\x93\x90"};
  std::string s;
  const int n = length(rng);
  const bool plain = pick(rng) < 60;  // six in ten strings have nothing to escape
  for (int i = 0; i < n; ++i) {
    const int k = plain ? 0 : pick(rng);
    if (k < 85) {
      char c = static_cast<char>(printable(rng));
      if (plain && (c == '"' || c == '\\')) c = 'q';
      s += c;
    } else if (k < 88) {
      s += '"';
    } else if (k < 91) {
      s += '\\';
    } else if (k < 94) {
      s += static_cast<char>(control(rng));
    } else if (k < 95) {
      s += '\x7f';
    } else if (k < 98) {
      s += utf8[k % 3];
    } else {
      s += static_cast<char>(k == 98 ? 0x80 : 0xc3);  // a lone continuation byte, a cut-off lead
    }
  }
  return s;
}

nlohmann::json wireTestValue(std::mt19937& rng, int depth) {
  std::uniform_int_distribution<int> kind(0, depth >= 4 ? 5 : 7), count(0, 5);
  switch (kind(rng)) {
    case 0: return nullptr;
    case 1: return std::uniform_int_distribution<int>(0, 1)(rng) == 1;
    case 2: return std::uniform_int_distribution<std::int64_t>(-1'000'000'000'000LL, 1'000'000'000'000LL)(rng);
    case 3: return std::uniform_int_distribution<std::uint64_t>()(rng);
    case 4: {
      const double values[] = {std::normal_distribution<double>(0.0, 1e3)(rng), 1e-300, -0.0, 0.1, 1e21,
                               std::numeric_limits<double>::quiet_NaN()};
      return values[std::uniform_int_distribution<int>(0, 5)(rng)];
    }
    case 5: return wireTestString(rng);
    case 6: {
      nlohmann::json array = nlohmann::json::array();
      for (int i = count(rng); i > 0; --i) array.push_back(wireTestValue(rng, depth + 1));
      return array;
    }
    default: {
      nlohmann::json object = nlohmann::json::object();
      for (int i = count(rng); i > 0; --i) object[wireTestString(rng)] = wireTestValue(rng, depth + 1);
      return object;
    }
  }
}

TEST(WireText, WritesWhatNlohmannWritesForFiveHundredRandomDocuments) {
  std::mt19937 rng(20261205);
  int escaped = 0, verbatim = 0;
  for (int i = 0; i < 500; ++i) {
    const nlohmann::json doc = wireTestValue(rng, 0);
    const std::string expected = nlohmannText(doc);
    ASSERT_EQ(wireText(doc), expected) << "document " << i;
    (expected.find('\\') != std::string::npos ? escaped : verbatim) += 1;
  }
  // Both paths ran: documents with something to escape and documents without.
  EXPECT_GT(escaped, 50);
  EXPECT_GT(verbatim, 50);
}

TEST(WireText, EscapesEveryByteThatNeedsItAtEveryPositionOfALongString) {
  // A byte that needs escaping (or is not ASCII) at each position of a 40-byte string: inside the
  // 8-byte words of the fast scan and in the tail.
  for (const char special : {'"', '\\', '\n', '\x01', '\x1f', '\x7f', '\x80', '\xff'}) {
    for (int at = 0; at < 40; ++at) {
      std::string text(40, 'A');
      text[static_cast<std::size_t>(at)] = special;
      const nlohmann::json doc{{"k", text}, {text, 1}};
      ASSERT_EQ(wireText(doc), nlohmannText(doc)) << "byte " << int(static_cast<unsigned char>(special)) << " at " << at;
    }
  }
  // The printable edges pass unchanged.
  const nlohmann::json edges = std::string(" ~!#[]{}/") + std::string(30, 'z');
  EXPECT_EQ(wireText(edges), "\"" + edges.get<std::string>() + "\"");
}

TEST(WireText, WritesAStreamedGeometryArrayAsItsBase64Text) {
  Eigen::MatrixXd m(1000, 3);
  for (int i = 0; i < m.rows(); ++i) m.row(i) << i * 0.5, -i * 0.25, 1.0 / (i + 1);
  const nlohmann::json message{{"type", "iterate"}, {"geometry", {{"vertices", float32Array(m)}}}};
  const std::string text = wireText(message);
  EXPECT_EQ(text, nlohmannText(message));
  // Read back by the parser, the array is the matrix to float precision.
  const Eigen::MatrixXd back = decodeFloat32Array(nlohmann::json::parse(text)["geometry"]["vertices"]);
  ASSERT_EQ(back.rows(), m.rows());
  EXPECT_LT((back - m).cwiseAbs().maxCoeff(), 1e-4);
}

TEST(Geometry, Base64EncodesEveryLengthAsTheDecoderReadsIt) {
  // Encoder against the decoder and against the length rule, for 0…200 random bytes.
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> byte(0, 255);
  for (std::size_t n = 0; n <= 200; ++n) {
    std::string raw(n, '\0');
    for (char& c : raw) c = static_cast<char>(byte(rng));
    const std::string text = base64Encode(raw.data(), raw.size());
    ASSERT_EQ(text.size(), (n + 2) / 3 * 4) << n;
    ASSERT_EQ(base64Decode(text), raw) << n;
    const std::size_t pad = n % 3 == 0 ? 0 : 3 - n % 3;
    ASSERT_EQ(text.find('='), pad == 0 ? std::string::npos : text.size() - pad) << n;
  }
}

}  // namespace
}  // namespace devsurf::proto
