// kin2grf I/O: C3D reader and writer.
//
// Written by hand from the C3D specification (c3d.org, "The C3D File Format User Guide"), because
// no C3D library is packaged in Debian (ezc3d and BTK are not). What is supported:
//  - processor types Intel (84), DEC/VAX (85, VAX F-floats, little-endian integers) and
//    SGI/MIPS (86, big-endian IEEE);
//  - float and scaled-integer point data (POINT:SCALE < 0 means float), residual word
//    (negative = invalid -> NaN; a point at exactly (0,0,0) is missing too), POINT:UNITS mm/cm/m, LABELS + LABELS2.., DESCRIPTIONS,
//    a first frame other than 1, frame counts above 65535 (TRIAL:ACTUAL_START/END_FIELD);
//  - analog data signed or unsigned (ANALOG:FORMAT), OFFSET, SCALE, GEN_SCALE, integer or float;
//  - FORCE_PLATFORM types 1, 2, 3 (Kistler 8 channels) and 4 (CAL_MATRIX), CORNERS, ORIGIN,
//    CHANNEL, ZERO; force, moment about the surface centre and COP in the lab frame;
//  - body mass from PROCESSING:Bodymass or SUBJECT(S):WEIGHT/MASS, PROCESSING:Height, the EVENT group.
// Every structural field is bounds-checked: bad input throws InputError naming the file and
// the field or byte offset.
#pragma once

#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "kin2grf/io/force_plate.hpp"
#include "kin2grf/trial.hpp"

namespace kin2grf {

struct C3dReadOptions {
  double cop_threshold_N = 10.0;     ///< COP is NaN where |Fz| is below this
  ZeroOffset zero_offset = ZeroOffset::None;
  double unloaded_threshold_N = 50.0;
  /// Type-4 CAL_MATRIX storage: true = element (row i, col j) at i + 6 j (C3D arrays are stored
  /// first-index-fastest); the c3d.org TYPE-2/TYPE-4 samples agree with this order.
  bool cal_matrix_first_index_fastest = true;
  /// false: the plates keep their geometry, type and rate but no samples (ForcePlateRecording::
  /// samples() is 0), and the analog samples are not read. For `estimate`, which needs the plates
  /// only to tell the lab's up axis: their force, moment and COP in doubles take 4 (float) to 8
  /// (integer) times the plates' analog data in the file, at 1-2 kHz (the memory of long trials).
  bool plate_samples = true;
};

/// One parameter as stored: numbers (int8/int16/float as double) or strings (char arrays).
struct C3dParameter {
  int type = 0;                      ///< -1 char, 1 byte, 2 int16, 4 float
  std::vector<int> dims;
  std::vector<double> numbers;       ///< flattened, first index fastest (non-char types)
  std::vector<std::string> strings;  ///< char arrays: one string per column, right-trimmed
  std::vector<std::uint8_t> raw;     ///< the data bytes as in the file (host order for int16)
};

/// Low-level view of a C3D file (header + parameters), for `info` and for tests.
struct C3dFile {
  std::string path;
  std::string processor;   ///< "Intel", "DEC", "SGI/MIPS"
  bool float_data = false;
  int first_frame = 1;
  int last_frame = 0;
  int point_count = 0;
  int analog_per_frame = 0;
  double point_rate_hz = 0.0;
  double point_scale = 0.0;
  int data_start_block = 0;
  std::map<std::string, C3dParameter> parameters;  ///< key "GROUP:NAME", upper case

  [[nodiscard]] const C3dParameter* find(const std::string& key) const;
};

/// Parse header and parameter section only.
C3dFile read_c3d_header(const std::vector<std::uint8_t>& bytes, const std::string& path);
C3dFile read_c3d_header(std::span<const std::uint8_t> bytes, const std::string& path);

/// Read a whole trial (markers, plates, events, mass) from a C3D file. The file is mapped, not
/// read into memory, and each block of frames is released once read (a long capture is never
/// resident whole); as with every reader that maps, a file cut short by another program while it
/// is being read stops the process.
Trial read_c3d(const std::string& path, const C3dReadOptions& options = {});
Trial read_c3d_bytes(const std::vector<std::uint8_t>& bytes, const std::string& path,
                     const C3dReadOptions& options = {});

enum class C3dProcessor { Intel = 84, DEC = 85, SGI = 86 };

struct C3dWriteOptions {
  C3dProcessor processor = C3dProcessor::Intel;
  bool float_data = true;          ///< false: scaled 16-bit integers
  double point_scale_mm = 0.1;     ///< integer resolution (POINT:SCALE) when !float_data
  int analog_samples_per_frame = 1;
  int first_frame = 1;
};

/// Write markers (in mm), force plates as TYPE-2 channels (N, N mm), events and body mass.
/// Plates need geometry; their analog rate must be an integer multiple of the marker rate.
std::vector<std::uint8_t> write_c3d_bytes(const Trial& trial, const C3dWriteOptions& options = {});
void write_c3d(const std::string& path, const Trial& trial, const C3dWriteOptions& options = {});

}  // namespace kin2grf
