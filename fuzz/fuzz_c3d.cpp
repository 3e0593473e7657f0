// libFuzzer target: the C3D reader must either read a file or throw InputError, never crash,
// with the plates' samples (info, validate) and without them (estimate: C3dReadOptions::
// plate_samples); the two reads agree on whether the file is readable.
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "kin2grf/error.hpp"
#include "kin2grf/io/c3d.hpp"

namespace {
bool reads(const std::vector<std::uint8_t>& bytes, bool plate_samples) {
  kin2grf::C3dReadOptions o;
  o.plate_samples = plate_samples;
  try {
    (void)kin2grf::read_c3d_bytes(bytes, "fuzz.c3d", o);
    return true;
  } catch (const kin2grf::InputError&) {
    return false;
  }
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::vector<std::uint8_t> bytes(data, data + size);
  const bool full = reads(bytes, true), lean = reads(bytes, false);
  // Without samples nothing is refused that the full read takes; the full read may refuse more
  // (a sample it cannot scale), never less.
  if (full && !lean) std::abort();
  return 0;
}
