#include "kin2grf/workflow/trial_list.hpp"

#include <CLI/CLI.hpp>

#include <filesystem>
#include <fstream>

#include "kin2grf/error.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/text.hpp"

namespace kin2grf {

namespace {

/// A trial line's options are read by one parser per list (building CLI11's parser for each line
/// made a long list slow: 100,000 lines took 12 s).
class TrialLineParser {
 public:
  TrialLineParser() {
    add_settings_options(&app_, settings_);
    app_.add_option("--plates", plates_);
  }
  TrialListEntry parse(std::string_view line, const std::string& where) {
    if (line.size() > kMaxTrialLineChars)
      throw InputError(where + ": a line of " + std::to_string(line.size()) + " characters, more than the " +
                       std::to_string(kMaxTrialLineChars) + " a trial line may have");
    std::vector<std::string> fields;
    std::size_t start = 0;
    for (std::size_t bar; fields.size() < 3 && (bar = line.find('|', start)) != std::string::npos; start = bar + 1)
      fields.emplace_back(line.substr(start, bar - start));
    // A plain line "TRIAL [options]" (no '|'): the trial is named by its file, its own lab, as
    // trials given one by one are.
    const bool plain = fields.empty();
    if (!plain && fields.size() < 2) throw InputError(where + ": expected activity|lab|name|TRIAL [options], or TRIAL [options]");
    TrialListEntry e;
    if (!plain) {
      e.activity = fields[0];
      e.lab = fields[1];  // the old 3-field form: the name is the lab
      e.name = fields.back();
    }
    for (const auto& f : fields)
      if (f.empty()) throw InputError(where + ": an empty field in activity|lab|name");
    const std::string rest(line.substr(start));
    std::size_t words = 0;
    for (std::size_t k = 0; k < rest.size(); ++k) words += rest[k] != ' ' && (k == 0 || rest[k - 1] == ' ');
    if (words > kMaxTrialLineWords)
      throw InputError(where + ": " + std::to_string(words) + " words of options, more than the " + std::to_string(kMaxTrialLineWords) +
                       " a trial line may have");
    settings_ = Settings{};
    plates_.clear();
    app_.clear();
    try {
      app_.parse(rest, false);
    } catch (const CLI::ParseError& err) {
      throw InputError(where + ": " + err.what());
    }
    e.settings = settings_;
    e.plates = plates_;
    if (plain) {
      e.activity = "trials";
      e.name = e.lab = std::filesystem::path(e.settings.trial).filename().string();
    }
    return e;
  }

 private:
  CLI::App app_{"trial"};
  Settings settings_;
  std::string plates_;
};

}  // namespace

TrialListEntry parse_trial_list_line(const std::string& line, const std::string& where) { return TrialLineParser().parse(line, where); }

std::vector<TrialListEntry> parse_trial_list(std::string_view text, const std::string& path) {
  // A UTF-8 byte-order mark (Windows editors) is no part of the first line.
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  TrialLineParser parser;
  std::vector<TrialListEntry> out;
  int number = 0;
  while (!text.empty()) {
    // Lines end with LF, CRLF or a lone CR (old Mac editors).
    const auto end = text.find_first_of("\r\n");
    std::string_view line = text.substr(0, end);
    text.remove_prefix(end == std::string_view::npos ? text.size() : end + (text.substr(end, 2) == "\r\n" ? 2 : 1));
    ++number;
    if (line.empty() || line[0] == '#' || is_blank(line)) continue;
    out.push_back(parser.parse(line, path + ":" + std::to_string(number)));
    out.back().line = number;
  }
  if (out.empty()) throw InputError(path + ": no trials in the list");
  return out;
}

std::vector<TrialListEntry> read_trial_list(const std::string& path) { return parse_trial_list(read_file_text(path), path); }

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

namespace {
/// What a study trial's pointers point into while it is used.
struct HeldTrial {
  Trial trial;
  std::optional<Trial> static_trial, plates_file;
  MarkerSet set;
};
}  // namespace

std::vector<StudyTrial> study_trials(const std::vector<TrialListEntry>& entries) {
  std::vector<StudyTrial> out;
  out.reserve(entries.size());
  for (const auto& in : entries) {
    // Each file is checked now (a missing one ends the command before any work), read when used.
    for (const auto* f : {&in.settings.trial, &in.settings.static_trial, &in.plates})
      if (!f->empty()) check_input_file(*f);
    StudyTrial x;
    x.name = in.name;
    x.activity = in.activity;
    x.lab = in.lab;
    x.options = to_options(in.settings);
    x.load = [settings = in.settings, plates = in.plates] {
      auto held = std::make_shared<HeldTrial>();
      held->trial = load_trial(settings.trial, load_options("unloaded"));
      apply_frame_range(held->trial, settings.frames);
      StudyTrialData d;
      d.trial = &held->trial;
      if (!settings.static_trial.empty()) {
        held->static_trial = load_trial(settings.static_trial);
        d.static_trial = &*held->static_trial;
      }
      const Trial* source = &held->trial;
      if (!plates.empty()) {
        held->plates_file = load_trial(plates, load_options("unloaded"));
        source = &*held->plates_file;
      }
      if (!source->plates || source->plates->plates.empty()) throw InputError(source->path + ": no force plates; give --plates");
      d.plates = &*source->plates;
      MarkerSet custom;
      held->set = resolve_marker_set(settings, held->trial, custom, nullptr, held->static_trial ? &*held->static_trial : nullptr);
      d.marker_set = &held->set;
      d.held = held;
      return d;
    };
    out.push_back(std::move(x));
  }
  return out;
}

}  // namespace kin2grf
