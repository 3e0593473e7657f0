#include "kin2grf/io/cop_function.hpp"

#include <cmath>

#include "kin2grf/error.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/io/json.hpp"

namespace kin2grf {

const char* cop_length_name(CopLength length) { return length == CopLength::Sole ? "sole" : "heel-mt"; }

std::optional<CopLength> parse_cop_length(const std::string& name) {
  if (name == cop_length_name(CopLength::Sole)) return CopLength::Sole;
  if (name == cop_length_name(CopLength::HeelMt)) return CopLength::HeelMt;
  return std::nullopt;
}

nlohmann::json cop_function_json(const CopFunction& f) {
  nlohmann::json j = {{"delta_hs", f.delta_hs}, {"delta_ho", f.delta_ho}, {"delta_mo", f.delta_mo}, {"delta_to", f.delta_to},
                      {"s_hs", f.s_hs},         {"s_ho", f.s_ho},         {"s_mo", f.s_mo},         {"s_to", f.s_to}};
  if (f.com_gain != 0.0) j["com_gain"] = f.com_gain;
  j["length"] = cop_length_name(f.length);
  return j;
}

CopFunction cop_function_from_json(const nlohmann::json& j, const std::string& path) {
  CopFunction f;
  f.com_gain = 0.0;            // a file without the field is a function of the angle alone (the paper's form)
  f.length = CopLength::Sole;  // and one without "length" counts in sole lengths, as the paper's (and every file before it)
  auto get = [&](const char* key, double& out, bool fraction) {
    if (!j.is_object() || !j.contains(key)) throw InputError(path + ": COP function: missing field '" + key + "'");
    if (!j[key].is_number()) throw InputError(path + ": COP function: field '" + key + "' is not a number");
    out = j[key].get<double>();
    if (!std::isfinite(out) || (fraction && (out < 0 || out > kMaxCopFraction)))
      throw InputError(path + ": COP function: field '" + key + "' must be " + (fraction ? "within 0..1.25" : "finite"));
  };
  get("delta_hs", f.delta_hs, false), get("delta_ho", f.delta_ho, false), get("delta_mo", f.delta_mo, false),
      get("delta_to", f.delta_to, false);
  get("s_hs", f.s_hs, true), get("s_ho", f.s_ho, true), get("s_mo", f.s_mo, true), get("s_to", f.s_to, true);
  if (j.is_object() && j.contains("com_gain")) {
    get("com_gain", f.com_gain, false);
    // Above 1 the COP would outrun the body over the foot; below 0 it would roll back.
    if (f.com_gain < 0 || f.com_gain > 1) throw InputError(path + ": COP function: field 'com_gain' must be within 0..1");
  }
  if (j.is_object() && j.contains("length")) {
    const auto& l = j["length"];
    const std::optional<CopLength> length = l.is_string() ? parse_cop_length(l.get<std::string>()) : std::nullopt;
    if (!length) throw InputError(path + ": COP function: field 'length' must be \"sole\" or \"heel-mt\"");
    f.length = *length;
  }
  if (!(f.delta_hs < f.delta_ho && f.delta_ho < f.delta_mo && f.delta_mo < f.delta_to))
    throw InputError(path + ": COP function: the event angles must increase (delta_hs < delta_ho < delta_mo < delta_to)");
  return f;
}

CopFunction read_cop_function(const std::string& path) { return cop_function_from_json(read_json_file(path), path); }

}  // namespace kin2grf
