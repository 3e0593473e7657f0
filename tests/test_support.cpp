#include "test_support.hpp"
#include "kin2grf/io/marker_presets.hpp"

#include <algorithm>
#include <limits>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace kin2grf::test {

std::string data_dir() {
  if (const char* env = std::getenv("KIN2GRF_DATA_DIR"); env && *env) return env;
  return KIN2GRF_DATA_DIR;
}

bool have_data() {
  return std::filesystem::exists(std::filesystem::path(data_dir()) / "README.md");
}

std::string data_file(const std::string& relative) {
  return (std::filesystem::path(data_dir()) / relative).string();
}

std::filesystem::path temp_dir(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  auto p = std::filesystem::temp_directory_path() / "kin2grf-tests" /
           (std::string(info ? info->test_suite_name() : "x") + "-" + (info ? info->name() : "y") + "-" + name);
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  return p;
}

::testing::AssertionResult matrices_near(const Eigen::Ref<const Eigen::MatrixXd>& actual,
                                         const Eigen::Ref<const Eigen::MatrixXd>& expected, double tol) {
  if (actual.rows() != expected.rows() || actual.cols() != expected.cols())
    return ::testing::AssertionFailure() << "shape " << actual.rows() << " x " << actual.cols() << ", expected "
                                         << expected.rows() << " x " << expected.cols();
  for (Eigen::Index i = 0; i < actual.rows(); ++i)
    for (Eigen::Index c = 0; c < actual.cols(); ++c) {
      const double a = actual(i, c), b = expected(i, c);
      const bool ok = std::isnan(b) ? std::isnan(a) : std::abs(a - b) <= tol;
      if (!ok)
        return ::testing::AssertionFailure() << "entry (" << i << ", " << c << ") is " << a << ", expected " << b
                                             << " within " << tol;
    }
  return ::testing::AssertionSuccess();
}

SagittalLandmarks synthetic_landmarks(const Trial& t) {
  SagittalLandmarks lm;
  lm.rate_hz = t.markers.rate_hz;
  lm.time_s = t.markers.time_s;
  for (int k = 0; k < kLandmarkCount; ++k) lm.p[k].resize(lm.frames(), 2);
  for (int side = 0; side < 2; ++side)
    for (int k = kKnee; k <= kHallux; ++k) {
      const auto& P = t.markers.positions_m[static_cast<std::size_t>(7 * side + 2 + k)];
      lm.p[landmark(side, static_cast<LegLandmark>(k))].col(0) = P.col(0);
      lm.p[landmark(side, static_cast<LegLandmark>(k))].col(1) = P.col(2);
    }
  for (int k : {kShoulder, kHip}) {
    lm.p[k].col(0) = t.markers.positions_m[static_cast<std::size_t>(k)].col(0);
    lm.p[k].col(1) = t.markers.positions_m[static_cast<std::size_t>(k)].col(2);
  }
  return lm;
}

EstimateResult run(const SyntheticOptions& so, EstimateOptions eo) {
  const Trial t = make_synthetic_trial(so);
  return estimate(t, nullptr, *find_marker_set("kin2grf-example"), eo);
}

SyntheticWalkOptions walk_3d_options() {
  SyntheticWalkOptions wo;
  wo.step_width_m = 0.16;
  wo.lateral_sway_m = 0.025;
  wo.toe_out_rad = 0.12;
  return wo;
}

void misregister_plate(ForcePlate& plate, double dx_m) {
  plate.cop_m.col(0).array() += dx_m;
  plate.moment_centre_Nm.setConstant(std::numeric_limits<double>::quiet_NaN());
}

SyntheticWithPlates synthetic_with_exact_plates() {
  SyntheticWithPlates s;
  s.trial = make_synthetic_trial(SyntheticOptions{});
  s.estimate = estimate(s.trial, nullptr, *find_marker_set("kin2grf-example"), {});
  s.plates = example_plates(s.estimate, s.trial, 10);
  return s;
}

Eigen::Vector2d foot_force(const FrameSolution& s, const FrameContacts& fc, int side) {
  Eigen::Vector2d f = Eigen::Vector2d::Zero();
  for (std::size_t j = 0; j < fc.points.size(); ++j)
    if (fc.points[j].side == side) f += Eigen::Vector2d(s.contact_lambda[static_cast<Eigen::Index>(2 * j + 1)], s.contact_lambda[static_cast<Eigen::Index>(2 * j)]);
  return f;
}

bool foot_active(const FrameSolution& s, const FrameContacts& fc, int side) {
  for (std::size_t j = 0; j < fc.points.size(); ++j)
    if (fc.points[j].side == side && s.contact_active[j]) return true;
  return false;
}

TrialContacts contact_frames(const Model& model, const ContactCalibration& soles, const ContactModelOptions& options,
                             const ModelMotion& motion) {
  TrialContacts out;
  const auto n = static_cast<std::size_t>(motion.frames());
  out.frames.resize(n);
  out.contacts.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    motion.frame(static_cast<Eigen::Index>(i), out.frames[i]);
    contact_frame(model, soles, options, false, out.frames[i], out.contacts[i]);
  }
  return out;
}

bool said(const EstimateResult& e, const std::string& what) {
  return std::any_of(e.messages.begin(), e.messages.end(), [&what](const std::string& m) { return m.find(what) != std::string::npos; });
}

}  // namespace kin2grf::test
