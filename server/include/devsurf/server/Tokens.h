#pragma once

#include <string>

namespace devsurf::server {

/// A 128-bit random token as 32 lowercase hex digits, from OpenSSL's CSPRNG (RAND_bytes).
/// @throws std::runtime_error if the generator cannot be seeded
std::string randomToken();

/// SHA-256 of a string as 64 lowercase hex digits (OpenSSL's EVP interface). Used to store
/// tokens and to fingerprint request bodies; a token is 128 random bits, so preimage resistance
/// is what counts.
std::string sha256Hex(const std::string& text);

/// The hash stored for a capability token: sha256Hex(token).
std::string tokenHash(const std::string& token);

/// The view token of a session whose edit token is `editToken` (sessions made by POST
/// /api/sessions): derived one-way (SHA-256), so that every editor can be told the view link while
/// the view token does not open the edit token.
std::string viewTokenFor(const std::string& editToken);

/// Whether `token` (a capability token, or a request body for idempotency fingerprints) hashes to `storedHash`, compared in constant time (CRYPTO_memcmp; only the
/// length can leak). Hashes stored before SHA-256 (40 hex digits: SHA-1, also through OpenSSL)
/// still match their tokens, so sessions created by earlier versions stay reachable.
bool hashMatches(const std::string& token, const std::string& storedHash);

/// Constant-time string comparison (only the length can leak).
bool constantTimeEquals(const std::string& a, const std::string& b);

}  // namespace devsurf::server
