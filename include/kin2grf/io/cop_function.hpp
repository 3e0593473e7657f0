// kin2grf I/O: the COP function of foot model 2 as JSON (written by `kin2grf fit-cop`, read by
// `--cop-function`). Fields: delta_hs, delta_ho, delta_mo, delta_to (rad), s_hs, s_ho, s_mo,
// s_to (arc fractions along the sole A -> B -> C from A, 0..1.25, in the lengths `length` says);
// optional length ("sole": the sole's |AB| + |BC|, 1 at C, the paper's; "heel-mt": the heel to
// the 2nd metatarsal head; absent: "sole"); optional com_gain (0..1; absent: 0, the function of the
// angle alone), the COP's arc fraction per length of the body's centre of mass ahead of the heel
// (model/foot_model.hpp); any other field (e.g. "provenance") is kept for the reader and ignored
// here.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "kin2grf/model/foot_model.hpp"

namespace kin2grf {

/// CopLength's name in a COP-function file and on the command line: "sole" or "heel-mt".
const char* cop_length_name(CopLength length);
/// The CopLength a name says; nullopt for any other name.
std::optional<CopLength> parse_cop_length(const std::string& name);

nlohmann::json cop_function_json(const CopFunction& f);
/// Throws InputError naming the file and the field when a field is missing, not a number, out
/// of range, or the event angles are not increasing.
CopFunction cop_function_from_json(const nlohmann::json& j, const std::string& path);
CopFunction read_cop_function(const std::string& path);

}  // namespace kin2grf
