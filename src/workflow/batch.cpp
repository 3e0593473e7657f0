#include "kin2grf/workflow/batch.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <atomic>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <mutex>
#include <numeric>
#include <set>
#include <sstream>
#include <system_error>
#include <thread>
#include <utility>

#include "kin2grf/error.hpp"
#include "kin2grf/io/output_file.hpp"
#include "kin2grf/output/c3d_export.hpp"
#include "kin2grf/output/opensim_export.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/output/results.hpp"
#include "kin2grf/io/json.hpp"
#include "kin2grf/parallel.hpp"

namespace kin2grf {

namespace {

/// A file name from a trial's name: letters, digits, '-', '_' and '.' kept, others '_'.
std::string file_stem(const std::string& name) {
  std::string s;
  for (char c : name) s += (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.') ? c : '_';
  return s.empty() || s[0] == '.' ? "trial" + s : s;
}

void fill_validation(BatchRow& row, const ValidationResult& v) {
  row.validated = true;
  const MeanMetrics m = mean_rrmse(v.stances);
  row.stances = m.n;
  if (m.n > 0) {
    row.vertical = m.vertical, row.anterior = m.anterior, row.cop = m.cop, row.moment = m.moment, row.cop_mm = m.cop_rmse_mm;
    row.lateral = m.lateral, row.cop_lateral_mm = m.cop_lateral_rmse_mm, row.knee_adduction = m.knee_adduction;
  }
  if (v.total) {
    if (v.total->metrics.vertical) row.total_vertical = v.total->metrics.vertical->rrmse_percent;
    if (v.total->metrics.moment) row.total_grm = v.total->metrics.moment->rrmse_percent;
  }
  for (const auto& e : v.excluded) row.messages.push_back("validation: excluded " + e);
}

}  // namespace

ValidationRun validate_trial(const Settings& s, const std::string& plates_file, const ValidationOptions& vo,
                             const std::string& zero_offset, std::function<void(long, long)> progress) {
  if (!(std::isfinite(vo.threshold_N) && vo.threshold_N > 0))
    throw InputError("setting threshold (N) = " + std::to_string(vo.threshold_N) + ": must be a force above 0 N");
  const TrialAndStatic files = load_trial_and_static(s, load_options(zero_offset));
  const Trial& trial = files.trial;
  std::optional<Trial> measured;
  if (!plates_file.empty()) measured = load_trial(plates_file, load_options(zero_offset));
  const Trial& source = measured ? *measured : trial;
  if (!source.plates || source.plates->plates.empty()) {
    // Why the file's plates were not read (an unsupported type, a broken calibration), if it says.
    std::string why;
    for (const auto& w : source.warnings)
      if (w.find("FORCE_PLATFORM") != std::string::npos || w.find("left out") != std::string::npos) why += "; " + w;
    throw InputError(source.path + ": no force plates to validate against" + why + (measured ? "" : "; give a plates file"));
  }
  EstimateOptions options = to_options(s);
  options.progress = std::move(progress);
  ValidationRun run;
  run.estimate = estimate_trial(s, options, trial, files.static_trial);
  run.validation = validate(run.estimate, *source.plates, vo);
  if (measured)  // what the plates file's reader noticed (the trial's own warnings are the estimate's)
    for (const auto& w : measured->warnings) run.validation.notes.push_back("plates file: " + w);
  run.settings = settings_json(s, options);
  run.settings["plates"] = source.path;
  run.settings["threshold_N"] = vo.threshold_N;
  run.settings["zero_offset"] = zero_offset;
  run.settings["sync"] = vo.sync == ValidationOptions::Sync::None   ? nlohmann::json("none")
                         : vo.sync == ValidationOptions::Sync::Auto ? nlohmann::json("auto")
                                                                    : nlohmann::json(vo.plate_shift_s);
  run.settings["timing"] = timing_name(vo.timing);
  run.plates_path = source.path;
  return run;
}

void parse_sync(const std::string& text, ValidationOptions& vo) {
  if (text == "none" || text.empty()) {
    vo.sync = ValidationOptions::Sync::None;
  } else if (text == "auto") {
    vo.sync = ValidationOptions::Sync::Auto;
  } else {
    double shift = 0;
    if (!parse_double(text, shift) || !std::isfinite(shift) || std::abs(shift) > 1.0)
      throw InputError("--sync " + text + ": must be none, auto or a shift of the plates in seconds between -1 and 1 (0.04: the plates led by 40 ms)");
    vo.sync = ValidationOptions::Sync::Fixed;
    vo.plate_shift_s = shift;
  }
}

namespace {
/// --timing's names, one table for the parser and the settings JSON.
constexpr std::array<std::pair<const char*, ValidationOptions::Timing>, 3> kTimingNames{
    {{"auto", ValidationOptions::Timing::Auto}, {"crossing", ValidationOptions::Timing::Crossing}, {"ramp", ValidationOptions::Timing::Ramp}}};
}  // namespace

void parse_timing(const std::string& text, ValidationOptions& vo) {
  for (const auto& [name, timing] : kTimingNames)
    if (text == name) {
      vo.timing = timing;
      return;
    }
  throw InputError("--timing " + text + ": must be auto, crossing or ramp");
}

const char* timing_name(ValidationOptions::Timing timing) {
  for (const auto& [name, t] : kTimingNames)
    if (t == timing) return name;
  return "auto";
}

std::vector<std::string> batch_trial_outputs(const TrialListEntry& entry, const std::string& out_dir, bool c3d) {
  const auto base = (std::filesystem::path(out_dir) / file_stem(entry.name)).string();
  const auto opensim = opensim_export_paths(out_dir, file_stem(entry.name));
  std::vector<std::string> out = {base + ".csv", opensim.grf_mot, base + ".json", opensim.markers_trc, opensim.external_loads_xml,
                                  base + "_stances.csv", base + "_stance_curves.csv"};
  if (c3d) out.push_back(base + ".c3d");
  return out;
}

BatchRow run_batch_entry(const TrialListEntry& entry, const BatchOptions& options) {
  BatchRow row;
  row.activity = entry.activity, row.lab = entry.lab, row.name = entry.name, row.trial = entry.settings.trial;
  const auto start = std::chrono::steady_clock::now();
  try {
    const TrialAndStatic files = load_trial_and_static(entry.settings, load_options("unloaded"));
    const Trial& trial = files.trial;
    std::optional<Trial> plates_file;
    if (!entry.plates.empty()) plates_file = load_trial(entry.plates, load_options("unloaded"));
    const EstimateOptions estimate_options = to_options(entry.settings);
    const EstimateResult r = estimate_trial(entry.settings, estimate_options, trial, files.static_trial);
    row.frames = static_cast<long>(r.time_s.size());
    row.duration_s = r.time_s.size() > 1 ? r.time_s[r.time_s.size() - 1] - r.time_s[0] : 0.0;
    row.mass_kg = r.mass_kg;
    row.marker_set = r.marker_set;
    row.messages = r.messages;
    const Trial& source = plates_file ? *plates_file : trial;
    std::optional<ValidationResult> v;
    if (source.plates && !source.plates->plates.empty()) {
      v = validate(r, *source.plates, options.validation);
      fill_validation(row, *v);
    }
    if (!options.out_dir.empty()) {
      // The trial's files are placed together, with the batch's, or not at all.
      OutputTransaction outputs;
      const auto written = batch_trial_outputs(entry, options.out_dir, options.c3d);
      const std::string &csv = written[0], &json = written[2];
      write_results_csv(csv, r);
      write_file_text(written[5], stance_parameters_csv(r));
      write_stance_curves_csv(written[6], r);
      auto settings = settings_json(entry.settings, estimate_options);
      // The OpenSim set, as `estimate --opensim` writes it: the GRF in OpenSim's frame over the
      // whole trial, the markers, the ExternalLoads file.
      OpenSimExportOptions eo;
      eo.settings = settings.dump();
      write_opensim_export(options.out_dir, file_stem(entry.name), trial, r, eo);
      if (options.c3d)
        for (auto& m : write_c3d_export(written.back(), trial, r)) row.messages.push_back(std::move(m));
      write_file_text(json, json_text(v ? validation_json(entry.name, r, *v, settings) : results_summary(r, settings)));
      outputs.commit();
      row.outputs = written;
    }
    row.ok = true;
  } catch (const std::bad_alloc&) {
    row.error = "out of memory";
  } catch (const InputError& e) {
    row.error = e.what();
  } catch (const std::exception& e) {
    row.error = std::string("internal error: ") + e.what();
  } catch (...) {  // nothing may leave a worker thread
    row.error = "internal error";
  }
  row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return row;
}

namespace {
std::vector<std::size_t> in_list_order(std::size_t n) {
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  return order;
}

/// The entries longest first, the bytes of each trial's files standing for its work: a long trial
/// left to the end would keep one thread busy while the others idle.
std::vector<std::size_t> longest_first(const std::vector<TrialListEntry>& entries) {
  std::vector<std::uintmax_t> bytes(entries.size(), 0);
  for (std::size_t k = 0; k < entries.size(); ++k) {
    auto files = input_files(entries[k].settings);
    files.push_back(entries[k].plates);
    for (const auto& f : files) {
      std::error_code ec;
      const auto b = f.empty() ? 0 : std::filesystem::file_size(f, ec);
      if (!ec) bytes[k] += b;
    }
  }
  auto order = in_list_order(entries.size());
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return bytes[a] > bytes[b]; });
  return order;
}
}  // namespace

std::vector<BatchRow> run_batch(const std::vector<TrialListEntry>& entries, const BatchOptions& options) {
  if (options.jobs < 1) throw InputError("jobs " + std::to_string(options.jobs) + ": must be at least 1");
  if (!options.out_dir.empty()) {
    // One trial's outputs must not replace another's, nor any trial's input (a trial's name may
    // be another's --plates file).
    std::set<std::string> stems;
    std::map<std::string, std::string> written_by;  // output file -> the trial that writes it
    std::vector<std::string> outputs;
    for (const auto& e : entries) {
      if (!stems.insert(file_stem(e.name)).second)
        throw InputError("two trials of the batch are named '" + e.name + "': their outputs would share a name");
      // Names can still meet across trials: trial "a" writes a_stances.csv, trial "a_stances" its a_stances.csv.
      for (auto& f : batch_trial_outputs(e, options.out_dir, options.c3d)) {
        const auto [at, fresh] = written_by.emplace(f, e.name);
        if (!fresh)
          throw InputError("trials '" + at->second + "' and '" + e.name + "' of the batch would both write " + f + ": rename one");
        outputs.push_back(std::move(f));
      }
    }
    ensure_no_output_is_an_input(outputs, list_input_files(entries));
    ensure_output_folder(options.out_dir);
  }
  std::vector<BatchRow> rows(entries.size());
  // Rows stay in the list's order whatever order the trials run in.
  const std::vector<std::size_t> order = options.jobs > 1 ? longest_first(entries) : in_list_order(entries.size());
  std::atomic<std::size_t> next{0};
  std::size_t done = 0;
  std::mutex progress_mutex;
  const auto n = std::min<std::size_t>(static_cast<std::size_t>(options.jobs), std::max<std::size_t>(1, entries.size()));
  auto work = [&] {
    // Several trials at once: each runs on its own thread only (no threads within a trial).
    const ThreadCountScope per_trial(n > 1 ? 1 : thread_count());
    for (std::size_t i; (i = next++) < entries.size();) {
      const std::size_t k = order[i];
      rows[k] = run_batch_entry(entries[k], options);
      std::lock_guard lock(progress_mutex);
      ++done;
      if (options.progress) options.progress(done, entries.size(), rows[k]);
    }
  };
  std::vector<std::thread> threads;
  for (std::size_t t = 1; t < n; ++t) threads.emplace_back(work);
  work();
  for (auto& t : threads) t.join();
  return rows;
}

namespace {
std::string cell(double v) {
  // Full precision, the shortest text that reads back as the same double (it was %.4g: a table
  // for analysis, not for the eye, which format_batch_table serves).
  if (!std::isfinite(v)) return "";
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}
nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }
}  // namespace

const std::vector<std::string>& batch_csv_columns() {
  static const std::vector<std::string> columns{
      "activity",        "lab",         "name",     "trial",  "ok",
      "frames",          "duration_s",  "seconds",  "frames_per_s",
      "mass_kg",         "marker_set",  "stances",  "vertical_rrmse_percent",
      "anterior_rrmse_percent", "cop_rrmse_percent", "moment_rrmse_percent", "total_vertical_rrmse_percent",
      "total_grm_rrmse_percent", "cop_rmse_mm", "lateral_rrmse_percent", "cop_lateral_rmse_mm",
      "knee_adduction_rrmse_percent", "error"};
  return columns;
}

std::string batch_csv(const std::vector<BatchRow>& rows) {
  std::ostringstream os;
  for (std::size_t k = 0; k < batch_csv_columns().size(); ++k) os << (k ? "," : "") << batch_csv_columns()[k];
  os << '\n';
  for (const auto& r : rows)
    os << csv_quoted(r.activity) << ',' << csv_quoted(r.lab) << ',' << csv_quoted(r.name) << ',' << csv_quoted(r.trial) << ','
       << (r.ok ? 1 : 0) << ',' << r.frames << ',' << cell(r.duration_s) << ',' << cell(r.seconds) << ','
       << cell(r.seconds > 0 ? static_cast<double>(r.frames) / r.seconds : NAN) << ',' << cell(r.mass_kg) << ','
       << csv_quoted(r.marker_set) << ',' << r.stances << ',' << cell(r.vertical) << ',' << cell(r.anterior) << ','
       << cell(r.cop) << ',' << cell(r.moment) << ',' << cell(r.total_vertical) << ',' << cell(r.total_grm) << ','
       << cell(r.cop_mm) << ',' << cell(r.lateral) << ',' << cell(r.cop_lateral_mm) << ',' << cell(r.knee_adduction) << ','
       << csv_quoted(r.error) << '\n';
  return os.str();
}

std::string format_batch_table(const std::vector<BatchRow>& rows) {
  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "%-28s %-8s %7s %6s %7s %7s %7s %7s\n", "trial", "status", "frames", "s", "vert %", "ant %",
                "COP %", "GRM %");
  out += line;
  auto pct = [](double v) {
    char buf[32] = "-";
    if (std::isfinite(v)) std::snprintf(buf, sizeof buf, "%.1f", v);
    return std::string(buf);
  };
  for (const auto& r : rows) {
    std::snprintf(line, sizeof line, "%-28.28s %-8s %7ld %6.1f %7s %7s %7s %7s  %s\n", r.name.c_str(), r.ok ? "ok" : "FAILED",
                  r.frames, r.seconds, pct(r.vertical).c_str(), pct(r.anterior).c_str(), pct(r.cop).c_str(),
                  pct(r.total_grm).c_str(), r.ok ? "" : r.error.substr(0, r.error.find('\n')).substr(0, 200).c_str());
    out += line;
  }
  return out;
}

nlohmann::json batch_row_json(const BatchRow& r) {
  return {{"activity", r.activity}, {"lab", r.lab}, {"name", r.name}, {"trial", r.trial}, {"ok", r.ok},
          {"error", r.ok ? nlohmann::json(nullptr) : nlohmann::json(r.error)}, {"frames", r.frames},
          {"duration_s", r.duration_s}, {"seconds", r.seconds}, {"mass_kg", r.mass_kg}, {"marker_set", r.marker_set},
          {"validated", r.validated}, {"stances", r.stances}, {"vertical_rrmse_percent", number(r.vertical)},
          {"anterior_rrmse_percent", number(r.anterior)}, {"cop_rrmse_percent", number(r.cop)}, {"moment_rrmse_percent", number(r.moment)},
          {"total_vertical_rrmse_percent", number(r.total_vertical)}, {"total_grm_rrmse_percent", number(r.total_grm)},
          {"cop_rmse_mm", number(r.cop_mm)}, {"lateral_rrmse_percent", number(r.lateral)},
          {"cop_lateral_rmse_mm", number(r.cop_lateral_mm)}, {"knee_adduction_rrmse_percent", number(r.knee_adduction)},
          {"messages", r.messages}, {"outputs", r.outputs}};
}

nlohmann::json batch_json(const std::vector<BatchRow>& rows) {
  nlohmann::json j = {{"kin2grf_version", KIN2GRF_VERSION}, {"trials", nlohmann::json::array()}};
  for (const auto& r : rows) j["trials"].push_back(batch_row_json(r));
  return j;
}

}  // namespace kin2grf
