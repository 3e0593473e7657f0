// kin2grf I/O: force-plate channels -> force, moment about the surface centre and centre of
// pressure in the lab frame (C3D FORCE_PLATFORM conventions).
//
// Plate frame from the corners (C3D order): x = c1 - c2, y = c1 - c4, z = x cross y (this
// points down into the plate for the usual corner order). Channel forces rotated with that frame
// give the ground reaction on the body in the lab frame.
// ORIGIN is the vector from the plate's sensor origin to the surface centre in plate axes; its
// z must then be negative (the origin lies below the surface). Vendors that store it positive
// (Vicon/AMTI files in ../shared/data) are handled by negating the vector when z > 0, as
// ezc3d and OpenSim do. Moments are transferred to the surface centre c:
//   M_c = M_o + (o - c) x F,  o - c = -ORIGIN.
// TYPE 1: channels Fx Fy Fz Px Py Tz (COP given). TYPE 2: Fx Fy Fz Mx My Mz. TYPE 4: TYPE 2
// after the 6x6 CAL_MATRIX. TYPE 3 (Kistler, 8 channels fx12 fx34 fy14 fy23 fz1..fz4, ORIGIN =
// sensor offsets a, b, az0): F = (fx12+fx34, fy14+fy23, sum fz), M_o = (b(fz1+fz2-fz3-fz4),
// a(-fz1+fz2+fz3-fz4), b(-fx12+fx34)+a(fy14-fy23)) about the sensor plane, o - c = (0,0,|az0|).
// COP on the surface (plate axes): p = (-M_c,y / F_z, M_c,x / F_z, 0); the free moment is
// T_z = M_c,z - (p_x F_y - p_y F_x). The COP is NaN where |vertical force| < threshold.
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "kin2grf/trial.hpp"

namespace kin2grf {

enum class ZeroOffset {
  None,            ///< use the plate channels as stored
  ZeroParameter,   ///< subtract the mean over FORCE_PLATFORM:ZERO's frame range when it is valid
  Unloaded         ///< subtract, per channel, the median over samples where the plate's
                   ///< |vertical force| is below `unloaded_threshold_N` (plates not zeroed)
};

struct AnalogData {
  double rate_hz = 0.0;
  double first_time_s = 0.0;
  Eigen::MatrixXd values;  ///< samples x channels, scaled to the channel units
  std::vector<std::string> labels;
  std::vector<std::string> units;
};

struct PlateDescription {
  std::string name;
  int type = 2;
  Eigen::Matrix<double, 3, 4> corners = Eigen::Matrix<double, 3, 4>::Zero();  ///< lab, metres
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();  ///< as stored (metres; a, b, az0 for type 3)
  std::vector<int> channels;                         ///< 0-based analog channel indices
  Eigen::Matrix<double, 6, 6> cal_matrix = Eigen::Matrix<double, 6, 6>::Identity();
};

/// The largest force a plate may show and still be read: no human's ground reaction comes near
/// (a 150 kg sprinter's landing is under 15 kN); more is a damaged calibration or scale.
inline constexpr double kMaxPlausibleForceN = 50000.0;

struct PlateProcessing {
  double cop_threshold_N = 10.0;
  ZeroOffset zero_offset = ZeroOffset::None;
  double unloaded_threshold_N = 50.0;
  long zero_first_sample = -1;  ///< from FORCE_PLATFORM:ZERO, analog samples, inclusive
  long zero_last_sample = -1;
  Axis up_axis = Axis::Z;
};

/// Plate frame (columns x, y, z in the lab) from the corners.
Eigen::Matrix3d plate_axes(const Eigen::Matrix<double, 3, 4>& corners);
/// A plate's corners (lab frame, C3D's order) and what follows from them: has_geometry, its axes
/// (plate_axes) and its surface centre (the corners' mean).
void set_plate_corners(ForcePlate& plate, const std::array<Eigen::Vector3d, 4>& corners_m);

ForcePlateRecording compute_plates(const AnalogData& analog,
                                   const std::vector<PlateDescription>& plates,
                                   const PlateProcessing& processing, const std::string& path,
                                   std::vector<std::string>& warnings);

}  // namespace kin2grf
