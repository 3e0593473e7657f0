// kin2grf JSON files: reading one with errors that name the file, and writing JSON as text.
// Outside the core (kin2grf_core reads and writes no file format).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace kin2grf {

/// JSON as text, 2-space indent and a newline; invalid UTF-8 from files is replaced, not fatal.
std::string json_text(const nlohmann::json& j);
/// A JSON file; InputError naming the file (and the parser's position) when it is not JSON.
nlohmann::json read_json_file(const std::string& path);

}  // namespace kin2grf
