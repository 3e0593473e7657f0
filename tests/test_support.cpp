#include "test_support.hpp"

#include <cstdlib>

namespace kin2grf::test {

std::string data_dir() {
  if (const char* env = std::getenv("KIN2GRF_DATA_DIR"); env && *env) return env;
  return KIN2GRF_DATA_DIR;
}

bool have_data() {
  return std::filesystem::exists(std::filesystem::path(data_dir()) / "README.md");
}

std::string data_file(const std::string& relative) {
  return (std::filesystem::path(data_dir()) / relative).string();
}

std::filesystem::path temp_dir(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  auto p = std::filesystem::temp_directory_path() / "kin2grf-tests" /
           (std::string(info ? info->test_suite_name() : "x") + "-" + (info ? info->name() : "y") + "-" + name);
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p;
}

}  // namespace kin2grf::test
