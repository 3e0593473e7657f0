#include "kin2grf/model/anthropometry.hpp"

#include "kin2grf/error.hpp"

namespace kin2grf {

namespace {
constexpr double kToesShare = 0.10;
}

const AnthropometricTable& winter_table() {
  static const AnthropometricTable t{"winter",
                                     {0.678, 0.626, 0.496},
                                     {0.100, 0.433, 0.323},
                                     {0.0465, 0.433, 0.302},
                                     {0.0145 * (1 - kToesShare), 0.50, 0.475},
                                     {0.0145 * kToesShare, 0.50, 0.29},
                                     {0.028, 0.436, 0.322},
                                     {0.016, 0.430, 0.303},
                                     {0.006, 0.0, 0.297},
                                     {0.081, 0.0, 0.495}};
  return t;
}

const AnthropometricTable& de_leva_table() {
  static const AnthropometricTable t{"de-leva",
                                     {0.6028, 0.626, 0.496},
                                     {0.1416, 0.4095, 0.329},
                                     {0.0433, 0.4459, 0.255},
                                     {0.0137 * (1 - kToesShare), 0.50, 0.257},
                                     {0.0137 * kToesShare, 0.50, 0.29},
                                     {0.0271, 0.5772, 0.285},
                                     {0.0162, 0.4574, 0.276},
                                     {0.0061, 0.0, 0.628},
                                     {0.0694, 0.0, 0.303}};
  return t;
}

const AnthropometricTable& anthropometric_table(const std::string& name) {
  if (name == "winter") return winter_table();
  if (name == "de-leva" || name == "deleva") return de_leva_table();
  throw InputError("unknown anthropometric table '" + name + "' (winter, de-leva)");
}

}  // namespace kin2grf
