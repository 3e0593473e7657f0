// kin2grf command line: a thin front end that wires the library's steps together and prints.
#include <CLI/CLI.hpp>
#include <fstream>
#include <iostream>

#include "kin2grf/error.hpp"
#include "kin2grf/io/load.hpp"
#include "kin2grf/io/summary.hpp"

namespace {

int run_info(const std::string& file, bool json, double threshold) {
  kin2grf::LoadOptions lo;
  const kin2grf::Trial t = kin2grf::load_trial(file, lo);
  const auto s = kin2grf::trial_summary(t, threshold);
  if (json) std::cout << s.dump(2) << "\n";
  else std::cout << kin2grf::format_summary(s);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"kin2grf: ground reaction forces, centre of pressure and joint torques from "
               "motion-capture markers alone (no force plates)"};
  app.set_version_flag("--version", std::string("kin2grf ") + KIN2GRF_VERSION);
  app.require_subcommand(1);

  std::string info_file;
  bool info_json = false;
  double info_threshold = 20.0;
  auto* info = app.add_subcommand("info", "Describe a recording (C3D, TRC, MOT/STO) before processing it");
  info->add_option("FILE", info_file, "The recording")->required();
  info->add_flag("--json", info_json, "Write the description as JSON (schema in docs/FORMATS.md)");
  info->add_option("--load-threshold", info_threshold, "Vertical force (N) above which a plate counts as loaded")
      ->capture_default_str();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    if (*info) return run_info(info_file, info_json, info_threshold);
  } catch (const kin2grf::InputError& e) {
    std::cerr << "kin2grf: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "kin2grf: internal error: " << e.what() << "\n";
    return 3;
  }
  return 0;
}
