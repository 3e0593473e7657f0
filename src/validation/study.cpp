#include "kin2grf/validation/study.hpp"

#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <sstream>

#include "kin2grf/error.hpp"

namespace kin2grf {
namespace {

struct Setting {
  std::string label;
  double value;
  std::function<void(EstimateOptions&)> apply;
};

std::vector<Setting> settings_for(const std::string& kind) {
  std::vector<Setting> s;
  char b[32];
  if (kind == "r") {
    for (int e = 2; e <= 12; ++e) {
      const double r = std::pow(10.0, 0.5 * e);
      std::snprintf(b, sizeof b, "%.3g", r);
      s.push_back({b, r, [r](EstimateOptions& o) { o.solver.r_N_per_m = r; }});
    }
  } else if (kind == "ground-shift") {
    for (double d : {-0.01, 0.0, 0.01}) {
      std::snprintf(b, sizeof b, "%+.0f mm", 1000 * d);
      s.push_back({b, d, [d](EstimateOptions& o) { o.contact.ground_shift_m = d; }});
    }
  } else if (kind == "cutoff") {
    for (double f : {4.0, 6.0, 8.0, 10.0, 12.0, 15.0, 20.0}) {
      std::snprintf(b, sizeof b, "%.0f Hz", f);
      s.push_back({b, f, [f](EstimateOptions& o) { o.post_cutoff_hz = f; }});
    }
  } else if (kind == "kinematic-cutoff") {
    for (double f : {4.0, 5.0, 6.0, 8.0, 10.0, 12.0}) {
      std::snprintf(b, sizeof b, "%.0f Hz", f);
      s.push_back({b, f, [f](EstimateOptions& o) { o.kinematic_cutoff_hz = f; }});
    }
  } else if (kind == "speed-gate") {
    for (double v : {0.0, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0}) {
      std::snprintf(b, sizeof b, v > 0 ? "%.2f m/s" : "off", v);
      s.push_back({b, v, [v](EstimateOptions& o) { o.solver.speed_gate_mps = v; }});
    }
  } else if (kind == "split-distance") {
    for (double d : {0.0, 0.05, 0.1, 0.15, 0.2}) {
      std::snprintf(b, sizeof b, d > 0 ? "%.2f m" : "off", d);
      s.push_back({b, d, [d](EstimateOptions& o) { o.solver.min_split_distance_m = d; }});
    }
  } else if (kind == "torso-length") {
    s.push_back({"fixed (the paper)", 0, [](EstimateOptions& o) { o.torso_length = TorsoLength::Fixed; }});
    s.push_back({"measured", 1, [](EstimateOptions& o) { o.torso_length = TorsoLength::Measured; }});
  } else if (kind == "foot-model") {
    s.push_back({"three-point (model 1)", 1, [](EstimateOptions& o) { o.contact.foot_model = FootModel::ThreePoint; }});
    s.push_back({"cop (model 2)", 2, [](EstimateOptions& o) { o.contact.foot_model = FootModel::Cop; }});
  } else {
    throw InputError("unknown study '" + kind + "' (r, ground-shift, cutoff, kinematic-cutoff, speed-gate, split-distance, torso-length, foot-model)");
  }
  return s;
}

}  // namespace

StudyResult run_study(const std::string& kind, const std::vector<StudyTrial>& trials) {
  StudyResult res;
  res.kind = kind;
  std::vector<std::string> activities;
  for (const auto& t : trials)
    if (std::find(activities.begin(), activities.end(), t.activity) == activities.end()) activities.push_back(t.activity);
  if (activities.size() > 1) activities.push_back("all");
  for (const Setting& s : settings_for(kind)) {
    StudyRow row;
    row.label = s.label;
    row.value = s.value;
    std::vector<std::vector<StanceValidation>> stances(activities.size());
    std::vector<std::vector<double>> totals(activities.size());
    std::vector<int> ntrials(activities.size(), 0);
    for (const auto& t : trials) {
      EstimateOptions o = t.options;
      s.apply(o);
      try {
        const EstimateResult e = estimate(*t.trial, t.static_trial, *t.marker_set, o);
        const ValidationResult v = validate(e, *t.plates);
        for (std::size_t a = 0; a < activities.size(); ++a) {
          if (activities[a] != t.activity && activities[a] != "all") continue;
          ++ntrials[a];
          stances[a].insert(stances[a].end(), v.stances.begin(), v.stances.end());
          if (v.total && v.total->metrics.moment) totals[a].push_back(v.total->metrics.moment->rrmse_percent);
        }
      } catch (const InputError& err) {
        res.failures.push_back(t.name + " at " + s.label + ": " + err.what());
      }
    }
    for (std::size_t a = 0; a < activities.size(); ++a) {
      StudyCell c;
      c.activity = activities[a];
      c.trials = ntrials[a];
      c.per_foot = mean_rrmse(stances[a]);
      c.total_trials = static_cast<int>(totals[a].size());
      double sum = 0;
      for (double x : totals[a]) sum += x;
      c.total_grm = totals[a].empty() ? std::numeric_limits<double>::quiet_NaN() : sum / static_cast<double>(totals[a].size());
      row.cells.push_back(c);
    }
    res.rows.push_back(std::move(row));
  }
  return res;
}

nlohmann::json study_json(const StudyResult& s) {
  auto num = [](double x) { return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr); };
  nlohmann::json j;
  j["study"] = s.kind;
  j["rows"] = nlohmann::json::array();
  for (const auto& r : s.rows) {
    nlohmann::json row = {{"setting", r.label}, {"value", r.value}};
    for (const auto& c : r.cells)
      row["activities"][c.activity] = {{"trials", c.trials},
                                       {"stances", c.per_foot.n},
                                       {"rrmse_percent",
                                        {{"vertical", num(c.per_foot.vertical)},
                                         {"anterior", num(c.per_foot.anterior)},
                                         {"cop", num(c.per_foot.cop)},
                                         {"moment", num(c.per_foot.moment)},
                                         {"total_grm", num(c.total_grm)}}}};
    j["rows"].push_back(row);
  }
  j["failures"] = s.failures;
  return j;
}

std::string format_study_table(const StudyResult& s) {
  std::ostringstream os;
  char b[256];
  os << "kin2grf study " << s.kind << ": mean rRMSE % over the plate stances (per foot) and over the trials (total GRM)\n";
  if (s.rows.empty()) return os.str();
  for (std::size_t a = 0; a < s.rows.front().cells.size(); ++a) {
    const auto& c0 = s.rows.front().cells[a];
    std::snprintf(b, sizeof b, "\n%s (%d trials, %d stances)\n%-24s %9s %9s %9s %9s %10s\n", c0.activity.c_str(), c0.trials,
                  c0.per_foot.n, "setting", "vertical", "anterior", "COP", "moment", "total GRM");
    os << b;
    for (const auto& r : s.rows) {
      const auto& c = r.cells[a];
      std::snprintf(b, sizeof b, "%-24s %9.1f %9.1f %9.1f %9.1f", r.label.c_str(), c.per_foot.vertical, c.per_foot.anterior,
                    c.per_foot.cop, c.per_foot.moment);
      os << b;
      // No trial with a total window (validate says why): a dash, not "nan".
      if (std::isfinite(c.total_grm)) std::snprintf(b, sizeof b, " %10.1f\n", c.total_grm);
      else std::snprintf(b, sizeof b, " %10s\n", "-");
      os << b;
    }
  }
  for (const auto& f : s.failures) os << "failed: " << f << "\n";
  return os.str();
}

}  // namespace kin2grf
