// kin2grf validation: fitting the COP function x_D = F(theta_A) of foot model 2 (paper Eq. 2,
// Sect. 2.3) to force-plate COPs.
//
// Samples: on the kept plate stances of validate(), every frame where the plate carries at least
// min_force_fraction of body weight gives (theta_A, s_measured): the foot inclination and the
// arc length along the sole polyline A -> B -> C of the point whose x is the measured COP, in the
// function's lengths (CopLength: sole lengths, or heel-to-MT-heads lengths) (0 behind A; beyond C
// the polyline is extended along B -> C, up to kMaxCopFraction sole lengths: the hallux landmark
// is a marker on the toe, and the COP rolls on to the toe tip at push-off). With the event angles
// fixed, F is linear in the four event positions
// (s_HS, s_HO, s_MO, s_TO): each sample's F value is a weighted sum of two of them (half-cosine or
// linear weights), so the fit is an ordinary linear least-squares problem, solved by QR, with the
// positions kept in order (the COP rolls forward; adjacent positions out of order tied).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "kin2grf/dynamics/contact.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/validation/study.hpp"
#include "kin2grf/validation/validate.hpp"

namespace kin2grf {

struct CopSamples {
  /// fraction and com_place (the whole body's centre of mass ahead of the heel point A;
  /// CopFunction::fraction's second argument) in the lengths of the CopLength they were collected for.
  std::vector<double> theta_rad, fraction, com_place;
};

/// Append the samples of one validated trial, counted in `length` (the function to be fitted's).
void collect_cop_samples(const EstimateResult& e, const ValidationResult& v, double min_force_fraction, CopLength length,
                         CopSamples& out);

struct CopFit {
  CopFunction function;
  int samples = 0;
  double rms_fraction = 0.0;          ///< RMS of F(theta) - s over the samples
  double rms_fraction_before = 0.0;   ///< the same for the starting function
};

/// Least-squares event positions for the event angles of `start` (its positions are only the
/// reference for rms_fraction_before), in order, s_HS <= s_HO <= s_MO <= s_TO: the COP rolls
/// forward as the foot turns forward (positions the data would put out of order are tied at their
/// joint least-squares value). Throws InputError with fewer than 20 samples.
/// fit_com: com_gain fitted with them (otherwise start's is kept); a least-squares gain outside
/// 0..1 is held at the bound it passes.
CopFit fit_cop_function(const CopSamples& samples, const CopFunction& start, bool fit_com = false);

/// Also the event angles: a coordinate search (steps of 0.01 rad, order kept) around `start`'s,
/// each candidate with its least-squares positions. Not the paper's fixed angles: for studies.
CopFit fit_cop_function_and_angles(const CopSamples& samples, const CopFunction& start, bool fit_com = false);

/// fit-cop on a set of trials with plates: samples from each trial's kept stances (estimated
/// with the trial's own options), one pooled fit and, on request, leave-one-lab-out: each
/// trial's mean COP rRMSE with the starting function, kin2grf's built-in walking function
/// (CopFunction{}), the pooled fit and a fit on the other labs' trials (StudyTrial::lab; a trial
/// without a lab is its own).
struct CopFitOnTrials {
  CopFit fit;
  std::vector<std::size_t> samples_per_trial;
  struct LeaveOneOut {
    std::string trial;
    double start = 0, builtin = 0, all = 0, others = 0;  ///< COP rRMSE %
    /// With the fit on the other labs: the trial's mean vertical and anterior rRMSE (%) and its
    /// total GRM rRMSE (%, NaN without a total window): what the COP's place does to the forces.
    double others_vertical = 0, others_anterior = 0, others_grm = 0;
    /// With the fit on the other labs: the trial's mean COP RMSE, mm (issue 29's "with the mm beside it").
    double others_cop_mm = 0;
  };
  std::vector<LeaveOneOut> leave_one_out;
};
CopFitOnTrials fit_cop_on_trials(const std::vector<StudyTrial>& trials, const CopFunction& start, double min_force_fraction,
                                 bool fit_angles, bool leave_one_out, bool fit_com = false);

/// How a fit was made, written with it.
struct CopFitProvenance {
  std::string command, activity;
  double min_force_fraction = ValidationOptions{}.cop_min_force_fraction;
  bool fit_angles = false;
};
/// The fitted function as a COP-function file (io/cop_function.hpp) with its provenance: the
/// command, version, trials and their samples, the RMS before and after, the leave-one-lab-out table.
nlohmann::json cop_fit_json(const CopFitOnTrials& res, const std::vector<StudyTrial>& trials, const CopFunction& start,
                            const CopFitProvenance& how);
/// The fit as text: event angles, positions, RMS, and the leave-one-lab-out table when made.
std::string format_cop_fit(const CopFitOnTrials& res, const std::vector<StudyTrial>& trials, const CopFunction& start,
                           const CopFitProvenance& how);

}  // namespace kin2grf
