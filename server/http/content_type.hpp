#pragma once

#include <filesystem>
#include <string_view>

namespace scanplan::http {

// The Content-Type for a file by its extension (case-insensitive); application/octet-stream for
// unknown ones, so browsers download rather than sniff and render them.
std::string_view content_type_for(const std::filesystem::path& file);

}  // namespace scanplan::http
