// kin2grf I/O: small text and file helpers shared by the readers.
#pragma once

#include <cstdint>
#include <fstream>
#include <memory>
#include <span>
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
/// InputError naming the file unless it is a regular file kin2grf can read (not missing, not a
/// folder, device or pipe, not over kMaxInputBytes).
void check_input_file(const std::string& path);
/// Whole file as bytes; InputError naming the file when it cannot be opened.
std::vector<std::uint8_t> read_file_bytes(const std::string& path);
std::string read_file_text(const std::string& path);

/// A regular file's text, mapped read-only (POSIX mmap): no zeroed buffer and no copy. Reading a
/// 1.5 MB TRC into a string was a fifth of a short estimate, mostly page faults on the fresh
/// buffer. The file is checked as read_file_text() checks it; an empty file, or one that cannot be
/// mapped, is read into memory instead.
///
/// A mapped file that another program cuts short while it is read would stop the process with
/// SIGBUS on the first page past its new end. kin2grf's SIGBUS handler maps a page of zeros there
/// instead and marks the file changed (a signal that is not about a mapped input is passed on as
/// before); read() then reports the change, whatever the parser made of the zeros.
class MappedFile {
 public:
  /// `populate`: read every page at once (a text parsed whole); false: pages are read as touched
  /// (a binary file read front to back, released behind the reading).
  explicit MappedFile(const std::string& path, bool populate = true);
  ~MappedFile();
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  std::string_view text() const { return mapped_ ? std::string_view(mapped_, size_) : std::string_view(copy_); }
  std::span<const std::uint8_t> bytes() const {
    const std::string_view t = text();
    return {reinterpret_cast<const std::uint8_t*>(t.data()), t.size()};
  }
  /// The pages wholly inside bytes [begin, end) leave the process's memory (they are read again
  /// from the page cache if touched): a long capture read front to back is never resident whole.
  /// Nothing for a file read into memory.
  void release(std::size_t begin, std::size_t end) const;
  /// Whether the file was cut short, grew or was rewritten since it was opened (a page past its
  /// new end was touched, or its size or modification time differ).
  bool changed() const;
  /// InputError naming the file when changed().
  void ensure_unchanged() const;
  /// parse() on the file, then ensure_unchanged(); an InputError of the parser's is replaced by
  /// the change's when the file changed (the parser read zeros, not the file).
  template <class Parse>
  auto read(Parse&& parse) const -> decltype(parse()) {
    try {
      auto result = parse();
      ensure_unchanged();
      return result;
    } catch (const std::exception&) {
      ensure_unchanged();
      throw;
    }
  }

 private:
  const char* mapped_ = nullptr;
  std::size_t size_ = 0;
  std::string copy_;
  std::string path_;
  int fd_ = -1;
  int slot_ = -1;  ///< in the SIGBUS handler's table of mapped inputs
  long long mtime_ns_ = 0;
};
/// Largest file the readers take (a 10-minute trial at 2 kHz markers and 10 kHz analog is
/// about 2 GB; more is refused before anything is allocated).
inline constexpr std::uintmax_t kMaxInputBytes = std::uintmax_t{4} << 30;
/// The marker rates the readers take: slower is no motion capture (a Time column in milliseconds
/// read as seconds, a damaged POINT:RATE), faster no camera.
inline constexpr double kMinMarkerRateHz = 1.0, kMaxMarkerRateHz = 1e6;
/// Whether a cell or line holds only blanks (space, tab, CR, LF, VT, FF).
bool is_blank(std::string_view s);
/// Strict number parse ("nan"/"NaN" accepted as NaN, empty -> NaN when allow_empty).
bool parse_double(std::string_view s, double& out);
/// The common case of a text table's row, fast: exactly out.size() fields separated by `delim`
/// (trailing blanks and delimiters aside, as TRC writers leave them), each a plain decimal
/// ([-]digits[.digits], space-padded or not), read into `out` as parse_double would read them.
/// False for anything else (blank fields, exponents, NaN, more or fewer fields), and then `out`
/// is undefined: the caller takes its general path.
bool parse_plain_fields(std::string_view line, char delim, std::span<double> out);
/// The candidate nearest `word` by edit distance (case-insensitive), when it is near enough to be
/// a slip (at most a third of the word's length, at least 1, at most 3 edits); else empty. For
/// "did you mean ...?" on a misspelt option, subcommand or preset.
std::string closest_match(const std::string& word, const std::vector<std::string>& candidates);
/// A CSV cell for text (RFC 4180): as it is, or in double quotes (inner quotes doubled) where it
/// holds a comma, a quote or a line break (a line break becomes a space: one row a line).
std::string csv_quoted(const std::string& s);
/// A CSV cell for a number, appended to `out`: 6 significant digits (as %.6g), nothing for NaN
/// or an infinity (an empty cell: the value does not exist).
void append_csv_number(std::string& out, double x);
/// Lower-case file extension without the dot ("c3d", "trc", "mot", "sto").
std::string extension(const std::string& path);

}  // namespace kin2grf
