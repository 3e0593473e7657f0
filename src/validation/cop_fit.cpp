#include "kin2grf/validation/cop_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>

#include "kin2grf/error.hpp"
#include "kin2grf/io/cop_function.hpp"

namespace kin2grf {
namespace {

/// F(theta) = w . (s_hs, s_ho, s_mo, s_to): the weights of CopFunction::fraction.
Eigen::Vector4d weights(const CopFunction& f, double th) {
  Eigen::Vector4d w = Eigen::Vector4d::Zero();
  auto hc = [](double u) { return 0.5 * (1.0 - std::cos(M_PI * u)); };
  if (th <= f.delta_hs) {
    w[0] = 1;
  } else if (th <= f.delta_ho) {
    const double c = hc((th - f.delta_hs) / (f.delta_ho - f.delta_hs));
    w[0] = 1 - c, w[1] = c;
  } else if (th <= f.delta_mo) {
    const double c = hc((th - f.delta_ho) / (f.delta_mo - f.delta_ho));
    w[1] = 1 - c, w[2] = c;
  } else if (th <= f.delta_to) {
    const double c = (th - f.delta_mo) / (f.delta_to - f.delta_mo);
    w[2] = 1 - c, w[3] = c;
  } else {
    w[3] = 1;
  }
  return w;
}

/// The least-squares positions with the COP rolling forward: s_HS <= s_HO <= s_MO <= s_TO. The
/// foot turns forward through the stance, heel strike to toe-off, and the COP rolls forward under
/// it (the paper's Fig. 3 and every plate's stance); a fit whose positions fall from one event to
/// the next has fitted something else (a lab's heel-strike transient, a ridge-held event no sample
/// reaches) and moves the COP backwards under a foot that turns on. Pool adjacent violators: two
/// positions out of order are tied (one column, the sum of their weights) and the problem solved
/// again, until the order holds (at most three ties). Columns past the fourth (the centre-of-mass
/// gain) stay free.
Eigen::VectorXd solve_rolling_forward(const Eigen::MatrixXd& Wa, const Eigen::VectorXd& ya) {
  const Eigen::Index p = Wa.cols();
  Eigen::VectorXd s = Wa.colPivHouseholderQr().solve(ya);
  std::array<int, 4> group{0, 1, 2, 3};  // the event positions' tie groups, in order
  for (int pass = 0; pass < 3; ++pass) {
    bool ordered = true;
    for (int k = 0; k < 3; ++k)
      if (group[static_cast<std::size_t>(k)] != group[static_cast<std::size_t>(k + 1)] && s[k] > s[k + 1]) {
        ordered = false;
        const int from = group[static_cast<std::size_t>(k + 1)], to = group[static_cast<std::size_t>(k)];
        for (int& g : group)
          if (g == from) g = to;
      }
    if (ordered) break;
    // Tie matrix T: s = T t, one column per group, then the free columns.
    std::array<int, 4> column{};
    Eigen::Index groups = 0;
    for (int k = 0; k < 4; ++k) {
      const bool first = k == 0 || group[static_cast<std::size_t>(k)] != group[static_cast<std::size_t>(k - 1)];
      if (first) ++groups;
      column[static_cast<std::size_t>(k)] = static_cast<int>(groups - 1);
    }
    Eigen::MatrixXd T = Eigen::MatrixXd::Zero(p, groups + (p - 4));
    for (int k = 0; k < 4; ++k) T(k, column[static_cast<std::size_t>(k)]) = 1.0;
    for (Eigen::Index j = 4; j < p; ++j) T(j, groups + (j - 4)) = 1.0;
    s = T * (Wa * T).colPivHouseholderQr().solve(ya);
  }
  return s;
}

}  // namespace

void collect_cop_samples(const EstimateResult& e, const ValidationResult& v, double min_force_fraction, CopLength length,
                         CopSamples& out) {
  const double bw = e.mass_kg * e.model().gravity_mps2;
  for (const auto& s : v.stances) {
    if (s.cop_reference_suspect) continue;  // the plate's COP is not where the foot is
    const FootResult& f = e.feet[static_cast<std::size_t>(s.foot)];
    const MeasuredPlate* mp = nullptr;
    for (const auto& p : v.plates)
      if (p.name == s.plate) mp = &p;
    if (!mp) continue;
    for (Eigen::Index i = s.first; i <= s.last; ++i) {
      if (!(mp->force_N(i, 1) > min_force_fraction * bw) || !std::isfinite(mp->cop_x_m[i])) continue;
      const Eigen::Vector2d A(f.sole_m(i, 0), f.sole_m(i, 1)), B(f.sole_m(i, 2), f.sole_m(i, 3)), C(f.sole_m(i, 4), f.sole_m(i, 5));
      const double l1 = (B - A).norm(), l2 = (C - B).norm(), x = mp->cop_x_m[i];
      if (l1 + l2 <= 0 || !(B.x() > A.x()) || !(C.x() >= B.x())) continue;  // a sole that does not point forward
      double along;
      if (x <= A.x()) along = 0;
      else if (x <= B.x()) along = l1 * (x - A.x()) / (B.x() - A.x());
      else if (C.x() > B.x()) along = l1 + l2 * (x - B.x()) / (C.x() - B.x());  // beyond C: extrapolated
      else along = l1 + l2;
      along = std::min(along, kMaxCopFraction * (l1 + l2));
      const double unit = cop_length_m(length, e.calibration.contact.feet[static_cast<std::size_t>(s.foot)], l1, l2);
      if (!(unit > 0)) continue;
      out.theta_rad.push_back(f.inclination_rad[i]);
      out.fraction.push_back(along / unit);
      out.com_place.push_back((whole_body_com(e.model(), e.motion.frame(i)).x() - A.x()) / unit);
    }
  }
}

CopFit fit_cop_function(const CopSamples& smp, const CopFunction& start, bool fit_com) {
  const Eigen::Index n = static_cast<Eigen::Index>(smp.theta_rad.size());
  if (n < 20) throw InputError("COP fit: only " + std::to_string(n) + " samples (need 20 or more loaded plate-stance frames)");
  const bool with_com = smp.com_place.size() == smp.theta_rad.size();
  if (fit_com && !with_com) throw InputError("COP fit: the samples carry no centre-of-mass place");
  const int p = fit_com ? 5 : 4;
  Eigen::MatrixXd W(n, p);
  Eigen::VectorXd y(n);
  auto com = [&](Eigen::Index i) { return with_com ? smp.com_place[static_cast<std::size_t>(i)] : 0.0; };
  for (Eigen::Index i = 0; i < n; ++i) {
    W.row(i).head<4>() = weights(start, smp.theta_rad[static_cast<std::size_t>(i)]).transpose();
    y[i] = smp.fraction[static_cast<std::size_t>(i)];
    if (fit_com) W(i, 4) = com(i);
    else y[i] -= start.com_gain * com(i);
  }
  // Events no sample reaches keep their starting position (a tiny ridge towards it).
  const double ridge = 1e-6;
  Eigen::MatrixXd Wa(n + p, p);
  Eigen::VectorXd ya(n + p), s0(p);
  s0.head<4>() = Eigen::Vector4d(start.s_hs, start.s_ho, start.s_mo, start.s_to);
  if (fit_com) s0[4] = start.com_gain;
  Wa << W, ridge * Eigen::MatrixXd::Identity(p, p);
  ya << y, ridge * s0;
  const Eigen::VectorXd s = solve_rolling_forward(Wa, ya);
  if (fit_com && (s[4] < 0.0 || s[4] > 1.0)) {
    // Outside what a COP function may hold (io/cop_function.hpp: a COP rolling back as the body
    // moves on, or outrunning it): the gain at its bound, the positions fitted for it.
    CopFunction bounded = start;
    bounded.com_gain = std::clamp(s[4], 0.0, 1.0);
    return fit_cop_function(smp, bounded, false);
  }
  CopFit fit;
  fit.function = start;
  if (fit_com) fit.function.com_gain = s[4];
  fit.function.s_hs = std::clamp(s[0], 0.0, kMaxCopFraction);
  fit.function.s_ho = std::clamp(s[1], 0.0, kMaxCopFraction);
  fit.function.s_mo = std::clamp(s[2], 0.0, kMaxCopFraction);
  fit.function.s_to = std::clamp(s[3], 0.0, kMaxCopFraction);
  fit.samples = static_cast<int>(n);
  double e0 = 0, e1 = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double th = smp.theta_rad[static_cast<std::size_t>(i)], yi = smp.fraction[static_cast<std::size_t>(i)];
    e0 += std::pow(start.fraction(th, com(i)) - yi, 2);
    e1 += std::pow(fit.function.fraction(th, com(i)) - yi, 2);
  }
  fit.rms_fraction_before = std::sqrt(e0 / static_cast<double>(n));
  fit.rms_fraction = std::sqrt(e1 / static_cast<double>(n));
  return fit;
}

CopFit fit_cop_function_and_angles(const CopSamples& smp, const CopFunction& start, bool fit_com) {
  CopFit best = fit_cop_function(smp, start, fit_com);
  const double before = best.rms_fraction_before;
  for (double step : {0.08, 0.04, 0.02, 0.01}) {
    bool improved = true;
    while (improved) {
      improved = false;
      for (int k = 0; k < 4; ++k)
        for (double d : {-step, step}) {
          CopFunction f = best.function;
          double* a[4] = {&f.delta_hs, &f.delta_ho, &f.delta_mo, &f.delta_to};
          *a[k] += d;
          if (!(f.delta_hs < f.delta_ho && f.delta_ho < f.delta_mo && f.delta_mo < f.delta_to)) continue;
          const CopFit c = fit_cop_function(smp, f, fit_com);
          if (c.rms_fraction < best.rms_fraction - 1e-6) {
            best = c;
            improved = true;
          }
        }
    }
  }
  best.rms_fraction_before = before;
  return best;
}

CopFitOnTrials fit_cop_on_trials(const std::vector<StudyTrial>& trials, const CopFunction& start, double min_force,
                                 bool fit_angles, bool leave_one_out, bool fit_com) {
  const std::size_t n = trials.size();
  std::vector<CopSamples> per(n);
  CopFitOnTrials out;
  // The samples depend on the kinematics only (sole points, inclination, kept stances), not on
  // the COP function the estimate ran with.
  // One trial held at a time (a fit over many long trials): loaded, used, let go.
  for (std::size_t k = 0; k < n; ++k) {
    const auto& t = trials[k];
    const StudyTrialData d = t.data();
    const auto e = estimate(*d.trial, d.static_trial, *d.marker_set, t.options);
    collect_cop_samples(e, validate(e, *d.plates), min_force, start.length, per[k]);
    out.samples_per_trial.push_back(per[k].theta_rad.size());
  }
  // Leave one LAB out: a trial's held-out fit uses no trial of its lab (same lab, same set-up).
  auto lab = [&](std::size_t k) { return trials[k].lab_or_name(); };
  auto pooled = [&](std::size_t skip) {
    CopSamples all;
    for (std::size_t k = 0; k < n; ++k) {
      if (skip < n && lab(k) == lab(skip)) continue;
      all.theta_rad.insert(all.theta_rad.end(), per[k].theta_rad.begin(), per[k].theta_rad.end());
      all.fraction.insert(all.fraction.end(), per[k].fraction.begin(), per[k].fraction.end());
      all.com_place.insert(all.com_place.end(), per[k].com_place.begin(), per[k].com_place.end());
    }
    return all;
  };
  auto fit_fn = [&](const CopSamples& smp) {
    return fit_angles ? fit_cop_function_and_angles(smp, start, fit_com) : fit_cop_function(smp, start, fit_com);
  };
  out.fit = fit_fn(pooled(n));
  if (!leave_one_out) return out;
  for (std::size_t k = 0; k < n; ++k) {
    const auto& t = trials[k];
    const auto others = pooled(k);
    if (others.theta_rad.size() < 20) continue;
    const StudyTrialData d = t.data();
    auto validated = [&](const CopFunction& f) {
      EstimateOptions o = t.options;
      o.contact.cop = f;
      o.contact.running_cop.reset();  // the candidate alone, on every frame
      const auto e = estimate(*d.trial, d.static_trial, *d.marker_set, o);
      return validate(e, *d.plates);
    };
    auto cop_rrmse = [&](const CopFunction& f) { return mean_rrmse(validated(f).stances).cop; };
    const ValidationResult held = validated(fit_fn(others).function);
    const MeanMetrics m = mean_rrmse(held.stances);
    CopFitOnTrials::LeaveOneOut l{t.name, cop_rrmse(start), cop_rrmse(CopFunction{}), cop_rrmse(out.fit.function), m.cop};
    l.others_vertical = m.vertical, l.others_anterior = m.anterior, l.others_cop_mm = m.cop_rmse_mm;
    l.others_grm = held.total && held.total->metrics.moment ? held.total->metrics.moment->rrmse_percent
                                                             : std::numeric_limits<double>::quiet_NaN();
    out.leave_one_out.push_back(l);
  }
  return out;
}

nlohmann::json cop_fit_json(const CopFitOnTrials& res, const std::vector<StudyTrial>& trials, const CopFunction& start,
                            const CopFitProvenance& how) {
  const CopFit& fit = res.fit;
  nlohmann::json j = cop_function_json(fit.function);
  nlohmann::json prov;
  prov["command"] = how.command;
  prov["kin2grf_version"] = KIN2GRF_VERSION;
  prov["trials"] = nlohmann::json::array();
  for (std::size_t k = 0; k < trials.size(); ++k) prov["trials"].push_back({{"name", trials[k].name}, {"samples", res.samples_per_trial[k]}});
  prov["samples"] = fit.samples;
  prov["event_angles"] = how.fit_angles ? "fitted" : "fixed (the paper's)";
  prov["min_force_fraction_of_body_weight"] = how.min_force_fraction;
  prov["rms_fraction_before"] = fit.rms_fraction_before;
  prov["rms_fraction_after"] = fit.rms_fraction;
  prov["start"] = cop_function_json(start);
  if (!res.leave_one_out.empty()) {
    nlohmann::json loo = nlohmann::json::array();
    auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
    for (const auto& l : res.leave_one_out)
      loo.push_back({{"trial", l.trial},
                     {"start", l.start},
                     {"builtin", l.builtin},
                     {"all", l.all},
                     {"other_labs", l.others},
                     {"other_labs_vertical", num(l.others_vertical)},
                     {"other_labs_anterior", num(l.others_anterior)},
                     {"other_labs_total_grm", num(l.others_grm)},
                     {"other_labs_cop_rmse_mm", num(l.others_cop_mm)}});
    prov["leave_one_lab_out_cop_rrmse_percent"] = loo;
  }
  j["provenance"] = prov;
  return j;
}

std::string format_cop_fit(const CopFitOnTrials& res, const std::vector<StudyTrial>& trials, const CopFunction& start,
                           const CopFitProvenance& how) {
  const CopFunction& f = res.fit.function;
  std::string out;
  char b[1024];
  std::snprintf(b, sizeof b, "COP function fitted on %d samples of %zu trials (%s)\n", res.fit.samples, trials.size(), how.activity.c_str());
  out += b;
  std::snprintf(b, sizeof b, "  event angles (rad)   HS %.3f  HO %.3f  MO %.3f  TO %.3f\n", f.delta_hs, f.delta_ho, f.delta_mo, f.delta_to);
  out += b;
  const char* unit = f.length == CopLength::Sole ? "sole" : "heel-MT";
  std::snprintf(b, sizeof b, "  positions (fraction of the %s length) HS %.3f  HO %.3f  MO %.3f  TO %.3f   (start %.3f %.3f %.3f %.3f)\n",
                unit, f.s_hs, f.s_ho, f.s_mo, f.s_to, start.s_hs, start.s_ho, start.s_mo, start.s_to);
  out += b;
  if (f.com_gain != 0.0 || start.com_gain != 0.0) {
    std::snprintf(b, sizeof b, "  centre-of-mass gain   %.3f per %s length ahead of the heel   (start %.3f)\n", f.com_gain, unit,
                  start.com_gain);
    out += b;
  }
  std::snprintf(b, sizeof b, "  RMS of F(theta) - s: %.3f (start: %.3f)\n", res.fit.rms_fraction, res.fit.rms_fraction_before);
  out += b;
  if (!res.leave_one_out.empty()) {
    std::snprintf(b, sizeof b,
                  "\nleave-one-lab-out: COP rRMSE %% (mean over the trial's stances; 'start': the fit's starting function, the\n"
                  "paper's angles and positions counted in the fit's length; 'built-in': kin2grf's default function;\n"
                  "'all': this fit; 'other labs': fitted without the trial's lab, with the trial's COP RMSE in mm,\n"
                  "vertical and anterior rRMSE %% and total GRM rRMSE %% under that fit)\n"
                  "%-26s %8s %9s %8s %11s %7s %9s %9s %6s\n",
                  "trial", "start", "built-in", "all", "other labs", "COP mm", "vertical", "anterior", "GRM");
    out += b;
    for (const auto& l : res.leave_one_out) {
      std::snprintf(b, sizeof b, "%-26s %8.1f %9.1f %8.1f %11.1f %7.1f %9.1f %9.1f %6.1f\n", l.trial.c_str(), l.start, l.builtin, l.all,
                    l.others, l.others_cop_mm, l.others_vertical, l.others_anterior, l.others_grm);
      out += b;
    }
  }
  return out;
}

}  // namespace kin2grf
