#include "rest/auth.hpp"

#include <openssl/crypto.h>
#include <openssl/rand.h>

#include <stdexcept>

#include "http/ascii.hpp"

namespace scanplan::server {
namespace {

// Compares without an early exit so response timing does not reveal how much of a guess
// was right; the length is not secret.
bool same_token(const std::string& a, std::string_view b) {
  return !a.empty() && a.size() == b.size() && CRYPTO_memcmp(a.data(), b.data(), a.size()) == 0;
}

}  // namespace

Auth::Auth(std::string operator_token, std::string viewer_token)
    : operator_token_(std::move(operator_token)), viewer_token_(std::move(viewer_token)) {}

Role Auth::role_of(const http::Request& request) const {
  const auto header = request.header("Authorization");
  if (!header) return Role::kNone;
  // credentials = auth-scheme 1*SP token68, the scheme case-insensitive (RFC 9110 §11.4).
  constexpr std::string_view kBearer = "bearer";
  const std::string_view value = *header;
  if (value.size() <= kBearer.size() ||
      !http::ascii::iequals(value.substr(0, kBearer.size()), kBearer) ||
      value[kBearer.size()] != ' ') {
    return Role::kNone;
  }
  std::string_view token = value.substr(kBearer.size());
  while (!token.empty() && token.front() == ' ') token.remove_prefix(1);
  return role_of_token(token);
}

Role Auth::role_of_token(std::string_view token) const {
  if (same_token(operator_token_, token)) return Role::kOperator;
  if (same_token(viewer_token_, token)) return Role::kViewer;
  return Role::kNone;
}

std::string Auth::random_token() {
  unsigned char bytes[16];
  if (RAND_bytes(bytes, sizeof bytes) != 1) throw std::runtime_error("no randomness for a token");
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (unsigned char b : bytes) {
    out += kHex[b >> 4];
    out += kHex[b & 15];
  }
  return out;
}

}  // namespace scanplan::server
