// kin2grf I/O: OpenSim text formats.
//  - TRC (marker trajectories): tab-separated, a 5-line header (PathFileType, keys, values,
//    marker names, X1 Y1 Z1 ...), units mm or m, usually Y up.
//  - MOT/STO (tables): a header ended by `endheader`, either OpenSim 1.x/4.x keys (`version`,
//    `nRows`, `nColumns` counting the time column, `inDegrees`, `DataType`) or the older SIMM keys
//    (`name`, `datacolumns`, `datarows`, `range`); then one line of column labels and the rows.
//  - GRF .mot: columns `<prefix>ground_force_<side>v[xyz]`, `..._p[xyz]`, `<prefix>ground_torque_
//    <side>[xyz]` (prefix "", "1_", "R_", "L_"...; side "", "r_", "l_"): force on the body (N),
//    COP (m) and the torque at the COP (N m), lab frame, Y up.
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "kin2grf/trial.hpp"

namespace kin2grf {

/// A MOT/STO table: the first column is time.
struct Table {
  std::string name;
  std::vector<std::string> labels;  ///< including "time"
  Eigen::MatrixXd data;             ///< rows x labels
  std::map<std::string, std::string> header;
  bool in_degrees = false;
  std::vector<std::string> warnings;  ///< what the reader noticed and read anyway
  [[nodiscard]] int column(const std::string& label) const;  ///< -1 when absent
};

MarkerTrajectories read_trc(const std::string& path, std::vector<std::string>* warnings = nullptr);
/// `release(begin, end)`, if given, is told the byte ranges of `text` whose rows are parsed (a
/// mapped file lets them go: read_trc).
MarkerTrajectories parse_trc(std::string_view text, const std::string& path, std::vector<std::string>* warnings = nullptr,
                             const std::function<void(std::size_t, std::size_t)>& release = {});
/// Writes millimetres (the TRC norm), `up_axis` kept as in memory.
std::string format_trc(const MarkerTrajectories& m, const std::string& file_name);
void write_trc(const std::string& path, const MarkerTrajectories& m);

Table read_sto(const std::string& path);
Table parse_sto(std::string_view text, const std::string& path);
/// OpenSim 4 header (version=1, nRows, nColumns, inDegrees, endheader).
std::string format_sto(const Table& t);
/// format_sto's header and column labels for a table of `rows` rows (t.data is not read), and
/// one row of numbers as format_sto writes them (8 significant digits, NaN): for writers that
/// stream their rows instead of holding the table.
std::string sto_header(const Table& t, Eigen::Index rows);
void append_sto_row(std::string& out, std::span<const double> values);
void write_sto(const std::string& path, const Table& t);

/// The GRF channel sets of a table (empty when it has none). Time regularised to a uniform grid
/// when the stored times deviate by less than half a sample (rounded time columns).
std::optional<ForcePlateRecording> grf_from_table(const Table& t, const std::string& path,
                                                  double cop_threshold_N,
                                                  std::vector<std::string>& warnings);

/// grf_table's column labels: time, then each foot's ground_force_v and _p (right unprefixed,
/// left `1_`-prefixed), then each foot's ground_torque_.
std::vector<std::string> grf_labels();
/// OpenSim ExternalLoads-ready table: right foot unprefixed, left foot `1_`-prefixed.
Table grf_table(const Eigen::VectorXd& time_s, const ForcePlate& right, const ForcePlate& left);

}  // namespace kin2grf
