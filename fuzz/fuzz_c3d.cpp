// libFuzzer target: the C3D reader must either read a file or throw InputError, never crash.
#include <cstdint>
#include <vector>

#include "kin2grf/error.hpp"
#include "kin2grf/io/c3d.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::vector<std::uint8_t> bytes(data, data + size);
  try {
    (void)kin2grf::read_c3d_bytes(bytes, "fuzz.c3d");
  } catch (const kin2grf::InputError&) {
  }
  return 0;
}
