#include "kin2grf/io/force_plate.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include "kin2grf/error.hpp"
#include "kin2grf/numeric.hpp"
#include "kin2grf/io/text.hpp"

namespace kin2grf {
namespace {


/// A number for a message: four significant digits.
std::string short_number(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.4g", v);
  return b;
}

/// Scale of a moment channel's unit to N m (N mm is the C3D norm when units are missing).
double moment_unit_scale(const std::string& unit, std::vector<std::string>& warnings,
                         const std::string& plate, const std::string& label) {
  std::string u = to_lower(trim(unit));
  u.erase(std::remove_if(u.begin(), u.end(), [](char c) { return c == '.' || c == '*' || c == ' ' || c == '-'; }),
          u.end());
  if (u == "nmm" || u == "ntmm") return 1e-3;
  if (u == "nm" || u == "ntm") return 1.0;
  warnings.push_back(plate + ": moment channel '" + label + "' has unit '" + unit +
                     "'; assuming N mm");
  return 1e-3;
}

double length_unit_scale_channel(const std::string& unit, std::vector<std::string>& warnings,
                                 const std::string& plate, const std::string& label) {
  const std::string u = to_lower(trim(unit));
  if (u == "mm") return 1e-3;
  if (u == "m") return 1.0;
  if (u == "cm") return 1e-2;
  warnings.push_back(plate + ": COP channel '" + label + "' has unit '" + unit + "'; assuming mm");
  return 1e-3;
}

struct PlateLoads {
  Eigen::MatrixX3d F;   // plate frame, force on the body convention applied later by rotation
  Eigen::MatrixX3d Mc;  // about surface centre, plate frame
};

PlateLoads plate_loads(const Eigen::MatrixXd& ch, const PlateDescription& d,
                       const std::vector<double>& scale) {
  const Eigen::Index n = ch.rows();
  PlateLoads L;
  L.F.resize(n, 3);
  L.Mc.resize(n, 3);
  Eigen::Vector3d o = d.origin;
  if (d.type != 3 && o.z() > 0) o = -o;
  for (Eigen::Index i = 0; i < n; ++i) {
    Eigen::Matrix<double, 8, 1> v = Eigen::Matrix<double, 8, 1>::Zero();
    // Type 4: the calibration matrix acts on the raw signals; the units apply to its outputs.
    for (std::size_t c = 0; c < d.channels.size(); ++c)
      v(static_cast<Eigen::Index>(c)) = ch(i, static_cast<Eigen::Index>(c)) * (d.type == 4 ? 1.0 : scale[c]);
    Eigen::Vector3d F, Mo, oc;
    switch (d.type) {
      case 1: {
        F = v.head<3>();
        const Eigen::Vector3d p(v(3), v(4), 0.0);
        Mo = p.cross(F) + Eigen::Vector3d(0, 0, v(5));
        oc.setZero();
        break;
      }
      case 3: {
        const double a = d.origin.x(), b = d.origin.y(), az0 = -std::abs(d.origin.z());
        F = Eigen::Vector3d(v(0) + v(1), v(2) + v(3), v(4) + v(5) + v(6) + v(7));
        Mo = Eigen::Vector3d(b * (v(4) + v(5) - v(6) - v(7)), a * (-v(4) + v(5) + v(6) - v(7)),
                             b * (-v(0) + v(1)) + a * (v(2) - v(3)));
        oc = Eigen::Vector3d(0, 0, -az0);
        break;
      }
      case 4: {
        Eigen::Matrix<double, 6, 1> w = d.cal_matrix * v.head<6>();
        for (Eigen::Index c = 0; c < 6; ++c) w(c) *= scale[static_cast<std::size_t>(c)];
        F = w.head<3>();
        Mo = w.tail<3>();
        oc = -o;
        break;
      }
      default:
        F = v.head<3>();
        Mo = v.segment<3>(3);
        oc = -o;
    }
    L.F.row(i) = F.transpose();
    L.Mc.row(i) = (Mo + oc.cross(F)).transpose();
  }
  return L;
}

/// The time of analog sample i, for messages.
std::string sample_time(const AnalogData& analog, Eigen::Index i) {
  return short_number(analog.first_time_s + static_cast<double>(i) / analog.rate_hz) + " s";
}

/// Non-finite samples are named with their times (the force there is unknown, and a stance they
/// fall in is split); a force no human exerts (a damaged calibration: 3e38 gave 6.9e42 N) leaves
/// the plate out. False: leave the plate out.
bool plate_samples_plausible(const Eigen::MatrixXd& ch, const PlateLoads& L, const std::string& name, const AnalogData& analog,
                             const std::string& path, std::vector<std::string>& warnings) {
  Eigen::Index bad = 0, first = -1, last = -1;
  for (Eigen::Index i = 0; i < ch.rows(); ++i)
    if (!ch.row(i).allFinite()) {
      ++bad;
      if (first < 0) first = i;
      last = i;
    }
  if (bad > 0)
    warnings.push_back(path + ": " + name + ": " + std::to_string(bad) + " analog samples are NaN or infinite (" +
                       sample_time(analog, first) + (last > first ? " to " + sample_time(analog, last) : std::string()) +
                       "): the plate's force there is unknown");
  Eigen::Index at = -1;
  double peak = 0;
  for (Eigen::Index i = 0; i < L.F.rows(); ++i) {
    const double f = L.F.row(i).norm();
    if (std::isfinite(f) && f > peak) peak = f, at = i;
  }
  if (peak > kMaxPlausibleForceN) {
    warnings.push_back(path + ": " + name + ": a force of " + short_number(peak) + " N at " + sample_time(analog, at) +
                       " is no ground reaction (more than " + short_number(kMaxPlausibleForceN) +
                       " N): check the plate's calibration (CAL_MATRIX) and its channels' SCALE; the plate is left out");
    return false;
  }
  return true;
}

}  // namespace

Eigen::Matrix3d plate_axes(const Eigen::Matrix<double, 3, 4>& c) {
  Eigen::Vector3d x = c.col(0) - c.col(1);
  Eigen::Vector3d y = c.col(0) - c.col(3);
  if (x.norm() < 1e-9 || y.norm() < 1e-9) return Eigen::Matrix3d::Identity();
  x.normalize();
  Eigen::Vector3d z = x.cross(y).normalized();
  y = z.cross(x);
  Eigen::Matrix3d R;
  R << x, y, z;
  return R;
}

void set_plate_corners(ForcePlate& p, const std::array<Eigen::Vector3d, 4>& corners_m) {
  Eigen::Matrix<double, 3, 4> C;
  for (int c = 0; c < 4; ++c) C.col(c) = corners_m[static_cast<std::size_t>(c)];
  p.has_geometry = true;
  p.corners_m = corners_m;
  p.lab_R_plate = plate_axes(C);
  p.centre_m = C.rowwise().mean();
}

namespace {
/// The plate's channels' scales to N and N m (and m for a type-1 plate's COP channels), from
/// their units.
std::vector<double> channel_scales(const AnalogData& analog, const PlateDescription& d, std::vector<std::string>& warnings) {
  std::vector<double> scale(d.channels.size(), 1.0);
  for (std::size_t c = 0; c < d.channels.size(); ++c) {
    const auto ch = static_cast<std::size_t>(d.channels[c]);
    const std::string unit = ch < analog.units.size() ? analog.units[ch] : "";
    const std::string label = ch < analog.labels.size() ? analog.labels[ch] : "";
    if (d.type == 2 || d.type == 4) {
      if (c >= 3) scale[c] = moment_unit_scale(unit, warnings, d.name, label);
    } else if (d.type == 1) {
      if (c == 3 || c == 4) scale[c] = length_unit_scale_channel(unit, warnings, d.name, label);
      if (c == 5) scale[c] = moment_unit_scale(unit, warnings, d.name, label);
    }
  }
  return scale;
}

/// The channels' zero offsets (PlateProcessing::zero_offset): the mean over FORCE_PLATFORM:ZERO's
/// samples, or the median over the unloaded samples; none (with a warning) when neither exists.
/// `L`: the loads before the offsets are removed.
std::optional<Eigen::RowVectorXd> channel_offsets(const Eigen::MatrixXd& ch, const PlateLoads& L, const PlateDescription& d,
                                                  const PlateProcessing& proc, std::vector<std::string>& warnings) {
  const Eigen::Index n = ch.rows();
  if (proc.zero_offset == ZeroOffset::ZeroParameter) {
    if (proc.zero_first_sample >= 0 && proc.zero_last_sample >= proc.zero_first_sample && proc.zero_last_sample < n &&
        proc.zero_last_sample > 0)
      return Eigen::RowVectorXd(ch.middleRows(proc.zero_first_sample, proc.zero_last_sample - proc.zero_first_sample + 1).colwise().mean());
    warnings.push_back(d.name + ": FORCE_PLATFORM:ZERO gives no valid frame range; offsets not removed");
    return std::nullopt;
  }
  // Unloaded: the force normal to the plate (its own z axis) is small. The plate's axis, not the
  // lab's up axis: a Y-up lab (RBDS001runT35.c3d) would otherwise take the lateral force for the
  // load and subtract half the body weight as an "offset".
  std::vector<Eigen::Index> idx;
  for (Eigen::Index i = 0; i < n; ++i)
    if (std::abs(L.F(i, 2)) < proc.unloaded_threshold_N) idx.push_back(i);
  if (idx.size() < 10) {
    warnings.push_back(d.name + ": never unloaded (|F| < " + std::to_string(proc.unloaded_threshold_N) + " N); offsets not removed");
    return std::nullopt;
  }
  Eigen::RowVectorXd offset = Eigen::RowVectorXd::Zero(ch.cols());
  for (Eigen::Index c = 0; c < ch.cols(); ++c) {
    std::vector<double> v;
    v.reserve(idx.size());
    for (auto i : idx) v.push_back(ch(i, c));
    offset(c) = median(std::move(v));
  }
  return offset;
}

/// The plate's lab-frame force, moment about its centre, COP and free moment from its loads in
/// its own frame (COP and free moment NaN below the COP threshold).
void plate_lab_series(const PlateLoads& L, double cop_threshold_N, ForcePlate& fp) {
  const Eigen::Index n = L.F.rows();
  const Eigen::Matrix3d& R = fp.lab_R_plate;
  fp.force_N = L.F * R.transpose();
  fp.moment_centre_Nm = L.Mc * R.transpose();
  fp.cop_m.resize(n, 3);
  fp.free_moment_Nm.resize(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d F = L.F.row(i).transpose();
    const Eigen::Vector3d Mc = L.Mc.row(i).transpose();
    if (!(std::abs(F.z()) >= cop_threshold_N)) {
      fp.cop_m.row(i).setConstant(kNaN);
      fp.free_moment_Nm.row(i).setConstant(kNaN);
      continue;
    }
    const Eigen::Vector3d p(-Mc.y() / F.z(), Mc.x() / F.z(), 0.0);
    const double Tz = Mc.z() - (p.x() * F.y() - p.y() * F.x());
    fp.cop_m.row(i) = (fp.centre_m + R * p).transpose();
    fp.free_moment_Nm.row(i) = (R * Eigen::Vector3d(0, 0, Tz)).transpose();
  }
}
}  // namespace

ForcePlateRecording compute_plates(const AnalogData& analog,
                                   const std::vector<PlateDescription>& plates,
                                   const PlateProcessing& proc, const std::string& path,
                                   std::vector<std::string>& warnings) {
  ForcePlateRecording rec;
  rec.rate_hz = analog.rate_hz;
  rec.cop_threshold_N = proc.cop_threshold_N;
  rec.up_axis = proc.up_axis;
  const Eigen::Index n = analog.values.rows();
  rec.time_s.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) rec.time_s[i] = analog.first_time_s + static_cast<double>(i) / analog.rate_hz;
  for (const auto& d : plates) {
    // A type-4 plate's calibration matrix turns its signals into forces: NaN or all zero (an
    // unused plate's, a damaged file's) gives no force, and the plate read as "never loaded" made
    // validate blame the clock.
    if (d.type == 4 && (!d.cal_matrix.allFinite() || d.cal_matrix.isZero(0.0))) {
      warnings.push_back(path + ": " + d.name + ": FORCE_PLATFORM:CAL_MATRIX is " +
                         (d.cal_matrix.allFinite() ? "all zero" : "not finite (NaN or infinity)") +
                         ": the plate's forces cannot be computed; it is left out");
      continue;
    }
    ForcePlate fp;
    fp.name = d.name;
    fp.type = d.type;
    fp.has_geometry = true;
    for (int c = 0; c < 4; ++c) fp.corners_m[static_cast<std::size_t>(c)] = d.corners.col(c);
    fp.centre_m = d.corners.rowwise().mean();
    fp.origin_m = (d.type != 3 && d.origin.z() > 0) ? Eigen::Vector3d(-d.origin) : d.origin;
    fp.lab_R_plate = plate_axes(d.corners);
    if ((d.corners.col(0) - d.corners.col(1)).norm() < 1e-6 ||
        (d.corners.col(0) - d.corners.col(3)).norm() < 1e-6) {
      throw InputError(path + ": FORCE_PLATFORM:CORNERS of " + d.name +
                       " are degenerate (coincident corners)");
    }
    const std::vector<double> scale = channel_scales(analog, d, warnings);
    Eigen::MatrixXd ch(n, static_cast<Eigen::Index>(d.channels.size()));
    for (std::size_t c = 0; c < d.channels.size(); ++c) ch.col(static_cast<Eigen::Index>(c)) = analog.values.col(d.channels[c]);
    PlateLoads L = plate_loads(ch, d, scale);
    if (proc.zero_offset != ZeroOffset::None) {
      if (const auto offset = channel_offsets(ch, L, d, proc, warnings)) {
        ch.rowwise() -= *offset;
        L = plate_loads(ch, d, scale);
      }
    }
    if (!plate_samples_plausible(ch, L, d.name, analog, path, warnings)) continue;
    plate_lab_series(L, proc.cop_threshold_N, fp);
    rec.plates.push_back(std::move(fp));
  }
  return rec;
}

}  // namespace kin2grf
