// libFuzzer target: the TRC reader must either read a file or throw InputError, never crash.
#include <cstdint>
#include <string>

#include "kin2grf/error.hpp"
#include "kin2grf/io/opensim.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)kin2grf::parse_trc(text, "fuzz.trc");
  } catch (const kin2grf::InputError&) {
  }
  return 0;
}
