#include "kin2grf/validation/validate.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>
#include <tuple>

#include "kin2grf/kinematics/filter.hpp"
#include "kin2grf/numeric.hpp"
#include "kin2grf/output/results.hpp"

namespace kin2grf {
namespace {




std::string frames_text(const EstimateResult& e, Eigen::Index a, Eigen::Index b) {
  return "frames " + std::to_string(e.first_frame_number + a) + "-" + std::to_string(e.first_frame_number + b);
}

double mean_finite(const Eigen::VectorXd& v) {
  double s = 0;
  int k = 0;
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (std::isfinite(v[i])) s += v[i], ++k;
  return k ? s / k : kNaN;
}

/// Sole point s (A, B, C) of foot f at frame i stands still on the floor: within
/// ground_contact_height_m of it and slower than still_speed_mps relative to it (or the belt).
bool sole_point_planted(const EstimateResult& e, int f, int s, Eigen::Index i, const ValidationOptions& o) {
  const auto& sm = e.feet[static_cast<std::size_t>(f)].sole_m;
  const Eigen::Index n = sm.rows();
  if (n < 2 || sm(i, 2 * s + 1) - e.ground_level_m() > o.ground_contact_height_m) return false;
  const Eigen::Index i0 = std::max<Eigen::Index>(i - 1, 0), i1 = std::min<Eigen::Index>(i + 1, n - 1);
  const double vx = (sm(i1, 2 * s) - sm(i0, 2 * s)) * e.landmarks.rate_hz / static_cast<double>(i1 - i0);
  return std::abs(vx - e.calibration.belt_velocity_mps) <= o.still_speed_mps;
}

}  // namespace

bool MeasuredPlate::covers(double x, double lateral, double margin_along_m) const {
  const Eigen::Vector2d d = Eigen::Vector2d(x, lateral) - centre_m;
  const Eigen::Vector2d across(-along.y(), along.x());
  return std::abs(d.dot(along)) <= half_along_m + margin_along_m && std::abs(d.dot(across)) <= half_across_m;
}

namespace {
/// A plate's surface height, and with geometry its centre and extent, in the sagittal frame
/// (with turns, the frame of the middle of its loaded samples; without geometry, the median
/// height of its loaded COPs).
void plate_place(const ForcePlate& p, const ForcePlateRecording& rec, const SagittalFrame& fr, const Eigen::VectorXd& t,
                 double cop_threshold_N, Eigen::Index first_index, MeasuredPlate& m) {
  const Eigen::Index n = t.size();
  const double dt = n > 1 ? (t[n - 1] - t[0]) / static_cast<double>(n - 1) : 1.0;
  const Eigen::Index ns = rec.samples();
  if (p.has_geometry) {
    // The plate's geometry in the frame of the middle of its loaded samples (turning walks).
    Eigen::Index g = first_index + n / 2;
    if (fr.turning()) {
      std::vector<double> loaded;
      for (Eigen::Index k = 0; k < ns; ++k)
        if (p.force_N.row(k).dot(fr.up.transpose()) > cop_threshold_N) loaded.push_back(rec.time_s[k]);
      if (!loaded.empty() && n > 1) {
        const double tm = loaded[loaded.size() / 2];
        g = first_index + std::clamp<Eigen::Index>(static_cast<Eigen::Index>(std::lround((tm - t[0]) / dt)), 0, n - 1);
      }
    }
    const Eigen::Vector3d fw = fr.forward_at(g), lt = fr.lateral_at(g);
    const double off = fr.x_offset_at(g);
    m.surface_y_m = p.centre_m.dot(fr.up);
    m.centre_m = {p.centre_m.dot(fw) + off, p.centre_m.dot(lt)};
    // The rectangle: its edges c1 - c2 and c1 - c4 in (x, lateral), the one nearer the progression
    // taken as its length.
    const auto flat = [&](const Eigen::Vector3d& v) { return Eigen::Vector2d(v.dot(fw), v.dot(lt)); };
    Eigen::Vector2d e1 = flat(p.corners_m[0] - p.corners_m[1]), e2 = flat(p.corners_m[0] - p.corners_m[3]);
    if (std::abs(e2.normalized().x()) > std::abs(e1.normalized().x())) std::swap(e1, e2);
    if (e1.norm() > 0 && e2.norm() > 0) {
      m.along = e1.normalized();
      m.half_along_m = 0.5 * e1.norm();
      m.half_across_m = 0.5 * e2.norm();
    }
  } else {
    std::vector<double> h;
    for (Eigen::Index k = 0; k < ns; ++k)
      if (p.cop_m.row(k).allFinite() && std::abs(p.force_N.row(k).dot(fr.up.transpose())) > cop_threshold_N)
        h.push_back(p.cop_m.row(k).dot(fr.up.transpose()));
    m.surface_y_m = h.empty() ? 0.0 : median(h);
  }
}

/// One plate sample: its force and 3D moment about the lab origin, both in the lab frame.
void plate_sample(const ForcePlate& p, Eigen::Index k, Eigen::Vector3d& F, Eigen::Vector3d& M, bool& has_cop) {
  F = p.force_N.row(k).transpose();
  has_cop = p.cop_m.row(k).allFinite();
  if (p.has_geometry && p.moment_centre_Nm.row(k).allFinite()) {
    M = p.moment_centre_Nm.row(k).transpose() + p.centre_m.cross(F);
  } else if (has_cop) {
    Eigen::Vector3d T = p.free_moment_Nm.row(k).transpose();
    if (!T.allFinite()) T.setZero();
    M = Eigen::Vector3d(p.cop_m.row(k).transpose()).cross(F) + T;
  } else {
    M.setZero();  // below the COP threshold: a few newtons at most
  }
}
}  // namespace

std::vector<MeasuredPlate> resample_plates(const ForcePlateRecording& rec, const SagittalFrame& fr,
                                           const Eigen::VectorXd& t, double cop_threshold_N, Eigen::Index first_index) {
  std::vector<MeasuredPlate> out;
  const Eigen::Index n = t.size();
  const double dt = n > 1 ? (t[n - 1] - t[0]) / static_cast<double>(n - 1) : 1.0;
  const Eigen::Index ns = rec.samples();
  for (const ForcePlate& p : rec.plates) {
    MeasuredPlate m;
    m.name = p.name;
    m.side_hint = p.side_hint;
    m.has_geometry = p.has_geometry;
    m.force_N = Eigen::MatrixX2d::Constant(n, 2, kNaN);
    m.force_lateral_N = Eigen::VectorXd::Constant(n, kNaN);
    m.moment_origin_Nm = Eigen::VectorXd::Constant(n, kNaN);
    m.cop_x_m = Eigen::VectorXd::Constant(n, kNaN);
    m.cop_lateral_m = Eigen::VectorXd::Constant(n, kNaN);
    m.force_lab_N = Eigen::MatrixX3d::Constant(n, 3, kNaN);
    m.moment_origin_lab_Nm = Eigen::MatrixX3d::Constant(n, 3, kNaN);
    plate_place(p, rec, fr, t, cop_threshold_N, first_index, m);
    for (Eigen::Index i = 0; i < n && ns > 0; ++i) {
      const double lo = (t[i] - 0.5 * dt - rec.time_s[0]) * rec.rate_hz;
      const double hi = (t[i] + 0.5 * dt - rec.time_s[0]) * rec.rate_hz;
      Eigen::Index k0 = static_cast<Eigen::Index>(std::ceil(lo - 1e-6));
      Eigen::Index k1 = static_cast<Eigen::Index>(std::ceil(hi - 1e-6)) - 1;
      k0 = std::max<Eigen::Index>(k0, 0);
      k1 = std::min<Eigen::Index>(k1, ns - 1);
      if (k1 < k0) continue;
      Eigen::Vector3d Fs = Eigen::Vector3d::Zero(), Ms = Eigen::Vector3d::Zero();
      double lat = 0, wlat = 0;
      int cnt = 0;
      for (Eigen::Index k = k0; k <= k1; ++k) {
        Eigen::Vector3d F, M;
        bool has_cop = false;
        plate_sample(p, k, F, M, has_cop);
        if (!F.allFinite() || !M.allFinite()) continue;
        Fs += F, Ms += M, ++cnt;
        if (has_cop) {
          const double w = std::abs(F.dot(fr.up));
          lat += w * p.cop_m.row(k).dot(fr.lateral_at(first_index + i).transpose()), wlat += w;
        }
      }
      if (cnt == 0) continue;  // no valid sample in this frame: stays NaN
      Fs /= cnt, Ms /= cnt;
      m.force_lab_N.row(i) = Fs.transpose();
      m.moment_origin_lab_Nm.row(i) = Ms.transpose();
      const double fx = Fs.dot(fr.forward_at(first_index + i)), fy = Fs.dot(fr.up);
      m.force_N(i, 0) = fx;
      m.force_N(i, 1) = fy;
      m.force_lateral_N[i] = Fs.dot(fr.lateral_at(first_index + i));
      // x = p . f + offset: the offset's share of x F_y (zero without turns).
      m.moment_origin_Nm[i] = Ms.dot(fr.lateral_at(first_index + i)) + fr.x_offset_at(first_index + i) * fy;
      if (fy > cop_threshold_N) {
        m.cop_x_m[i] = (m.moment_origin_Nm[i] + m.surface_y_m * fx) / fy;  // x F_y - y F_x = m_O
        if (wlat > 0) m.cop_lateral_m[i] = lat / wlat;
      }
    }
    out.push_back(std::move(m));
  }
  return out;
}

namespace {

/// A plate's stance and the foot it is assigned to.
struct Candidate {
  int plate;
  IndexRun run;
  int foot;
  double distance;
  bool kept;
  bool cut = false;  ///< cut by the processed window's ends: ValidationResult::cut_stances, no total
};

/// How far x lies outside the span between a and b (0 inside): a COP beyond a foot's heel-toe span.
double beyond_span(double x, double a, double b) { return std::max({0.0, std::min(a, b) - x, x - std::max(a, b)}); }

/// The median horizontal distance (m) over a plate stance from the plate's COP to foot f's
/// heel-hallux segment (lateral place from the landmarks); infinity without a loaded COP.
double cop_to_foot_m(const EstimateResult& e, const MeasuredPlate& mp, const IndexRun& run, int f) {
  std::vector<double> d;
  const int heel = f ? kHeelL : kHeelR, hal = f ? kHalluxL : kHalluxR;
  for (Eigen::Index i = run.first; i <= run.last; ++i) {
    if (!std::isfinite(mp.cop_x_m[i])) continue;
    const double xa = e.landmarks.p[heel](i, 0), xb = e.landmarks.p[hal](i, 0);
    const double dx = beyond_span(mp.cop_x_m[i], xa, xb);
    const double dl = std::isfinite(mp.cop_lateral_m[i]) ? mp.cop_lateral_m[i] - e.foot_lateral_m[f][i] : 0.0;
    d.push_back(std::hypot(dx, dl));
  }
  return d.empty() ? std::numeric_limits<double>::infinity() : median(d);
}

/// The frames of a plate stance in which foot f has a sole point at ground level over the plate
/// (`outside` false: the other foot, counted only when still, since a swinging foot's toes skim
/// the plate) or outside its edges by more than the margin (`outside` true: this foot).
int sole_frames(const EstimateResult& e, const MeasuredPlate& mp, const IndexRun& run, int f, bool outside,
                const ValidationOptions& o) {
  const double ground = e.ground_level_m();
  int k = 0;
  for (Eigen::Index i = run.first; i <= run.last; ++i) {
    const double lat = e.foot_lateral_m[f][i];
    bool hit = false;
    for (int s = 0; s < 3; ++s) {
      const double x = e.feet[static_cast<std::size_t>(f)].sole_m(i, 2 * s);
      const double y = e.feet[static_cast<std::size_t>(f)].sole_m(i, 2 * s + 1);
      if (y - ground > o.ground_contact_height_m) continue;
      const bool in = mp.covers(x, lat, outside ? o.edge_margin_m : 0.0);
      if (!outside && !sole_point_planted(e, f, s, i, o)) continue;
      hit = hit || (outside ? !in : in);
    }
    k += hit;
  }
  return k;
}

/// Plate stances -> candidates: runs above the threshold, cut ones and blips out, each assigned
/// to the foot its COP lies under, and set aside (kept = false, with the reason in v.excluded)
/// when the other foot also stands on the plate, the foot is partly off it, or a foot stands on
/// two plates at once.
std::vector<Candidate> assign_stances(const EstimateResult& e, ValidationResult& v, const ValidationOptions& o) {
  const Eigen::Index n = e.time_s.size();
  bool noted_geometry = false;
  std::vector<Candidate> cands;
  for (int pi = 0; pi < static_cast<int>(v.plates.size()); ++pi) {
    const MeasuredPlate& mp = v.plates[static_cast<std::size_t>(pi)];
    for (const IndexRun& run : runs_above(mp.force_N.col(1), o.threshold_N)) {
      const std::string where = "plate " + mp.name + " " + frames_text(e, run.first, run.last);
      if (run.last - run.first < 2) continue;  // a blip, not a stance
      const bool cut = run.first == 0 || run.last == n - 1;
      if ((run.first > 0 && !std::isfinite(mp.force_N(run.first - 1, 1))) || (run.last < n - 1 && !std::isfinite(mp.force_N(run.last + 1, 1)))) {
        v.excluded.push_back(where + ": stance cut by the plate recording's ends");
        continue;
      }
      const std::array<double, 2> dist{cop_to_foot_m(e, mp, run, 0), cop_to_foot_m(e, mp, run, 1)};
      const int foot = dist[1] < dist[0] ? 1 : 0;
      char buf[160];
      if (!(dist[static_cast<std::size_t>(foot)] <= o.max_assign_distance_m)) {
        std::snprintf(buf, sizeof buf, ": the COP is %.0f mm from the nearest foot (limit %.0f mm); not assigned",
                      1000 * dist[static_cast<std::size_t>(foot)], 1000 * o.max_assign_distance_m);
        v.excluded.push_back(where + buf);
        continue;
      }
      if (mp.side_hint != Side::General && (mp.side_hint == Side::Left) != (foot == 1))
        v.notes.push_back(where + ": assigned to the " + side_name(foot) + " foot by distance; its column names say " +
                          to_string(mp.side_hint));
      bool kept = true;
      if (mp.has_geometry) {
        const int other = sole_frames(e, mp, run, 1 - foot, false, o), off = sole_frames(e, mp, run, foot, true, o);
        if (other >= 3) {
          v.excluded.push_back(where + ": the " + side_name(1 - foot) + " foot also stands on this plate (" +
                               std::to_string(other) + " frames)");
          kept = false;
        } else if (off >= 3) {
          v.excluded.push_back(where + ": the " + side_name(foot) + " foot is partly off the plate (" + std::to_string(off) +
                               " frames with a sole point on the ground outside its edges)");
          kept = false;
        }
      } else if (!noted_geometry) {
        v.notes.push_back("plates without geometry (GRF .mot): a foot partly off a plate or two feet on one plate cannot be checked");
        noted_geometry = true;
      }
      if (kept && cut)
        v.notes.push_back(where + ": stance cut by the processed window's ends; compared as a cut stance, out of the means (and of "
                                  "the totals, unless no stance is complete)");
      cands.push_back({pi, run, foot, dist[static_cast<std::size_t>(foot)], kept, cut});
    }
  }
  // A foot on two plates at once (a cut stance there is set aside alone: it leaves a complete one be).
  for (std::size_t a = 0; a < cands.size(); ++a)
    for (std::size_t b = a + 1; b < cands.size(); ++b) {
      Candidate &ca = cands[a], &cb = cands[b];
      if (ca.foot != cb.foot || ca.plate == cb.plate) continue;
      if (ca.run.last < cb.run.first || cb.run.last < ca.run.first) continue;
      if (ca.cut != cb.cut) {
        (ca.cut ? ca : cb).kept = false;
        continue;
      }
      if (ca.kept || cb.kept)
        v.excluded.push_back(std::string("the ") + side_name(ca.foot) + " foot stands on plates " + v.plates[static_cast<std::size_t>(ca.plate)].name +
                             " and " + v.plates[static_cast<std::size_t>(cb.plate)].name + " at once (" +
                             frames_text(e, std::max(ca.run.first, cb.run.first), std::min(ca.run.last, cb.run.last)) + ")");
      ca.kept = cb.kept = false;
    }

  return cands;
}

/// The time shift (ms) of the estimate's vertical force that best matches the plate's over
/// frames a..last: RMSE of est(i + k) against plate(i) for shifts k of up to 60 ms, refined by a
/// parabola through the best three. + = the estimate lags; none when the best is at a limit.
std::optional<double> vertical_lag_ms(const Eigen::VectorXd& ev, const Eigen::VectorXd& pv, Eigen::Index a, Eigen::Index last,
                                      double rate) {
  const Eigen::Index n = ev.size();
  const int kmax = static_cast<int>(std::lround(0.06 * rate));
  std::vector<double> err;
  for (int k = -kmax; k <= kmax; ++k) {
    double se = 0;
    int cnt = 0;
    for (Eigen::Index i = a; i <= last; ++i) {
      const Eigen::Index j = i + k;
      if (j < 0 || j >= n) continue;
      se += std::pow(ev[j] - pv[i], 2), ++cnt;
    }
    err.push_back(cnt ? std::sqrt(se / cnt) : std::numeric_limits<double>::infinity());
  }
  const auto best = static_cast<int>(std::min_element(err.begin(), err.end()) - err.begin());
  if (best > 0 && best + 1 < static_cast<int>(err.size())) {
    const double frac = parabola_vertex_offset(err[static_cast<std::size_t>(best - 1)], err[static_cast<std::size_t>(best)],
                                               err[static_cast<std::size_t>(best + 1)], false);
    // est(i + k) matching plate(i): with est(t) = plate(t + L) (the estimate leading by L),
    // k = -L, so k itself is the lag (negative when the estimate leads).
    return 1000.0 * (best - kmax + frac) / rate;
  }
  return std::nullopt;
}

/// The registration check (step 4): over the stance's frames where the plate carries more than
/// half the body weight, the median distance of its COP (`mc`, from frame `a` of the window)
/// beyond the foot's heel-toe landmark span along x; NaN without such frames.
double cop_beyond_foot_m(const EstimateResult& e, const Candidate& c, const Eigen::VectorXd& mv, const Eigen::VectorXd& mc,
                         Eigen::Index a) {
  const double bw = e.mass_kg * e.model().gravity_mps2;
  const int heel = c.foot ? kHeelL : kHeelR, toe = c.foot ? kHalluxL : kHalluxR;
  std::vector<double> beyond;
  for (Eigen::Index i = 0; i < mv.size(); ++i) {
    if (!(mv[i] > 0.5 * bw) || !std::isfinite(mc[i])) continue;
    const double xa = e.landmarks.p[heel](a + i, 0), xb = e.landmarks.p[toe](a + i, 0);
    beyond.push_back(beyond_span(mc[i], xa, xb));
  }
  return beyond.empty() ? kNaN : median(beyond);
}

/// One kept stance compared (per-foot metrics, timing, lag); its measured force and COP go into
/// v's per-foot series.
/// The foot's sole length (heel point A to toe point C), median over the stance, for the COP
/// error in % of foot length: an rRMSE divides by the COP's range, 5-6 cm over a walking stance
/// overground and 50-60 cm on a treadmill, so the same error reads 32 % or 4.5 %. NaN without
/// the sole series.
double stance_foot_length_m(const EstimateResult& e, const Candidate& c) {
  const Eigen::MatrixXd& sole = e.feet[static_cast<std::size_t>(c.foot)].sole_m;
  std::vector<double> sole_length;
  if (sole.rows() == e.time_s.size())
    for (Eigen::Index i = c.run.first; i <= c.run.last; ++i) sole_length.push_back((sole.block<1, 2>(i, 4) - sole.block<1, 2>(i, 0)).norm());
  return sole_length.empty() ? kNaN : median(sole_length);
}

/// Contact timing: threshold crossings of the estimate near the plate's (+ = estimate late), and
/// the vertical force's best time shift.
/// `onset_by_ramp`, `offset_by_ramp`: which are scored by the ramps' intercepts
/// (ValidationOptions::Timing); both timings are kept.
void stance_timing(const EstimateResult& e, const MeasuredPlate& mp, const Candidate& c, const ValidationOptions& o, bool onset_by_ramp,
                   bool offset_by_ramp, StanceValidation& s) {
  const Eigen::Index n = e.time_s.size(), a = c.run.first;
  const double rate = e.landmarks.rate_hz;
  const Eigen::Index search = static_cast<Eigen::Index>(std::lround(0.2 * rate));
  const Eigen::VectorXd ev = e.feet[static_cast<std::size_t>(c.foot)].force_N.col(1);
  const Eigen::VectorXd pv = mp.force_N.col(1);
  const auto m_on = rising_crossing(pv, e.time_s, o.threshold_N, a - 1, c.run.last);
  const auto m_off = falling_crossing(pv, e.time_s, o.threshold_N, a, c.run.last + 1);
  const Eigen::Index from = std::max<Eigen::Index>(0, a - search), to = std::min<Eigen::Index>(n - 1, c.run.last + search);
  // The first peak is looked for before mid, the last from it: the one rule for halves.
  const Eigen::Index mid = stance_second_half(a, c.run.last);
  const auto ms = [](double estimated_s, double measured_s) { return 1000 * (estimated_s - measured_s); };
  // Only where the estimate was unloaded at the search's start (end): its rise (fall) is in it.
  if (!(ev[from] > o.threshold_N)) {
    if (m_on)
      if (const auto e_on = rising_crossing(ev, e.time_s, o.threshold_N, from, c.run.last)) s.onset_crossing_error_ms = ms(*e_on, *m_on);
    if (const auto p0 = loading_ramp_onset(pv, e.time_s, a - 1, mid, c.run.last))
      if (const auto e0 = loading_ramp_onset(ev, e.time_s, from, mid, c.run.last)) s.onset_ramp_error_ms = ms(*e0, *p0);
  }
  if (!(ev[to] > o.threshold_N)) {
    if (m_off)
      if (const auto e_off = falling_crossing(ev, e.time_s, o.threshold_N, a, to)) s.offset_crossing_error_ms = ms(*e_off, *m_off);
    if (const auto p0 = unloading_ramp_offset(pv, e.time_s, a, mid, c.run.last + 1))
      if (const auto e0 = unloading_ramp_offset(ev, e.time_s, a, mid, to)) s.offset_ramp_error_ms = ms(*e0, *p0);
  }
  s.onset_by_ramp = onset_by_ramp;
  s.offset_by_ramp = offset_by_ramp;
  s.onset_error_ms = onset_by_ramp ? s.onset_ramp_error_ms : s.onset_crossing_error_ms;
  s.offset_error_ms = offset_by_ramp ? s.offset_ramp_error_ms : s.offset_crossing_error_ms;
  // The loaded span: the estimate's load on the foot next to its stance, while the plate it lands
  // on (or leaves) reads below the threshold, counted against that reading (a NaN plate stops it).
  // Only a landing's or a lift-off's: the estimate's load must begin (end) within the search, so
  // that the foot was in the air before (after); a foot loaded throughout (a standing trial whose
  // plate signal starts late) keeps its stance.
  const auto loaded = [&](Eigen::Index i) { return ev[i] > o.threshold_N; };
  Eigen::Index first = a, last = c.run.last;
  while (first > from && loaded(first - 1) && pv[first - 1] < o.threshold_N) --first;
  const bool landed = first > from && !loaded(first - 1);  // the load began within the search
  if (first < a && !landed) first = a;
  while (last < to && loaded(last + 1) && pv[last + 1] < o.threshold_N) ++last;
  const bool lifted = last < to && !loaded(last + 1);  // and ended within it
  if (last > c.run.last && !lifted) last = c.run.last;
  s.span_first = first;
  s.span_last = last;
  s.vertical_loaded_span = compare_series(ev.segment(first, last - first + 1), pv.segment(first, last - first + 1));
  s.vertical_lag_ms = vertical_lag_ms(ev, pv, a, c.run.last, rate);
}

/// StanceValidation::vertical_rmse_double_support_N and its single-support counterpart: the
/// stance's frames with both series finite, in double support where the other foot's estimated
/// force or its plates' measured one (v.measured_force_N, complete once every stance is compared)
/// is above `threshold_N`.
void split_by_support(const EstimateResult& e, const ValidationResult& v, double threshold_N, StanceValidation& s) {
  const Eigen::VectorXd& pv = v.plates[static_cast<std::size_t>(s.plate_index)].force_N.col(1);
  const auto& ev = e.feet[static_cast<std::size_t>(s.foot)].force_N;
  const auto& other_e = e.feet[static_cast<std::size_t>(1 - s.foot)].force_N;
  const auto& other_m = v.measured_force_N[static_cast<std::size_t>(1 - s.foot)];
  double sq[2] = {0, 0};
  int count[2] = {0, 0};
  for (Eigen::Index k = s.first; k <= s.last; ++k) {
    if (!std::isfinite(pv[k]) || !std::isfinite(ev(k, 1))) continue;
    const bool both = other_e(k, 1) > threshold_N || (other_m.rows() > k && other_m(k, 1) > threshold_N);
    const double d = ev(k, 1) - pv[k];
    sq[both ? 0 : 1] += d * d;
    ++count[both ? 0 : 1];
  }
  s.double_support_frames = count[0];
  s.single_support_frames = count[1];
  s.vertical_rmse_double_support_N = count[0] > 0 ? std::sqrt(sq[0] / count[0]) : kNaN;
  s.vertical_rmse_single_support_N = count[1] > 0 ? std::sqrt(sq[1] / count[1]) : kNaN;
}

/// StanceValidation::parameters_estimated and parameters_measured: the estimate's and the plate's
/// force over the stance's loaded span (the plate's stance and the estimate's loaded frames next to
/// it), so that an estimate that loads the foot before the plate's onset has its rise, and its
/// loading rate, seen too.
void compare_parameters(const EstimateResult& e, const ValidationResult& v, StanceValidation& s) {
  const double rate = e.motion.rate_hz;
  s.parameters_measured = stance_parameters(v.plates[static_cast<std::size_t>(s.plate_index)].force_N, rate, s.span_first, s.span_last);
  s.parameters_estimated = stance_parameters(e.feet[static_cast<std::size_t>(s.foot)].force_N, rate, s.span_first, s.span_last);
}

/// Whether the onsets of the stances on plate `name` are timed by the loading ramp
/// (ValidationOptions::Timing): with Auto, when step 7 found the plate filtered before export.
bool onset_by_ramp(const ValidationResult& v, const std::string& name, const ValidationOptions& o) {
  if (o.timing != ValidationOptions::Timing::Auto) return o.timing == ValidationOptions::Timing::Ramp;
  return std::any_of(v.plate_onsets.begin(), v.plate_onsets.end(),
                     [&](const PlateOnsetRise& r) { return r.plate == name && r.filtered(); });
}
/// And their offsets: by the unloading ramp only when asked (Ramp).
bool offset_by_ramp(const ValidationOptions& o) { return o.timing == ValidationOptions::Timing::Ramp; }

StanceValidation compare_stance(const EstimateResult& e, ValidationResult& v, const Candidate& c, const ValidationOptions& o) {
  const Eigen::Index n = e.time_s.size();
  const double bw = e.mass_kg * e.model().gravity_mps2, ground = e.ground_level_m();
  const MeasuredPlate& mp = v.plates[static_cast<std::size_t>(c.plate)];
  const FootResult& fe = e.feet[static_cast<std::size_t>(c.foot)];
  const Eigen::Index a = c.run.first, len = c.run.last - c.run.first + 1;
  StanceValidation s;
  s.foot = c.foot;
  s.plate = mp.name;
  s.plate_index = c.plate;
  s.first = c.run.first;
  s.last = c.run.last;
  s.assign_distance_m = c.distance;
  s.body_weight_N = bw;
  const Eigen::VectorXd mv = mp.force_N.col(1).segment(a, len), ma = mp.force_N.col(0).segment(a, len);
  s.metrics.vertical = compare_series(fe.force_N.col(1).segment(a, len), mv);
  s.metrics.anterior = compare_series(fe.force_N.col(0).segment(a, len), ma);
  if (fe.force_lateral_N.size() == n) s.metrics.lateral = compare_series(fe.force_lateral_N.segment(a, len), mp.force_lateral_N.segment(a, len));
  Eigen::VectorXd mc = mp.cop_x_m.segment(a, len);
  for (Eigen::Index i = 0; i < len; ++i)
    if (!(mv[i] > o.cop_min_force_fraction * bw)) mc[i] = kNaN;
  s.metrics.cop = compare_series(fe.cop_x_m.segment(a, len), mc);
  s.cop_beyond_foot_m = cop_beyond_foot_m(e, c, mv, mc, a);
  if (fe.force_lateral_N.size() == n) {
    // The COP's lateral place (FootResult::cop_lateral_m), scored with the mediolateral force.
    Eigen::VectorXd ml = mp.cop_lateral_m.segment(a, len);
    for (Eigen::Index i = 0; i < len; ++i)
      if (!(mv[i] > o.cop_min_force_fraction * bw)) ml[i] = kNaN;
    const Eigen::VectorXd& el = fe.cop_lateral_m.size() == n ? fe.cop_lateral_m : e.foot_lateral_m[static_cast<std::size_t>(c.foot)];
    s.metrics.cop_lateral = compare_series(el.segment(a, len), ml);
    // The plate's free moment about the vertical at its COP: (M_O - c x F) . up.
    Eigen::VectorXd tz = Eigen::VectorXd::Constant(len, kNaN);
    for (Eigen::Index i = 0; i < len; ++i) {
      const Eigen::Index k = a + i;
      if (!std::isfinite(ml[i]) || !std::isfinite(mc[i]) || !mp.force_lab_N.row(k).allFinite()) continue;
      const Eigen::Vector3d c3 = e.frame.to_lab(mc[i], mp.surface_y_m, ml[i], e.first_index + k);
      tz[i] = (mp.moment_origin_lab_Nm.row(k).transpose() - c3.cross(mp.force_lab_N.row(k).transpose())).dot(e.frame.up);
    }
    s.metrics.free_moment = compare_series(Eigen::VectorXd::Zero(len), tz);
  }
  s.foot_length_m = stance_foot_length_m(e, c);
  if (s.cop_beyond_foot_m > o.max_cop_beyond_foot_m) {
    s.cop_reference_suspect = true;
    char buf[320];
    std::snprintf(buf, sizeof buf,
                  ": under more than half the body weight its COP lies a median %.0f mm beyond the %s foot's heel-toe "
                  "markers (limit %.0f mm): the plate does not seem registered with the markers; COP and moment are "
                  "shown but not scored",
                  1000 * s.cop_beyond_foot_m, side_name(c.foot), 1000 * o.max_cop_beyond_foot_m);
    v.notes.push_back("plate " + mp.name + " " + frames_text(e, c.run.first, c.run.last) + buf);
  }
  s.moment_reference_m = {mp.has_geometry ? mp.centre_m.x() : mean_finite(mc), mp.surface_y_m};
  const double rx = s.moment_reference_m.x(), ry = s.moment_reference_m.y();
  Eigen::VectorXd me(len), mm(len);
  for (Eigen::Index i = 0; i < len; ++i) {
    const Eigen::Index k = a + i;
    const double cx = std::isfinite(fe.cop_x_m[k]) ? fe.cop_x_m[k] : rx;
    me[i] = sagittal_moment(cx - rx, ground - ry, fe.force_N(k, 0), fe.force_N(k, 1));
    mm[i] = mp.moment_origin_Nm[k] - sagittal_moment(rx, ry, mp.force_N(k, 0), mp.force_N(k, 1));
  }
  s.metrics.moment = compare_series(me, mm);
  stance_timing(e, mp, c, o, onset_by_ramp(v, mp.name, o), offset_by_ramp(o), s);
  if (c.cut) {
    // The plate's onset (offset) lies outside the window: the crossing found at its edge is none.
    if (c.run.first == 0) s.onset_error_ms.reset(), s.onset_crossing_error_ms.reset(), s.onset_ramp_error_ms.reset();
    if (c.run.last == n - 1) s.offset_error_ms.reset(), s.offset_crossing_error_ms.reset(), s.offset_ramp_error_ms.reset();
  }
  for (Eigen::Index i = 0; i < len; ++i) {
    auto& mf = v.measured_force_N[static_cast<std::size_t>(c.foot)];
    if (!std::isfinite(mf(a + i, 1))) mf.row(a + i).setZero();
    mf.row(a + i) += mp.force_N.row(a + i);
    v.measured_cop_x_m[static_cast<std::size_t>(c.foot)][a + i] = mc[i];
  }
  if (fe.force_lateral_N.size() == n) {
    auto& ml = v.measured_lateral_N[static_cast<std::size_t>(c.foot)];
    auto& cl = v.measured_cop_lateral_m[static_cast<std::size_t>(c.foot)];
    for (Eigen::Index i = 0; i < len; ++i) {
      ml[a + i] = (std::isfinite(ml[a + i]) ? ml[a + i] : 0.0) + mp.force_lateral_N[a + i];
      if (std::isfinite(mc[i])) cl[a + i] = mp.cop_lateral_m[a + i];
    }
  }
  return s;
}

/// The frames of the total comparison and, per frame, the plates loaded (bit per plate): where
/// every loaded plate is in a kept stance, no foot is planted beside the plates, and the loaded
/// plates' vertical sum matches the whole body's (runs of equal plates and contacts, median
/// mismatch below total_mismatch_fraction of body weight).
std::pair<std::vector<Eigen::Index>, std::vector<unsigned>> total_frames(const EstimateResult& e, const ValidationResult& v,
                                                                         const std::vector<Candidate>& cands,
                                                                         const ValidationOptions& o) {
  const Eigen::Index n = e.time_s.size();
  const double bw = e.mass_kg * e.model().gravity_mps2;
  const int np = static_cast<int>(v.plates.size());
  // A cut stance counts for the total only in a trial with no complete one (standing, a squat):
  // elsewhere the totals are the complete stances' alone.
  const bool no_complete = std::none_of(cands.begin(), cands.end(), [](const Candidate& c) { return c.kept && !c.cut; });
  const auto counts = [&](const Candidate& c) { return c.kept && (!c.cut || no_complete); };
  // Total: every loaded plate in a kept stance, and the plates carrying the whole body.
  std::vector<unsigned> mask(static_cast<std::size_t>(n), 0u);
  std::vector<bool> ok(static_cast<std::size_t>(n), true);
  for (int pi = 0; pi < np && pi < 32; ++pi)
    for (Eigen::Index i = 0; i < n; ++i)
      if (v.plates[static_cast<std::size_t>(pi)].force_N(i, 1) > o.threshold_N) mask[static_cast<std::size_t>(i)] |= 1u << pi;
  // A foot on the floor off the plates, from the kinematics alone (not the estimate's contact
  // state): a sole point planted (sole_point_planted) while no kept stance of that foot covers the
  // frame. The plates then miss part of the body's load, whatever the other frames of its run
  // say: the frame is left out of an accepted run (it does not split runs, so it can only remove
  // frames).
  std::vector<bool> off_plate(static_cast<std::size_t>(n), false);
  for (Eigen::Index i = 0; i < n; ++i) {
    const unsigned mk = mask[static_cast<std::size_t>(i)];
    if (mk == 0) ok[static_cast<std::size_t>(i)] = false;
    for (int side = 0; side < 2; ++side) {
      if (!sole_point_planted(e, side, 0, i, o) && !sole_point_planted(e, side, 1, i, o) && !sole_point_planted(e, side, 2, i, o))
        continue;
      bool on_plate = false;
      for (const Candidate& c : cands) on_plate = on_plate || (counts(c) && c.foot == side && i >= c.run.first && i <= c.run.last);
      if (!on_plate) off_plate[static_cast<std::size_t>(i)] = true;
    }
    for (int pi = 0; pi < np && pi < 32; ++pi) {
      if (!(mk & (1u << pi))) continue;
      bool covered = false;
      for (const Candidate& c : cands)
        covered = covered || (counts(c) && c.plate == pi && i >= c.run.first && i <= c.run.last);
      if (!covered) ok[static_cast<std::size_t>(i)] = false;
    }
  }
  std::vector<Eigen::Index> frames;
  for (Eigen::Index i = 0; i < n;) {
    Eigen::Index j = i;
    // Runs of frames with the same plates loaded and the same estimated contacts (the latter
    // only splits runs, e.g. where a foot lands beside the plates; acceptance is measured).
    auto same = [&](Eigen::Index x, Eigen::Index y) {
      return mask[static_cast<std::size_t>(x)] == mask[static_cast<std::size_t>(y)] &&
             ok[static_cast<std::size_t>(x)] == ok[static_cast<std::size_t>(y)] &&
             e.feet[0].contact[static_cast<std::size_t>(x)] == e.feet[0].contact[static_cast<std::size_t>(y)] &&
             e.feet[1].contact[static_cast<std::size_t>(x)] == e.feet[1].contact[static_cast<std::size_t>(y)];
    };
    while (j + 1 < n && same(j + 1, i)) ++j;
    if (ok[static_cast<std::size_t>(i)]) {
      std::vector<double> mis;
      for (Eigen::Index k = i; k <= j; ++k) {
        double sum = 0;
        for (int pi = 0; pi < np && pi < 32; ++pi)
          if (mask[static_cast<std::size_t>(k)] & (1u << pi)) sum += v.plates[static_cast<std::size_t>(pi)].force_N(k, 1);
        mis.push_back(std::abs(sum - e.kinematic_total(k, 1)));
      }
      if (median(mis) < o.total_mismatch_fraction * bw)
        for (Eigen::Index k = i; k <= j; ++k)
          if (!off_plate[static_cast<std::size_t>(k)]) frames.push_back(k);
    }
    i = j + 1;
  }
  return {std::move(frames), std::move(mask)};
}

/// The whole body's comparison: the frames where every loaded plate is in a kept stance, no foot
/// stands beside the plates and the plates carry the whole body; there the totals and the GRM.
void compare_totals(const EstimateResult& e, ValidationResult& v, const std::vector<Candidate>& cands, const ValidationOptions& o) {
  const Eigen::Index n = e.time_s.size();
  const double ground = e.ground_level_m();
  const int np = static_cast<int>(v.plates.size());
  TotalValidation tv;
  std::vector<unsigned> mask;
  std::tie(tv.frames, mask) = total_frames(e, v, cands, o);
  if (tv.frames.size() < 10) {
    v.excluded.push_back("total: no window of 10 frames or more where every loaded foot stands on a kept plate stance");
    return;
  }
  // GRM reference: midpoint of the plate centres in use (geometry), else the mean measured COP.
  unsigned used = 0;
  for (Eigen::Index k : tv.frames) used |= mask[static_cast<std::size_t>(k)];
  double rx = 0, ry = 0, w = 0;
  for (int pi = 0; pi < np && pi < 32; ++pi) {
    if (!(used & (1u << pi))) continue;
    const MeasuredPlate& mp = v.plates[static_cast<std::size_t>(pi)];
    if (mp.has_geometry) {
      rx += mp.centre_m.x();
    } else {
      Eigen::VectorXd c(static_cast<Eigen::Index>(tv.frames.size()));
      for (std::size_t q = 0; q < tv.frames.size(); ++q) c[static_cast<Eigen::Index>(q)] = mp.cop_x_m[tv.frames[q]];
      rx += mean_finite(c);
    }
    ry += mp.surface_y_m;
    w += 1;
  }
  tv.grm_reference_m = {rx / w, ry / w};
  const Eigen::Index m = static_cast<Eigen::Index>(tv.frames.size());
  Eigen::VectorXd ev(m), mv(m), ea(m), ma(m), eg(m), mg(m);
  tv.grm_estimated_Nm = tv.grm_measured_Nm = Eigen::VectorXd::Constant(n, kNaN);
  tv.vertical_estimated_N = tv.vertical_measured_N = Eigen::VectorXd::Constant(n, kNaN);
  for (Eigen::Index q = 0; q < m; ++q) {
    const Eigen::Index k = tv.frames[static_cast<std::size_t>(q)];
    ev[q] = ea[q] = eg[q] = mv[q] = ma[q] = mg[q] = 0;
    for (int f = 0; f < 2; ++f) {
      const FootResult& fe = e.feet[static_cast<std::size_t>(f)];
      ev[q] += fe.force_N(k, 1), ea[q] += fe.force_N(k, 0);
      if (std::isfinite(fe.cop_x_m[k]))
        eg[q] += sagittal_moment(fe.cop_x_m[k] - tv.grm_reference_m.x(), ground - tv.grm_reference_m.y(), fe.force_N(k, 0), fe.force_N(k, 1));
    }
    for (int pi = 0; pi < np && pi < 32; ++pi) {
      if (!(mask[static_cast<std::size_t>(k)] & (1u << pi))) continue;
      const MeasuredPlate& mp = v.plates[static_cast<std::size_t>(pi)];
      mv[q] += mp.force_N(k, 1), ma[q] += mp.force_N(k, 0);
      mg[q] += mp.moment_origin_Nm[k] - sagittal_moment(tv.grm_reference_m.x(), tv.grm_reference_m.y(), mp.force_N(k, 0), mp.force_N(k, 1));
    }
    tv.grm_estimated_Nm[k] = eg[q];
    tv.grm_measured_Nm[k] = mg[q];
    tv.vertical_estimated_N[k] = ev[q];
    tv.vertical_measured_N[k] = mv[q];
  }
  {
    double num = 0, den = 0;
    for (Eigen::Index q = 0; q < m; ++q) {
      const double k = e.kinematic_total(tv.frames[static_cast<std::size_t>(q)], 1) / e.mass_kg;  // per kg
      num += mv[q] * k, den += k * k;
    }
    tv.implied_mass_kg = den > 0 ? num / den : kNaN;
    if (std::abs(tv.implied_mass_kg - e.mass_kg) > 0.03 * e.mass_kg) {
      char b[200];
      std::snprintf(b, sizeof b, "the plates imply a body mass of %.1f kg over the total window, %+.1f %% from the %.1f kg used",
                    tv.implied_mass_kg, 100 * (tv.implied_mass_kg / e.mass_kg - 1), e.mass_kg);
      v.notes.push_back(b);
    }
  }
  tv.metrics.vertical = compare_series(ev, mv);
  tv.metrics.anterior = compare_series(ea, ma);
  tv.metrics.moment = compare_series(eg, mg);
  v.total = std::move(tv);
}

/// Step 6 (SyncEstimate) from a comparison made with the plates as recorded.
std::optional<SyncEstimate> estimate_sync(const EstimateResult& e, const ValidationResult& v, double threshold_N) {
  if (e.kinematic_total.rows() != e.time_s.size()) return std::nullopt;
  const Eigen::Index n = e.time_s.size();
  const double rate = e.motion.rate_hz;
  if (!(rate > 0) || !(e.kinematic_cutoff_hz > 0) || e.kinematic_cutoff_hz >= max_zero_lag_cutoff_hz(rate)) return std::nullopt;
  Eigen::VectorXd plates = Eigen::VectorXd::Zero(n);
  std::vector<bool> recorded(static_cast<std::size_t>(n), true);
  for (const MeasuredPlate& mp : v.plates)
    for (Eigen::Index i = 0; i < n; ++i) {
      if (std::isfinite(mp.force_N(i, 1))) plates[i] += mp.force_N(i, 1);
      else recorded[static_cast<std::size_t>(i)] = false;
    }
  if (n < 20) return std::nullopt;
  plates = butterworth_filtfilt(plates, rate, e.kinematic_cutoff_hz);
  const int kmax = static_cast<int>(std::lround(kMaxSyncShiftS * rate));
  // Frames where the plates carry load; the loss is the median absolute difference, robust to
  // the frames where a foot stands beside the plates (a minority on a walk over plates).
  std::vector<Eigen::Index> loaded;
  for (Eigen::Index i = kmax; i + kmax < n; ++i) {
    bool ok = true;
    for (Eigen::Index j = i - kmax; j <= i + kmax && ok; ++j) ok = recorded[static_cast<std::size_t>(j)];
    if (ok && plates[i] > threshold_N) loaded.push_back(i);
  }
  const int frames = static_cast<int>(loaded.size());
  if (frames < 10) return std::nullopt;
  std::vector<double> err, d(loaded.size());
  for (int k = -kmax; k <= kmax; ++k) {
    for (std::size_t q = 0; q < loaded.size(); ++q) d[q] = std::abs(e.kinematic_total(loaded[q], 1) - plates[loaded[q] - k]);
    err.push_back(median(d));
  }
  const auto best = static_cast<int>(std::min_element(err.begin(), err.end()) - err.begin());
  if (best == 0 || best + 1 == static_cast<int>(err.size())) return std::nullopt;
  const auto at = [&](int k) { return err[static_cast<std::size_t>(k)]; };
  SyncEstimate s;
  s.offset_s = (best - kmax + parabola_vertex_offset(at(best - 1), at(best), at(best + 1), false)) / rate;
  s.error_at_offset_N = at(best);
  s.error_as_recorded_N = at(kmax);
  s.frames = frames;
  // Half-width of the shifts within 10 % of the least median error (linear between frames).
  const double level = 1.1 * at(best);
  double lo = -kmax, hi = kmax;
  for (int k = best; k > 0; --k)
    if (at(k - 1) > level) {
      lo = k - 1 + (level - at(k - 1)) / (at(k) - at(k - 1)) - kmax;
      break;
    }
  for (int k = best; k + 1 < static_cast<int>(err.size()); ++k)
    if (at(k + 1) > level) {
      hi = k + (level - at(k)) / (at(k + 1) - at(k)) - kmax;
      break;
    }
  s.uncertainty_s = 0.5 * (hi - lo) / rate;
  return s;
}

/// `rises`: step 7 on `rec` (plate_onset_rises), made first because a plate's noise and rise
/// decide how its onsets are timed, and made once: a time shift of the plates does not change it.
ValidationResult validate_as_recorded(const EstimateResult& e, const ForcePlateRecording& rec, const ValidationOptions& o,
                                      const std::vector<PlateOnsetRise>& rises) {
  ValidationResult v;
  v.mass_kg = e.mass_kg;
  v.first_frame_number = e.first_frame_number;
  const Eigen::Index n = e.time_s.size();
  v.plates = resample_plates(rec, e.frame, e.time_s, rec.cop_threshold_N, e.first_index);
  v.plate_onsets = rises;
  for (int f = 0; f < 2; ++f) {
    v.measured_force_N[static_cast<std::size_t>(f)] = Eigen::MatrixX2d::Constant(n, 2, kNaN);
    v.measured_cop_x_m[static_cast<std::size_t>(f)] = Eigen::VectorXd::Constant(n, kNaN);
    if (e.feet[static_cast<std::size_t>(f)].force_lateral_N.size() == n) {
      v.measured_lateral_N[static_cast<std::size_t>(f)] = Eigen::VectorXd::Constant(n, kNaN);
      v.measured_cop_lateral_m[static_cast<std::size_t>(f)] = Eigen::VectorXd::Constant(n, kNaN);
    }
  }
  bool any_plate_data = false;
  for (const auto& mp : v.plates) any_plate_data = any_plate_data || mp.force_N.col(1).array().isFinite().any();
  if (!any_plate_data)
    v.notes.push_back("the plate recording does not overlap the processed frames (" + frames_text(e, 0, n - 1) +
                      "): check that markers and plates share one clock");
  const std::vector<Candidate> cands = assign_stances(e, v, o);
  for (const Candidate& c : cands)
    if (c.kept) (c.cut ? v.cut_stances : v.stances).push_back(compare_stance(e, v, c, o));
  for (auto* list : {&v.stances, &v.cut_stances}) {
    std::sort(list->begin(), list->end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    for (StanceValidation& s : *list) {
      split_by_support(e, v, o.threshold_N, s);  // every foot's plates known now
      compare_parameters(e, v, s);
    }
  }
  compare_totals(e, v, cands, o);
  if (e.legs_3d) validate_joint_moments_3d(e, v);
  validate_joint_torques(e, v);
  validate_total_3d(e, v);
  return v;
}

}  // namespace

std::vector<PlateOnsetRise> plate_onset_rises(const ForcePlateRecording& rec, const Eigen::Vector3d& up, double threshold_N) {
  std::vector<PlateOnsetRise> out;
  const double floor_N = 0.01 * threshold_N;
  // A rise is looked for over at most 0.1 s: a plate whose signal sits above the floor longer
  // (an offset, someone standing on it) gives no rise there, and a long trial's many onsets
  // cost one short look each.
  const auto reach = static_cast<Eigen::Index>(std::ceil(0.1 * rec.rate_hz));
  // Where level is crossed between samples a and a + 1, in samples after a.
  const auto between = [](double fa, double fb, double level) { return fb != fa ? (level - fa) / (fb - fa) : 0.0; };
  for (const ForcePlate& p : rec.plates) {
    PlateOnsetRise r;
    r.plate = p.name;
    std::vector<double> rises;
    bool all_zero_steps = true;
    const Eigen::VectorXd f = p.force_N * up;
    for (Eigen::Index i = 1; i < f.size(); ++i) {
      if (!(f[i - 1] < threshold_N && f[i] >= threshold_N)) continue;
      Eigen::Index k = i - 1;
      while (k > 0 && i - k < reach && f[k] > floor_N) --k;
      if (!(f[k] <= floor_N)) continue;  // no rise from the floor within reach
      const double samples = static_cast<double>(i - 1 - k) + between(f[i - 1], f[i], threshold_N) - between(f[k], f[k + 1], floor_N);
      rises.push_back(1000.0 * samples / rec.rate_hz);
      all_zero_steps = all_zero_steps && k == i - 1 && f[k] == 0.0 && (k == 0 || f[k - 1] == 0.0);
    }
    r.onsets = static_cast<int>(rises.size());
    if (!rises.empty()) {
      r.rise_ms = median(rises);
      r.zero_below_threshold = all_zero_steps;
    }
    // The noise above kNoiseBandHz under load (a filtered export keeps none of it), inside the
    // loaded runs, two of the band's periods clear of their ends: a thresholded export's step at
    // the threshold, and the filter's ringing about it, are not noise.
    if (rec.rate_hz >= kNoiseRateHz && f.allFinite()) {
      const Eigen::VectorXd smooth = butterworth_filtfilt(f, rec.rate_hz, kNoiseBandHz);
      const auto clear = static_cast<Eigen::Index>(std::ceil(2.0 * rec.rate_hz / kNoiseBandHz));
      double sum = 0;
      long loaded = 0;
      Eigen::Index run = 0;  // loaded samples up to and including i
      for (Eigen::Index i = 0; i < f.size(); ++i) {
        run = f[i] > threshold_N ? run + 1 : 0;
        // Sample i - clear is inside when the run reaches clear samples on both of its sides.
        const Eigen::Index c = i - clear;
        if (run > 2 * clear) sum += (f[c] - smooth[c]) * (f[c] - smooth[c]), ++loaded;
      }
      if (loaded > 0) r.high_frequency_rms_N = std::sqrt(sum / static_cast<double>(loaded));
    }
    out.push_back(std::move(r));
  }
  return out;
}

ValidationResult validate(const EstimateResult& e, const ForcePlateRecording& rec, const ValidationOptions& o) {
  const std::vector<PlateOnsetRise> rises = plate_onset_rises(rec, e.frame.up, o.threshold_N);
  ValidationResult v = validate_as_recorded(e, rec, o, rises);
  const std::optional<SyncEstimate> sync = estimate_sync(e, v, o.threshold_N);
  double shift = 0.0;
  if (o.sync == ValidationOptions::Sync::Fixed) shift = o.plate_shift_s;
  else if (o.sync == ValidationOptions::Sync::Auto && sync) shift = sync->offset_s;
  char b[400];
  if (shift != 0.0) {
    ForcePlateRecording shifted = rec;
    shifted.time_s.array() += shift;
    v = validate_as_recorded(e, shifted, o, rises);
    std::snprintf(b, sizeof b, "compared with the plates shifted by %+.1f ms (%s)", 1000 * shift,
                  o.sync == ValidationOptions::Sync::Auto ? "--sync auto: the estimated marker-plate offset" : "--sync");
    v.notes.emplace_back(b);
  } else if (o.sync == ValidationOptions::Sync::Auto) {
    v.notes.emplace_back("--sync auto: no marker-plate offset could be estimated; compared as recorded");
  }
  v.sync = sync;
  v.plate_shift_s = shift;
  // Step 7: a plate whose export moved its onsets (only the plates a kept stance stands on).
  for (const PlateOnsetRise& r : v.plate_onsets) {
    const bool used = std::any_of(v.stances.begin(), v.stances.end(), [&](const StanceValidation& s) { return s.plate == r.plate; });
    if (!used) continue;
    // What the timing does with it (ValidationOptions::Timing).
    const bool ramp_onsets = onset_by_ramp(v, r.plate, o);
    const std::string timed =
        ramp_onsets && offset_by_ramp(o) ? "; its stances' onsets and offsets are timed by the loading and unloading ramps' zero "
                                           "intercepts (--timing ramp)"
        : ramp_onsets ? "; its stances' onsets are timed by the loading ramp's zero intercept (20-80 % of the peak, on the estimate "
                        "too), which such a filter moves less, their offsets by the crossings, which it moves little at a smooth "
                        "unloading"
        : o.timing == ValidationOptions::Timing::Crossing ? "; its stances are timed by the threshold's crossings (--timing crossing)"
                                                          : "";
    if (r.filtered()) {
      // The sign that decided (PlateOnsetRise::filtered): the noise where measured, else the rise.
      if (!std::isfinite(r.high_frequency_rms_N))
        std::snprintf(b, sizeof b,
                      "plate %s: its vertical force takes a median %.0f ms to rise from %.1f to %.0f N at its %d onset(s) (a raw plate's "
                      "signal takes a few ms at a foot strike): it looks low-pass filtered before export, so its threshold crossings "
                      "lead the foot's contact by up to that much",
                      r.plate.c_str(), r.rise_ms, 0.01 * o.threshold_N, o.threshold_N, r.onsets);
      else
        std::snprintf(b, sizeof b,
                      "plate %s: its vertical force carries %.3f N RMS above %.0f Hz under load (a raw plate's noise is 0.2 N or more): "
                      "it looks low-pass filtered before export, so its threshold crossings lead the foot's contact by the filter's "
                      "spread",
                      r.plate.c_str(), r.high_frequency_rms_N, kNoiseBandHz);
      v.notes.emplace_back(b + timed);
    } else if (r.zero_below_threshold) {
      std::snprintf(b, sizeof b,
                    "plate %s: its vertical force is exactly 0 N before each onset and then steps past %.0f N: it was set to zero "
                    "below a threshold before export, so its onsets are that threshold's crossing (of a signal that may have "
                    "been filtered)",
                    r.plate.c_str(), o.threshold_N);
      v.notes.emplace_back(b + timed);
    } else if (ramp_onsets) {
      v.notes.emplace_back("plate " + r.plate + ": timed by the loading and unloading ramps' zero intercepts (--timing ramp)");
    }
  }
  // An offset beyond a frame and 10 ms that the data pin down is worth a word when not applied.
  if (sync && shift == 0.0 && std::abs(sync->offset_s) > std::max(0.010, 1.0 / e.motion.rate_hz) &&
      sync->uncertainty_s < std::abs(sync->offset_s)) {
    std::snprintf(b, sizeof b,
                  "the plates seem to %s the markers by %.0f ms (+-%.0f ms; median |plates - kinematics| of the total vertical force %.0f N "
                  "as recorded, %.0f N shifted): check the capture's synchronisation; --sync auto compares after aligning them",
                  sync->offset_s > 0 ? "lead" : "lag", 1000 * std::abs(sync->offset_s), 1000 * sync->uncertainty_s,
                  sync->error_as_recorded_N, sync->error_at_offset_N);
    v.notes.emplace_back(b);
  }
  return v;
}

namespace {
/// The 3D joint moments' means (MeanMetrics::knee_sagittal, knee_adduction, kam_peak_error_percent).
void mean_joint_moments(const std::vector<StanceValidation>& stances, int foot, MeanMetrics& mm) {
  // Knee sagittal rRMSE, KAM rRMSE; per peak (first, second) the |error| and the plates' |peak|:
  // a ratio of means, since a stance whose plate-driven peak is near 0 N m would make a per-stance
  // percentage meaningless. A stance whose plate fails the registration check is left out: its
  // plate-driven moments take the plate's COP, which is not where the foot is (4-7 cm of lever on
  // Camargo's export are 0.3-0.7 N m/kg of knee adduction moment at 800 N).
  std::array<std::vector<double>, 6> x;
  std::vector<double> impulse_error, impulse_plates;  // the KAM impulse's |error| and the plates' (N m s)
  for (const auto& s : stances) {
    if ((foot >= 0 && s.foot != foot) || !s.moments_3d || s.cop_reference_suspect) continue;
    const JointMomentValidation& j = *s.moments_3d;
    if (j.knee[0] && std::isfinite(j.knee[0]->rrmse_percent)) x[0].push_back(j.knee[0]->rrmse_percent);
    if (j.knee_adduction && std::isfinite(j.knee_adduction->rrmse_percent)) x[1].push_back(j.knee_adduction->rrmse_percent);
    for (std::size_t p = 0; p < 2; ++p) {
      const double m = j.kam_peak_measured_Nm[p];
      if (std::isfinite(m) && std::isfinite(j.kam_peak_estimated_Nm[p])) {
        x[2 + 2 * p].push_back(std::abs(j.kam_peak_estimated_Nm[p] - m));
        x[3 + 2 * p].push_back(std::abs(m));
      }
    }
    if (std::isfinite(j.kam_impulse_estimated_Nm_s) && std::isfinite(j.kam_impulse_measured_Nm_s)) {
      impulse_error.push_back(std::abs(j.kam_impulse_estimated_Nm_s - j.kam_impulse_measured_Nm_s));
      impulse_plates.push_back(j.kam_impulse_measured_Nm_s);
    }
  }
  const auto mean = [](const std::vector<double>& v) {
    double sum = 0;
    for (double a : v) sum += a;
    return v.empty() ? kNaN : sum / static_cast<double>(v.size());
  };
  mm.knee_sagittal = mean(x[0]);
  mm.knee_adduction = mean(x[1]);
  // The sagittal joint torques (every model): hip, knee, ankle.
  std::array<std::vector<double>, 3> least_squares, bottom_up, rmse_per_kg, power;
  // The kinetic peaks per kg, |kin2grf - plates| and the plates': the ankle's push-off power, then
  // the moments (MeanMetrics::moment_peak_*'s order).
  std::array<std::vector<double>, 5> peak_error, peak_plates;
  for (const auto& s : stances) {
    if ((foot >= 0 && s.foot != foot) || !s.torques) continue;
    const JointTorqueValidation& jt = *s.torques;
    for (std::size_t c = 0; c < 3; ++c) {
      const auto &ls = jt.least_squares[c], &bu = jt.bottom_up[c], &pw = jt.power[c];
      if (ls && std::isfinite(ls->rrmse_percent)) least_squares[c].push_back(ls->rrmse_percent);
      if (bu && std::isfinite(bu->rrmse_percent)) bottom_up[c].push_back(bu->rrmse_percent);
      if (ls && std::isfinite(ls->rmse) && jt.mass_kg > 0) rmse_per_kg[c].push_back(ls->rmse / jt.mass_kg);
      if (pw && std::isfinite(pw->rrmse_percent)) power[c].push_back(pw->rrmse_percent);
    }
    const JointKineticPeaks &pe = jt.peaks_estimated, &pm = jt.peaks_measured;
    const std::array<std::pair<double, double>, 5> peaks = {{{pe.ankle_push_off_power_W, pm.ankle_push_off_power_W},
                                                             {pe.ankle_plantarflexor_moment_Nm, pm.ankle_plantarflexor_moment_Nm},
                                                             {pe.knee_extensor_moment_Nm, pm.knee_extensor_moment_Nm},
                                                             {pe.hip_extensor_moment_Nm, pm.hip_extensor_moment_Nm},
                                                             {pe.hip_flexor_moment_Nm, pm.hip_flexor_moment_Nm}}};
    for (std::size_t k = 0; k < peaks.size(); ++k)
      if (std::isfinite(peaks[k].first) && std::isfinite(peaks[k].second) && jt.mass_kg > 0) {
        peak_error[k].push_back(std::abs(peaks[k].first - peaks[k].second) / jt.mass_kg);
        peak_plates[k].push_back(peaks[k].second / jt.mass_kg);
      }
  }
  for (std::size_t c = 0; c < 3; ++c) {
    mm.torque_least_squares[c] = mean(least_squares[c]);
    mm.torque_bottom_up[c] = mean(bottom_up[c]);
    mm.torque_rmse_Nm_per_kg[c] = mean(rmse_per_kg[c]);
    mm.power[c] = mean(power[c]);
  }
  mm.ankle_push_off_error_W_per_kg = mean(peak_error[0]);
  mm.ankle_push_off_plates_W_per_kg = mean(peak_plates[0]);
  for (std::size_t k = 0; k < 4; ++k) {
    mm.moment_peak_error_Nm_per_kg[k] = mean(peak_error[1 + k]);
    mm.moment_peak_plates_Nm_per_kg[k] = mean(peak_plates[1 + k]);
  }
  for (std::size_t p = 0; p < 2; ++p) {
    const double plates = mean(x[3 + 2 * p]);
    mm.kam_peak_error_percent[p] = plates > 0 ? 100 * mean(x[2 + 2 * p]) / plates : kNaN;
  }
  const double plates_impulse = mean(impulse_plates);
  mm.kam_impulse_error_percent = plates_impulse > 0 ? 100 * mean(impulse_error) / plates_impulse : kNaN;
}
}  // namespace

MeanMetrics mean_rrmse(const std::vector<StanceValidation>& stances, int foot) {
  MeanMetrics mm;
  std::array<std::vector<double>, 5> vals;
  std::vector<double> lateral_rmse, cop_lateral_rmse, cop_rmse, onset_abs, loaded_span, double_support, single_support;
  double sq_double = 0, sq_all = 0;
  // The stance parameters' |estimate - plate| (peaks, % body weight; impulses, body weight x ms)
  // and the loading rate's |error| and plate value.
  std::array<std::vector<double>, 5> peak_errors;
  std::array<std::vector<double>, 2> impulse_errors;
  double rate_error_sum = 0, rate_plate_sum = 0;
  for (const auto& s : stances) {
    if (foot >= 0 && s.foot != foot) continue;
    if (s.body_weight_N > 0) {
      const StanceParameters &pe = s.parameters_estimated, &pm = s.parameters_measured;
      // The five peaks (x 100: % body weight), then the two impulses (x 1000: body weight x ms).
      const std::array<std::pair<double, double>, 7> pairs = {{{pe.vertical_first_peak_N, pm.vertical_first_peak_N},
                                                               {pe.vertical_valley_N, pm.vertical_valley_N},
                                                               {pe.vertical_second_peak_N, pm.vertical_second_peak_N},
                                                               {pe.braking_peak_N, pm.braking_peak_N},
                                                               {pe.propulsive_peak_N, pm.propulsive_peak_N},
                                                               {pe.braking_impulse_Ns, pm.braking_impulse_Ns},
                                                               {pe.propulsive_impulse_Ns, pm.propulsive_impulse_Ns}}};
      for (std::size_t k = 0; k < pairs.size(); ++k) {
        const auto [est, plate] = pairs[k];
        if (!(std::isfinite(est) && std::isfinite(plate))) continue;
        const double error = std::abs(est - plate);
        if (k < peak_errors.size()) peak_errors[k].push_back(100 * error / s.body_weight_N);
        else impulse_errors[k - peak_errors.size()].push_back(1000 * error / s.body_weight_N);
      }
      if (std::isfinite(pe.loading_rate_N_per_s) && std::isfinite(pm.loading_rate_N_per_s)) {
        rate_error_sum += std::abs(pe.loading_rate_N_per_s - pm.loading_rate_N_per_s);
        rate_plate_sum += pm.loading_rate_N_per_s;
      }
      if (s.double_support_frames > 0) double_support.push_back(100 * s.vertical_rmse_double_support_N / s.body_weight_N);
      if (s.single_support_frames > 0) single_support.push_back(100 * s.vertical_rmse_single_support_N / s.body_weight_N);
    }
    const double sq_d = s.double_support_frames > 0 ? s.double_support_frames * std::pow(s.vertical_rmse_double_support_N, 2) : 0.0;
    const double sq_s = s.single_support_frames > 0 ? s.single_support_frames * std::pow(s.vertical_rmse_single_support_N, 2) : 0.0;
    sq_double += sq_d;
    sq_all += sq_d + sq_s;
    if (s.onset_error_ms && std::isfinite(*s.onset_error_ms)) onset_abs.push_back(std::abs(*s.onset_error_ms));
    if (s.vertical_loaded_span && std::isfinite(s.vertical_loaded_span->rrmse_percent))
      loaded_span.push_back(s.vertical_loaded_span->rrmse_percent);
    const std::array<const std::optional<SeriesMetrics>*, 5> c = {&s.metrics.vertical, &s.metrics.anterior, &s.metrics.cop,
                                                                   &s.metrics.moment, &s.metrics.lateral};
    for (std::size_t k = 0; k < 5; ++k)
      if (*c[k] && std::isfinite((*c[k])->rrmse_percent) && !((k == 2 || k == 3) && s.cop_reference_suspect))
        vals[k].push_back((*c[k])->rrmse_percent);
    if (s.metrics.cop_lateral && std::isfinite(s.metrics.cop_lateral->rmse) && !s.cop_reference_suspect)
      cop_lateral_rmse.push_back(1000 * s.metrics.cop_lateral->rmse);
    if (s.metrics.cop && std::isfinite(s.metrics.cop->rmse) && !s.cop_reference_suspect) cop_rmse.push_back(1000 * s.metrics.cop->rmse);
    if (s.metrics.lateral && std::isfinite(s.metrics.lateral->rmse) && s.body_weight_N > 0)
      lateral_rmse.push_back(100 * s.metrics.lateral->rmse / s.body_weight_N);
    ++mm.n;
  }
  mean_joint_moments(stances, foot, mm);
  const auto mean_of = [](const std::vector<double>& x) {
    double sum = 0;
    for (double a : x) sum += a;
    return x.empty() ? kNaN : sum / static_cast<double>(x.size());
  };
  mm.cop_lateral_rmse_mm = mean_of(cop_lateral_rmse);
  mm.cop_rmse_mm = mean_of(cop_rmse);
  mm.onset_abs_ms = mean_of(onset_abs);
  mm.vertical_loaded_span = mean_of(loaded_span);
  mm.vertical_rmse_double_support_percent_bw = mean_of(double_support);
  mm.vertical_rmse_single_support_percent_bw = mean_of(single_support);
  mm.double_support_error_share_percent = sq_all > 0 ? 100 * sq_double / sq_all : kNaN;
  for (std::size_t k = 0; k < peak_errors.size(); ++k) mm.parameter_peak_error_percent_bw[k] = mean_of(peak_errors[k]);
  for (std::size_t k = 0; k < impulse_errors.size(); ++k) mm.parameter_impulse_error_bw_ms[k] = mean_of(impulse_errors[k]);
  mm.loading_rate_error_percent = rate_plate_sum > 0 ? 100 * rate_error_sum / rate_plate_sum : kNaN;
  mm.lateral_rmse_percent_bw = mean_of(lateral_rmse);
  std::array<double*, 5> mean = {&mm.vertical, &mm.anterior, &mm.cop, &mm.moment, &mm.lateral};
  std::array<double*, 5> sd = {&mm.vertical_sd, &mm.anterior_sd, &mm.cop_sd, &mm.moment_sd, &mm.lateral_sd};
  for (std::size_t k = 0; k < 5; ++k) {
    const auto& x = vals[k];
    if (x.empty()) {
      *mean[k] = *sd[k] = kNaN;
      continue;
    }
    *mean[k] = mean_of(x);
    double ss = 0;
    for (double a : x) ss += (a - *mean[k]) * (a - *mean[k]);
    *sd[k] = x.size() > 1 ? std::sqrt(ss / static_cast<double>(x.size() - 1)) : 0.0;
  }
  return mm;
}

namespace {

nlohmann::json num(double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); }
nlohmann::json opt(const std::optional<double>& x) { return x ? num(*x) : nlohmann::json(nullptr); }

nlohmann::json component_json(const ComponentMetrics& c, double bw) {
  auto field = [](const std::optional<SeriesMetrics>& m, auto get) { return m ? num(get(*m)) : nlohmann::json(nullptr); };
  const auto rr = [](const SeriesMetrics& m) { return m.rrmse_percent; };
  const auto rm = [](const SeriesMetrics& m) { return m.rmse; };
  const auto pr = [](const SeriesMetrics& m) { return m.pearson_r; };
  const auto pk = [](const SeriesMetrics& m) { return m.peak_difference; };
  nlohmann::json j;
  j["rrmse_percent"] = {{"vertical", field(c.vertical, rr)}, {"anterior", field(c.anterior, rr)},
                        {"cop", field(c.cop, rr)}, {"moment", field(c.moment, rr)}};
  j["rmse"] = {{"vertical_N", field(c.vertical, rm)}, {"anterior_N", field(c.anterior, rm)},
               {"cop_mm", c.cop ? num(1000 * c.cop->rmse) : nlohmann::json(nullptr)}, {"moment_Nm", field(c.moment, rm)}};
  j["rmse_percent_bw"] = {{"vertical", c.vertical ? num(100 * c.vertical->rmse / bw) : nlohmann::json(nullptr)},
                          {"anterior", c.anterior ? num(100 * c.anterior->rmse / bw) : nlohmann::json(nullptr)}};
  j["r"] = {{"vertical", field(c.vertical, pr)}, {"anterior", field(c.anterior, pr)}, {"cop", field(c.cop, pr)},
            {"moment", field(c.moment, pr)}};
  j["peak_difference"] = {{"vertical_N", field(c.vertical, pk)}, {"anterior_N", field(c.anterior, pk)},
                          {"moment_Nm", field(c.moment, pk)}};
  if (c.lateral) {  // with --mediolateral only: the sagittal model's JSON is unchanged
    j["rrmse_percent"]["lateral"] = num(c.lateral->rrmse_percent);
    j["rmse"]["lateral_N"] = num(c.lateral->rmse);
    j["rmse_percent_bw"]["lateral"] = num(100 * c.lateral->rmse / bw);
    j["r"]["lateral"] = num(c.lateral->pearson_r);
    j["peak_difference"]["lateral_N"] = num(c.lateral->peak_difference);
  }
  if (c.free_moment) j["rmse"]["free_moment_Nm"] = num(c.free_moment->rmse);  // the plate's RMS: the estimate's is 0
  if (c.cop_lateral) {
    j["rmse"]["cop_lateral_mm"] = num(1000 * c.cop_lateral->rmse);
    j["mean_error"] = {{"cop_lateral_mm", num(1000 * c.cop_lateral->mean_error)}};  // + = lateral of the plate's (right foot)
  }
  return j;
}

/// A series' comparison: rRMSE (%), RMSE (under `rmse_key`, in the series' unit), r; null when
/// there is none.
nlohmann::json metrics_json(const std::optional<SeriesMetrics>& m, const char* rmse_key) {
  return m ? nlohmann::json{{"rrmse_percent", num(m->rrmse_percent)}, {rmse_key, num(m->rmse)}, {"r", num(m->pearson_r)}}
           : nlohmann::json(nullptr);
}
/// A moment's (RMSE in N m) and a power's (W).
nlohmann::json moment_metrics_json(const std::optional<SeriesMetrics>& m) { return metrics_json(m, "rmse_Nm"); }
nlohmann::json power_metrics_json(const std::optional<SeriesMetrics>& m) { return metrics_json(m, "rmse_W"); }

/// A stance's 3D joint moments (ModelKind::ThreeD): per joint and plane the rRMSE, RMSE (N m) and
/// r, estimate-driven against plate-driven; the KAM's and its peaks.
nlohmann::json joint_moments_json(const JointMomentValidation& jm) {
  nlohmann::json j;
  const auto metrics = moment_metrics_json;
  for (std::size_t c = 0; c < 3; ++c) {
    j["ankle"][kPlaneNames[c]] = metrics(jm.ankle[c]);
    j["knee"][kPlaneNames[c]] = metrics(jm.knee[c]);
    j["hip"][kPlaneNames[c]] = metrics(jm.hip[c]);
  }
  j["knee_adduction_moment"] = metrics(jm.knee_adduction);
  j["knee_adduction_moment"]["peaks_estimated_Nm"] = {num(jm.kam_peak_estimated_Nm[0]), num(jm.kam_peak_estimated_Nm[1])};
  j["knee_adduction_moment"]["peaks_measured_Nm"] = {num(jm.kam_peak_measured_Nm[0]), num(jm.kam_peak_measured_Nm[1])};
  j["knee_adduction_moment"]["impulse_estimated_Nm_s"] = num(jm.kam_impulse_estimated_Nm_s);
  j["knee_adduction_moment"]["impulse_measured_Nm_s"] = num(jm.kam_impulse_measured_Nm_s);
  return j;
}

}  // namespace

nlohmann::json validation_json(const std::string& trial, const EstimateResult& e, const ValidationResult& v,
                               const nlohmann::json& settings) {
  const double bw = v.mass_kg * e.model().gravity_mps2;
  nlohmann::json j;
  j["trial"] = trial;
  j["kin2grf_version"] = KIN2GRF_VERSION;
  j["mass_kg"] = v.mass_kg;
  j["settings"] = settings;
  const auto stance_json = [&](const StanceValidation& s) {
    nlohmann::json x = component_json(s.metrics, bw);
    x["foot"] = side_name(s.foot);
    x["plate"] = s.plate;
    x["frames"] = {e.first_frame_number + s.first, e.first_frame_number + s.last};
    x["time_s"] = {e.time_s[s.first], e.time_s[s.last]};
    x["assign_distance_mm"] = 1000 * s.assign_distance_m;
    x["cop_beyond_foot_mm"] = num(1000 * s.cop_beyond_foot_m);
    x["foot_length_mm"] = num(1000 * s.foot_length_m);
    x["cop_rmse_percent_foot"] = s.metrics.cop ? num(100 * s.metrics.cop->rmse / s.foot_length_m) : nlohmann::json(nullptr);
    x["cop_reference_suspect"] = s.cop_reference_suspect;
    x["timing_ms"] = {{"onset", opt(s.onset_error_ms)},
                      {"offset", opt(s.offset_error_ms)},
                      {"onset_timed_by", s.onset_by_ramp ? "ramp" : "crossing"},
                      {"offset_timed_by", s.offset_by_ramp ? "ramp" : "crossing"},
                      {"onset_crossing", opt(s.onset_crossing_error_ms)},
                      {"offset_crossing", opt(s.offset_crossing_error_ms)},
                      {"onset_ramp", opt(s.onset_ramp_error_ms)},
                      {"offset_ramp", opt(s.offset_ramp_error_ms)},
                      {"vertical_lag", opt(s.vertical_lag_ms)}};
    x["loaded_span"] = {{"frames", {e.first_frame_number + s.span_first, e.first_frame_number + s.span_last}},
                        {"vertical_rrmse_percent", s.vertical_loaded_span ? num(s.vertical_loaded_span->rrmse_percent) : nlohmann::json(nullptr)},
                        {"vertical_rmse_percent_bw", s.vertical_loaded_span ? num(100 * s.vertical_loaded_span->rmse / bw) : nlohmann::json(nullptr)}};
    x["support_phases"] = {{"double_support_frames", s.double_support_frames},
                           {"single_support_frames", s.single_support_frames},
                           {"vertical_rmse_double_support_N", num(s.vertical_rmse_double_support_N)},
                           {"vertical_rmse_single_support_N", num(s.vertical_rmse_single_support_N)}};
    x["parameters"] = {{"estimated", stance_parameters_json(s.parameters_estimated, s.body_weight_N)},
                       {"measured", stance_parameters_json(s.parameters_measured, s.body_weight_N)}};
    if (s.moments_3d) x["joint_moments_3d"] = joint_moments_json(*s.moments_3d);
    if (s.torques) {
      for (std::size_t c = 0; c < 3; ++c)
        x["joint_torques"][kLegJointNames[c]] = {{"least_squares", moment_metrics_json(s.torques->least_squares[c])},
                                         {"bottom_up", moment_metrics_json(s.torques->bottom_up[c])},
                                         {"power", power_metrics_json(s.torques->power[c])}};
      x["joint_torques"]["peaks"] = {{"estimated", joint_kinetic_peaks_json(s.torques->peaks_estimated, s.torques->mass_kg)},
                                     {"measured", joint_kinetic_peaks_json(s.torques->peaks_measured, s.torques->mass_kg)}};
    }
    return x;
  };
  j["per_foot"] = nlohmann::json::array();
  for (const auto& s : v.stances) j["per_foot"].push_back(stance_json(s));
  j["cut_stances"] = nlohmann::json::array();
  for (const auto& s : v.cut_stances) j["cut_stances"].push_back(stance_json(s));
  if (v.total) {
    nlohmann::json x = component_json(v.total->metrics, bw);
    x["frames_compared"] = v.total->frames.size();
    x["grm_reference_m"] = {v.total->grm_reference_m.x(), v.total->grm_reference_m.y()};
    x["implied_mass_kg"] = num(v.total->implied_mass_kg);
    if (v.total->frontal_moment || v.total->transverse_moment) {
      x["frontal_moment"] = moment_metrics_json(v.total->frontal_moment);
      x["transverse_moment"] = moment_metrics_json(v.total->transverse_moment);
      x["lateral_reference_m"] = num(v.total->lateral_reference_m);
    }
    j["total"] = x;
  } else {
    j["total"] = nullptr;
  }
  nlohmann::json means;
  for (int f = -1; f < 2; ++f) {
    const MeanMetrics m = mean_rrmse(v.stances, f);
    means[f < 0 ? "all" : side_name(f)] = {{"stances", m.n},         {"vertical", num(m.vertical)}, {"anterior", num(m.anterior)},
                                            {"cop", num(m.cop)},      {"moment", num(m.moment)},
                                            {"vertical_loaded_span", num(m.vertical_loaded_span)},
                                            {"vertical_rmse_double_support_percent_bw", num(m.vertical_rmse_double_support_percent_bw)},
                                            {"vertical_rmse_single_support_percent_bw", num(m.vertical_rmse_single_support_percent_bw)},
                                            {"double_support_error_share_percent", num(m.double_support_error_share_percent)},
                                            {"parameter_errors",
                                             {{"vertical_first_peak_percent_bw", num(m.parameter_peak_error_percent_bw[0])},
                                              {"vertical_valley_percent_bw", num(m.parameter_peak_error_percent_bw[1])},
                                              {"vertical_second_peak_percent_bw", num(m.parameter_peak_error_percent_bw[2])},
                                              {"braking_peak_percent_bw", num(m.parameter_peak_error_percent_bw[3])},
                                              {"propulsive_peak_percent_bw", num(m.parameter_peak_error_percent_bw[4])},
                                              {"braking_impulse_bw_ms", num(m.parameter_impulse_error_bw_ms[0])},
                                              {"propulsive_impulse_bw_ms", num(m.parameter_impulse_error_bw_ms[1])},
                                              {"loading_rate_percent", num(m.loading_rate_error_percent)}}}};
    if (std::isfinite(m.torque_least_squares[0])) {
      auto& x = means[f < 0 ? "all" : side_name(f)];
      for (std::size_t c = 0; c < 3; ++c)
        x["joint_torques"][kLegJointNames[c]] = {{"least_squares", num(m.torque_least_squares[c])},
                                         {"bottom_up", num(m.torque_bottom_up[c])},
                                         {"least_squares_rmse_Nm_per_kg", num(m.torque_rmse_Nm_per_kg[c])},
                                         {"power", num(m.power[c])}};
      x["joint_torques"]["ankle_push_off_error_W_per_kg"] = num(m.ankle_push_off_error_W_per_kg);
      x["joint_torques"]["ankle_push_off_plates_W_per_kg"] = num(m.ankle_push_off_plates_W_per_kg);
      const char* moments[] = {"ankle_plantarflexor", "knee_extensor", "hip_extensor", "hip_flexor"};
      for (std::size_t k = 0; k < 4; ++k)
        x["joint_torques"]["moment_peaks"][moments[k]] = {{"error_Nm_per_kg", num(m.moment_peak_error_Nm_per_kg[k])},
                                                          {"plates_Nm_per_kg", num(m.moment_peak_plates_Nm_per_kg[k])}};
    }
    if (std::isfinite(m.knee_adduction)) {
      auto& x = means[f < 0 ? "all" : side_name(f)];
      x["knee_sagittal_moment"] = num(m.knee_sagittal);
      x["knee_adduction_moment"] = num(m.knee_adduction);
      x["knee_adduction_moment_peak_error_percent"] = {num(m.kam_peak_error_percent[0]), num(m.kam_peak_error_percent[1])};
      x["knee_adduction_moment_impulse_error_percent"] = num(m.kam_impulse_error_percent);
    }
    if (std::isfinite(m.lateral_rmse_percent_bw)) {
      means[f < 0 ? "all" : side_name(f)]["lateral"] = num(m.lateral);
      means[f < 0 ? "all" : side_name(f)]["lateral_rmse_percent_bw"] = num(m.lateral_rmse_percent_bw);
      means[f < 0 ? "all" : side_name(f)]["cop_lateral_rmse_mm"] = num(m.cop_lateral_rmse_mm);
    }
  }
  j["mean_rrmse_percent"] = means;
  if (v.sync)
    j["sync"] = {{"estimated_offset_ms", 1000 * v.sync->offset_s},
                 {"uncertainty_ms", 1000 * v.sync->uncertainty_s},
                 {"frames", v.sync->frames},
                 {"total_vertical_error_as_recorded_N", v.sync->error_as_recorded_N},
                 {"total_vertical_error_at_offset_N", v.sync->error_at_offset_N},
                 {"applied_shift_ms", 1000 * v.plate_shift_s}};
  else
    j["sync"] = {{"estimated_offset_ms", nullptr}, {"applied_shift_ms", 1000 * v.plate_shift_s}};
  nlohmann::json rises = nlohmann::json::array();
  for (const PlateOnsetRise& r : v.plate_onsets)
    rises.push_back({{"plate", r.plate},
                     {"onsets", r.onsets},
                     {"rise_ms", num(r.rise_ms)},
                     {"high_frequency_rms_N", num(r.high_frequency_rms_N)},
                     {"zero_below_threshold", r.zero_below_threshold},
                     {"filtered", r.filtered()}});
  j["plate_onsets"] = rises;
  j["excluded"] = v.excluded;
  j["notes"] = v.notes;
  return j;
}

namespace {
// The plain-text table's columns: a 30-character label, then 12-character cells (a value, or mean (SD)).
/// A table cell right-aligned in `width` characters (12: an rRMSE's; the KAM's peaks and impulse,
/// "[0.48/-0.03]", take 14).
std::string table_text(const std::string& t, int width = 12) {
  char b[64];
  std::snprintf(b, sizeof b, "%*s", width, t.c_str());
  return std::string(b);
}
/// An rRMSE cell; `bracketed`: a stance whose plate fails the registration check (not scored).
std::string table_cell(const std::optional<SeriesMetrics>& m, bool bracketed = false) {
  char b[40];
  if (!(m && std::isfinite(m->rrmse_percent))) return table_text("-");
  std::snprintf(b, sizeof b, bracketed ? "[%.1f]" : "%.1f", m->rrmse_percent);
  return table_text(b);
}
std::string table_msd(double mean, double sd) {
  char b[40];
  if (!std::isfinite(mean)) return table_text("-");
  std::snprintf(b, sizeof b, "%.1f (%.1f)", mean, sd);
  return table_text(b);
}
/// `x` printed with `fmt`, or "-" where it does not exist (the lines under the table).
std::string number_or_dash(double x, const char* fmt = "%.1f") {
  char t[40];
  if (!std::isfinite(x)) return "-";
  std::snprintf(t, sizeof t, fmt, x);
  return t;
}
std::string table_label(const std::string& l) {
  char b[64];
  std::snprintf(b, sizeof b, "  %-28s", l.c_str());
  return std::string(b);
}

/// The mediolateral rows (--mediolateral): per stance rRMSE, RMSE in % body weight, r and the
/// lateral COP's RMSE, then their means.
void format_lateral_rows(std::ostream& os, const ValidationResult& v, const MeanMetrics& m) {
  char buf[64];
  os << table_label("mediolateral force") << table_text("rRMSE %") << table_text("RMSE %BW") << table_text("r") << table_text("COP mm")
     << table_text("free N m") << "   free: the plate's free moment's RMS (the estimate's is zero)\n";
  for (const auto& s : v.stances) {
    if (!s.metrics.lateral) continue;
    char pct[40], r[40];
    std::snprintf(pct, sizeof pct, "%.1f", 100 * s.metrics.lateral->rmse / s.body_weight_N);
    std::snprintf(r, sizeof r, "%.2f", s.metrics.lateral->pearson_r);
    char cop[40] = "-";
    if (s.metrics.cop_lateral)
      std::snprintf(cop, sizeof cop, s.cop_reference_suspect ? "[%.0f]" : "%.0f", 1000 * s.metrics.cop_lateral->rmse);
    char free[40] = "-";
    if (s.metrics.free_moment)
      std::snprintf(free, sizeof free, s.cop_reference_suspect ? "[%.1f]" : "%.1f", s.metrics.free_moment->rmse);
    os << table_label(std::string(side_name(s.foot)) + " foot on " + s.plate) << table_cell(s.metrics.lateral) << table_text(pct)
       << table_text(r) << table_text(cop) << table_text(free) << "\n";
  }
  std::snprintf(buf, sizeof buf, "%.1f", m.lateral_rmse_percent_bw);
  os << table_label("per foot, mean (SD)") << table_msd(m.lateral, m.lateral_sd) << table_text(buf) << table_text("-");
  std::snprintf(buf, sizeof buf, "%.0f", m.cop_lateral_rmse_mm);
  os << table_text(buf);
  double free = 0;
  int n = 0;
  for (const auto& s : v.stances)
    if (s.metrics.free_moment && !s.cop_reference_suspect) free += s.metrics.free_moment->rmse, ++n;
  os << table_text(n ? number_or_dash(free / n) : "-") << "\n";
}
/// The 3D joint moments' rows (--model 3d): per stance the knee's sagittal and adduction moments'
/// rRMSE, the KAM's two peaks and its impulse, estimate-driven / plate-driven, then the means; in
/// brackets (not in the means) where the plate fails the registration check, since its moments
/// take its COP.
void format_joint_moment_rows(std::ostream& os, const ValidationResult& v, const MeanMetrics& m, double mass_kg) {
  // The peaks' and the impulse's cells are wider than an rRMSE's: "[0.48/-0.03]" fills twelve.
  const auto wide = [](const std::string& t) { return table_text(t, 14); };
  char a[40], b[40], imp[40];
  os << table_label("3D knee moments") << table_text("sagittal %") << table_text("KAM %") << wide("KAM peak 1") << wide("KAM peak 2")
     << wide("KAM impulse") << "   N m/kg and N m s/kg, estimate / plates\n";
  for (const auto& s : v.stances) {
    if (!s.moments_3d) continue;
    const JointMomentValidation& j = *s.moments_3d;
    const char* peak = s.cop_reference_suspect ? "[%.2f/%.2f]" : "%.2f/%.2f";
    std::snprintf(a, sizeof a, peak, j.kam_peak_estimated_Nm[0] / mass_kg, j.kam_peak_measured_Nm[0] / mass_kg);
    std::snprintf(b, sizeof b, peak, j.kam_peak_estimated_Nm[1] / mass_kg, j.kam_peak_measured_Nm[1] / mass_kg);
    std::snprintf(imp, sizeof imp, s.cop_reference_suspect ? "[%.3f/%.3f]" : "%.3f/%.3f", j.kam_impulse_estimated_Nm_s / mass_kg,
                  j.kam_impulse_measured_Nm_s / mass_kg);
    os << table_label(std::string(side_name(s.foot)) + " foot on " + s.plate) << table_cell(j.knee[0], s.cop_reference_suspect)
       << table_cell(j.knee_adduction, s.cop_reference_suspect) << wide(a) << wide(b) << wide(imp) << "\n";
  }
  const auto cell = [](double x, const char* unit) {
    char c[40];
    std::snprintf(c, sizeof c, "%.1f%s", x, unit);
    return std::isfinite(x) ? std::string(c) : std::string("-");
  };
  os << table_label("per foot, mean; peaks |error|") << table_text(cell(m.knee_sagittal, "")) << table_text(cell(m.knee_adduction, ""))
     << wide(cell(m.kam_peak_error_percent[0], " %")) << wide(cell(m.kam_peak_error_percent[1], " %"))
     << wide(cell(m.kam_impulse_error_percent, " %")) << "\n";
  // Every joint in every plane, over the stances whose plate passes the registration check (the
  // report's table, the JSON's joint_moments_3d): what the estimate does to each moment.
  os << "  per foot, 3D joint moments' mean rRMSE % hip / knee / ankle:";
  for (int plane = 0; plane < 3; ++plane) {
    std::array<double, 3> mean{};
    for (int joint = 0; joint < 3; ++joint) {
      double sum = 0;
      int n = 0;
      for (const auto& s : v.stances) {
        if (!s.moments_3d || s.cop_reference_suspect) continue;
        const JointMomentValidation& j = *s.moments_3d;
        const auto& metric = (joint == 0 ? j.hip : joint == 1 ? j.knee : j.ankle)[static_cast<std::size_t>(plane)];
        if (metric && std::isfinite(metric->rrmse_percent)) sum += metric->rrmse_percent, ++n;
      }
      mean[static_cast<std::size_t>(joint)] = n ? sum / n : std::numeric_limits<double>::quiet_NaN();
    }
    char text[96];
    std::snprintf(text, sizeof text, "%s %s %.1f / %.1f / %.1f", plane ? "," : "", kPlaneNames[plane], mean[0], mean[1], mean[2]);
    os << text;
  }
  os << "\n";
}

/// The total GRM row's tail: its RMSE in N m and the range Eq. 12 divides by (the mean of the
/// estimate's and the plates' ranges). A window of single support spans a few tens of N m, where a
/// few N m read as many percent; the N m say which.
std::string total_grm_note(const TotalValidation& t) {
  const auto& m = t.metrics.moment;
  if (!m || !(m->rrmse_percent > 0)) return "";
  char buf[96];
  std::snprintf(buf, sizeof buf, "   GRM RMSE %.1f N m of a %.0f N m range", m->rmse, m->rmse / (m->rrmse_percent / 100));
  return buf;
}
}  // namespace

ResultsTable validation_stance_curves_table(const EstimateResult& e, const ValidationResult& v, int points) {
  const bool lateral = e.feet[0].force_lateral_N.size() > 0 && v.measured_lateral_N[0].size() > 0;
  ResultsTable t;
  t.columns = {"side", "plate", "frame_first", "start_s", "duration_s", "percent", "vertical_bw_estimate", "vertical_bw_plate",
               "anterior_bw_estimate", "anterior_bw_plate"};
  if (lateral) t.columns.insert(t.columns.end(), {"lateral_bw_estimate", "lateral_bw_plate"});
  t.columns.insert(t.columns.end(), {"cop_progression_m_estimate", "cop_progression_m_plate"});
  // The 3D model: the external knee adduction moment by inverse dynamics with each ground reaction
  // on the same kinematics (validate_joint_moments_3d), N m per kg.
  const bool kam = e.legs_3d.has_value() && v.measured_moments_3d.has_value();
  if (kam) {
    t.columns.insert(t.columns.end(), {"knee_adduction_moment_Nm_per_kg_estimate", "knee_adduction_moment_Nm_per_kg_plate"});
    // And every joint's moments in every plane with each ground reaction (the estimate's
    // --stance-curves columns, the per-frame CSV's order).
    for (const char* joint : kJoint3DNames)
      for (const char* plane : kPlaneNames)
        for (const char* which : {"_estimate", "_plate"}) t.columns.push_back(joint_moment_curve_name(joint, plane) + which);
  }
  const double bw = e.mass_kg * e.model().gravity_mps2;
  const auto nan = std::numeric_limits<double>::quiet_NaN();
  const Eigen::Index series_columns = static_cast<Eigen::Index>(t.columns.size()) - 6;
  t.values.resize(static_cast<Eigen::Index>(v.stances.size()) * points, static_cast<Eigen::Index>(t.columns.size()));
  Eigen::Index out = 0;
  for (const StanceValidation& st : v.stances) {
    const auto f = static_cast<std::size_t>(st.foot);
    const FootResult& foot = e.feet[f];
    const Eigen::Index frames = st.last - st.first + 1;
    Eigen::MatrixXd series(frames, series_columns);
    double origin = nan;
    for (Eigen::Index k = 0; k < frames && !std::isfinite(origin); ++k) origin = v.measured_cop_x_m[f][st.first + k];
    if (st.cop_reference_suspect) origin = nan;  // a misplaced plate's COP: not compared
    for (Eigen::Index k = 0; k < frames; ++k) {
      const Eigen::Index i = st.first + k;
      Eigen::Index c = 0;
      series(k, c++) = foot.force_N(i, 1) / bw;
      series(k, c++) = v.measured_force_N[f](i, 1) / bw;
      series(k, c++) = foot.force_N(i, 0) / bw;
      series(k, c++) = v.measured_force_N[f](i, 0) / bw;
      if (lateral) {
        series(k, c++) = foot.force_lateral_N[i] / bw;
        series(k, c++) = v.measured_lateral_N[f][i] / bw;
      }
      const bool compared = std::isfinite(v.measured_cop_x_m[f][i]);  // where the plate's COP is over its threshold
      // Over the ground: on a treadmill over the belt, which carries the foot back (0 overground).
      const double belt = e.calibration.belt_velocity_mps * (e.time_s[i] - e.time_s[st.first]);
      series(k, c++) = compared ? foot.cop_x_m[i] - origin - belt : nan;
      series(k, c++) = v.measured_cop_x_m[f][i] - origin - belt;
      if (kam) {
        // A misplaced plate's moments take its COP as their lever: not compared, as the means do.
        series(k, c++) = knee_adduction_moment(e.legs_3d->moments, st.foot, i) / e.mass_kg;
        series(k, c++) = st.cop_reference_suspect ? nan : knee_adduction_moment(*v.measured_moments_3d, st.foot, i) / e.mass_kg;
        for (int joint = 0; joint < 3; ++joint)
          for (int a = 0; a < 3; ++a) {
            series(k, c++) = joint_moments_of(e.legs_3d->moments, joint, st.foot)(i, a) / e.mass_kg;
            series(k, c++) = st.cop_reference_suspect ? nan : joint_moments_of(*v.measured_moments_3d, joint, st.foot)(i, a) / e.mass_kg;
          }
      }
    }
    const Eigen::MatrixXd curves = stance_normalised(series, 0, frames - 1, points);
    for (int k = 0; k < points; ++k, ++out) {
      t.values(out, 0) = st.foot;
      t.values(out, 1) = st.plate_index;
      t.values(out, 2) = static_cast<double>(v.first_frame_number + st.first);
      t.values(out, 3) = e.time_s[st.first];
      t.values(out, 4) = static_cast<double>(frames) / e.motion.rate_hz;
      t.values(out, 5) = 100.0 * k / (points - 1);
      t.values.row(out).tail(series_columns) = curves.row(k);
    }
  }
  return t;
}

std::string validation_stance_curves_csv(const EstimateResult& e, const ValidationResult& v) {
  const ResultsTable t = validation_stance_curves_table(e, v);
  std::string out;
  for (std::size_t k = 0; k < t.columns.size(); ++k) (out += k ? "," : "") += t.columns[k];
  out += '\n';
  for (Eigen::Index i = 0; i < t.values.rows(); ++i)
    append_stance_curve_row(out, static_cast<int>(t.values(i, 0)), &v.plates[static_cast<std::size_t>(t.values(i, 1))].name,
                            t.values(i, 2), t.values(i, 3), t.values.row(i).tail(t.values.cols() - 4));
  return out;
}

std::string format_validation_table(const std::string& trial, const ValidationResult& v) {
  std::ostringstream os;
  char buf[256];
  os << "kin2grf validate: " << trial << " (body mass " << v.mass_kg << " kg)\n";
  os << table_label("rRMSE % (paper's Eq. 12)") << table_text("vertical") << table_text("anterior") << table_text("COP") << table_text("moment")
     << "   frames\n";
  for (const auto& s : v.stances) {
    os << table_label(std::string(side_name(s.foot)) + " foot on " + s.plate) << table_cell(s.metrics.vertical)
       << table_cell(s.metrics.anterior) << table_cell(s.metrics.cop, s.cop_reference_suspect)
       << table_cell(s.metrics.moment, s.cop_reference_suspect);
    std::snprintf(buf, sizeof buf, "   %ld-%ld\n", static_cast<long>(v.first_frame_number + s.first),
                  static_cast<long>(v.first_frame_number + s.last));
    os << buf;
  }
  for (const auto& s : v.cut_stances) {
    os << table_label(std::string(side_name(s.foot)) + " foot on " + s.plate + ", cut") << table_cell(s.metrics.vertical)
       << table_cell(s.metrics.anterior) << table_cell(s.metrics.cop, s.cop_reference_suspect)
       << table_cell(s.metrics.moment, s.cop_reference_suspect);
    std::snprintf(buf, sizeof buf, "   %ld-%ld, vertical RMSE %.1f %%BW", static_cast<long>(v.first_frame_number + s.first),
                  static_cast<long>(v.first_frame_number + s.last),
                  s.metrics.vertical ? 100 * s.metrics.vertical->rmse / s.body_weight_N : std::nan(""));
    os << buf;
    // A quiet stance's COP barely moves: its error in mm, not over its range.
    if (s.metrics.cop) {
      std::snprintf(buf, sizeof buf, ", COP RMSE %.0f mm", 1000 * s.metrics.cop->rmse);
      os << buf;
    }
    os << "\n";
  }
  if (!v.cut_stances.empty())
    os << "  (cut: a stance cut by the processed window's ends, compared over its frames in the window and out of the means)\n";
  if (v.stances.empty() && v.cut_stances.empty()) os << "  (no stance on a plate could be compared)\n";
  const MeanMetrics m = mean_rrmse(v.stances);
  if (m.n > 0)
    os << table_label("per foot, mean (SD), n = " + std::to_string(m.n)) << table_msd(m.vertical, m.vertical_sd)
       << table_msd(m.anterior, m.anterior_sd) << table_msd(m.cop, m.cop_sd) << table_msd(m.moment, m.moment_sd) << "\n";
  if (m.n > 0 && std::isfinite(m.cop_rmse_mm)) {
    // The COP's error in mm and in % of the foot's length beside its rRMSE (issue 29): an rRMSE
    // divides by the COP's range, a few cm overground and half a metre on a treadmill.
    double percent = 0;
    int n = 0;
    for (const auto& s : v.stances)
      if (s.metrics.cop && !s.cop_reference_suspect && s.foot_length_m > 0) percent += 100 * s.metrics.cop->rmse / s.foot_length_m, ++n;
    std::snprintf(buf, sizeof buf, "  per foot, COP RMSE %.1f mm, %s %% of the foot's length (heel to toe sole points)\n", m.cop_rmse_mm,
                  n ? number_or_dash(percent / n).c_str() : "-");
    os << buf;
  }
  if (m.n > 0 && std::isfinite(m.vertical_loaded_span)) {
    // The early and late loaded frames the stance columns do not see.
    long early = 0, late = 0;
    for (const auto& s : v.stances) early += static_cast<long>(s.first - s.span_first), late += static_cast<long>(s.span_last - s.last);
    std::snprintf(buf, sizeof buf, "%.1f", m.vertical_loaded_span);
    os << table_label("per foot, loaded span") << table_text(buf);
    std::snprintf(buf, sizeof buf, "   vertical with the foot's load before its plate's onset (%ld frames) and after its offset (%ld)\n", early, late);
    os << buf;
  }
  if (m.n > 0 && std::isfinite(m.double_support_error_share_percent)) {
    std::snprintf(buf, sizeof buf, "  per foot, vertical RMSE in double / single support: %s / %s %% body weight; %.0f %% of the squared error "
                                   "in double support\n",
                  number_or_dash(m.vertical_rmse_double_support_percent_bw).c_str(),
                  number_or_dash(m.vertical_rmse_single_support_percent_bw).c_str(), m.double_support_error_share_percent);
    os << buf;
  }
  if (m.n > 0) {
    // Contact timing: the mean |onset| and |offset|, and which reference timed them (Timing).
    double on = 0, off = 0;
    int n_on = 0, n_off = 0, on_ramp = 0, off_ramp = 0;
    for (const auto& s : v.stances) {
      if (s.onset_error_ms) on += std::abs(*s.onset_error_ms), ++n_on;
      if (s.offset_error_ms) off += std::abs(*s.offset_error_ms), ++n_off;
      on_ramp += s.onset_by_ramp ? 1 : 0;
      off_ramp += s.offset_by_ramp ? 1 : 0;
    }
    const auto count = static_cast<int>(v.stances.size());
    const auto by = [count](int ramps, const char* ramp) {
      if (ramps == 0) return std::string("the threshold's crossings");
      if (ramps == count) return std::string(ramp);
      return std::to_string(ramps) + " by " + ramp + ", " + std::to_string(count - ramps) + " by the crossings";
    };
    os << "  per foot, contact timing, mean |estimate - plates|: onset " << number_or_dash(n_on ? on / n_on : std::nan(""), "%.0f")
       << " ms (" << by(on_ramp, "the loading ramp's zero intercept") << "), offset "
       << number_or_dash(n_off ? off / n_off : std::nan(""), "%.0f") << " ms (" << by(off_ramp, "the unloading ramp's zero intercept")
       << ")\n";
  }
  if (m.n > 0 && std::isfinite(m.parameter_peak_error_percent_bw[0])) {
    const auto& pk = m.parameter_peak_error_percent_bw;
    os << "  per foot, stance parameters' mean |estimate - plates|: vertical first peak / valley / second peak " << number_or_dash(pk[0])
       << " / " << number_or_dash(pk[1]) << " / " << number_or_dash(pk[2]) << " % body weight, braking / propulsive peak "
       << number_or_dash(pk[3]) << " / " << number_or_dash(pk[4]) << " % body weight, braking / propulsive impulse "
       << number_or_dash(m.parameter_impulse_error_bw_ms[0]) << " / " << number_or_dash(m.parameter_impulse_error_bw_ms[1])
       << " body weight ms, loading rate " << number_or_dash(m.loading_rate_error_percent, "%.0f") << " %\n";
  }
  if (m.n > 0 && std::isfinite(m.torque_least_squares[0])) {
    const auto& ls = m.torque_least_squares;
    const auto& bu = m.torque_bottom_up;
    os << "  per foot, sagittal joint torques against the plates' inverse dynamics, rRMSE % hip / knee / ankle: " << number_or_dash(ls[0])
       << " / " << number_or_dash(ls[1]) << " / " << number_or_dash(ls[2]) << " (kin2grf's, RMSE "
       << number_or_dash(m.torque_rmse_Nm_per_kg[0], "%.2f") << " / " << number_or_dash(m.torque_rmse_Nm_per_kg[1], "%.2f") << " / "
       << number_or_dash(m.torque_rmse_Nm_per_kg[2], "%.2f") << " N m/kg); " << number_or_dash(bu[0]) << " / " << number_or_dash(bu[1])
       << " / " << number_or_dash(bu[2]) << " bottom-up from its forces\n";
    os << "  per foot, joint powers, rRMSE % hip / knee / ankle: " << number_or_dash(m.power[0]) << " / " << number_or_dash(m.power[1])
       << " / " << number_or_dash(m.power[2]) << "; ankle push-off peak mean |kin2grf - plates| "
       << number_or_dash(m.ankle_push_off_error_W_per_kg, "%.2f") << " W/kg (plates " << number_or_dash(m.ankle_push_off_plates_W_per_kg, "%.2f")
       << " W/kg)\n";
    const auto& pe = m.moment_peak_error_Nm_per_kg;
    os << "  per foot, moment peaks' mean |kin2grf - plates|: ankle plantarflexor / knee extensor / hip extensor / hip flexor "
       << number_or_dash(pe[0], "%.2f") << " / " << number_or_dash(pe[1], "%.2f") << " / " << number_or_dash(pe[2], "%.2f") << " / "
       << number_or_dash(pe[3], "%.2f") << " N m/kg\n";
  }
  if (std::isfinite(m.lateral_rmse_percent_bw)) format_lateral_rows(os, v, m);
  if (std::isfinite(m.knee_adduction)) format_joint_moment_rows(os, v, m, v.mass_kg);
  if (v.total)
    os << table_label("total, GRM (" + std::to_string(v.total->frames.size()) + " frames)") << table_cell(v.total->metrics.vertical)
       << table_cell(v.total->metrics.anterior) << table_text("-") << table_cell(v.total->metrics.moment) << total_grm_note(*v.total) << "\n";
  if (v.total && v.total->frontal_moment && v.total->transverse_moment) {
    // The 3D totals (validate_total_3d): the ground reaction's frontal and transverse moments about
    // the GRM reference on the walker's midline, the plates' free moments in theirs.
    std::snprintf(buf, sizeof buf, "  total, frontal / transverse moment rRMSE %% %.1f / %.1f (RMSE %.1f / %.1f N m)\n",
                  v.total->frontal_moment->rrmse_percent, v.total->transverse_moment->rrmse_percent, v.total->frontal_moment->rmse,
                  v.total->transverse_moment->rmse);
    os << buf;
  }
  os << table_label("paper, Table 1 (24 gait)") << table_text("4.1 (1.1)") << table_text("11.2 (1.7)") << table_text("-") << table_text("5.3 (1.1)") << "\n";
  os << table_label("Fluit et al. (paper's Tab. 1)") << table_text("2.7") << table_text("9.3") << table_text("-") << table_text("7.4") << "\n";
  if (v.sync) {
    std::snprintf(buf, sizeof buf, "marker-plate offset: %+.0f ms (+-%.1f; + = the plates lead; median |plates - kinematics| of the total vertical force "
                                   "%.0f N as recorded, %.0f N at the offset); applied: %+.0f ms\n",
                  1000 * v.sync->offset_s, 1000 * v.sync->uncertainty_s, v.sync->error_as_recorded_N, v.sync->error_at_offset_N,
                  1000 * v.plate_shift_s);
    os << buf;
  }
  for (const auto& x : v.excluded) os << "excluded: " << x << "\n";
  for (const auto& x : v.notes) os << "note: " << x << "\n";
  return os.str();
}

}  // namespace kin2grf
