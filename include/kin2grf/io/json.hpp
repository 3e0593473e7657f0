// kin2grf JSON files: reading one with errors that name the file, and writing JSON as text.
// Outside the core (kin2grf_core reads and writes no file format).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace kin2grf {

/// JSON as text, 2-space indent and a newline; invalid UTF-8 from files is replaced, not fatal.
std::string json_text(const nlohmann::json& j);
/// Deepest nesting a JSON input may have (kin2grf's own files need 4).
inline constexpr int kMaxJsonDepth = 64;
/// A JSON file; InputError naming the file (and the parser's position) when it is not JSON or is
/// nested deeper than kMaxJsonDepth.
nlohmann::json read_json_file(const std::string& path);
/// The same for text already read; `path` names it in errors.
nlohmann::json parse_json_text(std::string_view text, const std::string& path);
/// A value as one line of JSON for a message, cut at `max_chars`.
std::string json_excerpt(const nlohmann::json& j, std::size_t max_chars = 200);

}  // namespace kin2grf
