// Marker-set presets: the JSON files of data/presets (embedded at build time) and users' mapping
// files, read into MarkerSets, and the recognition of a trial's set. An adapter around the core:
// the core's landmark computation takes a MarkerSet and knows no file format.
#include "kin2grf/io/marker_presets.hpp"

#include <algorithm>
#include <map>

#include "kin2grf/error.hpp"
#include "kin2grf/io/json.hpp"

namespace kin2grf {

const std::vector<std::pair<std::string, std::string>>& builtin_preset_texts();  // generated

namespace {

constexpr const char* kRuleKinds[] = {"marker", "mean", "harrington", "static", "functional", "pelvis_up", "virtual_hallux"};

/// Every key of "landmarks" is a landmark kin2grf knows: a misspelt one would be ignored.
void check_landmark_names(const nlohmann::json& lm, const std::string& source) {
  if (!lm.is_object()) throw InputError(source + ": \"landmarks\" is not an object of landmark rules");
  for (const auto& [key, value] : lm.items()) {
    bool known = false;
    for (int id = 0; id < kLandmarkCount; ++id) known = known || key == landmark_name(id);
    if (known) continue;
    std::string names;
    for (int id = 0; id < kLandmarkCount; ++id) names += std::string(id ? ", " : "") + landmark_name(id);
    throw InputError(source + ": unknown landmark '" + key + "' (the landmarks are: " + names + ")");
  }
}

/// A landmark has exactly one rule: with two, which one is meant?
void check_one_rule(const nlohmann::json& r, const std::string& where) {
  if (!r.is_object()) throw InputError(where + ": the rule is not an object (" + json_excerpt(r) + ")");
  std::vector<std::string> found;
  for (const char* k : kRuleKinds)
    if (r.contains(k)) found.emplace_back(k);
  if (found.size() > 1) throw InputError(where + ": two rules in one landmark ('" + found[0] + "' and '" + found[1] + "')");
}

/// The pelvis's markers (harrington, pelvis_up) are distinct markers: four times one marker has
/// no pelvis frame.
void check_distinct_pelvis_markers(const std::map<std::string, std::string>& pelvis, const std::string& where) {
  for (auto a = pelvis.begin(); a != pelvis.end(); ++a)
    for (auto b = std::next(a); b != pelvis.end(); ++b)
      if (a->second == b->second)
        throw InputError(where + ": the pelvis's " + a->first + " and " + b->first + " are the same marker '" + a->second + "'");
}

}  // namespace

MarkerSet parse_marker_set(const nlohmann::json& j, const std::string& source) {
  MarkerSet s;
  try {
    s.name = j.at("name").get<std::string>();
    s.description = j.value("description", "");
    s.signature = j.value("signature", std::vector<std::string>{});
    const auto& lm = j.at("landmarks");
    check_landmark_names(lm, source);
    for (int id = 0; id < kLandmarkCount; ++id) {
      if (!lm.contains(landmark_name(id))) throw InputError(source + ": landmark '" + landmark_name(id) + "' has no rule");
      const auto& r = lm.at(landmark_name(id));
      check_one_rule(r, source + ": landmark '" + landmark_name(id) + "'");
      LandmarkRule rule;
      if (r.contains("marker")) { rule.kind = RuleKind::Marker; rule.markers = {r["marker"].get<std::string>()}; }
      else if (r.contains("mean")) { rule.kind = RuleKind::Mean; rule.markers = r["mean"].get<std::vector<std::string>>(); }
      else if (r.contains("harrington")) { rule.kind = RuleKind::Harrington; rule.pelvis = r["harrington"].get<std::map<std::string, std::string>>(); }
      else if (r.contains("static")) {
        rule.kind = RuleKind::Static;
        rule.markers = r["static"].get<std::vector<std::string>>();
        rule.cluster = r.at("cluster").get<std::vector<std::string>>();
        if (rule.cluster.size() < 3) throw InputError(source + ": landmark '" + landmark_name(id) + "': a cluster needs 3 or more markers");
      } else if (r.contains("functional")) {
        // A joint centre from the motion itself (SCoRE): the point fixed in both segments.
        rule.kind = RuleKind::Functional;
        const auto& f = r["functional"];
        rule.cluster = f.at("proximal").get<std::vector<std::string>>();
        rule.markers = f.at("distal").get<std::vector<std::string>>();
        if (rule.cluster.size() < 3 || rule.markers.size() < 3)
          throw InputError(source + ": landmark '" + landmark_name(id) + "': a functional joint needs 3 or more markers on each segment");
      } else if (r.contains("pelvis_up")) {
        rule.kind = RuleKind::PelvisUp;
        rule.value = r["pelvis_up"].get<double>();
        rule.sway_gain = r.value("sway_gain", kTrunkSwayGain);
        if (!(rule.sway_gain >= 0.0 && rule.sway_gain <= 1.5))
          throw InputError(source + ": landmark '" + landmark_name(id) + "': sway_gain " + std::to_string(rule.sway_gain) +
                           " is outside 0-1.5 (0.5: measured walking; 1: a rigid upright torso)");
        rule.pelvis = r.at("pelvis").get<std::map<std::string, std::string>>();
        // The hip-to-shoulder length of an adult's upright torso is 0.4-0.6 m.
        if (!(rule.value >= 0.2 && rule.value <= 1.0))
          throw InputError(source + ": landmark '" + landmark_name(id) + "': pelvis_up " + std::to_string(rule.value) +
                           " m is not a torso length (0.2-1.0 m above the hip centre)");
      } else if (r.contains("virtual_hallux")) {
        rule.kind = RuleKind::VirtualHallux;
        rule.value = r["virtual_hallux"].get<double>();
      } else {
        throw InputError(source + ": landmark '" + landmark_name(id) + "': unknown rule " + json_excerpt(r) +
                         " (a rule is one of: marker, mean, harrington, static, functional, pelvis_up, virtual_hallux)");
      }
      if (r.contains("surface")) {
        const std::string surface = r["surface"].get<std::string>();
        const std::string name = landmark_name(id);
        if (surface != "lateral")
          throw InputError(source + ": landmark '" + name + "': surface '" + surface + "' is not known (\"lateral\": a marker on the joint's lateral skin)");
        if (name.rfind("knee_", 0) != 0 && name.rfind("ankle_", 0) != 0 && name.rfind("mt_", 0) != 0)
          throw InputError(source + ": landmark '" + name + "': \"surface\" applies to knee, ankle and MT landmarks only");
        rule.lateral_surface = true;
      }
      check_distinct_pelvis_markers(rule.pelvis, source + ": landmark '" + landmark_name(id) + "'");
      if ((rule.kind == RuleKind::Marker || rule.kind == RuleKind::Mean || rule.kind == RuleKind::Static) && rule.markers.empty())
        throw InputError(source + ": landmark '" + landmark_name(id) + "' names no marker");
      s.rules[static_cast<std::size_t>(id)] = rule;
    }
    // Optional: the arms' and the head's landmarks, each the mean of the markers named.
    if (j.contains("upper_body")) {
      const auto& ub = j["upper_body"];
      if (!ub.is_object()) throw InputError(source + ": \"upper_body\" is not an object of landmark: [markers]");
      for (const auto& [key, value] : ub.items()) {
        int id = -1;
        std::string names;
        for (int k = 0; k < kUpperBodyCount; ++k) {
          if (key == upper_body_name(k)) id = k;
          names += std::string(k ? ", " : "") + upper_body_name(k);
        }
        if (id < 0) throw InputError(source + ": unknown upper-body landmark '" + key + "' (they are: " + names + ")");
        auto markers = value.get<std::vector<std::string>>();
        if (markers.empty()) throw InputError(source + ": upper-body landmark '" + key + "' names no marker");
        s.upper_body[static_cast<std::size_t>(id)] = std::move(markers);
      }
    }
  } catch (const nlohmann::json::exception& e) {
    throw InputError(source + ": invalid marker-set file: " + e.what());
  }
  return s;
}

MarkerSet load_marker_set(const std::string& path) { return parse_marker_set(read_json_file(path), path); }

const std::vector<MarkerSet>& builtin_marker_sets() {
  static const std::vector<MarkerSet> sets = [] {
    std::vector<MarkerSet> v;
    for (const auto& [name, text] : builtin_preset_texts()) {
      v.push_back(parse_marker_set(parse_json_text(text, name), name));
      v.back().preset = true;
    }
    // Recognition order: the more specific sets first.
    std::stable_sort(v.begin(), v.end(), [](const MarkerSet& a, const MarkerSet& b) { return a.signature.size() > b.signature.size(); });
    return v;
  }();
  return sets;
}

const MarkerSet* find_marker_set(const std::string& name) {
  for (const auto& s : builtin_marker_sets())
    if (s.name == name) return &s;
  return nullptr;
}

const MarkerSet* recognise_marker_set(const MarkerTrajectories& m, std::string* why) {
  // Among the presets whose signature markers are in the file, the one whose markers all hold
  // data in the most frames: a label with no sample (LSHO/RSHO kept empty in a lower-body
  // capture) does not count as present. Ties go to the set that uses more markers (the more
  // specific one, e.g. full Plug-in Gait over its lower-body variant).
  const MarkerSet* best = nullptr;
  long best_frames = -1;
  std::size_t best_used = 0;
  std::string report;
  for (const auto& s : builtin_marker_sets()) {
    if (!std::all_of(s.signature.begin(), s.signature.end(), [&](const std::string& n) { return m.find(n) >= 0; })) continue;
    std::vector<std::string> used = s.motion_markers();
    std::sort(used.begin(), used.end());
    used.erase(std::unique(used.begin(), used.end()), used.end());
    long frames = 0;
    std::vector<int> idx;
    bool all_there = true;
    for (const auto& u : used) {
      const int k = m.find(u);
      if (k < 0) all_there = false;
      else idx.push_back(k);
    }
    if (all_there)
      for (Eigen::Index i = 0; i < m.frames(); ++i)
        frames += std::all_of(idx.begin(), idx.end(), [&](int k) { return m.positions_m[static_cast<std::size_t>(k)].row(i).allFinite(); });
    report += (report.empty() ? "" : ", ") + s.name + " " + std::to_string(frames) + " frames";
    if (frames > best_frames || (frames == best_frames && used.size() > best_used)) best = &s, best_frames = frames, best_used = used.size();
  }
  if (best && best_frames == 0) best = nullptr;  // no set has a single complete frame
  if (why) *why = report.empty() ? "no preset's signature markers are in the file" : "frames with every marker of the set: " + report;
  return best;
}

}  // namespace kin2grf
