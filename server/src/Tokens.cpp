#include "devsurf/server/Tokens.h"

#include <array>
#include <cstdio>
#include <stdexcept>

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/rand.h>

namespace devsurf::server {
namespace {

std::string toHex(const unsigned char* bytes, std::size_t n) {
  static constexpr char kDigits[] = "0123456789abcdef";
  std::string out(2 * n, '0');
  for (std::size_t i = 0; i < n; ++i) {
    out[2 * i] = kDigits[bytes[i] >> 4];
    out[2 * i + 1] = kDigits[bytes[i] & 0xf];
  }
  return out;
}

std::string digestHex(const EVP_MD* md, const std::string& text) {
  std::array<unsigned char, EVP_MAX_MD_SIZE> digest{};
  unsigned int length = 0;
  if (EVP_Digest(text.data(), text.size(), digest.data(), &length, md, nullptr) != 1)
    throw std::runtime_error("OpenSSL digest failed");
  return toHex(digest.data(), length);
}

}  // namespace

std::string randomToken() {
  std::array<unsigned char, 16> bytes{};
  if (RAND_bytes(bytes.data(), static_cast<int>(bytes.size())) != 1)
    throw std::runtime_error("OpenSSL RAND_bytes failed: no random token");
  return toHex(bytes.data(), bytes.size());
}

std::string sha256Hex(const std::string& text) { return digestHex(EVP_sha256(), text); }

std::string tokenHash(const std::string& token) { return sha256Hex(token); }

std::string viewTokenFor(const std::string& editToken) { return sha256Hex("devsurf-view-token:" + editToken).substr(0, 32); }

bool hashMatches(const std::string& token, const std::string& storedHash) {
  // Legacy rows hold SHA-1 (40 hex digits); everything written now is SHA-256 (64).
  const std::string hash = storedHash.size() == 40 ? digestHex(EVP_sha1(), token) : sha256Hex(token);
  return constantTimeEquals(hash, storedHash);
}

bool constantTimeEquals(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  return CRYPTO_memcmp(a.data(), b.data(), a.size()) == 0;
}

}  // namespace devsurf::server
