// A mapping from a file's own marker labels, for a marker set that no preset recognises
// (`--markers labels`, and the fallback when no preset matches).
//
// Gait labs name the same bony landmarks in a few dozen ways: Plug-in Gait's RKNE, ISB's and the
// CAST protocol's R_FLE or RLE (lateral femoral epicondyle), OpenSim's R.Knee.Lat, Visual3D's
// RLKN... Each label is split into a side (a leading or trailing R/L, Right/Left, r_/_r) and a
// landmark word, and the word is looked up in a vocabulary of those spellings (marker_labels.cpp).
// The mapping then follows the rules a biomechanist would write by hand (docs/MARKERSETS.md):
//   - hip: the mean of the hip joint centres where the file has them, else Harrington et al. 2007
//     from both ASIS and both PSIS (or the sacrum);
//   - knee and ankle: the joint centre marker, else the mean of the lateral and medial markers
//     (epicondyles, malleoli), else the static trial's pair carried by the thigh's (knee) or the
//     shank's (ankle) cluster, else the lateral marker alone (`"surface": "lateral"`), else the
//     functional centre of the two clusters (or the shank's and the foot's markers);
//   - MT head: the mean of the metatarsal-head markers (1st, 2nd, 5th) where there are two or
//     more, else the 2nd, else the 5th (lateral surface), else a Plug-in Gait TOE (which sits on
//     the 2nd MT head), else the 1st;
//   - hallux: a hallux or toe-tip marker, else virtual toes;
//   - shoulder: the mean of the acromia, else of C7 and the sternum's top, else an upright torso
//     over the pelvis (pelvis_up, as the lower-body presets);
//   - the arms and the head (3D model) where their markers hold data.
// A label counts only where it holds data in at least a fifth as many frames as the file's
// best-seen marker (a lower-body capture keeps empty trunk labels). Two labels for one place: the one with more frames, said.
// Nothing is guessed silently: every rule taken is listed, and a landmark that no label gives
// is named in the error with the spellings looked for.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "kin2grf/trial.hpp"

namespace kin2grf {

/// One label read as a side and a landmark word.
struct MarkerLabel {
  char side = 0;         ///< 'r', 'l', or 0 (on the midline, or not told)
  std::string landmark;  ///< the vocabulary's key ("asis", "knee_lateral", "mt1", ...), empty if unknown
};
/// How kin2grf reads `label` ("RKNE" -> r knee_lateral, "L_FLE" -> l knee_lateral,
/// "R.Toe.Tip" -> r hallux, "C7" -> midline c7).
MarkerLabel read_marker_label(const std::string& label);

/// The mapping made from the labels of `m`.
struct LabelMapping {
  std::optional<nlohmann::json> mapping;  ///< a mapping file's JSON (docs/MARKERSETS.md) when every landmark has a rule
  /// The same with a "FILL IN: ..." marker for each missing landmark: a mapping file to complete
  /// by hand (`kin2grf info FILE --write-mapping OUT.json`).
  nlohmann::json draft;
  std::vector<std::string> rules;         ///< one line a landmark: what it was made from
  std::vector<std::string> notes;         ///< choices between labels, fallbacks taken
  std::vector<std::string> missing;       ///< a landmark that no label gives, with the spellings looked for
  /// Labels that read as a landmark but hold a sample in no frame, or in under a fifth of the
  /// best-held marker's frames (an empty label, a ghost), each with its count: "RASI (0 of 201
  /// frames)". What the trial's frames lack, where `missing` would only name the spellings.
  std::vector<std::string> too_few;
};
/// `static_markers`: the static trial's, whose lateral and medial joint markers a cluster then
/// carries (a set that takes its epicondyles and malleoli off for the motion trials).
LabelMapping map_marker_labels(const MarkerTrajectories& m, const MarkerTrajectories* static_markers = nullptr);

}  // namespace kin2grf
