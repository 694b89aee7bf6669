#include "http/content_type.hpp"

#include <array>
#include <utility>

#include "http/ascii.hpp"

namespace scanplan::http {

std::string_view content_type_for(const std::filesystem::path& file) {
  static constexpr std::array<std::pair<std::string_view, std::string_view>, 17> kTypes = {{
      {".html", "text/html; charset=utf-8"},
      {".htm", "text/html; charset=utf-8"},
      {".js", "text/javascript; charset=utf-8"},
      {".mjs", "text/javascript; charset=utf-8"},
      {".css", "text/css; charset=utf-8"},
      // Browsers refuse WebAssembly.instantiateStreaming without exactly this type.
      {".wasm", "application/wasm"},
      {".json", "application/json"},
      {".map", "application/json"},
      {".png", "image/png"},
      {".jpg", "image/jpeg"},
      {".jpeg", "image/jpeg"},
      {".svg", "image/svg+xml"},
      {".ico", "image/x-icon"},
      {".drc", "application/octet-stream"},
      {".txt", "text/plain; charset=utf-8"},
      {".woff2", "font/woff2"},
      {".ply", "application/octet-stream"},
  }};
  const std::string extension = ascii::lower(file.extension().string());
  for (const auto& [ext, type] : kTypes) {
    if (extension == ext) return type;
  }
  return "application/octet-stream";
}

}  // namespace scanplan::http
