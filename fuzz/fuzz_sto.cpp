// libFuzzer target: the MOT/STO reader and GRF column detection must read or throw InputError.
#include <cstdint>
#include <string>
#include <vector>

#include "kin2grf/error.hpp"
#include "kin2grf/io/opensim.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto t = kin2grf::parse_sto(text, "fuzz.mot");
    std::vector<std::string> w;
    (void)kin2grf::grf_from_table(t, "fuzz.mot", 10.0, w);
  } catch (const kin2grf::InputError&) {
  }
  return 0;
}
