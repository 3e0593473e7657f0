#include "kin2grf/io/load.hpp"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdio>
#include <limits>

#include "kin2grf/error.hpp"
#include "kin2grf/numeric.hpp"
#include "kin2grf/io/opensim.hpp"
#include "kin2grf/io/text.hpp"

namespace kin2grf {

std::optional<Axis> up_axis_from_data(const Trial& t, std::string* why) {
  if (t.plates) {
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    for (const auto& p : t.plates->plates)
      if (p.has_geometry) normal += p.lab_R_plate.col(2).cwiseAbs();
    Eigen::Index a = 0;
    if (normal.maxCoeff(&a) > 0) {
      if (why) *why = "the force plates' normal";
      return static_cast<Axis>(a);
    }
  }
  const auto& m = t.markers;
  const Eigen::Index n = m.frames();
  if (m.positions_m.size() < 4 || n == 0) return std::nullopt;
  std::array<std::vector<double>, 3> spread;
  std::array<long, 3> positive{0, 0, 0};
  long valid = 0;
  const Eigen::Index step = std::max<Eigen::Index>(1, (n + 199) / 200);  // at most 200 frames: plenty
  std::array<std::vector<double>, 3> c;
  for (Eigen::Index i = 0; i < n; i += step) {
    for (auto& v : c) v.clear();
    for (const auto& P : m.positions_m) {
      if (!P.row(i).allFinite()) continue;
      for (int a = 0; a < 3; ++a) c[a].push_back(P(i, a)), positive[a] += P(i, a) > 0;
      ++valid;
    }
    if (c[0].size() < 4) continue;
    // 10th-90th percentile, so that a stray or unlabelled point far from the body does not count.
    for (int a = 0; a < 3; ++a) {
      const std::size_t k = c[a].size() - 1;
      const auto lo = c[a].begin() + static_cast<std::ptrdiff_t>(0.1 * static_cast<double>(k) + 0.5);
      const auto hi = c[a].begin() + static_cast<std::ptrdiff_t>(0.9 * static_cast<double>(k) + 0.5);
      std::nth_element(c[a].begin(), hi, c[a].end());  // two selections, not a sort: same values
      std::nth_element(c[a].begin(), lo, hi);
      spread[a].push_back(*hi - *lo);
    }
  }
  if (spread[0].size() < 3) return std::nullopt;
  std::array<double, 3> med{};
  for (int a = 0; a < 3; ++a) med[a] = median(spread[a]);
  const int best = static_cast<int>(std::max_element(med.begin(), med.end()) - med.begin());
  double next = 0;
  for (int a = 0; a < 3; ++a)
    if (a != best) next = std::max(next, med[a]);
  if (med[best] < 1.3 * next || med[best] > 2.5 || 5 * positive[best] < 4 * valid) return std::nullopt;
  if (why) {
    char b[160];
    std::snprintf(b, sizeof b, "the markers' spread (median %.2f m along %s against %.2f m across)", med[best],
                  to_string(static_cast<Axis>(best)), next);
    *why = b;
  }
  return static_cast<Axis>(best);
}

namespace {

/// Use the data's up axis where the file's convention disagrees, and say so.
void check_up_axis(Trial& t) {
  std::string why;
  const auto a = up_axis_from_data(t, &why);
  if (!a) return;
  const bool has_markers = !t.markers.names.empty();
  const Axis file_axis = has_markers ? t.markers.up_axis : t.plates ? t.plates->up_axis : *a;
  if (*a != file_axis)
    t.warnings.push_back(std::string("up axis: the file's convention is ") + to_string(file_axis) + " but " + why +
                         " say " + to_string(*a) + "; " + to_string(*a) + " is used (an up-axis setting overrides it)");
  if (has_markers) t.markers.up_axis = *a;
  if (t.plates) t.plates->up_axis = *a;
}

Trial load_by_extension(const std::string& path, const LoadOptions& options) {
  check_input_file(path);  // a folder or /dev/zero is named as such, not as an unknown file type
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
    t.warnings.insert(t.warnings.end(), table.warnings.begin(), table.warnings.end());
    // kin2grf's own GRF in OpenSim's frame lines up with the markers of the same --opensim set,
    // not with the capture file's lab frame (unless its axes are OpenSim's).
    if (const auto frame = table.header.find("kin2grf_frame");
        frame != table.header.end() && frame->second.rfind("OpenSim", 0) == 0)
      t.warnings.push_back(path + ": written by kin2grf in OpenSim's frame (X the walker's progression, Y up): it lines up with "
                                  "the TRC of the same --opensim set; to compare it with the capture file, write it with -o --lab-frame");
    t.plates = grf_from_table(table, path, options.cop_threshold_N, t.warnings);
    if (!t.plates) t.warnings.push_back("no ground_force columns: not a GRF file (" +
                                        std::to_string(table.labels.size()) + " columns)");
    if (t.plates) t.markers.up_axis = t.plates->up_axis;
    return t;
  }
  throw InputError(path + ": unknown file type '." + ext + "' (kin2grf reads .c3d, .trc, .mot, .sto)");
}

}  // namespace

void remove_subject_prefix(MarkerTrajectories& m, std::vector<std::string>& warnings) {
  std::string prefix;
  std::size_t prefixed = 0;
  for (const auto& n : m.names) {
    const auto colon = n.find(':');
    if (colon == std::string::npos) continue;
    if (colon == 0) return;  // ":X" is no subject's name
    const std::string p = n.substr(0, colon + 1);
    if (prefixed++ == 0) prefix = p;
    else if (p != prefix) return;  // several subjects: the labels as they are
  }
  if (prefixed == 0) return;
  std::vector<std::string> stripped = m.names;
  for (auto& n : stripped)
    if (n.starts_with(prefix)) n.erase(0, prefix.size());
  std::vector<std::string> sorted = stripped;
  std::sort(sorted.begin(), sorted.end());
  if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end() ||
      std::any_of(stripped.begin(), stripped.end(), [](const std::string& n) { return n.empty(); })) {
    warnings.push_back("marker labels carry the subject prefix '" + prefix +
                       "', kept: without it two labels would be the same");
    return;
  }
  m.names = std::move(stripped);
  m.label_prefix = prefix;
  warnings.push_back("marker labels carry the subject prefix '" + prefix + "' (" + std::to_string(prefixed) + " of " +
                     std::to_string(m.names.size()) + "); it is removed, and names with it still find the markers");
}

Trial load_trial(const std::string& path, const LoadOptions& options) {
  Trial t = load_by_extension(path, options);
  check_up_axis(t);
  remove_subject_prefix(t.markers, t.warnings);
  return t;
}

}  // namespace kin2grf
