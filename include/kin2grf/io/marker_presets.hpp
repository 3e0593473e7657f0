// kin2grf marker-set presets (data/presets/*.json, format in docs/MARKERSETS.md): reading a set
// from JSON or a mapping file, the built-in sets, and recognising a trial's set by the markers
// that hold data. The core (markers/landmarks.hpp) takes a MarkerSet and reads no file.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "kin2grf/markers/landmarks.hpp"

namespace kin2grf {

/// A set from its JSON; InputError naming `source` and the landmark on a bad rule.
MarkerSet parse_marker_set(const nlohmann::json& j, const std::string& source);
MarkerSet load_marker_set(const std::string& path);
/// The embedded presets, the more specific first.
const std::vector<MarkerSet>& builtin_marker_sets();
/// Preset by name, or nullptr.
const MarkerSet* find_marker_set(const std::string& name);
/// The built-in set for a trial, or nullptr: among the sets whose signature markers are in the
/// file, the one whose markers all hold data in the most frames (ties: the one using more
/// markers). `why`, when given, lists each candidate's count of complete frames.
const MarkerSet* recognise_marker_set(const MarkerTrajectories& m, std::string* why = nullptr);

}  // namespace kin2grf
