#include "kin2grf/io/load.hpp"

#include "kin2grf/error.hpp"
#include "kin2grf/io/opensim.hpp"
#include "kin2grf/io/text.hpp"

namespace kin2grf {

Trial load_trial(const std::string& path, const LoadOptions& options) {
  const std::string ext = extension(path);
  if (ext == "c3d") {
    C3dReadOptions o = options.c3d;
    o.cop_threshold_N = options.cop_threshold_N;
    return read_c3d(path, o);
  }
  Trial t;
  t.path = path;
  if (ext == "trc") {
    t.format = "TRC";
    t.encoding = "text";
    t.markers = read_trc(path, &t.warnings);
    return t;
  }
  if (ext == "mot" || ext == "sto") {
    t.format = ext == "mot" ? "MOT" : "STO";
    t.encoding = "text";
    const Table table = read_sto(path);
    t.plates = grf_from_table(table, path, options.cop_threshold_N, t.warnings);
    if (!t.plates) t.warnings.push_back("no ground_force columns: not a GRF file (" +
                                        std::to_string(table.labels.size()) + " columns)");
    if (t.plates) t.markers.up_axis = Axis::Y;
    return t;
  }
  throw InputError(path + ": unknown file type '." + ext + "' (kin2grf reads .c3d, .trc, .mot, .sto)");
}

}  // namespace kin2grf
