// kin2grf I/O: small text and file helpers shared by the readers.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace kin2grf {

std::string trim(std::string_view s);
std::string rtrim(std::string_view s);
std::string to_lower(std::string s);
/// Split on any run of the given delimiters; `keep_empty` keeps empty fields (tab-separated).
std::vector<std::string> split(std::string_view s, std::string_view delims, bool keep_empty);
/// The fields of `s` between `delim`s (empty ones kept), as views into `s`; `out` is reused.
void split_views(std::string_view s, char delim, std::vector<std::string_view>& out);
/// Whole file as bytes; InputError naming the file when it cannot be opened.
std::vector<std::uint8_t> read_file_bytes(const std::string& path);
std::string read_file_text(const std::string& path);
/// Write through a temporary file renamed at the end (no half file on failure).
void write_file_text(const std::string& path, std::string_view text);
/// InputError when `output` is one of `inputs` (the same file by any name): an output never
/// overwrites a run's input.
void ensure_not_an_input(const std::string& output, const std::vector<std::string>& inputs);
/// Largest file the readers take (a 10-minute trial at 2 kHz markers and 10 kHz analog is
/// about 2 GB; more is refused before anything is allocated).
inline constexpr std::uintmax_t kMaxInputBytes = std::uintmax_t{4} << 30;
/// Whether a cell or line holds only blanks (space, tab, CR, LF, VT, FF).
bool is_blank(std::string_view s);
/// Strict number parse ("nan"/"NaN" accepted as NaN, empty -> NaN when allow_empty).
bool parse_double(std::string_view s, double& out);
/// Lower-case file extension without the dot ("c3d", "trc", "mot", "sto").
std::string extension(const std::string& path);

}  // namespace kin2grf
