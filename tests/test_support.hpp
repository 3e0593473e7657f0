// Shared helpers for the kin2grf tests: where the shared recordings are, and a skip that says why.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <filesystem>
#include <string>

#include "kin2grf/dynamics/inverse_dynamics.hpp"
#include "kin2grf/pipeline.hpp"
#include "kin2grf/synth/example.hpp"

namespace kin2grf::test {

/// ../shared/data, or $KIN2GRF_DATA_DIR when set.
std::string data_dir();
bool have_data();
std::string data_file(const std::string& relative);
/// A fresh temporary directory for one test.
std::filesystem::path temp_dir(const std::string& name);

/// Matrix matcher: same shape, every entry within tol, NaN only where the expected has NaN. On
/// failure it names the first entry that differs: EXPECT_TRUE(matrices_near(a, b, 1e-9)).
::testing::AssertionResult matrices_near(const Eigen::Ref<const Eigen::MatrixXd>& actual,
                                         const Eigen::Ref<const Eigen::MatrixXd>& expected, double tol);

/// Whether any of the estimate's messages contains `what`.
bool said(const EstimateResult& e, const std::string& what);

/// The synthetic trial's markers are the landmarks themselves (x forward, z up).
SagittalLandmarks synthetic_landmarks(const Trial& t);
/// estimate() on a synthetic trial with the example marker set.
EstimateResult run(const SyntheticOptions& so, EstimateOptions eo = {});

/// contact_frame on every frame of a motion, as the pipeline does frame by frame: each frame's
/// q, qd, qdd (D* filled in) and its contact points, for tests that look at many frames.
struct TrialContacts {
  std::vector<MotionFrame> frames;
  std::vector<FrameContacts> contacts;
};
TrialContacts contact_frames(const Model& model, const ContactCalibration& soles, const ContactModelOptions& options,
                             const ModelMotion& motion);
/// A squat whose "plates" are the estimate's own forces, unloaded for 10 frames at each end so
/// that the stances begin and end inside the trial.
struct SyntheticWithPlates {
  Trial trial;
  EstimateResult estimate;
  ForcePlateRecording plates;
};
SyntheticWithPlates synthetic_with_exact_plates();
/// The synthetic 3D walk of the lateral tests (issue 28): a 16 cm step, 2.5 cm of sway toward the
/// stance foot and 0.12 rad of toe-out.
SyntheticWalkOptions walk_3d_options();
/// A plate registered `dx_m` off along the lab's x (the synthetic walks' progression): its COP
/// moved and its centre moments dropped, so that the moved COP makes its moment.
void misregister_plate(ForcePlate& plate, double dx_m);
/// One foot's (anterior, vertical) force of a frame's solve: its contact points' multipliers.
Eigen::Vector2d foot_force(const FrameSolution& s, const FrameContacts& fc, int side);
/// Whether any of the foot's contact points is active.
bool foot_active(const FrameSolution& s, const FrameContacts& fc, int side);

}  // namespace kin2grf::test

#define KIN2GRF_REQUIRE_DATA()                                                                 \
  do {                                                                                         \
    if (!::kin2grf::test::have_data())                                                         \
      GTEST_SKIP() << "shared recordings not found at '" << ::kin2grf::test::data_dir()        \
                   << "' (set KIN2GRF_DATA_DIR or place ../shared/data beside the checkout)"; \
  } while (0)

/// Tests that run the command line skip where it is not built (the sanitizer build makes the
/// test executable alone).
#define KIN2GRF_REQUIRE_CLI()                                                                   \
  do {                                                                                         \
    if (std::string(KIN2GRF_CLI).empty() || !std::filesystem::exists(KIN2GRF_CLI)) GTEST_SKIP() << "the command line is not built here: " << KIN2GRF_CLI; \
  } while (0)
