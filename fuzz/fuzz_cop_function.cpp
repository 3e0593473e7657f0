// libFuzzer target: a COP-function file (JSON, `kin2grf fit-cop -o`) must be read or refused with
// InputError.
#include <cstdint>
#include <string_view>

#include "kin2grf/error.hpp"
#include "kin2grf/io/cop_function.hpp"
#include "kin2grf/io/json.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto j = kin2grf::parse_json_text(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
    (void)kin2grf::cop_function_from_json(j, "fuzz.json");
  } catch (const kin2grf::InputError&) {
  }
  return 0;
}
