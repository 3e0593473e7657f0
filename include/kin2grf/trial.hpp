// kin2grf I/O: the one in-memory form of a motion-capture recording, whatever the file format.
//
// Conventions (all readers produce, all writers take, exactly this):
//  - SI units: metres, seconds, newtons, newton-metres.
//  - Positions in the file's own lab frame; `up_axis` records which lab axis points up.
//  - Missing marker samples are NaN (C3D negative residual, blank/NaN TRC cells).
//  - Forces are the ground reaction acting ON the body (upward vertical positive).
//  - Times: marker frame i (0-based in the arrays) is at time_s[i]; for C3D this is
//    (first_frame - 1 + i) / rate_hz, the same clock as the C3D EVENT group.
#pragma once

#include <Eigen/Dense>
#include <array>
#include <optional>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace kin2grf {

enum class Axis { X = 0, Y = 1, Z = 2 };
enum class Side { Right, Left, General };

const char* to_string(Axis a);

/// The labels read from a file, made unique as they come: the k-th label NAME is NAME#k (the
/// first keeps NAME), with a warning, so that a label used twice is never silently shadowed by the
/// first and a mapping file can name each occurrence. Linear in the labels (a file of 10,000
/// repeats is read at once).
class UniqueLabels {
 public:
  /// `index`: the label's column (for the warning).
  std::string add(const std::string& name, std::size_t index, std::vector<std::string>* warnings);
  /// After the last label: one warning for the repeats past the tenth.
  void finish(std::vector<std::string>* warnings) const;

 private:
  std::unordered_set<std::string> taken_;
  std::unordered_map<std::string, std::size_t> next_;  ///< the next k to try for NAME#k
  std::size_t repeats_ = 0;
};
const char* to_string(Side s);

/// Marker trajectories of one trial, N frames x 3 per marker, metres, lab frame.
struct MarkerTrajectories {
  std::vector<std::string> names;
  std::vector<std::string> descriptions;  ///< empty strings when the file has none
  std::vector<Eigen::MatrixX3d> positions_m;  ///< per marker, N x 3, NaN where missing
  double rate_hz = 0.0;
  int first_frame = 1;            ///< the file's frame number of row 0
  Eigen::VectorXd time_s;         ///< N
  Axis up_axis = Axis::Z;
  /// The subject prefix removed from the labels ("Bob:" of Vicon's "Bob:LASI"), empty if none;
  /// see remove_subject_prefix in io/load.hpp.
  std::string label_prefix;

  [[nodiscard]] Eigen::Index frames() const { return time_s.size(); }
  /// Index of a marker by exact name, or -1. A name given with the removed subject prefix
  /// ("Bob:LASI" when the labels' "Bob:" was removed) finds the marker too, so that a mapping
  /// file written for the file's own labels still works.
  [[nodiscard]] int find(const std::string& name) const;
  /// Frames (0-based) where the marker is missing (any coordinate NaN).
  [[nodiscard]] std::vector<Eigen::Index> missing_frames(int marker) const;
};

/// The markers in another lab frame: each position p becomes R p (a missing sample stays NaN), and
/// `up_axis` is the new frame's (writing a TRC in OpenSim's Y-up frame).
MarkerTrajectories rotated(MarkerTrajectories m, const Eigen::Matrix3d& R, Axis up_axis);

/// Gaussian noise of SD sigma_m on every marker coordinate, from a generator seeded with `seed`
/// (the same draw every time); a missing sample stays NaN. What real capture adds (the noise
/// study, make-example --marker-noise).
void add_marker_noise(MarkerTrajectories& m, double sigma_m, unsigned seed);

/// Every `factor`-th frame of the markers (frames 0, factor, 2 factor, ...), at rate_hz / factor,
/// each kept frame at its own time: what a capture at a lower rate would have sampled of the same
/// motion (a camera samples positions; it does not low-pass them first). The marker-rate study.
/// Its frame numbers are the slower capture's: first_frame becomes (first_frame - 1) / factor + 1.
/// factor 1 returns the markers as they are; factor < 1 is an InputError.
MarkerTrajectories decimated(MarkerTrajectories m, int factor);

/// A dynamically similar subject (Froude similarity, Alexander and Jayes 1983: the same gait at
/// the same speed / sqrt(g L)): every length times `length_scale` L, every time times sqrt(L), so
/// velocities scale by sqrt(L) and accelerations not at all, as gravity does not. The markers keep
/// their samples at rate_hz / sqrt(L). A subject 0.6 times as tall walking at the same Froude
/// number: a child's gait, faster in cadence. The subject-scale study; InputError for L <= 0.
MarkerTrajectories dynamically_scaled(MarkerTrajectories m, double length_scale);

/// The whole factor that brings `rate_hz` nearest to `target_hz` (at least 1: never upsampled).
int decimation_factor(double rate_hz, double target_hz);

/// Frames [first, first + count) of the markers (0-based rows), each at its own time and file
/// frame number: a trial cut short, as a user's frame range or a recording that stopped early
/// gives it. InputError naming the range when it is empty or outside the recording.
MarkerTrajectories cropped(MarkerTrajectories m, Eigen::Index first, Eigen::Index count);

/// One force plate (or one per-foot channel set of a processed GRF file).
struct ForcePlate {
  std::string name;               ///< e.g. "FP1" or "right" for GRF .mot columns
  int type = 0;                   ///< C3D FORCE_PLATFORM:TYPE (1-4); 0 for processed GRF files
  bool has_geometry = false;      ///< corners/origin known (C3D); false for GRF .mot
  std::array<Eigen::Vector3d, 4> corners_m{};  ///< lab frame, C3D corner order
  Eigen::Vector3d centre_m = Eigen::Vector3d::Zero();   ///< surface centre, lab frame
  Eigen::Vector3d origin_m = Eigen::Vector3d::Zero();   ///< FORCE_PLATFORM:ORIGIN as used (plate frame)
  Eigen::Matrix3d lab_R_plate = Eigen::Matrix3d::Identity();  ///< plate axes in the lab frame
  Side side_hint = Side::General; ///< from GRF column names (r/l), General for C3D plates

  // Per sample (rate of the owning ForcePlateRecording), lab frame:
  Eigen::MatrixX3d force_N;            ///< ground reaction on the body
  Eigen::MatrixX3d moment_centre_Nm;   ///< moment about the surface centre (NaN without geometry)
  Eigen::MatrixX3d cop_m;              ///< centre of pressure on the surface; NaN below threshold
  Eigen::MatrixX3d free_moment_Nm;     ///< moment about the COP (only its vertical part is non-zero
                                       ///< for a plate); NaN where the COP is undefined

  [[nodiscard]] double width_m() const;   ///< |c1 - c2|
  [[nodiscard]] double length_m() const;  ///< |c1 - c4|
};

struct ForcePlateRecording {
  double rate_hz = 0.0;
  Eigen::VectorXd time_s;           ///< same clock as MarkerTrajectories::time_s
  double cop_threshold_N = 10.0;    ///< |vertical force| below which the COP is NaN
  std::vector<ForcePlate> plates;
  Axis up_axis = Axis::Z;
  [[nodiscard]] Eigen::Index samples() const { return time_s.size(); }
};

struct Event {
  std::string label;   ///< "Foot Strike", "Foot Off", ...
  Side side = Side::General;
  double time_s = 0.0;
};

/// The plates of a dynamically similar subject (see the markers' dynamically_scaled): its mass
/// scales by L^3, so forces by L^3, moments by L^4, places by L, times by sqrt(L).
ForcePlateRecording dynamically_scaled(ForcePlateRecording r, double length_scale);

/// A loaded trial: what `kin2grf info` describes.
struct Trial {
  std::string path;
  std::string format;      ///< "C3D", "TRC", "MOT"
  std::string encoding;    ///< C3D processor type ("Intel", "DEC", "SGI/MIPS"), data format
  MarkerTrajectories markers;
  std::optional<ForcePlateRecording> plates;
  std::vector<Event> events;
  std::optional<double> body_mass_kg;
  std::optional<double> height_m;
  /// The subject's knee and ankle widths (m; right, left) and the markers' diameter (m) where the
  /// file holds them (Vicon Plug-in Gait's PROCESSING:RKneeWidth, LAnkleWidth, MarkerDiameter, in
  /// mm): what moves a lateral knee or ankle marker to the joint centre (joint_centre_offsets).
  std::array<std::optional<double>, 2> knee_width_m, ankle_width_m;
  std::optional<double> marker_diameter_m;
  std::vector<std::string> model_outputs;  ///< C3D points that are model outputs, not markers
  std::vector<std::string> warnings;
};

/// The whole trial of a dynamically similar subject: markers, plates, events, the body mass
/// (L^3), height and joint widths.
Trial dynamically_scaled(Trial t, double length_scale);

}  // namespace kin2grf
