#include "kin2grf/model/foot_model.hpp"

#include <algorithm>
#include <cmath>

namespace kin2grf {

namespace {
double half_cosine(double a, double b, double u) { return a + (b - a) * 0.5 * (1.0 - std::cos(M_PI * u)); }
}  // namespace

// Eq. 2's F: half-cosine HS->HO and HO->MO, linear MO->TO, constant outside; then kin2grf's
// centre-of-mass term (foot_model.hpp), kept on the sole.
double CopFunction::fraction(double th, double com_place) const {
  double s;
  if (th <= delta_hs) s = s_hs;
  else if (th <= delta_ho) s = half_cosine(s_hs, s_ho, (th - delta_hs) / (delta_ho - delta_hs));
  else if (th <= delta_mo) s = half_cosine(s_ho, s_mo, (th - delta_ho) / (delta_mo - delta_ho));
  else if (th <= delta_to) s = s_mo + (s_to - s_mo) * (th - delta_mo) / (delta_to - delta_mo);
  else s = s_to;
  if (com_gain == 0.0) return s;
  return std::clamp(s + com_gain * com_place, 0.0, kMaxCopFraction);
}

}  // namespace kin2grf
