#pragma once

#include <string>

namespace devsurf::server {

/// A 128-bit random token as 32 lowercase hex digits, from the operating system's random source
/// (std::random_device reads /dev/urandom on Linux).
std::string randomToken();

/// SHA-1 of a string as 40 hex digits (Boost.Uuid's implementation). Used to store tokens and to
/// fingerprint request bodies; a token is 128 random bits, so preimage resistance is what counts.
std::string sha1Hex(const std::string& text);

/// Constant-time string comparison (only the length can leak).
bool constantTimeEquals(const std::string& a, const std::string& b);

}  // namespace devsurf::server
