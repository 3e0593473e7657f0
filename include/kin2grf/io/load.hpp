// kin2grf I/O: open any supported recording by its extension (.c3d, .trc, .mot, .sto).
#pragma once

#include <optional>
#include <string>

#include "kin2grf/io/c3d.hpp"
#include "kin2grf/trial.hpp"

namespace kin2grf {

struct LoadOptions {
  C3dReadOptions c3d;
  double cop_threshold_N = 10.0;  ///< also used for GRF .mot files
};

/// Open a recording. The lab's up axis is then checked against the data (check_up_axis): where
/// the file's convention (C3D: Z, TRC: Y) disagrees, the data's axis is used, with a warning; and
/// a subject prefix common to the marker labels is removed (remove_subject_prefix).
Trial load_trial(const std::string& path, const LoadOptions& options = {});

/// Vicon Nexus names a subject's markers "Subject:LASI" (SUBJECTS:USES_PREFIXES), and so do TRCs
/// exported from such files; presets name the markers alone. When every label that holds a ':'
/// starts with the same prefix up to its first ':', that prefix is removed from them, kept in
/// MarkerTrajectories::label_prefix, and said in a warning. Labels without it (Nexus's unlabelled
/// "*12") stay as they are. Several subjects in one file (two prefixes), or a label that would
/// then be taken twice, leave every label as it is (a mapping file names them).
void remove_subject_prefix(MarkerTrajectories& m, std::vector<std::string>& warnings);

/// The lab up axis the data show, or nothing when they do not tell:
///  - force plates with geometry: the axis along the plates' normal (a plate lies on the floor);
///  - else markers: the axis of the largest spread across the markers of a frame (median over
///    frames), when it exceeds the next by 30 % and the markers stand mostly on its positive side
///    (a body is taller than it is wide or deep; a stride is shorter than the pelvis-foot height
///    only by a little, hence the median, not the maximum).
/// `why` says which evidence decided.
std::optional<Axis> up_axis_from_data(const Trial& t, std::string* why = nullptr);

}  // namespace kin2grf
