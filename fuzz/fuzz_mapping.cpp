// libFuzzer target: a marker-set mapping file (JSON) must be read or refused with InputError,
// whatever its nesting or content.
#include <cstdint>
#include <string_view>

#include "kin2grf/error.hpp"
#include "kin2grf/io/json.hpp"
#include "kin2grf/io/marker_presets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const auto j = kin2grf::parse_json_text(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.json");
    (void)kin2grf::parse_marker_set(j, "fuzz.json");
  } catch (const kin2grf::InputError&) {
  }
  return 0;
}
