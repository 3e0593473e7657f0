// kin2grf's Python binding (pybind11): the library's settings, estimate, validate and batch,
// with numpy arrays and plain dicts. The Python package (python/kin2grf/__init__.py) turns
// keyword arguments into the command line's settings and adds pandas and Dask on top.
#include <pybind11/eigen.h>
#include <pybind11/functional.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <CLI/CLI.hpp>

#include <filesystem>

#include "kin2grf/error.hpp"
#include "kin2grf/io/summary.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/output/c3d_export.hpp"
#include "kin2grf/output/opensim_export.hpp"
#include "kin2grf/output/results.hpp"
#include "kin2grf/validation/validate.hpp"
#include "kin2grf/workflow/batch.hpp"
#include "kin2grf/workflow/settings.hpp"
#include "kin2grf/workflow/trial_list.hpp"
#include "kin2grf/io/json.hpp"

namespace py = pybind11;

namespace {

/// JSON -> Python objects through the json module (one copy, no hand-written walker).
py::object to_python(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(kin2grf::json_text(j)); }

kin2grf::Settings settings_from(const std::string& trial, const std::vector<std::string>& words) {
  kin2grf::Settings s;
  // The trial first (a path starting with '-' would read as an option: "./" keeps it a path).
  std::vector<std::string> all = {!trial.empty() && trial[0] == '-' ? "./" + trial : trial};
  all.insert(all.end(), words.begin(), words.end());
  kin2grf::parse_settings(all, s, "settings");
  return s;
}

py::dict estimate_dict(const kin2grf::Settings& s, const kin2grf::EstimateOptions& o, const kin2grf::EstimateResult& r) {
  const auto table = kin2grf::results_table(r);
  py::dict d;
  d["columns"] = table.columns;
  d["values"] = table.values;
  const auto curves = kin2grf::stance_curves_table(r);
  d["stance_curves_columns"] = curves.columns;
  d["stance_curves_values"] = curves.values;
  d["summary"] = to_python(kin2grf::results_summary(r, kin2grf::settings_json(s, o)));
  d["messages"] = r.messages;
  return d;
}

py::dict estimate(const std::string& trial, const std::vector<std::string>& words, const std::string& opensim_dir,
                  const std::string& mot_path, bool lab_frame, const std::string& c3d_path) {
  const auto s = settings_from(trial, words);
  kin2grf::EstimateResult r;
  kin2grf::EstimateOptions o;
  std::vector<std::string> written;
  {
    py::gil_scoped_release nogil;
    const auto files = kin2grf::load_trial_and_static(s, kin2grf::estimate_load_options());
    o = kin2grf::to_options(s);
    r = kin2grf::estimate_trial(s, o, files.trial, files.static_trial);
    const std::string stem = std::filesystem::path(s.trial).stem().string(), settings = kin2grf::settings_json(s, o).dump();
    if (!opensim_dir.empty()) {
      // The OpenSim set, as `estimate --opensim DIR` writes it (the files named after the trial).
      kin2grf::OpenSimExportOptions eo;
      eo.settings = settings;
      const auto f = kin2grf::write_opensim_export(opensim_dir, stem, files.trial, r, eo);
      written = {f.grf_mot, f.markers_trc, f.external_loads_xml};
    }
    if (!mot_path.empty()) {  // as `estimate -o` (with --lab-frame)
      if (lab_frame) kin2grf::write_grf_mot(mot_path, r, settings);
      else kin2grf::write_opensim_grf_mot(mot_path, stem, files.trial.markers.time_s, r, settings);
      written.push_back(mot_path);
    }
    if (!c3d_path.empty()) {  // as `estimate --c3d`
      kin2grf::write_c3d_export(c3d_path, files.trial, r);
      written.push_back(c3d_path);
    }
  }
  py::dict d = estimate_dict(s, o, r);
  d["written"] = written;
  return d;
}

py::dict validate(const std::string& trial, const std::vector<std::string>& words, const std::string& plates,
                  double threshold_N, const std::string& zero_offset, const std::string& sync, const std::string& timing) {
  const auto s = settings_from(trial, words);
  kin2grf::ValidationOptions vo;
  vo.threshold_N = threshold_N;
  kin2grf::parse_sync(sync, vo);
  kin2grf::parse_timing(timing, vo);
  std::optional<kin2grf::ValidationRun> run;
  {
    py::gil_scoped_release nogil;
    run = kin2grf::validate_trial(s, plates, vo, zero_offset);
  }
  py::dict d;
  d["validation"] = to_python(kin2grf::validation_json(s.trial, run->estimate, run->validation, run->settings));
  d["estimate"] = estimate_dict(s, kin2grf::to_options(s), run->estimate);
  const auto curves = kin2grf::validation_stance_curves_table(run->estimate, run->validation);
  d["stance_curves_columns"] = curves.columns;
  d["stance_curves_values"] = curves.values;
  std::vector<std::string> plate_names;
  for (const auto& p : run->validation.plates) plate_names.push_back(p.name);
  d["plate_names"] = plate_names;
  return d;
}

py::list batch_lines(const std::vector<std::string>& lines, int jobs, const std::string& out_dir) {
  std::vector<kin2grf::TrialListEntry> entries;
  for (std::size_t k = 0; k < lines.size(); ++k)
    entries.push_back(kin2grf::parse_trial_list_line(lines[k], "trial " + std::to_string(k + 1)));
  kin2grf::BatchOptions o;
  o.jobs = jobs;
  o.out_dir = out_dir;
  std::vector<kin2grf::BatchRow> rows;
  {
    py::gil_scoped_release nogil;
    rows = kin2grf::run_batch(entries, o);
  }
  py::list out;
  for (const auto& r : rows) out.append(to_python(kin2grf::batch_row_json(r)));
  return out;
}

/// The settings' names, defaults and help, from the command line's own parser.
py::list settings_help() {
  kin2grf::Settings s;
  CLI::App app{"settings"};
  kin2grf::add_settings_options(&app, s);
  py::list out;
  for (const auto* opt : app.get_options()) {
    if (opt->get_lnames().empty() || opt->get_lnames().front() == "help") continue;
    py::dict d;
    d["name"] = opt->get_lnames().front();
    d["flag"] = opt->get_items_expected_max() == 0;  // a flag takes no value
    d["default"] = opt->get_default_str();
    d["help"] = opt->get_description();
    out.append(d);
  }
  return out;
}

}  // namespace

PYBIND11_MODULE(_kin2grf, m) {
  m.doc() = "kin2grf's C++ core (use the kin2grf package)";
  m.attr("__version__") = KIN2GRF_VERSION;
  // Bad input raises kin2grf.InputError (a ValueError) with the library's own message.
  py::register_exception<kin2grf::InputError>(m, "InputError", PyExc_ValueError);
  m.def("estimate", &estimate, py::arg("trial"), py::arg("words"), py::arg("opensim_dir") = std::string(),
        py::arg("mot_path") = std::string(), py::arg("lab_frame") = false, py::arg("c3d_path") = std::string());
  m.def("validate", &validate, py::arg("trial"), py::arg("words"), py::arg("plates"), py::arg("threshold_N"),
        py::arg("zero_offset"), py::arg("sync"), py::arg("timing") = std::string("auto"));
  m.def("batch_lines", &batch_lines, py::arg("lines"), py::arg("jobs"), py::arg("out_dir"));
  // What `kin2grf info --json` prints (docs/FORMATS.md), the marker set estimate would take included.
  m.def(
      "info",
      [](const std::string& path, double threshold_N, const std::string& zero_offset) {
        nlohmann::json j;
        {
          py::gil_scoped_release release;
          j = kin2grf::describe_file(path, threshold_N, kin2grf::load_options(zero_offset), std::nullopt);
        }
        return to_python(j);
      },
      py::arg("path"), py::arg("threshold_N") = 20.0, py::arg("zero_offset") = std::string("none"));
  m.def("settings_help", &settings_help);
  m.def("batch_columns", [] { return kin2grf::batch_csv_columns(); });
}
