#include "devsurf/server/Tokens.h"

#include <cstdio>
#include <random>

#include <boost/uuid/detail/sha1.hpp>

namespace devsurf::server {

std::string randomToken() {
  static thread_local std::random_device device;
  std::string out;
  char buffer[9];
  for (int i = 0; i < 4; ++i) {
    std::snprintf(buffer, sizeof(buffer), "%08x", static_cast<unsigned>(device()));
    out += buffer;
  }
  return out;
}

std::string sha1Hex(const std::string& text) {
  boost::uuids::detail::sha1 sha;
  sha.process_bytes(text.data(), text.size());
  boost::uuids::detail::sha1::digest_type digest;
  sha.get_digest(digest);
  std::string out;
  char buffer[9];
  for (unsigned word : digest) {
    std::snprintf(buffer, sizeof(buffer), "%08x", word);
    out += buffer;
  }
  return out;
}

bool constantTimeEquals(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  unsigned char diff = 0;
  for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
  return diff == 0;
}

}  // namespace devsurf::server
