#include "kin2grf/model/foot_model.hpp"

#include <cmath>

namespace kin2grf {

namespace {
double half_cosine(double a, double b, double u) { return a + (b - a) * 0.5 * (1.0 - std::cos(M_PI * u)); }
}  // namespace

// Eq. 2's F: half-cosine HS->HO and HO->MO, linear MO->TO, constant outside.
double CopFunction::fraction(double th) const {
  if (th <= delta_hs) return s_hs;
  if (th <= delta_ho) return half_cosine(s_hs, s_ho, (th - delta_hs) / (delta_ho - delta_hs));
  if (th <= delta_mo) return half_cosine(s_ho, s_mo, (th - delta_ho) / (delta_mo - delta_ho));
  if (th <= delta_to) return s_mo + (s_to - s_mo) * (th - delta_mo) / (delta_to - delta_mo);
  return s_to;
}

}  // namespace kin2grf
