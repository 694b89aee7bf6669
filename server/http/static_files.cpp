#include "http/static_files.hpp"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <system_error>

#include "http/content_type.hpp"

namespace fs = std::filesystem;

namespace scanplan::http {
namespace {

bool is_within(const fs::path& root, const fs::path& candidate) {
  // Component-wise, so that "/srv/web2" is not taken to be inside "/srv/web".
  const auto [root_end, _] =
      std::mismatch(root.begin(), root.end(), candidate.begin(), candidate.end());
  return root_end == root.end();
}

// The canonical regular file for candidate, or nullopt when it is missing, not a regular file,
// or (through symlinks) outside root.
std::optional<fs::path> resolve(const fs::path& root, const fs::path& candidate) {
  std::error_code ec;
  fs::path resolved = fs::weakly_canonical(candidate, ec);
  if (ec || !is_within(root, resolved)) return std::nullopt;
  if (fs::is_directory(resolved, ec)) {
    resolved = fs::weakly_canonical(resolved / "index.html", ec);
    if (ec || !is_within(root, resolved)) return std::nullopt;
  }
  if (!fs::is_regular_file(resolved, ec)) return std::nullopt;
  return resolved;
}

std::optional<std::string> read_file(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream content;
  content << in.rdbuf();
  if (in.bad()) return std::nullopt;
  return std::move(content).str();
}

}  // namespace

StaticFiles::StaticFiles(fs::path root) {
  std::error_code ec;
  root_ = fs::canonical(root, ec);
  if (ec || !fs::is_directory(root_, ec)) {
    throw std::invalid_argument("static file root '" + root.string() +
                                "' is not an existing directory");
  }
}

Response StaticFiles::serve(const Request& request) const {
  if (request.method != "GET" && request.method != "HEAD") {
    Response response = Response::error(405, "method_not_allowed",
                                        "static files can only be fetched with GET or HEAD");
    response.set_header("Allow", "GET, HEAD");
    return response;
  }
  const std::string& path = request.path;
  if (path.empty() || path.front() != '/') {
    return Response::error(400, "bad_request", "path must start with '/'");
  }
  if (path.find('\0') != std::string::npos) {
    return Response::error(400, "bad_request", "path contains a NUL byte");
  }

  // Built segment by segment: appending an absolute path (from "//etc") to root would replace it.
  fs::path candidate = root_;
  std::string_view rest(path);
  while (!rest.empty()) {
    rest.remove_prefix(1);
    const std::size_t slash = rest.find('/');
    const std::string_view segment = rest.substr(0, slash);
    if (segment == "..") {
      return Response::error(400, "bad_request", "path must not contain '..' segments");
    }
    if (!segment.empty() && segment != ".") candidate /= fs::path(std::string(segment));
    rest = slash == std::string_view::npos ? std::string_view() : rest.substr(slash);
  }
  if (path.back() == '/') candidate /= "index.html";

  const auto file = resolve(root_, candidate);
  const auto content = file ? read_file(*file) : std::nullopt;
  if (!content) return Response::error(404, "not_found", "no file at " + path);

  Response response = Response::bytes(std::move(*content), content_type_for(*file));
  response.set_header("X-Content-Type-Options", "nosniff");
  if (file->filename() == "index.html") response.set_header("Cache-Control", "no-cache");
  // The page loads nothing from elsewhere: its scripts, its worker (which instantiates the Draco
  // decoder's WebAssembly), styles, images from its layers and the API on its own origin. Should
  // an injected string ever reach the DOM, it cannot load or run anything (issue 16); nor may
  // another site frame the page to trick an operator into approving a move.
  response.set_header("Content-Security-Policy",
                      "default-src 'self'; script-src 'self' 'wasm-unsafe-eval'; "
                      "worker-src 'self'; connect-src 'self'; img-src 'self' data: blob:; "
                      "style-src 'self' 'unsafe-inline'; object-src 'none'; base-uri 'none'; "
                      "form-action 'none'; frame-ancestors 'none'");
  response.set_header("X-Frame-Options", "DENY");
  response.set_header("Referrer-Policy", "no-referrer");
  return response;
}

}  // namespace scanplan::http
