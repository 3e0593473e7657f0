// Shared helpers for the kin2grf tests: where the shared recordings are, and a skip that says why.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

namespace kin2grf::test {

/// ../shared/data, or $KIN2GRF_DATA_DIR when set.
std::string data_dir();
bool have_data();
std::string data_file(const std::string& relative);
/// A fresh temporary directory for one test.
std::filesystem::path temp_dir(const std::string& name);

}  // namespace kin2grf::test

#define KIN2GRF_REQUIRE_DATA()                                                                 \
  do {                                                                                         \
    if (!::kin2grf::test::have_data())                                                         \
      GTEST_SKIP() << "shared recordings not found at '" << ::kin2grf::test::data_dir()        \
                   << "' (set KIN2GRF_DATA_DIR or place ../shared/data beside the checkout)"; \
  } while (0)
