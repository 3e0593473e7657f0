// Tests of io/text: the number parser every text reader uses, and reading a file.
#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <string_view>
#include <vector>

#include "kin2grf/error.hpp"
#include "kin2grf/io/output_file.hpp"
#include "kin2grf/io/text.hpp"
#include "test_support.hpp"

using namespace kin2grf;

namespace {

double by_from_chars(const std::string& s) {
  double v = 0;
  const char* b = s.data() + (s[0] == '+' ? 1 : 0);
  const auto r = std::from_chars(b, s.data() + s.size(), v);
  EXPECT_TRUE(r.ec == std::errc() && r.ptr == s.data() + s.size()) << s;
  return v;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

// Plain decimals take a fast path (Clinger's): it must give the very double from_chars gives
// (correct rounding) for every number a capture system writes, and leave the rest to from_chars.
TEST(Text, ParseDoubleGivesTheCorrectlyRoundedDouble) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mm(-5000.0, 5000.0);
  std::uniform_int_distribution<int> decimals(0, 17);
  char buf[64];
  for (int k = 0; k < 200000; ++k) {
    std::snprintf(buf, sizeof buf, "%.*f", decimals(rng), mm(rng) * std::pow(10.0, static_cast<double>(k % 9) - 4));
    double v = 0;
    ASSERT_TRUE(parse_double(buf, v)) << buf;
    ASSERT_TRUE(same_bits(v, by_from_chars(buf))) << buf;
  }
  for (const char* s : {"0", "-0", "-0.0", "+12.5", "9007199254740993", "9007199254740992.5", "0.1", "1e-3", "-2.5E+04",
                        "123456789012345678901", "1.", ".5", "0.0000000000000000000001", "4.9406564584124654e-324"}) {
    double v = 0;
    ASSERT_TRUE(parse_double(s, v)) << s;
    EXPECT_TRUE(same_bits(v, by_from_chars(s))) << s;
  }
  double v = 0;
  EXPECT_TRUE(parse_double("  -1.25\r", v));
  EXPECT_EQ(v, -1.25);
  EXPECT_TRUE(parse_double("NaN", v) && std::isnan(v));
  for (const char* bad : {"", "  ", "-", "1.2.3", "12a", "--1", "0x10"}) EXPECT_FALSE(parse_double(bad, v)) << bad;
}

TEST(Text, AMappedFileHasTheFilesTextAndAnEmptyOrOddFileIsHandled) {
  const auto dir = test::temp_dir("mapped_file");
  const std::string path = (dir / "a.txt").string(), empty = (dir / "empty.txt").string();
  const std::string text = "PathFileType\t4\n1\t2.5\t\n" + std::string(10000, 'x');
  { std::ofstream(path, std::ios::binary) << text; }
  { std::ofstream(empty, std::ios::binary); }
  EXPECT_EQ(MappedFile(path).text(), text);
  EXPECT_EQ(read_file_text(path), text);
  EXPECT_TRUE(MappedFile(empty).text().empty());
  // The checks of read_file_text: a missing file, a folder and a device are named errors.
  for (const std::string& bad : {(dir / "missing.txt").string(), dir.string(), std::string("/dev/null")}) {
    try {
      const MappedFile f(bad);
      ADD_FAILURE() << "no error for " << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

TEST(Text, SplitViewsMatchesAPlainSplitOnEveryByte) {
  // The split reads eight bytes at a time: check it against a plain split on random texts of
  // every length, with the delimiter's neighbours in value (0x08, 0x0a, 0x89) and runs of it.
  auto plain = [](std::string_view s, char delim) {
    std::vector<std::string_view> f;
    std::size_t start = 0;
    for (std::size_t i = 0; i <= s.size(); ++i)
      if (i == s.size() || s[i] == delim) f.push_back(s.substr(start, i - start)), start = i + 1;
    return f;
  };
  std::mt19937 rng(7);
  const std::string alphabet = std::string("\t\t\t\x08\x0a\x0b\x01\x89\x88 .-0123456789") + '\0';
  std::vector<std::string_view> got;
  for (int len = 0; len < 80; ++len)
    for (int rep = 0; rep < 50; ++rep) {
      std::string s(static_cast<std::size_t>(len), ' ');
      for (auto& c : s) c = alphabet[rng() % alphabet.size()];
      for (char delim : {'\t', '\n', ','}) {
        split_views(s, delim, got);
        ASSERT_EQ(got, plain(s, delim)) << "length " << len;
      }
    }
}

TEST(Text, ParsePlainFieldsReadsARowAsSplittingAndParsingWould) {
  // The fused fast path of TRC and STO rows: whenever it accepts a row, every value must be the
  // double parse_double gives for that cell (trailing blank cells dropped, as the readers do);
  // and the rows capture software writes (plain or printf-padded numbers, a trailing tab or CR)
  // must take it.
  auto reference = [](std::string_view line, std::size_t width, std::vector<double>& v) {
    std::vector<std::string_view> cells;
    split_views(line, '\t', cells);
    while (cells.size() > width && is_blank(cells.back())) cells.pop_back();
    if (cells.size() != width) return false;
    v.assign(width, 0.0);
    for (std::size_t c = 0; c < width; ++c)
      if (is_blank(cells[c]) || !parse_double(cells[c], v[c])) return false;
    return true;
  };
  std::mt19937 rng(11);
  const std::vector<std::string> plain = {"0", "-0", "12", "-463.902787", "  0.230000", " 95.849552 ", "1082.20154",
                                          "0.0000001", "9007199254740992", "123456.7890123"};
  const std::vector<std::string> odd = {"", " ", "1e-3", "nan", "+1.5", "1.", ".5", "1 2", "12a", "-", "1.2.3",
                                        "12345678901234567890", "\r", "-.5", "1..2", "1.5.", "12-3", "1.2 3",
                                        "1234567890.123456789", "0.12345678901234567890"};
  std::vector<double> fast, slow;
  int accepted = 0;
  for (int rep = 0; rep < 20000; ++rep) {
    const std::size_t width = 1 + rng() % 7;
    const bool only_plain = rng() % 2 == 0;
    std::string line;
    for (std::size_t c = 0; c < width; ++c) {
      if (c) line += '\t';
      line += only_plain || rng() % 4 ? plain[rng() % plain.size()] : odd[rng() % odd.size()];
    }
    const char* tails[] = {"", "\t", "\r", "\t\r", "\t\t", "\t7"};
    const std::string tail = tails[rng() % (only_plain ? 5 : 6)];
    line += tail;
    fast.assign(width, 0.0);
    const bool ok = parse_plain_fields(line, '\t', fast);
    if (only_plain) {
      ASSERT_TRUE(ok) << line;
    }
    if (!ok) continue;
    ++accepted;
    ASSERT_TRUE(reference(line, width, slow)) << line;
    for (std::size_t c = 0; c < width; ++c) ASSERT_TRUE(same_bits(fast[c], slow[c])) << line << " field " << c;
  }
  EXPECT_GT(accepted, 10000);
  EXPECT_FALSE(parse_plain_fields("1\t2", '\t', fast = std::vector<double>(3)));  // too few fields
  EXPECT_FALSE(parse_plain_fields("1\t2\t3\t4", '\t', fast = std::vector<double>(3)));  // too many
}

