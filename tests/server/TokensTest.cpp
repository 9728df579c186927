#include "devsurf/server/Tokens.h"

#include <set>

#include <gtest/gtest.h>

namespace devsurf::server {
namespace {

TEST(Tokens, AreRandom128BitLowercaseHex) {
  std::set<std::string> seen;
  for (int i = 0; i < 1000; ++i) {
    const std::string t = randomToken();
    ASSERT_EQ(t.size(), 32u);
    ASSERT_EQ(t.find_first_not_of("0123456789abcdef"), std::string::npos) << t;
    seen.insert(t);
  }
  EXPECT_EQ(seen.size(), 1000u);
}

TEST(Tokens, AreStoredAsSha256) {
  // FIPS 180-2 test vectors.
  EXPECT_EQ(sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(tokenHash("abc"), sha256Hex("abc"));
}

TEST(Tokens, MatchTheirHashAndNothingElse) {
  const std::string token = randomToken();
  EXPECT_TRUE(hashMatches(token, tokenHash(token)));
  EXPECT_FALSE(hashMatches(token + "0", tokenHash(token)));
  EXPECT_FALSE(hashMatches("", tokenHash(token)));
  EXPECT_FALSE(hashMatches(token, ""));
}

TEST(Tokens, StoredBeforeSha256StillMatchTheirSha1Hash) {
  // A session created by an earlier version keeps working: SHA-1 of "abc" (FIPS 180-1).
  EXPECT_TRUE(hashMatches("abc", "a9993e364706816aba3e25717850c26c9cd0d89d"));
  EXPECT_FALSE(hashMatches("abd", "a9993e364706816aba3e25717850c26c9cd0d89d"));
}

TEST(Tokens, CompareInConstantTimeByContentAndLength) {
  EXPECT_TRUE(constantTimeEquals("x1", "x1"));
  EXPECT_FALSE(constantTimeEquals("x1", "x2"));
  EXPECT_FALSE(constantTimeEquals("x1", "x12"));
  EXPECT_TRUE(constantTimeEquals("", ""));
}

}  // namespace
}  // namespace devsurf::server
