// kin2grf I/O: small text and file helpers shared by the readers.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace kin2grf {

std::string trim(std::string_view s);
std::string rtrim(std::string_view s);
std::string to_lower(std::string s);
/// Split on any run of the given delimiters; `keep_empty` keeps empty fields (tab-separated).
std::vector<std::string> split(std::string_view s, std::string_view delims, bool keep_empty);
/// Whole file as bytes; InputError naming the file when it cannot be opened.
std::vector<std::uint8_t> read_file_bytes(const std::string& path);
std::string read_file_text(const std::string& path);
void write_file_text(const std::string& path, const std::string& text);
/// A JSON file; InputError naming the file (and the parser's position) when it is not JSON.
nlohmann::json read_json_file(const std::string& path);
/// Strict number parse ("nan"/"NaN" accepted as NaN, empty -> NaN when allow_empty).
bool parse_double(std::string_view s, double& out);
/// Lower-case file extension without the dot ("c3d", "trc", "mot", "sto").
std::string extension(const std::string& path);

}  // namespace kin2grf
