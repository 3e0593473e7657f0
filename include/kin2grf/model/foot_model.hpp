// kin2grf model: the paper's two foot models (Sect. 2.3) and model 2's COP function, x_D =
// F(theta_A) (Eq. 2). Parameters of the model, read by the contact stage (dynamics/contact.hpp)
// and by the COP function's file adapter (io/cop_function.hpp), which therefore need not know
// the contact dynamics.
#pragma once

namespace kin2grf {

enum class FootModel { Cop, ThreePoint };

/// The length model 2's COP fractions are counted in, from the heel point A along A -> B -> C.
/// - Sole: the sole's whole length |AB| + |BC| (the paper's "foot length"; 1 at C).
/// - HeelMt: the heel-to-metatarsal-heads length, A to the 2nd metatarsal head (|AB|, plus
///   FootContactGeometry::heel_mt_length_m's allowance where B is a 5th-metatarsal marker); the
///   sole past B is followed as before. Why (session 47): a toe marker's place varies between labs
///   (25 to 117 mm ahead of B on the development walks, virtual toes elsewhere), and the rear
///   foot's rocker, which carries the COP until heel-off, does not lengthen with the toes. The
///   plates' COP place per 0.1 rad of foot angle spreads between the walks by 6-16 mm in heel-MT
///   lengths against 10-17 mm in sole lengths from -0.3 to 0.3 rad (less in 5 bins of 7); with
///   the function refitted without each lab, walking COP rRMSE 6.2 -> 5.7 % (docs/METHOD-NOTES.md).
enum class CopLength { Sole, HeelMt };

/// Largest COP fraction, in the function's lengths: with Sole, C plus a quarter of the sole
/// beyond it.
inline constexpr double kMaxCopFraction = 1.25;

/// x_D = F(theta_A) of the paper: event angles (rad) and the COP's arc fraction at each event
/// (0 at A; in lengths of `length`: with Sole 1 at C, up to 1.25 extends the sole beyond C along
/// B -> C: the hallux landmark is a marker on the toe and the COP rolls on to the toe tip).
///
/// kin2grf adds one term to the paper's function (session 46): com_gain times how far the whole
/// body's centre of mass is ahead of the heel point A, in the function's lengths. Why: the foot's
/// angle barely moves in foot-flat (the fitted HO -> MO events are 0.11 rad apart) while the COP rolls
/// from the heel to the metatarsal heads as the body passes over the foot (the second rocker);
/// the angle alone cannot tell how far it has rolled, and a long or slow foot-flat holds it
/// still. In single support the ground reaction points from the COP towards the centre of mass,
/// so the COP follows the body over the foot. A ratio of lengths: it scales with the subject.
///
/// The defaults are kin2grf's fit to the plate COPs of the 10 development walking trials (7 labs;
/// 1359 frames of the plate stances loaded above 5 % body weight, the frames validate judges the
/// COP on; event angles, positions and com_gain fitted, in heel-MT lengths; `kin2grf fit-cop
/// --fit-angles --fit-com`). Leave-one-lab-out (each lab scored with the function refitted on the
/// other labs; `fit-cop --leave-one-out`, mean over the trials), walking COP rRMSE: in sole lengths
/// 6.6 % with the angle alone and 6.2 % with the centre-of-mass term (session 46); in heel-MT
/// lengths 6.4 and 5.7 % (session 47; over the stances 6.39 -> 6.24 %).
/// Provenance and the command that remakes it: data/cop-function/walking-fitted.json and
/// docs/METHOD-NOTES.md. paper() keeps the paper's event angles (-0.3, 0, 0.15, 1 rad) with
/// positions fitted for them in sole lengths and no centre-of-mass term (--paper).
struct CopFunction {
  double delta_hs = -0.15, delta_ho = -0.05, delta_mo = 0.06, delta_to = 1.48;
  double s_hs = 0.2862, s_ho = 0.3578, s_mo = 0.7631, s_to = 1.1135;
  /// The COP's arc fraction per length of the centre of mass ahead of the heel point A
  /// (0: the paper's function of the angle alone).
  double com_gain = 0.1132;
  /// What the fractions are counted in (the paper's: Sole).
  CopLength length = CopLength::HeelMt;
  /// F(theta_A) + com_gain x com_place, within 0..1.25 (F alone when com_gain is 0); com_place:
  /// the whole body's centre of mass ahead of the heel point A along progression, in the
  /// function's lengths.
  [[nodiscard]] double fraction(double theta_a, double com_place = 0.0) const;
  /// The paper's event angles; positions fitted with those angles fixed (same data).
  static CopFunction paper() { return {-0.3, 0.0, 0.15, 1.0, 0.052, 0.453, 0.837, 0.944, 0.0, CopLength::Sole}; }
  /// Running (frames near a flight phase, see flight_frames()): the paper's event angles with
  /// positions fitted to the plate COPs of the development running trials (3 trials, 2 labs,
  /// 5869 frames; data/cop-function/running-fitted.json). A runner's COP stays on the forefoot
  /// from mid-stance on (s_HO 0.71 against walking's 0.26) and a forefoot strike lands there.
  /// Leave-one-lab-out COP rRMSE 9.1 / 6.4 / 6.3 % against 11.5 / 9.7 / 7.7 % with the paper's
  /// positions (docs/METHOD-NOTES.md). Event angles not fitted: fitting them overfits two labs.
  static CopFunction running() { return {-0.3, 0.0, 0.15, 1.0, 0.000, 0.709, 0.840, 1.078, 0.0, CopLength::Sole}; }
};

}  // namespace kin2grf
