#pragma once

#include <string>

#include "http/request.hpp"

namespace scanplan::server {

enum class Role { kNone, kViewer, kOperator };

// Bearer tokens (DESIGN.md "REST"): a viewer may read, an operator may also act.
class Auth {
 public:
  Auth(std::string operator_token, std::string viewer_token);
  Role role_of(const http::Request& request) const;
  Role role_of_token(std::string_view token) const;
  // 128 random bits as hex, for a session started without a configured token.
  static std::string random_token();

 private:
  std::string operator_token_;
  std::string viewer_token_;
};

}  // namespace scanplan::server
