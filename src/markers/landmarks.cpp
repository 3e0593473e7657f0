#include "kin2grf/markers/landmarks.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>

#include "kin2grf/error.hpp"
#include "kin2grf/numeric.hpp"
#include "kin2grf/kinematics/filter.hpp"

namespace kin2grf {


namespace {

const char* kNames[kLandmarkCount] = {"shoulder", "hip",     "knee_r", "ankle_r", "heel_r", "mt_r",
                                      "hallux_r", "knee_l", "ankle_l", "heel_l",  "mt_l",   "hallux_l"};

/// How many labels NAME the file had (the readers renamed the k-th to NAME#k).
std::size_t occurrences(const MarkerTrajectories& m, const std::string& name) {
  std::size_t n = 0;
  for (const auto& other : m.names) {
    if (other == name) ++n;
    else if (other.size() > name.size() + 1 && other.compare(0, name.size() + 1, name + "#") == 0 &&
             other.find_first_not_of("0123456789", name.size() + 1) == std::string::npos)
      ++n;
  }
  return n;
}

Eigen::MatrixX3d marker(const MarkerTrajectories& m, const std::string& name, const std::string& path,
                        const std::string& what) {
  const int k = m.find(name);
  if (k < 0) throw InputError(path + ": marker '" + name + "' (needed for " + what + ") is not in the trial");
  // The readers rename the k-th label NAME to NAME#k: a landmark must not silently take one.
  if (const std::size_t n = occurrences(m, name); n > 1) {
    std::string which;
    for (std::size_t j = 1; j <= n; ++j) which += (j > 1 ? (j == n ? " or " : ", ") : "") + name + "#" + std::to_string(j);
    throw InputError(path + ": marker '" + name + "' (needed for " + what + ") appears " + std::to_string(n) +
                     " times in the file: name the one meant in a mapping file (--markers) as " + which + " (in the file's order)");
  }
  const Eigen::MatrixX3d& p = m.positions_m[static_cast<std::size_t>(k)];
  // compute_landmarks releases a marker after the last landmark that reads it: reading it later is
  // a bug of that bookkeeping, never silently an empty series.
  if (p.rows() != m.frames()) throw std::logic_error("marker '" + name + "' read after its samples were released (" + what + ")");
  return p;
}

Eigen::MatrixX3d mean_of(const MarkerTrajectories& m, const std::vector<std::string>& names, const std::string& path,
                         const std::string& what) {
  Eigen::MatrixX3d s = Eigen::MatrixX3d::Zero(m.frames(), 3);
  for (const auto& n : names) s += marker(m, n, path, what);  // NaN propagates: all must be present
  return s / static_cast<double>(names.size());
}

/// Pelvis frame per frame: origin mid-ASIS, x anterior, y superior, z right; PW, PD.
struct Pelvis {
  Eigen::MatrixX3d origin, x, y;
  Eigen::VectorXd width, depth;
};

Pelvis pelvis(const MarkerTrajectories& m, const std::map<std::string, std::string>& p, const std::string& path) {
  auto get = [&](const char* key) -> std::string {
    auto it = p.find(key);
    return it == p.end() ? "" : it->second;
  };
  const Eigen::MatrixX3d ra = marker(m, get("rasis"), path, "the pelvis");
  const Eigen::MatrixX3d la = marker(m, get("lasis"), path, "the pelvis");
  Eigen::MatrixX3d back;
  if (!get("sacrum").empty()) back = marker(m, get("sacrum"), path, "the pelvis");
  else back = 0.5 * (marker(m, get("rpsis"), path, "the pelvis") + marker(m, get("lpsis"), path, "the pelvis"));
  Pelvis pv;
  const Eigen::Index n = m.frames();
  pv.origin = 0.5 * (ra + la);
  pv.x.resize(n, 3);
  pv.y.resize(n, 3);
  pv.width.resize(n);
  pv.depth.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d z = (ra.row(i) - la.row(i)).transpose().normalized();
    const Eigen::Vector3d t = (pv.origin.row(i) - back.row(i)).transpose();
    const Eigen::Vector3d x = (t - t.dot(z) * z).normalized();
    pv.x.row(i) = x.transpose();
    pv.y.row(i) = z.cross(x).transpose();
    pv.width[i] = (ra.row(i) - la.row(i)).norm();
    pv.depth[i] = t.norm();
  }
  return pv;
}

/// Rigid frame of a cluster (>= 3 markers) at frame i: rotation and origin (centroid).
bool cluster_frame(const std::vector<Eigen::MatrixX3d>& c, Eigen::Index i, Eigen::Matrix3d& R, Eigen::Vector3d& o) {
  for (const auto& m : c)
    if (!m.row(i).allFinite()) return false;
  o.setZero();
  for (const auto& m : c) o += m.row(i).transpose();
  o /= static_cast<double>(c.size());
  const Eigen::Vector3d a = (c[0].row(i).transpose() - o).normalized();
  Eigen::Vector3d b = c[1].row(i).transpose() - o;
  Eigen::Vector3d z = a.cross(b);
  if (z.norm() < 1e-9) return false;
  z.normalize();
  R << a, z.cross(a), z;
  return true;
}

/// A cluster's reference shape: each marker's place in the cluster's own frame (cluster_frame),
/// the median over the frames that show the whole cluster; empty when none does.
std::vector<Eigen::Vector3d> cluster_shape(const std::vector<Eigen::MatrixX3d>& c) {
  std::vector<std::array<std::vector<double>, 3>> xyz(c.size());
  for (Eigen::Index i = 0; i < c.front().rows(); ++i) {
    Eigen::Matrix3d R;
    Eigen::Vector3d o;
    if (!cluster_frame(c, i, R, o)) continue;
    for (std::size_t k = 0; k < c.size(); ++k) {
      const Eigen::Vector3d l = R.transpose() * (c[k].row(i).transpose() - o);
      for (int a = 0; a < 3; ++a) xyz[k][static_cast<std::size_t>(a)].push_back(l[a]);
    }
  }
  std::vector<Eigen::Vector3d> shape;
  if (xyz.front()[0].empty()) return shape;
  for (auto& v : xyz) shape.emplace_back(median(v[0]), median(v[1]), median(v[2]));
  return shape;
}

/// The cluster's pose at frame i: the rigid motion (R, t) that best carries its reference shape
/// onto the markers, x_k ~ R s_k + t, by least squares (Soderkvist and Wedin 1993, J Biomech
/// 26:1473; the SVD of the markers' cross-covariance). Why not cluster_frame's axes: those come
/// from the first two markers alone, so a skin-mounted cluster's deformation moves a virtual point
/// by whichever markers a mapping lists first (Rajagopal's run: anterior force 9.7 % with RTH1,
/// RTH2, RTH3 and 15.3 % with RTH2, RTH3, RTH1); the fit weighs every marker alike, in any order.
bool fit_cluster(const std::vector<Eigen::MatrixX3d>& c, Eigen::Index i, const std::vector<Eigen::Vector3d>& shape, Eigen::Matrix3d& R,
                 Eigen::Vector3d& t) {
  if (shape.size() != c.size()) return false;
  Eigen::Vector3d xbar = Eigen::Vector3d::Zero(), sbar = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < c.size(); ++k) {
    if (!c[k].row(i).allFinite()) return false;
    xbar += c[k].row(i).transpose(), sbar += shape[k];
  }
  xbar /= static_cast<double>(c.size()), sbar /= static_cast<double>(c.size());
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (std::size_t k = 0; k < c.size(); ++k) H += (shape[k] - sbar) * (c[k].row(i).transpose() - xbar).transpose();
  // H = U S V^T and R = V diag(1, 1, det) U^T. From the two largest singular directions alone
  // (H H^T's closed-form eigenvectors, about ten times faster than an iterative SVD per frame):
  // v_k = H^T u_k / s_k, and the third pair is their cross products, which is the proper rotation
  // whether the cluster is planar (three markers: s_3 = 0) or not.
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
  es.computeDirect(H * H.transpose());
  const Eigen::Vector3d u1 = es.eigenvectors().col(2), u2 = es.eigenvectors().col(1);
  const double s1 = std::sqrt(std::max(es.eigenvalues()[2], 0.0)), s2 = std::sqrt(std::max(es.eigenvalues()[1], 0.0));
  if (!(s2 > 1e-9 * s1) || !(s1 > 0)) return false;  // the markers on one line: no orientation
  const Eigen::Vector3d v1 = (H.transpose() * u1 / s1).normalized();
  const Eigen::Vector3d v2 = (H.transpose() * u2 / s2 - v1.dot(H.transpose() * u2 / s2) * v1).normalized();
  R = v1 * u1.transpose() + v2 * u2.transpose() + v1.cross(v2) * u1.cross(u2).transpose();
  t = xbar - R * sbar;
  return true;
}

/// SCoRE (Ehrig et al. 2006, J Biomech 39:2798): the joint centre is the point fixed in both
/// segments, c1 in the proximal cluster's frame and c2 in the distal one's, by least squares over
/// every frame where both clusters are seen: sum_i |R1_i c1 + o1_i - R2_i c2 - o2_i|^2 -> min.
/// A hinge (the knee in gait) leaves the point's place along its axis undetermined: directions of
/// the normal equations with an eigenvalue below kScoreHingeRatio of the largest take the prior,
/// the midpoint of the two cluster centroids (on the limb, near the joint), so that the centre
/// stays on the limb instead of drifting along the axis. Returns the lab positions (N x 3, NaN
/// where either cluster is missing) and a message with the fit's residual; empty when the
/// clusters are never seen together in at least 20 frames.
constexpr double kScoreHingeRatio = 1e-2;

Eigen::MatrixX3d functional_joint_centre(const std::vector<Eigen::MatrixX3d>& prox, const std::vector<Eigen::MatrixX3d>& dist,
                                         std::string& message) {
  const Eigen::Index n = prox.front().rows();
  Eigen::Matrix<double, 6, 6> AtA = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> Atb = Eigen::Matrix<double, 6, 1>::Zero();
  Eigen::Matrix<double, 6, 1> prior = Eigen::Matrix<double, 6, 1>::Zero();
  // Both clusters' frames, once per frame seen (the fit and the positions below use them).
  struct Seen {
    Eigen::Index i;
    Eigen::Matrix3d R1, R2;
    Eigen::Vector3d o1, o2;
  };
  std::vector<Seen> frames;
  const std::vector<Eigen::Vector3d> shape1 = cluster_shape(prox), shape2 = cluster_shape(dist);
  for (Eigen::Index i = 0; i < n; ++i) {
    Seen f{i, {}, {}, {}, {}};
    if (!fit_cluster(prox, i, shape1, f.R1, f.o1) || !fit_cluster(dist, i, shape2, f.R2, f.o2)) continue;
    const auto &R1 = f.R1, &R2 = f.R2;
    const auto &o1 = f.o1, &o2 = f.o2;
    Eigen::Matrix<double, 3, 6> A;
    A << R1, -R2;
    const Eigen::Vector3d b = o2 - o1;
    AtA += A.transpose() * A;
    Atb += A.transpose() * b;
    const Eigen::Vector3d mid = 0.5 * (o1 + o2);
    prior.head<3>() += R1.transpose() * (mid - o1);
    prior.tail<3>() += R2.transpose() * (mid - o2);
    frames.push_back(f);
  }
  if (frames.size() < 20) {
    message = "the two segments' clusters are seen together in " + std::to_string(frames.size()) +
              " frames; a functional joint centre needs 20 or more";
    return {};
  }
  prior /= static_cast<double>(frames.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(AtA);
  const double top = es.eigenvalues().maxCoeff();
  Eigen::Matrix<double, 6, 1> x = prior;
  const Eigen::Matrix<double, 6, 1> g = Atb - AtA * prior;
  int dropped = 0;
  for (int k = 0; k < 6; ++k) {
    const double lambda = es.eigenvalues()[k];
    if (lambda > kScoreHingeRatio * top) x += es.eigenvectors().col(k) * (es.eigenvectors().col(k).dot(g) / lambda);
    else ++dropped;
  }
  Eigen::MatrixX3d P = Eigen::MatrixX3d::Constant(n, 3, kNaN);
  double sq = 0;
  for (const Seen& f : frames) {
    const Eigen::Vector3d p1 = f.R1 * x.head<3>() + f.o1, p2 = f.R2 * x.tail<3>() + f.o2;
    sq += (p1 - p2).squaredNorm();
    P.row(f.i) = (0.5 * (p1 + p2)).transpose();
  }
  char b[200];
  std::snprintf(b, sizeof b, "functional joint centre (SCoRE) from %zu frames, the two segments' points %.1f mm apart (RMS)%s",
                frames.size(), 1000 * std::sqrt(sq / static_cast<double>(frames.size())),
                dropped ? "; a hinge: its place along the axis from the limb's midline" : "");
  message = b;
  return P;
}

}  // namespace

const char* landmark_name(int id) { return kNames[id]; }

const char* upper_body_name(int id) {
  static const char* const names[kUpperBodyCount] = {"shoulder_r", "elbow_r", "wrist_r", "shoulder_l", "elbow_l", "wrist_l", "head"};
  return names[id];
}

namespace {
/// The mean of every marker at frame i, or NaN.
Eigen::Vector3d marker_centroid(const MarkerTrajectories& m, Eigen::Index i) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  int count = 0;
  for (const auto& q : m.positions_m)
    if (q.rows() == m.frames() && q.row(i).allFinite()) c += q.row(i).transpose(), ++count;
  return count ? Eigen::Vector3d(c / count) : Eigen::Vector3d::Constant(kNaN);
}

/// The body's horizontal medial-lateral axis: across the direction the markers' centroid
/// travels over the trial. None when it travels less than 0.3 m (a treadmill, a trial in place).
std::optional<Eigen::Vector3d> lateral_axis(const MarkerTrajectories& m) {
  Eigen::Vector3d first = Eigen::Vector3d::Constant(kNaN), last = first;
  for (Eigen::Index i = 0; i < m.frames() && !first.allFinite(); ++i) first = marker_centroid(m, i);
  for (Eigen::Index i = m.frames() - 1; i >= 0 && !last.allFinite(); --i) last = marker_centroid(m, i);
  const int up = static_cast<int>(m.up_axis);
  Eigen::Vector3d travel = last - first;
  travel[up] = 0;
  if (!travel.allFinite() || travel.norm() < 0.3) return std::nullopt;
  Eigen::Vector3d vertical = Eigen::Vector3d::Zero();
  vertical[up] = 1;
  return vertical.cross(travel).normalized();
}

/// Medians over (up to 200 of) the frames where both markers exist: |a's offset from the
/// centroid along `lateral`|, |b's|, and the share of their separation that lies along `lateral`.
std::array<double, 3> medial_lateral_measure(const MarkerTrajectories& m, const Eigen::MatrixX3d& a, const Eigen::MatrixX3d& b,
                                             const Eigen::Vector3d& lateral) {
  std::array<std::vector<double>, 3> v;
  for (Eigen::Index i = 0; i < m.frames() && v[0].size() < 200; ++i) {
    const Eigen::Vector3d c = marker_centroid(m, i);
    if (!a.row(i).allFinite() || !b.row(i).allFinite() || !c.allFinite()) continue;
    const Eigen::Vector3d ab = (b.row(i) - a.row(i)).transpose();
    v[0].push_back(std::abs((a.row(i).transpose() - c).dot(lateral)));
    v[1].push_back(std::abs((b.row(i).transpose() - c).dot(lateral)));
    v[2].push_back(ab.norm() > 0 ? std::abs(ab.dot(lateral)) / ab.norm() : 0.0);
  }
  std::array<double, 3> out{};
  for (int k = 0; k < 3; ++k) {
    if (v[k].empty()) return {0, 0, 0};
    std::nth_element(v[k].begin(), v[k].begin() + static_cast<std::ptrdiff_t>(v[k].size() / 2), v[k].end());
    out[k] = v[k][v[k].size() / 2];
  }
  return out;
}
}  // namespace

std::optional<MarkerSet> choose_repeated_markers(const MarkerSet& set, const MarkerTrajectories& m, std::vector<std::string>& messages) {
  std::optional<MarkerSet> out;
  bool looked = false;  // the lateral axis is found once, when first needed
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  bool travels = false;
  for (const auto& name : set.motion_markers()) {
    if (occurrences(m, name) != 2 || m.find(name) < 0 || m.find(name + "#2") < 0) continue;
    // The presets' markers of a joint's medial-lateral pair (knee, ankle) are the lateral ones.
    // Two markers under one label are such a pair when what separates them lies across the
    // direction of travel (a medial and a lateral marker are at one fore-aft place and height).
    // Then the one farther out from the body's centroid is taken; otherwise (a heel and a toe
    // under one label, or a trial that does not travel) nothing is guessed.
    if (!looked) {
      const auto found = lateral_axis(m);
      looked = true, travels = found.has_value();
      if (found) axis = *found;
    }
    if (!travels) continue;
    const auto& p1 = m.positions_m[static_cast<std::size_t>(m.find(name))];
    const auto& p2 = m.positions_m[static_cast<std::size_t>(m.find(name + "#2"))];
    const auto [d1, d2, across] = medial_lateral_measure(m, p1, p2, axis);
    if (across < 0.8) continue;
    const std::string taken = d2 > d1 ? name + "#2" : name + "#1";
    if (!out) out = set;
    for (auto& r : out->rules) {
      for (auto* list : {&r.markers, &r.cluster})
        for (auto& s : *list)
          if (s == name) s = taken;
      for (auto& [key, s] : r.pelvis)
        if (s == name) s = taken;
    }
    char b[64];
    std::snprintf(b, sizeof b, "%.0f mm", 1e3 * std::abs(d2 - d1));
    messages.push_back("marker '" + name + "' appears twice, a medial-lateral pair; the " + set.name + " preset takes " + taken +
                       ", the lateral one (" + b + " farther from the body's centre line); a mapping file (--markers) can name " +
                       "the other (" + name + "#1, " + name + "#2 in the file's order)");
  }
  return out;
}

const char* rule_kind_name(RuleKind kind) {
  switch (kind) {
    case RuleKind::Marker: return "marker";
    case RuleKind::Mean: return "mean";
    case RuleKind::Harrington: return "harrington";
    case RuleKind::Static: return "static";
    case RuleKind::Functional: return "functional";
    case RuleKind::PelvisUp: return "pelvis_up";
    case RuleKind::VirtualHallux: return "virtual_hallux";
  }
  return "?";
}

std::optional<MarkerSet> without_trunk_markers(const MarkerSet& set, std::string& why) {
  const LandmarkRule& shoulder = set.rules[kShoulder];
  if (shoulder.kind == RuleKind::PelvisUp) {
    MarkerSet out = set;
    out.upper_body = {};  // no arm or head markers either
    return out;
  }
  const LandmarkRule& hip = set.rules[kHip];
  const bool from_pelvis = hip.kind == RuleKind::Harrington && !hip.pelvis.empty();
  const bool from_markers = (hip.kind == RuleKind::Mean || hip.kind == RuleKind::Marker) && !hip.markers.empty();
  if (!from_pelvis && !from_markers) {
    why = set.name + ": the hip centre is made by a '" + rule_kind_name(hip.kind) + "' rule, above which kin2grf puts no model torso";
    return std::nullopt;
  }
  MarkerSet out = set;
  out.name = set.name + " without trunk markers";
  LandmarkRule& r = out.rules[kShoulder];
  r = LandmarkRule{};
  r.kind = RuleKind::PelvisUp;
  r.value = 0.5;  // the presets' model torso (plug-in-gait-lower and the others)
  r.sway_gain = kTrunkSwayGain;
  if (from_pelvis) r.pelvis = hip.pelvis;
  else r.markers = hip.markers;  // upright above their mean
  out.upper_body = {};
  return out;
}

std::vector<std::string> MarkerSet::motion_markers() const {
  std::vector<std::string> out;
  for (const auto& r : rules) {
    if (r.kind == RuleKind::Marker || r.kind == RuleKind::Mean || r.kind == RuleKind::PelvisUp) out.insert(out.end(), r.markers.begin(), r.markers.end());
    if (r.kind == RuleKind::Static) out.insert(out.end(), r.cluster.begin(), r.cluster.end());
    if (r.kind == RuleKind::Functional) {
      out.insert(out.end(), r.cluster.begin(), r.cluster.end());
      out.insert(out.end(), r.markers.begin(), r.markers.end());
    }
    for (const auto& [k, v] : r.pelvis) out.push_back(v);
  }
  return out;
}

namespace {
constexpr double kTrunkTrendCutoffHz = 0.5;
}  // namespace


namespace {

/// The samples of marker k that no body can produce (see without_marker_outliers), in frame order.
std::vector<Eigen::Index> outlier_samples(const MarkerTrajectories& m, std::size_t k) {
  const Eigen::Index n = m.frames();
  const double limit = kMaxMarkerSpeedMps / std::max(m.rate_hz, 1e-9) + 0.02;
  const double dt = 1.0 / std::max(m.rate_hz, 1e-9);
  const double spike = std::max(0.02, 0.5 * kMaxMarkerAccelMps2 * dt * dt);
  const auto& P = m.positions_m[k];
  // Usable samples: finite and inside any capture volume.
  std::vector<bool> ok(static_cast<std::size_t>(n));
  std::vector<Eigen::Index> where;
  for (Eigen::Index i = 0; i < n; ++i) {
    ok[static_cast<std::size_t>(i)] = P.row(i).allFinite() && P.row(i).cwiseAbs().maxCoeff() <= kMaxLabCoordinateM;
    if (P.row(i).allFinite() && !ok[static_cast<std::size_t>(i)]) where.push_back(i);
  }
  for (Eigen::Index i = 1; i + 1 < n; ++i) {
    if (!ok[static_cast<std::size_t>(i - 1)] || !ok[static_cast<std::size_t>(i)] || !ok[static_cast<std::size_t>(i + 1)]) continue;
    const bool jump = (P.row(i) - P.row(i - 1)).norm() > limit && (P.row(i + 1) - P.row(i)).norm() > limit &&
                      (P.row(i + 1) - P.row(i - 1)).norm() < limit;
    // A sample's excursion from its neighbours' midpoint is a dt^2 / 2: past kMaxMarkerAccelMps2
    // (and 2 cm, above any marker noise) it is no motion: two markers swapped for a frame (a heel
    // jumping 17 cm and back at 100 Hz, 17 m/s, under the speed limit).
    // A spike, not a step: the sample leaves farther than its neighbours are apart (a virtual
    // marker's discontinuity is a step, not a swap: it is left).
    const double excursion = (P.row(i) - 0.5 * (P.row(i - 1) + P.row(i + 1))).norm();
    if (jump || (excursion > spike && excursion > (P.row(i + 1) - P.row(i - 1)).norm())) {
      ok[static_cast<std::size_t>(i)] = false;
      where.push_back(i);
    }
  }
  std::sort(where.begin(), where.end());
  return where;
}

std::string outlier_message(const MarkerTrajectories& m, std::size_t k, const std::vector<Eigen::Index>& where) {
  std::string frames;
  for (std::size_t w = 0; w < where.size() && w < 5; ++w) frames += (w ? ", " : "") + std::to_string(m.first_frame + where[w]);
  if (where.size() > 5) frames += ", ...";
  return m.names[k] + ": " + std::to_string(where.size()) + " sample(s) no body can produce (frame " + frames +
         ": outside the lab, a one-frame jump faster than " + std::to_string(static_cast<int>(kMaxMarkerSpeedMps)) +
         " m/s, or a one-frame excursion of more than " + std::to_string(static_cast<int>(kMaxMarkerAccelMps2 / 9.81)) +
         " g, such as two markers swapped) treated as gaps";
}

bool checked(const MarkerTrajectories& m, std::size_t k, const std::vector<std::string>& only) {
  return only.empty() || std::find(only.begin(), only.end(), m.names[k]) != only.end();
}

}  // namespace

std::optional<MarkerTrajectories> without_marker_outliers(const MarkerTrajectories& m, const std::vector<std::string>& only,
                                                          std::vector<std::string>& messages) {
  std::optional<MarkerTrajectories> out;  // copied only when there is something to remove
  for (std::size_t k = 0; k < m.positions_m.size(); ++k) {
    if (!checked(m, k, only)) continue;
    const std::vector<Eigen::Index> where = outlier_samples(m, k);
    if (where.empty()) continue;
    if (!out) out = m;
    for (const Eigen::Index i : where) out->positions_m[k].row(i).setConstant(kNaN);
    messages.push_back(outlier_message(m, k, where));
  }
  return out;
}

std::size_t remove_marker_outliers(MarkerTrajectories& m, const std::vector<std::string>& only, std::vector<std::string>& messages) {
  std::size_t removed = 0;
  for (std::size_t k = 0; k < m.positions_m.size(); ++k) {
    if (!checked(m, k, only)) continue;
    // Each marker's outliers are found on its own samples before any of them is changed, so the
    // result is without_marker_outliers' (markers do not read each other).
    const std::vector<Eigen::Index> where = outlier_samples(m, k);
    if (where.empty()) continue;
    for (const Eigen::Index i : where) m.positions_m[k].row(i).setConstant(kNaN);
    messages.push_back(outlier_message(m, k, where));
    removed += where.size();
  }
  return removed;
}

namespace {
/// A gap [first, end) of marker `marker`, seen at first - 1 and at end.
struct InteriorGap {
  std::size_t marker;
  Eigen::Index first, end;
};

std::vector<InteriorGap> long_interior_gaps(const MarkerTrajectories& m, const std::vector<std::string>& only, int longer_than) {
  std::vector<InteriorGap> out;
  for (std::size_t k = 0; k < m.positions_m.size(); ++k) {
    if (!checked(m, k, only)) continue;
    const Eigen::MatrixX3d& P = m.positions_m[k];
    const Eigen::Index n = P.rows();
    Eigen::Index i = 0;
    while (i < n && !P.row(i).allFinite()) ++i;  // the trial's start: not inside
    while (i < n) {
      if (P.row(i).allFinite()) {
        ++i;
        continue;
      }
      Eigen::Index j = i;
      while (j < n && !P.row(j).allFinite()) ++j;
      if (j < n && j - i > longer_than) out.push_back({k, i, j});
      i = j;
    }
  }
  return out;
}

/// SD (m) of the distance between two markers over the frames both are seen; infinity when
/// those are fewer than kMinRigidFrames.
double distance_sd(const Eigen::MatrixX3d& a, const Eigen::MatrixX3d& b) {
  double s = 0, s2 = 0;
  Eigen::Index count = 0;
  for (Eigen::Index i = 0; i < a.rows(); ++i) {
    if (!a.row(i).allFinite() || !b.row(i).allFinite()) continue;
    const double d = (a.row(i) - b.row(i)).norm();
    s += d, s2 += d * d, ++count;
  }
  if (count < kMinRigidFrames) return std::numeric_limits<double>::infinity();
  const double mean = s / static_cast<double>(count);
  return std::sqrt(std::max(s2 / static_cast<double>(count) - mean * mean, 0.0));
}

/// Each height of the triangle p0 p1 p2 (twice its area over each side) at least `span`.
bool spans_triangle(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, const Eigen::Vector3d& p2, double span) {
  const double twice_area = (p1 - p0).cross(p2 - p0).norm();
  const double longest = std::max({(p1 - p0).norm(), (p2 - p0).norm(), (p2 - p1).norm()});
  return longest > 0 && twice_area / longest >= span;
}

/// distance_sd of markers i and j of `m`, each pair computed once per call of
/// fill_marker_gaps_rigidly (a long trial's many gaps of one marker ask for the same pairs; the
/// markers do not change until every fill is made).
class DistanceSds {
 public:
  explicit DistanceSds(const MarkerTrajectories& m) : m_(m) {}
  double operator()(std::size_t i, std::size_t j) {
    const auto key = std::minmax(i, j);
    const auto [it, added] = sd_.try_emplace(key, 0.0);
    if (added) it->second = distance_sd(m_.positions_m[key.first], m_.positions_m[key.second]);
    return it->second;
  }

 private:
  const MarkerTrajectories& m_;
  std::map<std::pair<std::size_t, std::size_t>, double> sd_;
};

/// One gap's fill (its frames, N x 3) from its partners, or nothing when they are not found.
std::optional<Eigen::MatrixX3d> rigid_fill(const MarkerTrajectories& m, const InteriorGap& g, DistanceSds& sds, std::string& message) {
  const Eigen::Index before = g.first - 1, len = g.end - before + 1;  // the gap and a seen frame at each end
  const Eigen::MatrixX3d& T = m.positions_m[g.marker];
  std::vector<std::pair<double, std::size_t>> candidates;
  for (std::size_t k = 0; k < m.positions_m.size(); ++k) {
    const Eigen::MatrixX3d& P = m.positions_m[k];
    // An unlabelled trajectory (Vicon's "*12") is not known to be one marker throughout.
    if (k == g.marker || P.rows() != T.rows() || m.names[k].starts_with('*')) continue;
    bool seen = true;
    for (Eigen::Index i = before; i <= g.end && seen; ++i) seen = P.row(i).allFinite();
    if (!seen) continue;
    const double sd = sds(g.marker, k);
    if (sd <= kMaxRigidPartnerSdM) candidates.emplace_back(sd, k);
  }
  std::sort(candidates.begin(), candidates.end());
  // Of the candidates nearest rigid with it, the triple that moves rigidly with each other too and
  // spans a triangle at the frame before the gap, the most rigid such (least largest SD of its six
  // distances). A marker on a joint's axis (a knee marker) keeps its distance to both segments'
  // markers: its partners must be one body, not two.
  const std::size_t nc = std::min<std::size_t>(candidates.size(), kMaxRigidCandidates);
  const auto pair_sd = [&](std::size_t a, std::size_t b) { return sds(candidates[a].second, candidates[b].second); };
  const auto at = [&](std::size_t c) { return m.positions_m[candidates[c].second].row(before).transpose().eval(); };
  std::array<std::size_t, 3> pick{};
  double least = std::numeric_limits<double>::infinity();  // the triple's largest SD of its six distances
  for (std::size_t a = 0; a < nc; ++a)
    for (std::size_t b = a + 1; b < nc; ++b)
      for (std::size_t c = b + 1; c < nc; ++c) {
        // candidates[c] is the least rigid with the marker of the three (sorted by that SD).
        const double worst = std::max({candidates[c].first, pair_sd(a, b), pair_sd(a, c), pair_sd(b, c)});
        if (worst <= kMaxRigidPartnerSdM && worst < least && spans_triangle(at(a), at(b), at(c), kMinRigidPartnerSpanM))
          least = worst, pick = {a, b, c};
      }
  if (!std::isfinite(least)) return std::nullopt;
  std::vector<Eigen::MatrixX3d> cluster;
  for (const std::size_t c : pick) cluster.push_back(m.positions_m[candidates[c].second].middleRows(before, len));
  std::vector<Eigen::Vector3d> from_before, from_after;
  for (const auto& P : cluster) from_before.push_back(P.row(0).transpose()), from_after.push_back(P.row(len - 1).transpose());
  const Eigen::Vector3d x_before = T.row(before).transpose(), x_after = T.row(g.end).transpose();
  Eigen::MatrixX3d fill(len - 2, 3);
  for (Eigen::Index i = 1; i + 1 < len; ++i) {
    Eigen::Matrix3d R1, R2;
    Eigen::Vector3d t1, t2;
    if (!fit_cluster(cluster, i, from_before, R1, t1) || !fit_cluster(cluster, i, from_after, R2, t2)) return std::nullopt;
    const double w = static_cast<double>(i) / static_cast<double>(len - 1);
    fill.row(i - 1) = ((1.0 - w) * (R1 * x_before + t1) + w * (R2 * x_after + t2)).transpose();
  }
  char b[160];
  std::snprintf(b, sizeof b, "%.1f-%.1f mm", 1000 * candidates[pick[0]].first, 1000 * candidates[pick[2]].first);
  message = m.names[g.marker] + ": filled a gap of " + std::to_string(g.end - g.first) + " frames at frames " +
            std::to_string(m.first_frame + g.first) + "-" + std::to_string(m.first_frame + g.end - 1) +
            " from the markers that move rigidly with it (" + m.names[candidates[pick[0]].second] + ", " +
            m.names[candidates[pick[1]].second] + ", " + m.names[candidates[pick[2]].second] + ": their distances to it vary by " + b +
            " SD over the trial)";
  return fill;
}
}  // namespace

bool has_long_marker_gap(const MarkerTrajectories& m, const std::vector<std::string>& only, int longer_than_frames) {
  return !long_interior_gaps(m, only, longer_than_frames).empty();
}

std::vector<RigidGapFill> rigid_gap_fills(const MarkerTrajectories& m, const std::vector<std::string>& only, int longer_than_frames,
                                          std::vector<std::string>& messages) {
  // Every fill is made from the markers as given, then written: a marker filled here is no
  // partner for another's gap, and the order of the markers does not matter.
  std::vector<RigidGapFill> fills;
  DistanceSds sds(m);
  for (const InteriorGap& g : long_interior_gaps(m, only, longer_than_frames)) {
    std::string message;
    std::optional<Eigen::MatrixX3d> fill = rigid_fill(m, g, sds, message);
    if (!fill) continue;
    messages.push_back(std::move(message));
    fills.push_back({g.marker, g.first, std::move(*fill)});
  }
  return fills;
}

void write_gap_fills(MarkerTrajectories& m, const std::vector<RigidGapFill>& fills) {
  for (const RigidGapFill& f : fills) m.positions_m[f.marker].middleRows(f.first, f.positions_m.rows()) = f.positions_m;
}

std::size_t fill_marker_gaps_rigidly(MarkerTrajectories& m, const std::vector<std::string>& only, int longer_than_frames,
                                     std::vector<std::string>& messages) {
  const std::vector<RigidGapFill> fills = rigid_gap_fills(m, only, longer_than_frames, messages);
  write_gap_fills(m, fills);
  return fills.size();
}

namespace {
/// Per marker of the trial, the last landmark whose rule reads it (-1: none): after it, the
/// marker's samples can be let go.
std::vector<int> last_landmark_use(const MarkerSet& set, const MarkerTrajectories& m) {
  std::vector<int> last_use(m.names.size(), -1);
  for (int id = 0; id < kLandmarkCount; ++id) {
    const LandmarkRule& r = set.rules[static_cast<std::size_t>(id)];
    auto use = [&](const std::string& name) {
      if (const int k = m.find(name); k >= 0) last_use[static_cast<std::size_t>(k)] = id;
    };
    for (const auto& name : r.markers) use(name);
    for (const auto& name : r.cluster) use(name);
    for (const auto& [key, name] : r.pelvis) use(name);
  }
  return last_use;
}

/// A virtual point calibrated on the static trial (RuleKind::Static): its place in the cluster's
/// frame (the static cluster's shape fitted to each frame, fit_cluster), the median over the
/// static frames, then carried by the cluster, fitted the same way, through the trial.
Eigen::MatrixX3d static_landmark(const MarkerSet& set, const LandmarkRule& r, int id, const MarkerTrajectories& m,
                                 const MarkerTrajectories* st, const std::string& path) {
  const std::string what = std::string("landmark ") + kNames[id];
  if (!st) {
    throw InputError(path + ": landmark " + kNames[id] + " of marker set '" + set.name +
                     "' is a virtual point calibrated on a static trial: give --static STATIC (it needs markers " +
                     r.markers[0] + (r.markers.size() > 1 ? ", " + r.markers[1] : "") +
                     "); without a static trial, --markers labels maps the set from the trial's own labels (a joint centre "
                     "from its markers, or the functional centre of the clusters on either side)");
  }
  std::vector<Eigen::MatrixX3d> cs, cm;
  for (const auto& c : r.cluster) {
    cs.push_back(marker(*st, c, path + " (static)", what));
    cm.push_back(marker(m, c, path, what));
  }
  const Eigen::MatrixX3d sp = mean_of(*st, r.markers, path + " (static)", what);
  const std::vector<Eigen::Vector3d> shape = cluster_shape(cs);  // the cluster as the static trial shows it
  std::vector<double> lx, ly, lz;
  for (Eigen::Index i = 0; i < st->frames(); ++i) {
    Eigen::Matrix3d R;
    Eigen::Vector3d o;
    if (!sp.row(i).allFinite() || !fit_cluster(cs, i, shape, R, o)) continue;
    const Eigen::Vector3d l = R.transpose() * (sp.row(i).transpose() - o);
    lx.push_back(l.x()); ly.push_back(l.y()); lz.push_back(l.z());
  }
  if (lx.empty()) throw InputError(path + ": the static trial never shows landmark " + kNames[id] + "'s markers and cluster together");
  const Eigen::Vector3d local(median(lx), median(ly), median(lz));
  Eigen::MatrixX3d P = Eigen::MatrixX3d::Constant(m.frames(), 3, kNaN);
  for (Eigen::Index i = 0; i < m.frames(); ++i) {
    Eigen::Matrix3d R;
    Eigen::Vector3d o;
    if (fit_cluster(cm, i, shape, R, o)) P.row(i) = (o + R * local).transpose();
  }
  return P;
}
}  // namespace

Landmarks3D compute_landmarks(const MarkerSet& set, const MarkerTrajectories& m, const MarkerTrajectories* st,
                              const LandmarkOptions& options, const std::string& path, MarkerTrajectories* release) {
  Landmarks3D out;
  const Eigen::Index n = m.frames();
  const std::vector<int> last_use = last_landmark_use(set, m);
  auto release_after = [&](int id) {
    if (!release) return;
    for (std::size_t k = 0; k < last_use.size(); ++k)
      if (last_use[k] == id) release->positions_m[k].resize(0, 3);
  };
  // The upper body's landmarks first: their markers may be released by the loop below.
  if (options.upper_body)
    for (int id = 0; id < kUpperBodyCount; ++id) {
      const auto& names = set.upper_body[static_cast<std::size_t>(id)];
      if (names.empty()) continue;
      // An arm or the head is optional: a marker not in the file (or under a repeated label)
      // lumps its part into the torso rather than refusing the trial.
      std::string absent;
      for (const auto& name : names)
        if (m.find(name) < 0 || occurrences(m, name) > 1) absent += (absent.empty() ? "" : ", ") + name;
      if (!absent.empty()) {
        out.messages.push_back(std::string(upper_body_name(id)) + ": marker " + absent + " not in the file (or repeated): its part is lumped into the torso");
        continue;
      }
      out.upper_body[static_cast<std::size_t>(id)] = mean_of(m, names, path, std::string("landmark ") + upper_body_name(id));
    }
  release_after(-1);
  for (int id = 0; id < kLandmarkCount; ++id) {
    const LandmarkRule& r = set.rules[static_cast<std::size_t>(id)];
    const std::string what = std::string("landmark ") + kNames[id];
    Eigen::MatrixX3d P = Eigen::MatrixX3d::Constant(n, 3, kNaN);
    if (r.kind == RuleKind::Marker || r.kind == RuleKind::Mean) {
      P = mean_of(m, r.markers, path, what);
      if (id == kHip && r.kind == RuleKind::Mean && r.markers.size() == 2) {  // the two hip centres
        const Eigen::MatrixX3d a = marker(m, r.markers[0], path, what), b = marker(m, r.markers[1], path, what);
        std::vector<double> half;
        for (Eigen::Index i = 0; i < n; ++i)
          if (a.row(i).allFinite() && b.row(i).allFinite()) half.push_back(0.5 * (a.row(i) - b.row(i)).norm());
        if (!half.empty()) out.hip_half_width_m = median(half);
      }
    } else if (r.kind == RuleKind::Harrington) {
      const Pelvis pv = pelvis(m, r.pelvis, path);
      std::vector<double> half;
      for (Eigen::Index i = 0; i < n; ++i) {
        const double ax = -0.24 * pv.depth[i] - 0.0099, ay = -0.30 * pv.width[i] - 0.0109;
        P.row(i) = pv.origin.row(i) + ax * pv.x.row(i) + ay * pv.y.row(i);
        if (std::isfinite(pv.width[i])) half.push_back(0.33 * pv.width[i] + 0.0073);  // Harrington's lateral term
      }
      if (id == kHip && !half.empty()) out.hip_half_width_m = median(half);
    } else if (r.kind == RuleKind::PelvisUp && r.pelvis.empty()) {
      // The model torso above a hip centre made of markers (without_trunk_markers on a set whose
      // hip rule is a mean): upright above their mean.
      Eigen::Vector3d up = Eigen::Vector3d::Zero();
      up[static_cast<int>(options.up_axis.value_or(m.up_axis))] = 1.0;
      P = mean_of(m, r.markers, path, what);
      P.rowwise() += (r.value * up).transpose();
      out.messages.push_back("shoulder: the torso is an upright segment of " + std::to_string(r.value).substr(0, 4) +
                             " m above the hip centre, its top swaying by " + std::to_string(r.sway_gain).substr(0, 4) +
                             " x the hip's fore-aft oscillation (trunk markers not used)");
    } else if (r.kind == RuleKind::PelvisUp) {
      const Pelvis pv = pelvis(m, r.pelvis, path);
      // Without upper-body markers the torso is an upright segment above the hip centre: the
      // pelvis's tilt (10-15 deg forward) and its oscillations are not the trunk's, and a torso
      // that follows them adds spurious moments of the heavy HAT segment (measured:
      // docs/METHOD-NOTES.md). Its fore-aft sway (sway_gain) is applied in sagittal_landmarks,
      // where gaps are filled and the progression axis is known.
      Eigen::Vector3d up = Eigen::Vector3d::Zero();
      up[static_cast<int>(options.up_axis.value_or(m.up_axis))] = 1.0;
      for (Eigen::Index i = 0; i < n; ++i) {
        const double ax = -0.24 * pv.depth[i] - 0.0099, ay = -0.30 * pv.width[i] - 0.0109;
        const Eigen::Vector3d base = pv.origin.row(i).transpose() + ax * pv.x.row(i).transpose() + ay * pv.y.row(i).transpose();
        P.row(i) = (base + r.value * up).transpose();
      }
      out.messages.push_back("shoulder: no upper-body markers; the torso is an upright segment of " +
                             std::to_string(r.value).substr(0, 4) + " m above the hip centre, its top swaying by " +
                             std::to_string(r.sway_gain).substr(0, 4) + " x the hip's fore-aft oscillation, an approximation");
    } else if (r.kind == RuleKind::Functional) {
      std::vector<Eigen::MatrixX3d> prox, dist;
      for (const auto& c : r.cluster) prox.push_back(marker(m, c, path, what));
      for (const auto& c : r.markers) dist.push_back(marker(m, c, path, what));
      std::string msg;
      P = functional_joint_centre(prox, dist, msg);
      if (P.rows() == 0) throw InputError(path + ": landmark " + kNames[id] + ": " + msg);
      out.messages.push_back(std::string(kNames[id]) + ": " + msg);
    } else if (r.kind == RuleKind::Static) {
      P = static_landmark(set, r, id, m, st, path);
    }
    // A landmark with no sample in any frame (its markers empty in the trial or in the frames cut
    // from it) is named here; the steps after would fail on it with less to say (a walker who
    // does not travel, no run of defined frames).
    if (r.kind != RuleKind::VirtualHallux && n > 0 && !(P.array().isFinite().rowwise().all()).any()) {
      std::vector<std::string> names = r.markers;
      names.insert(names.end(), r.cluster.begin(), r.cluster.end());
      for (const auto& [role, name] : r.pelvis) names.push_back(name);
      std::string list;
      for (const auto& name : names) list += (list.empty() ? "" : ", ") + name;
      throw InputError(path + ": landmark " + kNames[id] + " is undefined in every one of the trial's frames " + std::to_string(m.first_frame) +
                       "-" + std::to_string(m.first_frame + n - 1) +
                       (list.empty() ? std::string() : ": its markers " + list + " never all hold a sample there") +
                       " (`kin2grf info` lists each marker's missing frames; --frames cuts the trial)");
    }
    out.p[static_cast<std::size_t>(id)] = std::move(P);  // virtual_hallux stays NaN: built in the sagittal step
    release_after(id);
  }
  return out;
}

namespace {

/// Turning walks: the body's heading is the direction its feet point (the 0.5 Hz zero-lag trend,
/// below the step frequency, of the sum of both feet's horizontal heel -> MT directions: the
/// feet's toe-out cancels between the sides, and unlike the pelvis's path it also holds while the
/// subject stands or side-steps). When that heading turns by more than kTurnLimitRad and the
/// pelvis travels kMinTravelM or more (not a treadmill, not on the spot), the frame follows it
/// (SagittalFrame); otherwise the fixed frame stays.
/// Both are measured over the body's seen span alone (heading_span): the longest run of frames
/// where the hip and both feet's heel and MT landmarks are defined, gaps of up to max_gap frames
/// bridged, as the processed window bridges them. Outside it a foot's markers come and go as the
/// subject leaves the capture volume: one foot's direction alone, held over hundreds of frames and
/// spread by the 0.5 Hz trend, turned two straight overground runs (UWA's, a 0.37 s window) by
/// 50 degrees within their one stance. Outside the span the heading holds its ends' value.
constexpr double kTurnLimitRad = 30 * M_PI / 180;
constexpr double kMinTravelM = 2.0;  ///< the slow pelvis path's length below which nothing turns

/// [first, end) of the longest run of frames where the hip and the four foot landmarks (heel, MT)
/// are defined, runs of up to `max_gap` undefined frames inside it bridged; {0, 0} when none.
std::pair<Eigen::Index, Eigen::Index> heading_span(const Landmarks3D& lm, int max_gap) {
  const Eigen::Index n = lm.p[kHip].rows();
  const auto seen = [&](Eigen::Index i) {
    if (!lm.p[kHip].row(i).allFinite()) return false;
    for (int side = 0; side < 2; ++side)
      for (int part : {kHeel, kMt})
        if (lm.p[landmark(side, static_cast<LegLandmark>(part))].rows() != n ||
            !lm.p[landmark(side, static_cast<LegLandmark>(part))].row(i).allFinite())
          return false;
    return true;
  };
  std::pair<Eigen::Index, Eigen::Index> best{0, 0};
  Eigen::Index i = 0;
  while (i < n) {
    if (!seen(i)) { ++i; continue; }
    Eigen::Index last = i, j = i + 1;  // the run's last seen frame; j scans on across short gaps
    while (j < n && j - last <= max_gap + 1) {
      if (seen(j)) last = j;
      ++j;
    }
    if (last + 1 - i > best.second - best.first) best = {i, last + 1};
    i = last + 1;
  }
  return best;
}

/// `span`: heading_span's.
void follow_heading(SagittalFrame& f, const Landmarks3D& lm, double rate_hz, const std::pair<Eigen::Index, Eigen::Index>& span) {
  const auto& hip_all = lm.p[kHip];
  const Eigen::Index n_all = hip_all.rows();
  // Not a structured binding: the lambdas below read s0, which C++20 lets clang refuse.
  const Eigen::Index s0 = span.first, s1 = span.second;
  if (n_all < 10 || rate_hz <= 0 || s1 - s0 < 10) return;
  // The span's own landmarks (views, not copies: a long trial's memory); the heading is made over
  // them and held beyond them.
  const Eigen::Index n = s1 - s0;
  const auto hip = hip_all.middleRows(s0, n);
  // Horizontal basis e1, e2 (e1 x e2 = up): the two lab axes other than the up axis.
  Eigen::Index ua = 0;
  f.up.cwiseAbs().maxCoeff(&ua);
  const Eigen::Vector3d e1 = Eigen::Vector3d::Unit((ua + 1) % 3), e2 = Eigen::Vector3d::Unit((ua + 2) % 3);
  auto hold = [&](const std::function<bool(Eigen::Index, Eigen::RowVector2d&)>& at) {
    // Per frame a 2D value; undefined frames hold the nearest defined one before (or after).
    Eigen::MatrixXd out(n, 2);
    Eigen::RowVector2d last(kNaN, kNaN), v;
    for (Eigen::Index i = 0; i < n; ++i) {
      if (at(i, v)) last = v;
      out.row(i) = last;
    }
    Eigen::Index first = 0;
    while (first < n && !out.row(first).allFinite()) ++first;
    if (first == n) return Eigen::MatrixXd();
    for (Eigen::Index i = 0; i < first; ++i) out.row(i) = out.row(first);
    return out;
  };
  const Eigen::MatrixXd h = hold([&](Eigen::Index i, Eigen::RowVector2d& v) {
    if (!hip.row(i).allFinite()) return false;
    v = {hip.row(i).dot(e1.transpose()), hip.row(i).dot(e2.transpose())};
    return true;
  });
  const Eigen::MatrixXd feet = hold([&](Eigen::Index i, Eigen::RowVector2d& v) {
    v.setZero();
    for (int side = 0; side < 2; ++side) {
      const Eigen::RowVector3d d = lm.p[landmark(side, kMt)].row(s0 + i) - lm.p[landmark(side, kHeel)].row(s0 + i);
      const Eigen::RowVector2d dh(d.dot(e1.transpose()), d.dot(e2.transpose()));
      if (dh.allFinite()) v += dh;  // not normalised: a foot pitched steeply (swing) weighs little
    }
    return v.norm() > 0.05;
  });
  if (h.rows() == 0 || feet.rows() == 0) return;
  const Eigen::MatrixXd c = butterworth_filtfilt(h, rate_hz, 0.5);
  const Eigen::MatrixXd d = butterworth_filtfilt(feet, rate_hz, 0.5);
  std::vector<double> psi(static_cast<std::size_t>(n));
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (Eigen::Index i = 0; i < n; ++i) {
    double a = std::atan2(d(i, 1), d(i, 0));
    if (i > 0) a = psi[static_cast<std::size_t>(i - 1)] + std::remainder(a - psi[static_cast<std::size_t>(i - 1)], 2 * M_PI);
    psi[static_cast<std::size_t>(i)] = a;
    lo = std::min(lo, a), hi = std::max(hi, a);
  }
  if (!(hi - lo > kTurnLimitRad)) return;  // a straight walk: the fixed frame
  double travel = 0;  // on a treadmill or on the spot the body does not travel: nothing to follow
  for (Eigen::Index i = 1; i < n; ++i) travel += (c.row(i) - c.row(i - 1)).norm();
  if (travel < kMinTravelM) return;
  f.heading.resize(n_all, 3);
  f.x_offset_m.resize(n_all);
  double arc = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double a = psi[static_cast<std::size_t>(i)];
    const Eigen::Vector3d hd = std::cos(a) * e1 + std::sin(a) * e2;
    f.heading.row(s0 + i) = hd.transpose();
    const Eigen::Vector3d ci = c(i, 0) * e1 + c(i, 1) * e2;
    arc = i == 0 ? ci.dot(hd) : arc + (c.row(i) - c.row(i - 1)).dot(Eigen::RowVector2d(std::cos(a), std::sin(a)));
    f.x_offset_m[s0 + i] = arc - ci.dot(hd);  // so that the path point's x is its arc length
  }
  // Beyond the span the frame holds still (a fixed frame there, continuous with the span's ends).
  for (Eigen::Index i = 0; i < s0; ++i) f.heading.row(i) = f.heading.row(s0), f.x_offset_m[i] = f.x_offset_m[s0];
  for (Eigen::Index i = s1; i < n_all; ++i) f.heading.row(i) = f.heading.row(s1 - 1), f.x_offset_m[i] = f.x_offset_m[s1 - 1];
  f.treadmill = false;
  const Eigen::Vector3d mean = f.heading.colwise().mean().transpose();
  f.forward = mean.norm() > 1e-6 ? Eigen::Vector3d(mean.normalized()) : Eigen::Vector3d(f.heading.row(0).transpose());
  f.lateral = f.forward.cross(f.up);
  char b[160];
  std::snprintf(b, sizeof b, "the heading follows the feet's direction (it turns by %.0f degrees)", (hi - lo) * 180 / M_PI);
  f.how = b;
}

}  // namespace

SagittalFrame detect_sagittal_frame(const Landmarks3D& lm, const MarkerTrajectories& m, const LandmarkOptions& o) {
  SagittalFrame f;
  const Axis up = o.up_axis.value_or(m.up_axis);
  f.up = Eigen::Vector3d::Unit(static_cast<int>(up));
  auto horizontal = [&](Eigen::Vector3d v) { return Eigen::Vector3d(v - v.dot(f.up) * f.up); };
  // Progression from the hip's horizontal travel between its first and last defined frames: the
  // body travels (overground) or not (a treadmill, on the spot). Its direction is the travel over
  // the span where the body is seen (heading_span), where the processed window lies, when the hip
  // travels kMinSpanTravelM there: a walker who turns away after the feet are lost would otherwise
  // tilt the window's frame by the turn (Estimate.APelvisSeenTurningAfterTheFeetAreLostDoesNotTiltTheFrame).
  constexpr double kMinSpanTravelM = 0.3;
  const auto& hip = lm.p[kHip];
  const auto [s0, s1] = heading_span(lm, o.max_gap_frames);
  Eigen::Index a = -1, b = -1;
  for (Eigen::Index i = 0; i < hip.rows(); ++i)
    if (hip.row(i).allFinite()) { if (a < 0) a = i; b = i; }
  Eigen::Vector3d dir = Eigen::Vector3d::Zero();
  if (a >= 0 && b > a) {
    const Eigen::Vector3d d = horizontal((hip.row(b) - hip.row(a)).transpose());
    const double dur = m.time_s[b] - m.time_s[a];
    if (d.norm() > 0.5 && d.norm() / dur > 0.2) {
      dir = d.normalized();
      f.how = "pelvis travel " + std::to_string(d.norm()) + " m";
      if (s1 - s0 >= 10 && hip.row(s0).allFinite() && hip.row(s1 - 1).allFinite()) {
        const Eigen::Vector3d ds = horizontal((hip.row(s1 - 1) - hip.row(s0)).transpose());
        if (ds.norm() >= kMinSpanTravelM) {
          dir = ds.normalized();
          f.how = "pelvis travel " + std::to_string(ds.norm()) + " m";
        }
      }
    }
  }
  if (dir.norm() == 0) {
    // Treadmill or stationary: the feet's heel-to-MT direction.
    Eigen::Vector3d s = Eigen::Vector3d::Zero();
    for (int side = 0; side < 2; ++side)
      for (Eigen::Index i = 0; i < hip.rows(); ++i) {
        const Eigen::Vector3d d = (lm.p[landmark(side, kMt)].row(i) - lm.p[landmark(side, kHeel)].row(i)).transpose();
        if (d.allFinite()) s += horizontal(d);
      }
    if (s.norm() == 0) throw InputError("cannot find the direction of progression: the pelvis does not travel and the feet give no direction (check the up axis, --up-axis, and the heel and MT markers)");
    dir = s.normalized();
    f.treadmill = true;
    f.how = "heel-to-toe direction (treadmill or stationary trial)";
  }
  if (o.progression_axis) {
    Eigen::Vector3d ax = Eigen::Vector3d::Unit(static_cast<int>(*o.progression_axis));
    dir = ax * (ax.dot(dir) >= 0 ? 1.0 : -1.0);
    f.how += ", axis forced";
  } else {
    // Snap to the nearest lab axis when within 10 degrees: labs walk along an axis.
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d ax = Eigen::Vector3d::Unit(k);
      if (std::abs(ax.dot(dir)) > std::cos(10 * M_PI / 180)) dir = ax * (ax.dot(dir) > 0 ? 1.0 : -1.0);
    }
  }
  if (o.progression_sign) dir *= (*o.progression_sign > 0 ? 1.0 : -1.0) * (dir.sum() >= 0 ? 1.0 : -1.0);
  f.forward = dir;
  f.lateral = f.forward.cross(f.up);
  if (!o.progression_axis) follow_heading(f, lm, m.rate_hz, {s0, s1});
  return f;
}

namespace {

/// A landmark's gaps of up to `max_gap` frames with defined frames on both sides, filled by a
/// cubic Hermite curve (end slopes from the neighbours); returns the gaps it filled and, in
/// `unfilled`, the others, as [first, end) frame ranges.
using FrameRange = std::pair<Eigen::Index, Eigen::Index>;
std::vector<FrameRange> fill_gaps(Eigen::MatrixX3d& P, int max_gap, std::vector<FrameRange>& unfilled) {
  const Eigen::Index n = P.rows();
  std::vector<FrameRange> filled;
  Eigen::Index i = 0;
  while (i < n) {
    if (P.row(i).allFinite()) { ++i; continue; }
    Eigen::Index j = i;
    while (j < n && !P.row(j).allFinite()) ++j;
    const Eigen::Index len = j - i;
    if (i > 0 && j < n && len <= max_gap) {
      const Eigen::Index i0 = i - 1, i1 = j;
      const double span = static_cast<double>(i1 - i0);
      const Eigen::RowVector3d p1 = P.row(i0), p2 = P.row(i1);
      const Eigen::RowVector3d d1 = (i0 > 0 && P.row(i0 - 1).allFinite()) ? Eigen::RowVector3d((p2 - P.row(i0 - 1)) / (span + 1))
                                                                       : Eigen::RowVector3d((p2 - p1) / span);
      const Eigen::RowVector3d d2 = (i1 + 1 < n && P.row(i1 + 1).allFinite()) ? Eigen::RowVector3d((P.row(i1 + 1) - p1) / (span + 1))
                                                                          : Eigen::RowVector3d((p2 - p1) / span);
      for (Eigen::Index k = i; k < j; ++k) {
        const double t = static_cast<double>(k - i0) / span, t2 = t * t, t3 = t2 * t;
        P.row(k) = (2 * t3 - 3 * t2 + 1) * p1 + (t3 - 2 * t2 + t) * span * d1 + (-2 * t3 + 3 * t2) * p2 + (t3 - t2) * span * d2;
      }
      filled.emplace_back(i, j);
    } else {
      unfilled.emplace_back(i, j);
    }
    i = j;
  }
  return filled;
}

/// Short gaps filled in place (fill_gaps), each named in `messages`; `ok` false on the frames of
/// the gaps left.
void fill_short_gaps(std::array<Eigen::MatrixX3d, kLandmarkCount>& p, const MarkerSet& set, const MarkerTrajectories& m,
                     const LandmarkOptions& o, std::vector<bool>& ok, std::vector<std::string>& messages) {
  for (int id = 0; id < kLandmarkCount; ++id) {
    if (set.rules[static_cast<std::size_t>(id)].kind == RuleKind::VirtualHallux) continue;
    std::vector<FrameRange> unfilled;
    for (const auto& [i, j] : fill_gaps(p[static_cast<std::size_t>(id)], o.max_gap_frames, unfilled))
      messages.push_back(std::string(kNames[id]) + ": filled a gap of " + std::to_string(j - i) + " frames at frames " +
                         std::to_string(m.first_frame + i) + "-" + std::to_string(m.first_frame + j - 1));
    for (const auto& [i, j] : unfilled)
      for (Eigen::Index k = i; k < j; ++k) ok[static_cast<std::size_t>(k)] = false;
  }
}

/// The upper-body landmarks over the window [a, a + len): short gaps filled; one still undefined
/// somewhere in it is dropped (its part lumped into the HAT), with a message naming the frames.
std::array<Eigen::MatrixX3d, kUpperBodyCount> upper_body_window(std::array<Eigen::MatrixX3d, kUpperBodyCount>& u, Eigen::Index a,
                                                                Eigen::Index len, const MarkerTrajectories& m, const LandmarkOptions& o,
                                                                std::vector<std::string>& messages) {
  std::array<Eigen::MatrixX3d, kUpperBodyCount> out;
  for (int id = 0; id < kUpperBodyCount; ++id) {
    auto& P = u[static_cast<std::size_t>(id)];
    if (P.rows() < a + len) continue;
    Eigen::MatrixX3d W = P.middleRows(a, len);
    P.resize(0, 3);
    std::vector<FrameRange> unfilled;
    const auto filled = fill_gaps(W, o.max_gap_frames, unfilled);
    if (!unfilled.empty()) {
      Eigen::Index missing = 0;
      for (const auto& [i, j] : unfilled) missing += j - i;
      messages.push_back(std::string(upper_body_name(id)) + ": undefined on " + std::to_string(missing) + " frames of the window (from frame " +
                         std::to_string(m.first_frame + a + unfilled.front().first) + "): its part is lumped into the torso");
      continue;
    }
    for (const auto& [i, j] : filled)
      messages.push_back(std::string(upper_body_name(id)) + ": filled a gap of " + std::to_string(j - i) + " frames at frames " +
                         std::to_string(m.first_frame + a + i) + "-" + std::to_string(m.first_frame + a + j - 1));
    out[static_cast<std::size_t>(id)] = std::move(W);
  }
  return out;
}

/// The longest run of frames where every landmark is defined (`ok`): its first frame and length;
/// InputError naming the landmarks missing when it is under 10 frames.
std::pair<Eigen::Index, Eigen::Index> longest_defined_window(const std::vector<bool>& ok, const std::array<Eigen::MatrixX3d, kLandmarkCount>& p,
                                                             const MarkerSet& set, const std::string& path) {
  const auto n = static_cast<Eigen::Index>(ok.size());
  Eigen::Index best_a = 0, best_len = 0;
  for (Eigen::Index i = 0; i < n;) {
    if (!ok[static_cast<std::size_t>(i)]) { ++i; continue; }
    Eigen::Index j = i;
    while (j < n && ok[static_cast<std::size_t>(j)]) ++j;
    if (j - i > best_len) { best_len = j - i; best_a = i; }
    i = j;
  }
  if (best_len < 10) {
    std::string which;
    for (int id = 0; id < kLandmarkCount; ++id) {
      if (set.rules[static_cast<std::size_t>(id)].kind == RuleKind::VirtualHallux) continue;
      Eigen::Index bad = 0;
      for (Eigen::Index i = 0; i < n; ++i) bad += !p[static_cast<std::size_t>(id)].row(i).allFinite();
      if (bad) which += std::string(" ") + kNames[id] + " (" + std::to_string(bad) + " frames)";
    }
    throw InputError(path + ": no run of 10 frames where every landmark is defined; missing:" + which);
  }
  return {best_a, best_len};
}

/// Virtual toes: straight along the foot (ankle A -> MT head M) for `share` of its length, held
/// at the MT head's foot-flat height (they do not go through the floor).
void place_virtual_toes(const Eigen::MatrixX2d& A, const Eigen::MatrixX2d& M, Eigen::MatrixX2d& T, double share) {
  const Eigen::Index len = M.rows();
  std::vector<double> hm;
  for (Eigen::Index i = 0; i < len; ++i) hm.push_back(M(i, 1));
  std::sort(hm.begin(), hm.end());
  const double flat_h = hm[hm.size() / 10];
  std::vector<double> flat_ang;
  for (Eigen::Index i = 0; i < len; ++i)
    if (M(i, 1) < flat_h + 0.01) flat_ang.push_back(std::atan2(M(i, 1) - A(i, 1), M(i, 0) - A(i, 0)));
  const double th_flat = median(flat_ang);
  for (Eigen::Index i = 0; i < len; ++i) {
    const double L = share * (M.row(i) - A.row(i)).norm();
    const double th_f = std::atan2(M(i, 1) - A(i, 1), M(i, 0) - A(i, 0));
    const double limit = -std::asin(std::clamp((M(i, 1) - flat_h) / L, -1.0, 1.0));
    const double th_t = std::max(th_f - th_flat, limit);
    T(i, 0) = M(i, 0) + L * std::cos(th_t);
    T(i, 1) = M(i, 1) + L * std::sin(th_t);
  }
}

/// One foot's toes: virtual ones where the set has no hallux marker, or where its toe marker
/// stands implausibly near the MT head (a toe segment under kMinToeShare of the ankle-MT length;
/// the development trials' toe markers give 0.25-0.86, a held-out overground run's marker mapped
/// as the toe about 0.08), which cannot carry the COP's roll to the toe tip.
/// Toes grown from a 5th-metatarsal marker start behind the 2nd head: they are
/// kLateralMtToeExtraShare longer.
void check_toes(SagittalLandmarks& s, const MarkerSet& set, int side, std::vector<std::string>& messages) {
  const LandmarkRule& r = set.rules[static_cast<std::size_t>(landmark(side, kHallux))];
  const auto& A = s.p[landmark(side, kAnkle)];
  const auto& M = s.p[landmark(side, kMt)];
  auto& T = s.p[landmark(side, kHallux)];
  const bool lateral_mt = set.rules[static_cast<std::size_t>(landmark(side, kMt))].lateral_surface;
  const double extra = lateral_mt ? kLateralMtToeExtraShare : 0.0;
  const std::string from_mt5 = lateral_mt ? " (from a 5th-metatarsal marker, which lies behind the 2nd head: " +
                                                std::to_string(extra).substr(0, 4) + " longer)"
                                          : "";
  if (r.kind == RuleKind::VirtualHallux) {
    place_virtual_toes(A, M, T, r.value + extra);
    messages.push_back(std::string("hallux_") + side_letter(side) + ": no hallux marker; virtual toes of " +
                       std::to_string(r.value + extra).substr(0, 4) + " x ankle-MT length" + from_mt5);
    return;
  }
  std::vector<double> toe, foot;
  for (Eigen::Index i = 0; i < M.rows(); ++i) toe.push_back((T.row(i) - M.row(i)).norm()), foot.push_back((M.row(i) - A.row(i)).norm());
  const double toe_m = median(toe), foot_m = median(foot);
  if (toe_m < kMinToeShare * foot_m) {
    place_virtual_toes(A, M, T, kVirtualToeShare + extra);
    char b[300];
    std::snprintf(b, sizeof b,
                  "hallux_%s: the toe marker stands a median %.0f mm ahead of the MT head, under %.2f x the ankle-MT length "
                  "(%.0f mm): too near for a toe; virtual toes of %.2f x ankle-MT length instead",
                  side_letter(side), 1000 * toe_m, kMinToeShare, 1000 * foot_m, kVirtualToeShare + extra);
    messages.emplace_back(std::string(b) + from_mt5);
  }
}

}  // namespace

SagittalWindow sagittal_landmarks(Landmarks3D lm3, const MarkerSet& set, const SagittalFrame& fr,
                                  const MarkerTrajectories& m, const LandmarkOptions& o, const std::string& path, bool keep_lateral,
                                  const std::vector<std::array<double, kLandmarkCount>>& lab_sums) {
  SagittalWindow w;
  w.hip_half_width_m = lm3.hip_half_width_m;
  const Eigen::Index n = m.frames();
  std::array<Eigen::MatrixX3d, kLandmarkCount>& p = lm3.p;
  std::vector<bool> ok(static_cast<std::size_t>(n), true);
  fill_short_gaps(p, set, m, o, ok, w.messages);
  const auto [best_a, best_len] = longest_defined_window(ok, p, set, path);
  if (best_len < n) {
    w.messages.push_back("processing frames " + std::to_string(m.first_frame + best_a) + "-" +
                         std::to_string(m.first_frame + best_a + best_len - 1) + " of " + std::to_string(m.first_frame) + "-" +
                         std::to_string(m.first_frame + n - 1) + " (landmarks missing outside, gaps longer than " +
                         std::to_string(o.max_gap_frames) + " frames end the window)");
  }
  w.first = best_a;
  SagittalLandmarks& s = w.landmarks;
  s.rate_hz = m.rate_hz;
  s.time_s = m.time_s.segment(best_a, best_len);
  // Each 3D landmark is released once projected (the heels and MT heads once the feet's lateral
  // places are taken too): a long trial's memory.
  const auto lateral_needs = [](int id) {
    for (int side = 0; side < 2; ++side)
      if (id == landmark(side, kHeel) || id == landmark(side, kMt)) return true;
    return false;
  };
  if (keep_lateral || !lab_sums.empty()) {
    w.lateral_axis.resize(best_len, 3);
    for (Eigen::Index i = 0; i < best_len; ++i) w.lateral_axis.row(i) = fr.lateral_at(best_a + i).transpose();
    w.upper_body_lab_m = upper_body_window(lm3.upper_body, best_a, best_len, m, o, w.messages);
  }
  w.lab_sums_m.assign(lab_sums.size(), Eigen::MatrixX3d::Zero(lab_sums.empty() ? 0 : best_len, 3));
  for (int id = 0; id < kLandmarkCount; ++id) {
    // The weighted sums, as each landmark passes (its lab positions are let go below); a virtual
    // hallux has no 3D place and counts at its MT head (kept until the feet's loop), as in lab_m.
    for (std::size_t k = 0; k < lab_sums.size(); ++k) {
      const double weight = lab_sums[k][static_cast<std::size_t>(id)];
      if (weight == 0) continue;
      const auto& P = p[static_cast<std::size_t>(id)];
      const bool toes = id == landmark(kRight, kHallux) || id == landmark(kLeft, kHallux);
      const auto& M = p[static_cast<std::size_t>(toes ? id - 1 : id)];
      for (Eigen::Index i = 0; i < best_len; ++i) {
        const bool own = P.rows() >= best_a + best_len && P.row(best_a + i).allFinite();
        w.lab_sums_m[k].row(i) += weight * (own ? P.row(best_a + i) : M.row(best_a + i));
      }
    }
    s.p[static_cast<std::size_t>(id)].resize(best_len, 2);
    if (keep_lateral && p[static_cast<std::size_t>(id)].rows() >= best_a + best_len)
      w.lab_m[static_cast<std::size_t>(id)] = p[static_cast<std::size_t>(id)].middleRows(best_a, best_len);
    for (Eigen::Index i = 0; i < best_len; ++i)
      s.p[static_cast<std::size_t>(id)].row(i) =
          fr.to_sagittal(p[static_cast<std::size_t>(id)].row(best_a + i).transpose(), best_a + i).transpose();
    if (!lateral_needs(id)) p[static_cast<std::size_t>(id)].resize(0, 3);
  }
  // A virtual hallux has no 3D place: the toes take the MT head's.
  if (keep_lateral)
    for (int side = 0; side < 2; ++side) {
      auto& H = w.lab_m[static_cast<std::size_t>(landmark(side, kHallux))];
      const auto& M = w.lab_m[static_cast<std::size_t>(landmark(side, kMt))];
      if (H.rows() != best_len) H = M;
      for (Eigen::Index i = 0; i < best_len; ++i)
        if (!H.row(i).allFinite()) H.row(i) = M.row(i);
    }
  for (int side = 0; side < 2; ++side) {
    w.foot_lateral_m[side].resize(best_len);
    // The COP's lateral line (ModelKind::ThreeD): from the heel to the forefoot's midline; a
    // 5th-metatarsal marker ("surface": "lateral") is kLateralMtToMidline of the heel-MT length
    // lateral of it.
    const bool lateral_mt = set.rules[static_cast<std::size_t>(landmark(side, kMt))].lateral_surface;
    s.mt_head_ahead_share[static_cast<std::size_t>(side)] = lateral_mt ? kLateralMtToeExtraShare : 0.0;
    const double to_medial = side == kRight ? -1.0 : 1.0;
    if (keep_lateral) w.foot_line[side].resize(best_len, 4);
    std::vector<double> shift_m;
    for (Eigen::Index i = 0; i < best_len; ++i) {
      const Eigen::RowVector3d heel = p[landmark(side, kHeel)].row(best_a + i), mt = p[landmark(side, kMt)].row(best_a + i);
      const Eigen::RowVector3d lat = fr.lateral_at(best_a + i).transpose();
      w.foot_lateral_m[side][i] = 0.5 * (heel + mt).dot(lat);
      if (!keep_lateral) continue;
      const double shift = lateral_mt ? to_medial * kLateralMtToMidline * (mt - heel).norm() : 0.0;
      if (lateral_mt) shift_m.push_back(std::abs(shift));
      w.foot_line[side].row(i) << fr.to_sagittal(heel.transpose(), best_a + i).x(), heel.dot(lat),
          fr.to_sagittal(mt.transpose(), best_a + i).x(), mt.dot(lat) + shift;
    }
    if (lateral_mt && keep_lateral) {
      char b[240];
      std::snprintf(b, sizeof b, "mt_%s: a 5th-metatarsal marker; the COP's lateral line ends a median %.0f mm medial of it (%.2f x the "
                    "heel-MT length, the foot's midline)", side_letter(side), 1000 * median(shift_m), kLateralMtToMidline);
      w.messages.emplace_back(b);
    }
    p[landmark(side, kHeel)].resize(0, 3);
    p[landmark(side, kMt)].resize(0, 3);
    check_toes(s, set, side, w.messages);
  }
  // Torso without trunk markers: the shoulder point sways fore-aft by sway_gain times the hip
  // centre's oscillation instead of rigidly with the hip (kTrunkSwayGain, measured).
  const LandmarkRule& sr = set.rules[kShoulder];
  if (sr.kind == RuleKind::PelvisUp) sway_model_torso(s, 1.0, sr.sway_gain);
  return w;
}

void sway_model_torso(SagittalLandmarks& s, double from_gain, double to_gain) {
  if (to_gain == from_gain || s.frames() == 0) return;
  const Eigen::VectorXd hx = s.p[kHip].col(0);
  const Eigen::VectorXd trend = butterworth_filtfilt(hx, s.rate_hz, kTrunkTrendCutoffHz);
  s.p[kShoulder].col(0) += (to_gain - from_gain) * (hx - trend);
}

}  // namespace kin2grf
