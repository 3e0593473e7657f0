// libFuzzer target: a trial list (`study`, `fit-cop`, `batch`) must be read or refused with
// InputError, in time linear in its length.
#include <cstdint>
#include <string_view>

#include "kin2grf/error.hpp"
#include "kin2grf/workflow/trial_list.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    (void)kin2grf::parse_trial_list(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.txt");
  } catch (const kin2grf::InputError&) {
  }
  return 0;
}
