// kin2grf: the numeric estimate options, each declared once.
//
// A row names one EstimateOptions field that is a plain number: its name on the command line
// (and in trial lists and Python's keyword arguments), its key in the settings JSON, the range
// the command line accepts, its value under --paper (none: the user's), its help, and the grid
// `kin2grf study <flag>` runs. workflow/settings builds the flags, the --paper resolution and the
// settings JSON from the rows; validation/study builds that study from the row's grid. Adding
// such a setting: a row here, and the field with its use.
#pragma once

#include <optional>
#include <vector>

#include "kin2grf/pipeline.hpp"

namespace kin2grf {

struct NumericOption {
  const char* flag;  ///< without the dashes
  const char* json_key;
  double& (*field)(EstimateOptions&);
  double lo, hi;  ///< the command line's range; lo > hi: none there (check_options has the library's)
  std::optional<double> paper;
  const char* help;
  /// The study of this setting (`kin2grf study <flag>`): its values (none: no study from the row),
  /// each labelled by label_format applied to label_scale x the value, 0 by zero_label when given.
  std::vector<double> grid = {};
  const char* label_format = "%g";
  double label_scale = 1.0;
  const char* zero_label = nullptr;
  /// The study's condition: Gaussian noise (m) added to every marker coordinate at every value
  /// (a setting that acts only on noisy markers is studied there).
  double study_marker_noise_m = 0.0;
};

/// Every row, in the order the command line lists them.
const std::vector<NumericOption>& numeric_options();

/// The row whose flag is `flag`; none.
const NumericOption* find_numeric_option(const char* flag);

}  // namespace kin2grf
