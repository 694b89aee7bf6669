#pragma once

#include <filesystem>

#include "http/request.hpp"
#include "http/response.hpp"

namespace scanplan::http {

// Serves the files under one directory (the built web page) for GET and HEAD.
//
// Requests can never reach outside the root: a decoded path containing NUL or a ".." segment is
// refused with 400, and the resolved file (after following symlinks) must still lie under the
// canonical root, otherwise it is reported as missing. "/" and directories map to index.html,
// which is sent with "Cache-Control: no-cache" so a rebuilt page is picked up at once.
class StaticFiles {
 public:
  // Throws std::invalid_argument when root is not an existing directory.
  explicit StaticFiles(std::filesystem::path root);

  Response serve(const Request& request) const;

  const std::filesystem::path& root() const { return root_; }

 private:
  std::filesystem::path root_;  // canonical
};

}  // namespace scanplan::http
