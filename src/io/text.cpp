#include "kin2grf/io/text.hpp"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <utility>

#include <atomic>
#include <csignal>
#include <mutex>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/mman.h>
#include <unistd.h>

#include "kin2grf/error.hpp"

namespace kin2grf {

std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r\n\v\f");
  if (b == std::string_view::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n\v\f");
  return std::string(s.substr(b, e - b + 1));
}

std::string rtrim(std::string_view s) {
  const auto e = s.find_last_not_of(" \t\r\n\v\f");
  if (e == std::string_view::npos) return "";
  return std::string(s.substr(0, e + 1));
}

std::string to_lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::vector<std::string> split(std::string_view s, std::string_view delims, bool keep_empty) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= s.size()) {
    const auto pos = s.find_first_of(delims, start);
    const auto end = pos == std::string_view::npos ? s.size() : pos;
    if (keep_empty || end > start) out.emplace_back(s.substr(start, end - start));
    if (pos == std::string_view::npos) break;
    start = pos + 1;
  }
  return out;
}

namespace {

/// The size of a regular file that kin2grf will read, or an InputError naming why not.
std::size_t checked_input_size(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const auto st = fs::status(path, ec);
  if (ec || !fs::exists(st)) throw InputError(path + ": cannot open file (" + (ec ? ec.message() : std::string("no such file")) + ")");
  if (fs::is_directory(st)) throw InputError(path + ": is a directory, not a file");
  // A FIFO, a terminal or /dev/zero has no end to read to: refused before reading.
  if (!fs::is_regular_file(st)) throw InputError(path + ": is not a regular file (a device, pipe or socket)");
  const auto size = fs::file_size(path, ec);
  if (ec) throw InputError(path + ": cannot read its size (" + ec.message() + ")");
  if (size > kMaxInputBytes)
    throw InputError(path + ": " + std::to_string(size >> 20) + " MiB, more than the " + std::to_string(kMaxInputBytes >> 20) +
                     " MiB kin2grf reads");
  return static_cast<std::size_t>(size);
}

/// A whole regular file into a byte buffer (a vector or a string), read once, no second copy.
template <class Buffer>
Buffer read_whole_file(const std::string& path) {
  const auto size = checked_input_size(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open file (" + std::strerror(errno) + ")");
  Buffer data(size, typename Buffer::value_type{});
  in.read(reinterpret_cast<char*>(data.data()), static_cast<std::streamsize>(size));
  if (in.gcount() != static_cast<std::streamsize>(size))
    throw InputError(path + ": read " + std::to_string(in.gcount()) + " of " + std::to_string(size) + " bytes");
  return data;
}

}  // namespace

void check_input_file(const std::string& path) { (void)checked_input_size(path); }

std::vector<std::uint8_t> read_file_bytes(const std::string& path) { return read_whole_file<std::vector<std::uint8_t>>(path); }

std::string read_file_text(const std::string& path) { return read_whole_file<std::string>(path); }

namespace {

// The mapped inputs, for the SIGBUS handler: a fixed table read without a lock (a signal may come
// while any lock is held). A file mapped while the table is full is read into memory instead.
struct MappedSlot {
  std::atomic<std::uintptr_t> begin{0}, end{0};
  std::atomic<bool> used{false}, faulted{false};
};
constexpr int kMappedSlots = 256;
MappedSlot mapped_slots[kMappedSlots];
struct sigaction previous_sigbus {};

extern "C" void on_sigbus(int sig, siginfo_t* info, void* context) {
  const auto addr = reinterpret_cast<std::uintptr_t>(info->si_addr);
  for (auto& s : mapped_slots) {
    if (!s.used.load() || addr < s.begin.load() || addr >= s.end.load()) continue;
    // A page of the mapped input past the file's new end: zeros in its place, the file marked
    // changed, and the read goes on to its end, where the change is reported.
    const auto page = static_cast<std::uintptr_t>(::sysconf(_SC_PAGESIZE));
    void* at = reinterpret_cast<void*>(addr / page * page);
    if (::mmap(at, page, PROT_READ, MAP_PRIVATE | MAP_ANONYMOUS | MAP_FIXED, -1, 0) != MAP_FAILED) {
      s.faulted.store(true);
      return;
    }
    break;
  }
  // Not ours: the disposition there was before (a host's handler, or the default's end of the
  // process) takes the same fault again when the instruction is retried on return.
  (void)sig, (void)context;
  ::sigaction(SIGBUS, &previous_sigbus, nullptr);
}

void install_sigbus_handler() {
  static std::once_flag once;
  std::call_once(once, [] {
    struct sigaction sa {};
    sa.sa_sigaction = on_sigbus;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_SIGINFO | SA_NODEFER;
    ::sigaction(SIGBUS, &sa, &previous_sigbus);
  });
}

int claim_slot(const char* begin, std::size_t size) {
  for (int k = 0; k < kMappedSlots; ++k) {
    bool expected = false;
    auto& s = mapped_slots[k];
    if (!s.used.load() && s.used.compare_exchange_strong(expected, true)) {
      s.faulted.store(false);
      s.begin.store(reinterpret_cast<std::uintptr_t>(begin));
      s.end.store(reinterpret_cast<std::uintptr_t>(begin) + size);
      return k;
    }
  }
  return -1;
}

long long mtime_ns(const struct stat& st) { return static_cast<long long>(st.st_mtim.tv_sec) * 1000000000LL + st.st_mtim.tv_nsec; }

}  // namespace

MappedFile::MappedFile(const std::string& path, bool populate) : path_(path) {
  const std::size_t size = checked_input_size(path);
  fd_ = size > 0 ? ::open(path.c_str(), O_RDONLY | O_CLOEXEC) : -1;
  struct stat st {};
  void* p = MAP_FAILED;
  if (fd_ >= 0 && ::fstat(fd_, &st) == 0 && static_cast<std::size_t>(st.st_size) == size) {
    install_sigbus_handler();
    p = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE | (populate ? MAP_POPULATE : 0), fd_, 0);
  }
  if (p != MAP_FAILED) {
    slot_ = claim_slot(static_cast<const char*>(p), size);
    if (slot_ < 0) {
      ::munmap(p, size);
      p = MAP_FAILED;
    }
  }
  if (p == MAP_FAILED) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    copy_ = read_file_text(path);
    return;
  }
  mapped_ = static_cast<const char*>(p);
  size_ = size;
  mtime_ns_ = mtime_ns(st);
}

void MappedFile::release(std::size_t begin, std::size_t end) const {
  if (!mapped_) return;
  const auto page = static_cast<std::size_t>(::sysconf(_SC_PAGESIZE));
  const std::size_t first = (begin + page - 1) / page * page, last = std::min(end, size_) / page * page;
  if (last > first) ::madvise(const_cast<char*>(mapped_) + first, last - first, MADV_DONTNEED);
}

bool MappedFile::changed() const {
  if (!mapped_) return false;
  if (mapped_slots[slot_].faulted.load()) return true;
  struct stat st {};
  return ::fstat(fd_, &st) != 0 || static_cast<std::size_t>(st.st_size) != size_ || mtime_ns(st) != mtime_ns_;
}

void MappedFile::ensure_unchanged() const {
  if (!changed()) return;
  struct stat st {};
  const bool known = ::fstat(fd_, &st) == 0;
  throw InputError(path_ + ": the file changed while it was read (" + std::to_string(size_) + " bytes when opened" +
                   (known && static_cast<std::size_t>(st.st_size) != size_ ? ", " + std::to_string(st.st_size) + " now" : std::string()) +
                   "); read it again once the program writing it has finished");
}

MappedFile::~MappedFile() {
  if (mapped_) {
    ::munmap(const_cast<char*>(mapped_), size_);
    mapped_slots[slot_].used.store(false);
  }
  if (fd_ >= 0) ::close(fd_);
}

bool is_blank(std::string_view s) {
  for (const char c : s)
    if (c != ' ' && c != '\t' && c != '\r' && c != '\n' && c != '\v' && c != '\f') return false;
  return true;
}

namespace {

/// Clinger's fast path for the plain decimals text files are made of ([-]digits.digits): the
/// digits as an integer w <= 2^53 and 10^k with k <= 22 are both exact doubles, so w / 10^k is
/// one correctly rounded division, the same double from_chars gives, in a fraction of its time.
/// Reads from p up to e, the first `stop` byte, a space or a CR, and returns where it stopped;
/// nullptr for anything else (exponents, more digits, "1.", ".5"), which from_chars then reads.
const char* scan_plain_decimal(const char* p, const char* e, char stop, double& out) {
  static constexpr double kPow10[23] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                        1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  const bool negative = p < e && *p == '-';
  if (negative) ++p;
  if (p == e || *p < '0' || *p > '9') return nullptr;
  std::uint64_t w = 0;
  int digits = 0, fraction = -1;  // digits after the point; -1: no point
  // The digits before the point, then those after it, each in a loop of one test a byte (a loop
  // that asked every byte four questions made reading a TRC take 1.7 times as long); then the
  // field must end.
  auto digits_run = [&] {
    for (; p < e; ++p) {
      const auto d = static_cast<unsigned>(static_cast<unsigned char>(*p)) - unsigned{'0'};
      if (d > 9) return true;
      if (++digits > 19) return false;
      w = w * 10 + d;
    }
    return true;
  };
  if (!digits_run()) return nullptr;
  if (p < e && *p == '.') {
    ++p;
    const int before = digits;
    if (!digits_run()) return nullptr;
    fraction = digits - before;
  }
  if (p < e && *p != stop && *p != ' ' && *p != '\r') return nullptr;
  if (fraction == 0 || fraction > 22 || w > (std::uint64_t{1} << 53)) return nullptr;
  const double v = static_cast<double>(w) / kPow10[fraction < 0 ? 0 : fraction];
  out = negative ? -v : v;
  return p;
}

bool plain_decimal(const char* b, const char* e, double& out) {
  double v = 0;
  if (scan_plain_decimal(b, e, '\0', v) != e) return false;  // a NUL inside is not a number either
  out = v;
  return true;
}

}  // namespace

bool parse_double(std::string_view s, double& out) {
  // Called for every cell of a text file: views only, no allocation, and the blanks skipped by
  // hand (find_first_not_of over a set of six was a third of reading a TRC).
  auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; };
  std::size_t b0 = 0, e0 = s.size();
  while (b0 < e0 && space(s[b0])) ++b0;
  while (e0 > b0 && space(s[e0 - 1])) --e0;
  if (b0 == e0) return false;
  const std::string_view t = s.substr(b0, e0 - b0);
  const char* b = t.data();
  const char* e = t.data() + t.size();
  if (*b == '+') ++b;
  if (plain_decimal(b, e, out)) return true;
  auto r = std::from_chars(b, e, out);
  if (r.ec == std::errc() && r.ptr == e) return true;
  // Missing-value spellings of other tools (NaN, -nan, MATLAB's and MSVC's): NaN.
  auto same = [&](std::string_view word) {
    if (t.size() != word.size()) return false;
    for (std::size_t i = 0; i < t.size(); ++i)
      if (std::tolower(static_cast<unsigned char>(t[i])) != word[i]) return false;
    return true;
  };
  if (same("nan") || same("-nan") || same("-1.#ind") || same("1.#qnan")) {
    out = std::numeric_limits<double>::quiet_NaN();
    return true;
  }
  return false;
}

bool parse_plain_fields(std::string_view line, char delim, std::span<double> out) {
  // Splitting and parsing in one pass over the bytes: the rows of marker files are made of
  // nothing else, and the split cost as much as the parse.
  const char* p = line.data();
  const char* const e = p + line.size();
  for (std::size_t c = 0; c < out.size(); ++c) {
    if (c > 0) {
      if (p == e) return false;
      ++p;  // the delimiter
    }
    while (p < e && *p == ' ') ++p;  // printf's padding ("%10f"), as parse_double trims it
    p = scan_plain_decimal(p, e, delim, out[c]);
    if (p == nullptr) return false;
    while (p < e && *p == ' ') ++p;
    if (p < e && *p != delim && c + 1 < out.size()) return false;
  }
  return is_blank(std::string_view(p, static_cast<std::size_t>(e - p)));  // trailing tabs or CR are no field
}

void split_views(std::string_view s, char delim, std::vector<std::string_view>& out) {
  // The fields of a text table are a few characters long: a call to memchr per field cost more
  // than the scan (a third of splitting a TRC row). Eight bytes at a time: the bytes equal to
  // the delimiter are the zero bytes of word ^ pattern, found exactly (no borrow between bytes).
  out.clear();
  const char* const d = s.data();
  const std::size_t n = s.size();
  std::size_t start = 0, i = 0;
  if constexpr (std::endian::native == std::endian::little) {
    constexpr std::uint64_t low7 = 0x7F7F7F7F7F7F7F7FULL;
    const std::uint64_t pattern = 0x0101010101010101ULL * static_cast<unsigned char>(delim);
    for (; i + 8 <= n; i += 8) {
      std::uint64_t w;
      std::memcpy(&w, d + i, 8);
      const std::uint64_t x = w ^ pattern;
      std::uint64_t zero = ~(((x & low7) + low7) | x | low7);  // high bit of each zero byte
      while (zero) {
        const std::size_t at = i + static_cast<std::size_t>(std::countr_zero(zero) >> 3);
        out.emplace_back(d + start, at - start);
        start = at + 1;
        zero &= zero - 1;
      }
    }
  }
  for (; i < n; ++i)
    if (d[i] == delim) {
      out.emplace_back(d + start, i - start);
      start = i + 1;
    }
  out.emplace_back(d + start, n - start);
}

std::string closest_match(const std::string& word, const std::vector<std::string>& candidates) {
  const std::string w = to_lower(word);
  const std::size_t allowed = std::clamp<std::size_t>(w.size() / 3, 1, 3);
  std::string best;
  std::size_t best_d = allowed + 1;
  for (const auto& c : candidates) {
    const std::string v = to_lower(c);
    // Levenshtein distance, one row at a time.
    std::vector<std::size_t> row(v.size() + 1);
    for (std::size_t j = 0; j <= v.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= w.size(); ++i) {
      std::size_t diagonal = row[0];
      row[0] = i;
      for (std::size_t j = 1; j <= v.size(); ++j) {
        const std::size_t up = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (w[i - 1] == v[j - 1] ? 0 : 1)});
        diagonal = up;
      }
    }
    if (row[v.size()] < best_d) best_d = row[v.size()], best = c;
  }
  return best;
}

std::string extension(const std::string& path) {
  const auto ext = std::filesystem::path(path).extension().string();
  return ext.empty() ? "" : to_lower(ext.substr(1));
}

void append_csv_number(std::string& out, double x) {
  if (!std::isfinite(x)) return;
  char num[64];
  out.append(num, std::to_chars(num, num + sizeof num, x, std::chars_format::general, 6).ptr);
}

std::string csv_quoted(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : c == '\n' ? std::string(" ") : std::string(1, c);
  return q + "\"";
}

}  // namespace kin2grf
