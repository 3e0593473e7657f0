// kin2grf model: the paper's two foot models (Sect. 2.3) and model 2's COP function, x_D =
// F(theta_A) (Eq. 2). Parameters of the model, read by the contact stage (dynamics/contact.hpp)
// and by the COP function's file adapter (io/cop_function.hpp), which therefore need not know
// the contact dynamics.
#pragma once

namespace kin2grf {

enum class FootModel { Cop, ThreePoint };

/// x_D = F(theta_A) of the paper: event angles (rad) and the COP's arc fraction at each event
/// (0 at A, 1 at C; up to 1.25 extends the sole beyond C along B -> C: the hallux landmark is a
/// marker on the toe and the COP rolls on to the toe tip).
///
/// The defaults are kin2grf's fit to the plate COPs of the 7 development walking trials
/// (932 frames of 13 plate stances loaded above 20 % body weight; event angles and positions
/// both fitted; RMS of F - s 0.060 against 0.098 with the paper's angles; leave-one-trial-out
/// COP rRMSE 6.3 % against 9.7 %). Provenance and the command that remakes it:
/// data/cop-function/walking-fitted.json and docs/METHOD-NOTES.md. paper() keeps the paper's
/// event angles (-0.3, 0, 0.15, 1 rad) with positions fitted for them (--paper).
struct CopFunction {
  double delta_hs = -0.20, delta_ho = -0.06, delta_mo = 0.08, delta_to = 1.08;
  double s_hs = 0.138, s_ho = 0.260, s_mo = 0.761, s_to = 1.012;
  [[nodiscard]] double fraction(double theta_a) const;
  /// The paper's event angles; positions fitted with those angles fixed (same data).
  static CopFunction paper() { return {-0.3, 0.0, 0.15, 1.0, 0.052, 0.453, 0.837, 0.944}; }
  /// Running (frames near a flight phase, see flight_frames()): the paper's event angles with
  /// positions fitted to the plate COPs of the development running trials (3 trials, 2 labs,
  /// 5869 frames; data/cop-function/running-fitted.json). A runner's COP stays on the forefoot
  /// from mid-stance on (s_HO 0.71 against walking's 0.26) and a forefoot strike lands there.
  /// Leave-one-lab-out COP rRMSE 9.1 / 6.4 / 6.3 % against 11.5 / 9.7 / 7.7 % with the paper's
  /// positions (docs/METHOD-NOTES.md). Event angles not fitted: fitting them overfits two labs.
  static CopFunction running() { return {-0.3, 0.0, 0.15, 1.0, 0.000, 0.709, 0.840, 1.078}; }
};

}  // namespace kin2grf
