// kin2grf model: anthropometric tables (segment mass, centre of mass, radius of gyration).
//
// kin2grf's default is de Leva: on the 7 development walking trials it lowers the per-foot
// vertical rRMSE on every trial (0.2-1.2 points; mean 10.2 -> 9.5 %), running unchanged
// (docs/METHOD-NOTES.md). Winter is the paper's (--paper, --anthropometry winter).
// Winter: D.A. Winter, Biomechanics and Motor Control of Human Movement, 4th ed.
// (2009), Table 4.1 (Dempster's cadaver data). Fractions of body mass M and of segment length L:
//   HAT  greater trochanter -> glenohumeral joint  0.678  COM 0.626 from the hip  rho 0.496
//   thigh  hip -> knee                              0.100  COM 0.433 from the hip  rho 0.323
//   shank  knee -> ankle                            0.0465 COM 0.433 from the knee rho 0.302
//   foot   ankle -> 2nd metatarsal head             0.0145 COM 0.50  from ankle    rho 0.475
// de Leva (1996, J Biomech 29:1223, male, Table 4): thigh 0.1416 (COM 0.4095 from the hip,
// sagittal rho 0.329), shank 0.0433 (0.4459 from the knee, rho 0.255), foot 0.0137 (rho 0.257),
// HAT = 1 - legs = 0.6028; de Leva gives no composite HAT, so its COM and rho stay Winter's,
// and the foot COM stays at mid ankle-MT (de Leva measures the foot from heel to toe tip).
// Toes are in neither table: they get 10 % of the foot mass (the foot keeps 90 %), COM at
// mid MT-hallux, rho 0.29 (a slender rod); documented choices.
// The upper body's parts (part of the HAT above; the 3D model's lateral force takes the arms and
// the head as segments of their own where their markers hold data): Winter upper arm 0.028 (COM
// 0.436 from the shoulder), forearm 0.016 (0.430 from the elbow), hand 0.006, head and neck
// 0.081; de Leva (male) upper arm 0.0271 (0.5772), forearm 0.0162 (0.4574), hand 0.0061, head
// 0.0694. The hand's COM is taken at the wrist and the head's at its markers' mean (no hand or
// skull landmarks), so their COM fractions are not used.
#pragma once

#include <string>

namespace kin2grf {

struct SegmentInertia {
  double mass_fraction;   ///< of body mass
  double com_fraction;    ///< of segment length, from the proximal end
  double gyration_fraction;  ///< radius of gyration about the COM / segment length
};

struct AnthropometricTable {
  std::string name;
  SegmentInertia hat, thigh, shank, foot, toes;
  SegmentInertia upper_arm, forearm, hand, head;  ///< parts of the HAT (see above)
};

const AnthropometricTable& winter_table();
const AnthropometricTable& de_leva_table();
/// "winter" or "de-leva"; InputError otherwise.
const AnthropometricTable& anthropometric_table(const std::string& name);

}  // namespace kin2grf
