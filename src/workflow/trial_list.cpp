#include "kin2grf/workflow/trial_list.hpp"

#include <CLI/CLI.hpp>

#include <filesystem>
#include <fstream>

#include "kin2grf/error.hpp"
#include "kin2grf/io/load.hpp"

namespace kin2grf {

TrialListEntry parse_trial_list_line(const std::string& line, const std::string& where) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  for (std::size_t bar; fields.size() < 3 && (bar = line.find('|', start)) != std::string::npos; start = bar + 1)
    fields.push_back(line.substr(start, bar - start));
  if (fields.size() < 2) throw InputError(where + ": expected activity|lab|name|TRIAL [options]");
  TrialListEntry e;
  e.activity = fields[0];
  e.lab = fields[1];  // the old 3-field form: the name is the lab
  e.name = fields.back();
  for (const auto& f : fields)
    if (f.empty()) throw InputError(where + ": an empty field in activity|lab|name");
  CLI::App parser{"trial"};
  add_settings_options(&parser, e.settings);
  parser.add_option("--plates", e.plates);
  try {
    parser.parse(line.substr(start), false);
  } catch (const CLI::ParseError& err) {
    throw InputError(where + ": " + err.what());
  }
  return e;
}

std::vector<TrialListEntry> read_trial_list(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path + ": cannot open the trial list");
  std::vector<TrialListEntry> out;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#' || line.find_first_not_of(" \t\r") == std::string::npos) continue;
    out.push_back(parse_trial_list_line(line, path + ":" + std::to_string(number)));
    out.back().line = number;
  }
  if (out.empty()) throw InputError(path + ": no trials in the list");
  return out;
}

std::vector<std::string> list_input_files(const std::vector<TrialListEntry>& entries) {
  std::vector<std::string> in;
  for (const auto& e : entries) {
    for (auto& f : input_files(e.settings)) in.push_back(std::move(f));
    in.push_back(e.plates);
  }
  return in;
}

std::vector<TrialListEntry> trial_list_of_files(const std::vector<std::string>& files, const Settings& settings,
                                                const std::string& plates) {
  std::vector<TrialListEntry> out;
  for (const auto& f : files) {
    TrialListEntry e;
    e.activity = "trials";
    e.name = std::filesystem::path(f).filename().string();
    e.lab = e.name;
    e.settings = settings;
    e.settings.trial = f;
    e.plates = plates;
    out.push_back(std::move(e));
  }
  return out;
}

LoadedTrials load_trials(const std::vector<TrialListEntry>& entries) {
  LoadedTrials L;
  // Reserved up front: StudyTrial points into these vectors.
  L.trials.reserve(entries.size()), L.statics.reserve(entries.size()), L.plates.reserve(entries.size()), L.sets.reserve(entries.size());
  for (const auto& in : entries) {
    L.trials.push_back(load_trial(in.settings.trial, load_options("unloaded")));
    StudyTrial x;
    x.name = in.name;
    x.activity = in.activity;
    x.lab = in.lab;
    x.trial = &L.trials.back();
    if (!in.settings.static_trial.empty()) {
      L.statics.push_back(load_trial(in.settings.static_trial));
      x.static_trial = &L.statics.back();
    }
    const Trial* source = x.trial;
    if (!in.plates.empty()) {
      L.plates.push_back(load_trial(in.plates, load_options("unloaded")));
      source = &L.plates.back();
    }
    if (!source->plates || source->plates->plates.empty()) throw InputError(source->path + ": no force plates; give --plates");
    x.plates = &*source->plates;
    MarkerSet custom;
    L.sets.push_back(resolve_marker_set(in.settings, *x.trial, custom));
    x.marker_set = &L.sets.back();
    x.options = to_options(in.settings);
    L.study.push_back(x);
  }
  return L;
}

}  // namespace kin2grf
