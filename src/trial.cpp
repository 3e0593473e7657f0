#include "kin2grf/trial.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include "kin2grf/error.hpp"

namespace kin2grf {

const char* to_string(Axis a) {
  switch (a) {
    case Axis::X: return "X";
    case Axis::Y: return "Y";
    default: return "Z";
  }
}

const char* to_string(Side s) {
  switch (s) {
    case Side::Right: return "right";
    case Side::Left: return "left";
    default: return "general";
  }
}

std::string UniqueLabels::add(const std::string& name, std::size_t index, std::vector<std::string>* warnings) {
  if (taken_.insert(name).second) return name;
  std::size_t& k = next_.try_emplace(name, 2).first->second;
  std::string renamed;
  do renamed = name + "#" + std::to_string(k++);
  while (!taken_.insert(renamed).second);
  if (warnings && ++repeats_ <= 10)
    warnings->push_back("marker label '" + name + "' repeated (column " + std::to_string(index + 1) + "); this one is named " + renamed +
                        ", the first " + name + " (" + name + "#1)");
  return renamed;
}

void UniqueLabels::finish(std::vector<std::string>* warnings) const {
  if (warnings && repeats_ > 10) warnings->push_back("and " + std::to_string(repeats_ - 10) + " more repeated marker labels, named NAME#k likewise");
}

int MarkerTrajectories::find(const std::string& name) const {
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  // NAME#1: the first of a repeated label, which keeps its plain name.
  if (name.size() > 2 && name.ends_with("#1")) {
    const std::string base = name.substr(0, name.size() - 2);
    if (find(base + "#2") >= 0) return find(base);
  }
  if (!label_prefix.empty() && name.size() > label_prefix.size() && name.starts_with(label_prefix))
    return find(name.substr(label_prefix.size()));
  return -1;
}

std::vector<Eigen::Index> MarkerTrajectories::missing_frames(int marker) const {
  std::vector<Eigen::Index> out;
  const auto& P = positions_m.at(static_cast<std::size_t>(marker));
  for (Eigen::Index i = 0; i < P.rows(); ++i)
    if (!P.row(i).allFinite()) out.push_back(i);
  return out;
}

MarkerTrajectories rotated(MarkerTrajectories m, const Eigen::Matrix3d& R, Axis up_axis) {
  for (auto& P : m.positions_m) P = (P * R.transpose()).eval();
  m.up_axis = up_axis;
  return m;
}

void add_marker_noise(MarkerTrajectories& m, double sigma_m, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma_m);
  for (auto& P : m.positions_m)
    for (Eigen::Index i = 0; i < P.size(); ++i) P.data()[i] += noise(rng);
}

namespace {
void check_length_scale(double L) {
  if (!(L > 0) || !std::isfinite(L)) throw InputError("length scale " + std::to_string(L) + ": it must be a positive number");
}
}  // namespace

MarkerTrajectories dynamically_scaled(MarkerTrajectories m, double L) {
  check_length_scale(L);
  const double time_scale = std::sqrt(L);
  for (auto& P : m.positions_m) P *= L;
  m.time_s *= time_scale;
  m.rate_hz /= time_scale;
  return m;
}

ForcePlateRecording dynamically_scaled(ForcePlateRecording r, double L) {
  check_length_scale(L);
  const double time_scale = std::sqrt(L), force = L * L * L, moment = force * L;
  r.time_s *= time_scale;
  r.rate_hz /= time_scale;
  r.cop_threshold_N *= force;
  for (ForcePlate& p : r.plates) {
    for (auto& c : p.corners_m) c *= L;
    p.centre_m *= L;
    p.origin_m *= L;
    p.force_N *= force;
    p.moment_centre_Nm *= moment;
    p.cop_m *= L;
    p.free_moment_Nm *= moment;
  }
  return r;
}

Trial dynamically_scaled(Trial t, double L) {
  t.markers = dynamically_scaled(std::move(t.markers), L);
  if (t.plates) t.plates = dynamically_scaled(std::move(*t.plates), L);
  for (Event& e : t.events) e.time_s *= std::sqrt(L);
  if (t.body_mass_kg) *t.body_mass_kg *= L * L * L;
  if (t.height_m) *t.height_m *= L;
  for (auto* w : {&t.knee_width_m, &t.ankle_width_m})
    for (auto& x : *w)
      if (x) *x *= L;
  if (t.marker_diameter_m) *t.marker_diameter_m *= L;
  return t;
}

MarkerTrajectories decimated(MarkerTrajectories m, int factor) {
  if (factor < 1) throw InputError("decimation factor " + std::to_string(factor) + ": it must be 1 or more");
  if (factor == 1) return m;
  const Eigen::Index n = m.frames(), kept = (n + factor - 1) / factor;
  Eigen::VectorXd t(kept);
  for (Eigen::Index i = 0; i < kept; ++i) t[i] = m.time_s[i * factor];
  for (auto& P : m.positions_m) {
    Eigen::MatrixX3d Q(kept, 3);
    for (Eigen::Index i = 0; i < kept; ++i) Q.row(i) = P.row(i * factor);
    P = std::move(Q);
  }
  m.time_s = std::move(t);
  m.rate_hz /= factor;
  // Frame numbers count the slower capture's frames, as a camera at rate_hz / factor would number
  // them (row 0 keeps its time; the file's number of row i was first_frame + i * factor, which no
  // one offset can give, so messages naming a frame would be off by i * (factor - 1)).
  m.first_frame = (m.first_frame - 1) / factor + 1;
  return m;
}

MarkerTrajectories cropped(MarkerTrajectories m, Eigen::Index first, Eigen::Index count) {
  const Eigen::Index n = m.frames();
  if (first < 0 || count < 1 || first + count > n)
    throw InputError("frames " + std::to_string(m.first_frame + first) + "-" + std::to_string(m.first_frame + first + count - 1) +
                     " are not within the recording's frames " + std::to_string(m.first_frame) + "-" +
                     std::to_string(m.first_frame + n - 1));
  for (auto& P : m.positions_m) P = Eigen::MatrixX3d(P.middleRows(first, count));
  m.time_s = Eigen::VectorXd(m.time_s.segment(first, count));
  m.first_frame += static_cast<int>(first);
  return m;
}

int decimation_factor(double rate_hz, double target_hz) {
  if (!(rate_hz > 0) || !(target_hz > 0)) return 1;
  return std::max(1, static_cast<int>(std::lround(rate_hz / target_hz)));
}

double ForcePlate::width_m() const { return (corners_m[0] - corners_m[1]).norm(); }
double ForcePlate::length_m() const { return (corners_m[0] - corners_m[3]).norm(); }

}  // namespace kin2grf
