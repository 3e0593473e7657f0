#include "kin2grf/io/summary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "kin2grf/error.hpp"
#include "kin2grf/io/marker_labels.hpp"
#include "kin2grf/io/marker_presets.hpp"
#include "kin2grf/numeric.hpp"

namespace kin2grf {

std::vector<LoadedInterval> loaded_intervals(const ForcePlateRecording& rec, const ForcePlate& plate,
                                             double threshold_N) {
  std::vector<LoadedInterval> out;
  const auto vertical = plate.force_N.col(static_cast<int>(rec.up_axis));
  for (const IndexRun& run : runs_above(vertical, threshold_N)) {
    LoadedInterval L;
    L.first_sample = run.first;
    L.last_sample = run.last;
    L.peak_vertical_N = vertical.segment(run.first, run.last - run.first + 1).maxCoeff();
    L.start_s = rec.time_s[L.first_sample];
    L.end_s = rec.time_s[L.last_sample];
    // Bridge dips shorter than 10 ms (noise around the threshold) into the previous interval.
    if (!out.empty() && L.start_s - out.back().end_s < 0.010) {
      out.back().end_s = L.end_s;
      out.back().last_sample = L.last_sample;
      out.back().peak_vertical_N = std::max(out.back().peak_vertical_N, L.peak_vertical_N);
    } else {
      out.push_back(L);
    }
  }
  // Blips shorter than 10 ms are noise, not contacts.
  std::erase_if(out, [](const LoadedInterval& L) { return L.end_s - L.start_s < 0.010; });
  return out;
}

nlohmann::json trial_summary(const Trial& t, double thr) {
  using nlohmann::json;
  json s;
  s["path"] = t.path;
  s["format"] = t.format;
  s["encoding"] = t.encoding;
  const auto& m = t.markers;
  const auto n = m.frames();
  s["rate_hz"] = n > 0 ? json(m.rate_hz) : json(nullptr);
  s["frames"] = {{"first", n > 0 ? m.first_frame : 0},
                 {"last", n > 0 ? m.first_frame + static_cast<int>(n) - 1 : 0},
                 {"count", n}};
  s["duration_s"] = n > 1 ? m.time_s[n - 1] - m.time_s[0] : 0.0;
  s["start_s"] = n > 0 ? m.time_s[0] : 0.0;
  s["up_axis"] = to_string(t.plates && n == 0 ? t.plates->up_axis : m.up_axis);
  s["markers"] = m.names;
  json missing = json::array();
  for (std::size_t k = 0; k < m.names.size(); ++k) {
    const auto fr = m.missing_frames(static_cast<int>(k));
    if (fr.empty()) continue;
    json iv = json::array();
    std::size_t a = 0;
    while (a < fr.size()) {
      std::size_t b = a;
      while (b + 1 < fr.size() && fr[b + 1] == fr[b] + 1) ++b;
      iv.push_back({m.first_frame + fr[a], m.first_frame + fr[b]});
      a = b + 1;
    }
    missing.push_back({{"marker", m.names[k]}, {"frames", fr.size()}, {"intervals", iv}});
  }
  s["missing"] = missing;
  s["model_outputs"] = t.model_outputs.size();
  // The marker set estimate would take without --markers: a preset, else the labels' mapping
  // (its rules, or the landmarks no label gives). Joints that need the static trial are not
  // mapped here (info reads one file).
  if (!m.names.empty()) {
    json set;
    if (const MarkerSet* p = recognise_marker_set(m)) {
      set = {{"preset", p->name}};
    } else {
      const LabelMapping lm = map_marker_labels(m);
      set = {{"preset", nullptr}, {"labels", lm.rules}, {"notes", lm.notes}, {"missing", lm.missing}, {"too_few_samples", lm.too_few}};
    }
    s["marker_set"] = set;
  } else {
    s["marker_set"] = nullptr;
  }
  json plates = json::array();
  if (t.plates) {
    for (const auto& p : t.plates->plates) {
      json jp;
      jp["name"] = p.name;
      jp["type"] = p.type;
      jp["rate_hz"] = t.plates->rate_hz;
      jp["side_hint"] = to_string(p.side_hint);
      if (p.has_geometry) {
        jp["size_m"] = {p.width_m(), p.length_m()};
        jp["centre_m"] = {p.centre_m.x(), p.centre_m.y(), p.centre_m.z()};
      } else {
        jp["size_m"] = nullptr;
        jp["centre_m"] = nullptr;
      }
      json loaded = json::array();
      for (const auto& L : loaded_intervals(*t.plates, p, thr))
        loaded.push_back({{"start_s", L.start_s}, {"end_s", L.end_s}, {"peak_vertical_N", L.peak_vertical_N}});
      jp["loaded"] = loaded;
      plates.push_back(jp);
    }
  }
  s["force_plates"] = plates;
  json ev = json::array();
  for (const auto& e : t.events) ev.push_back({{"label", e.label}, {"side", to_string(e.side)}, {"time_s", e.time_s}});
  s["events"] = ev;
  s["body_mass_kg"] = t.body_mass_kg ? json(*t.body_mass_kg) : json(nullptr);
  s["height_m"] = t.height_m ? json(*t.height_m) : json(nullptr);
  s["warnings"] = t.warnings;
  return s;
}

nlohmann::json describe_file(const std::string& path, double threshold, const LoadOptions& load, std::optional<Axis> up_axis,
                             Trial* loaded) {
  if (!(std::isfinite(threshold) && threshold > 0))
    throw InputError("setting load threshold (N) = " + std::to_string(threshold) + ": must be a force above 0 N");
  Trial t = load_trial(path, load);
  if (up_axis) {
    t.markers.up_axis = *up_axis;
    if (t.plates) t.plates->up_axis = *up_axis;
  }
  nlohmann::json s = trial_summary(t, threshold);
  if (loaded) *loaded = std::move(t);
  return s;
}

std::string format_summary(const nlohmann::json& s) {
  std::ostringstream os;
  char buf[256];
  os << s["path"].get<std::string>() << "\n";
  os << "  format:      " << s["format"].get<std::string>() << " (" << s["encoding"].get<std::string>() << ")\n";
  const auto& fr = s["frames"];
  if (fr["count"].get<long>() > 0) {
    std::snprintf(buf, sizeof buf, "  markers:     %zu at %.6g Hz, frames %d-%d (%ld), %.3f-%.3f s (%.3f s), up axis %s\n",
                  s["markers"].size(), s["rate_hz"].get<double>(), fr["first"].get<int>(), fr["last"].get<int>(),
                  fr["count"].get<long>(), s["start_s"].get<double>(),
                  s["start_s"].get<double>() + s["duration_s"].get<double>(), s["duration_s"].get<double>(),
                  s["up_axis"].get<std::string>().c_str());
    os << buf;
    std::string line = "               ";
    for (const auto& name : s["markers"]) {
      const std::string n = name.get<std::string>();
      if (line.size() + n.size() + 1 > 100) { os << line << "\n"; line = "               "; }
      line += n + " ";
    }
    os << line << "\n";
    if (s["model_outputs"].get<std::size_t>() > 0)
      os << "  model outputs stored as points (not markers): " << s["model_outputs"].get<std::size_t>() << "\n";
    if (!s["missing"].empty()) {
      os << "  missing samples:\n";
      for (const auto& mm : s["missing"]) {
        os << "    " << mm["marker"].get<std::string>() << ": " << mm["frames"].get<std::size_t>() << " frames in";
        int shown = 0;
        for (const auto& iv : mm["intervals"]) {
          if (shown++ == 4) { os << " ..."; break; }
          os << " " << iv[0].get<long>() << "-" << iv[1].get<long>();
        }
        os << "\n";
      }
    }
  } else {
    os << "  markers:     none\n";
  }
  if (s.contains("marker_set") && s["marker_set"].is_object()) {
    const auto& set = s["marker_set"];
    if (set["preset"].is_string()) {
      os << "  marker set:  " << set["preset"].get<std::string>() << " (preset recognised)\n";
    } else {
      os << "  marker set:  no preset recognised; " << (set["missing"].empty() ? "made from the labels" : "from the labels, missing") << ":\n";
      for (const auto& x : set["missing"]) os << "    missing " << x.get<std::string>() << "\n";
      for (const auto& x : set["labels"]) os << "    " << x.get<std::string>() << "\n";
      for (const auto& x : set["notes"]) os << "    (" << x.get<std::string>() << ")\n";
      if (set.contains("too_few_samples"))
        for (const auto& x : set["too_few_samples"]) os << "    left out, samples in too few frames: " << x.get<std::string>() << "\n";
    }
  }
  os << "  force plates: " << s["force_plates"].size() << "\n";
  for (const auto& p : s["force_plates"]) {
    os << "    " << p["name"].get<std::string>();
    if (p["type"].get<int>() > 0) os << "  type " << p["type"].get<int>();
    std::snprintf(buf, sizeof buf, "  %.6g Hz", p["rate_hz"].get<double>());
    os << buf;
    if (!p["size_m"].is_null()) {
      std::snprintf(buf, sizeof buf, "  %.1f x %.1f mm, centre (%.1f, %.1f, %.1f) mm", p["size_m"][0].get<double>() * 1e3,
                    p["size_m"][1].get<double>() * 1e3, p["centre_m"][0].get<double>() * 1e3,
                    p["centre_m"][1].get<double>() * 1e3, p["centre_m"][2].get<double>() * 1e3);
      os << buf;
    }
    if (p["side_hint"] != "general") os << "  (" << p["side_hint"].get<std::string>() << " foot)";
    os << "\n";
    if (p["loaded"].empty()) os << "      never loaded\n";
    for (const auto& L : p["loaded"]) {
      std::snprintf(buf, sizeof buf, "      loaded %.3f-%.3f s, peak vertical %.1f N\n", L["start_s"].get<double>(),
                    L["end_s"].get<double>(), L["peak_vertical_N"].get<double>());
      os << buf;
    }
  }
  os << "  events:      " << s["events"].size() << "\n";
  for (const auto& e : s["events"]) {
    std::snprintf(buf, sizeof buf, "    %.3f s  %s %s\n", e["time_s"].get<double>(), e["side"].get<std::string>().c_str(),
                  e["label"].get<std::string>().c_str());
    os << buf;
  }
  if (!s["body_mass_kg"].is_null()) os << "  body mass:   " << s["body_mass_kg"].get<double>() << " kg\n";
  else os << "  body mass:   not stored (give --mass to estimate)\n";
  for (const auto& w : s["warnings"]) os << "  warning: " << w.get<std::string>() << "\n";
  return os.str();
}

}  // namespace kin2grf
