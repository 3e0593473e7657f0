// Tests of output/report: the HTML reports.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <string>

#include "kin2grf/error.hpp"
#include "kin2grf/io/cop_function.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/output_file.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/output/report.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/synth/example.hpp"
#include "kin2grf/validation/cop_fit.hpp"
#include "kin2grf/validation/metrics.hpp"
#include "kin2grf/validation/study.hpp"
#include "kin2grf/validation/validate.hpp"
#include "test_support.hpp"

using namespace kin2grf;
using kin2grf::test::synthetic_with_exact_plates;

TEST(Report, RendersInHeadlessChromium) {
  const char* candidates[] = {"/usr/bin/chromium", "/usr/bin/chromium-browser", "/usr/bin/google-chrome"};
  std::string browser;
  for (const char* c : candidates)
    if (std::filesystem::exists(c)) browser = c;
  if (browser.empty()) GTEST_SKIP() << "no Chromium found (scripts/setup.sh installs Debian's chromium)";
  const auto s = synthetic_with_exact_plates();
  const auto v = validate(s.estimate, s.plates);
  const auto j = validation_json("synthetic", s.estimate, v, nlohmann::json::object());
  const auto dir = test::temp_dir("report");
  const auto html = dir / "report.html";
  write_file_text(html.string(), validation_report_html("synthetic", s.estimate, v, j));
  const std::string cmd = browser + " --headless --no-sandbox --disable-gpu --user-data-dir=" + (dir / "profile").string() +
                          " --dump-dom file://" + html.string() + " 2>/dev/null";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(cmd.c_str(), "r"), pclose);
  ASSERT_TRUE(pipe);
  std::string dom;
  char buf[4096];
  while (std::size_t k = std::fread(buf, 1, sizeof buf, pipe.get())) dom.append(buf, k);
  // 3 figures per foot and 2 totals, each drawn by Chart.js (the script sets the attribute
  // only after every chart was constructed).
  EXPECT_NE(dom.find("data-charts-rendered=\"8\""), std::string::npos) << dom.substr(0, 400);
  const auto p = dom.find("data-points=\"");
  ASSERT_NE(p, std::string::npos);
  EXPECT_GT(std::stoi(dom.substr(p + 13)), 1000);
}
