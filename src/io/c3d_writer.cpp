// C3D writer (hand-written, see c3d.hpp): Intel, DEC or SGI encoding, float or scaled integers.
// Used for the project's own example trial, for round-trip tests of the reader in every
// encoding, and to make the corrupt-file corpus.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "kin2grf/error.hpp"
#include "kin2grf/io/c3d.hpp"
#include "kin2grf/io/force_plate.hpp"
#include "kin2grf/io/output_file.hpp"
#include "kin2grf/io/text.hpp"

namespace kin2grf {
namespace {

class Writer {
 public:
  explicit Writer(C3dProcessor p) : proc_(static_cast<int>(p)) {}
  std::vector<std::uint8_t> out;

  void u8(int v) { out.push_back(static_cast<std::uint8_t>(v & 0xFF)); }
  void i16(int v) {
    const auto u = static_cast<std::uint16_t>(static_cast<std::int16_t>(v));
    if (proc_ == 86) { u8(u >> 8); u8(u & 0xFF); }
    else { u8(u & 0xFF); u8(u >> 8); }
  }
  void f32(double d) {
    const float f = static_cast<float>(d);
    std::uint8_t b[4];
    if (proc_ == 85) {
      const float g = f * 4.0f;  // DEC F-float: IEEE bits of 4x, words swapped
      std::memcpy(b, &g, 4);
      if (f == 0.0f) { for (auto& x : b) x = 0; }
      out.push_back(b[2]); out.push_back(b[3]); out.push_back(b[0]); out.push_back(b[1]);
      return;
    }
    std::memcpy(b, &f, 4);
    if (proc_ == 86) { out.push_back(b[3]); out.push_back(b[2]); out.push_back(b[1]); out.push_back(b[0]); }
    else { out.insert(out.end(), b, b + 4); }
  }
  void pad_to_block() {
    while (out.size() % 512) out.push_back(0);
  }
  void put_i16_at(std::size_t pos, int v) {
    const auto u = static_cast<std::uint16_t>(static_cast<std::int16_t>(v));
    if (proc_ == 86) { out[pos] = static_cast<std::uint8_t>(u >> 8); out[pos + 1] = static_cast<std::uint8_t>(u & 0xFF); }
    else { out[pos] = static_cast<std::uint8_t>(u & 0xFF); out[pos + 1] = static_cast<std::uint8_t>(u >> 8); }
  }
  int proc() const { return proc_; }

 private:
  int proc_;
};

struct Param {
  std::string group, name;
  int type = 2;
  std::vector<int> dims;
  std::vector<double> numbers;
  std::vector<std::string> strings;  // for type -1: dims = {len, count}
};

Param ints(const std::string& g, const std::string& n, std::vector<double> v, std::vector<int> dims = {}) {
  Param p{g, n, 2, dims.empty() ? std::vector<int>{static_cast<int>(v.size())} : dims, std::move(v), {}};
  if (p.numbers.size() == 1 && dims.empty()) p.dims.clear();
  return p;
}
Param floats(const std::string& g, const std::string& n, std::vector<double> v, std::vector<int> dims = {}) {
  Param p = ints(g, n, std::move(v), std::move(dims));
  p.type = 4;
  return p;
}
/// A parameter's dimension is one byte: 255 at most.
constexpr std::size_t kMaxDimension = 255;

Param strs(const std::string& g, const std::string& n, const std::vector<std::string>& s, bool array = true) {
  std::size_t len = 1;
  for (const auto& x : s) len = std::max(len, x.size());
  if (len > kMaxDimension || (array && s.size() > kMaxDimension))
    throw InputError("write_c3d: " + g + ":" + n + " would need a dimension over 255 (" + std::to_string(len) + " characters, " +
                     std::to_string(s.size()) + " entries)");
  Param p{g, n, -1, {}, {}, s};
  p.dims = {static_cast<int>(len)};
  if (array) p.dims.push_back(static_cast<int>(s.size()));
  return p;
}

/// Strings of any count as C3D holds them: NAME with the first 255, NAME2 with the next, and so on
/// (POINT:LABELS2, as Vicon, ezc3d and BTK write and read them).
void push_strs_in_parts(std::vector<Param>& params, const std::string& g, const std::string& n, const std::vector<std::string>& s) {
  for (std::size_t first = 0, part = 1; first < s.size() || part == 1; first += kMaxDimension, ++part) {
    const auto last = std::min(s.size(), first + kMaxDimension);
    params.push_back(strs(g, n + (part == 1 ? "" : std::to_string(part)),
                          std::vector<std::string>(s.begin() + static_cast<std::ptrdiff_t>(first), s.begin() + static_cast<std::ptrdiff_t>(last))));
  }
}

}  // namespace

namespace {

/// The plates' analog channels: force and moment about the sensor origin in plate axes (N, N mm),
/// and each channel's ANALOG:SCALE (1 for float data; 16-bit integers use the full range).
std::pair<Eigen::MatrixXd, std::vector<double>> plate_channels(const ForcePlateRecording* fpr, long samples, bool float_data) {
  const int nplates = fpr ? static_cast<int>(fpr->plates.size()) : 0;
  const int nchan = 6 * nplates;
  // Plate channels: force and moment about the sensor origin, in plate axes, N and N mm.
  Eigen::MatrixXd analog(samples, nchan);
  for (int p = 0; p < nplates; ++p) {
    const ForcePlate& fp = fpr->plates[static_cast<std::size_t>(p)];
    const Eigen::Matrix3d Rt = fp.lab_R_plate.transpose();
    for (Eigen::Index i = 0; i < analog.rows(); ++i) {
      const Eigen::Vector3d F = fp.force_N.row(i).transpose();
      Eigen::Vector3d Mc = Eigen::Vector3d::Zero();
      const Eigen::Vector3d cop = fp.cop_m.row(i).transpose();
      const Eigen::Vector3d T = fp.free_moment_Nm.row(i).transpose();
      if (cop.allFinite() && T.allFinite()) Mc = (cop - fp.centre_m).cross(F) + T;
      else if (fp.moment_centre_Nm.rows() > i && fp.moment_centre_Nm.row(i).allFinite()) Mc = fp.moment_centre_Nm.row(i).transpose();
      const Eigen::Vector3d Fp = Rt * F;
      const Eigen::Vector3d Mo = Rt * Mc + fp.origin_m.cross(Fp);
      for (int a = 0; a < 3; ++a) {
        analog(i, 6 * p + a) = Fp(a);
        analog(i, 6 * p + 3 + a) = Mo(a) * 1000.0;
      }
    }
  }
  std::vector<double> ch_scale(static_cast<std::size_t>(nchan), 1.0);
  if (!float_data) {
    for (int c = 0; c < nchan; ++c) {
      const double mx = analog.col(c).cwiseAbs().maxCoeff();
      ch_scale[static_cast<std::size_t>(c)] = mx > 0 ? mx / 30000.0 : 1.0;
    }
  }

  return {std::move(analog), std::move(ch_scale)};
}

/// The parameters the writer stores (POINT, ANALOG, FORCE_PLATFORM, EVENT, PROCESSING, TRIAL).
std::vector<Param> c3d_parameters(const Trial& trial, const C3dWriteOptions& o, const std::vector<double>& ch_scale, double pscale) {
  const MarkerTrajectories& m = trial.markers;
  const auto nframes = static_cast<long>(m.frames());
  const int spf = o.analog_samples_per_frame;
  const ForcePlateRecording* fpr = trial.plates ? &*trial.plates : nullptr;
  const int nplates = fpr ? static_cast<int>(fpr->plates.size()) : 0;
  const int nchan = 6 * nplates;
  std::vector<Param> params;
  params.push_back(ints("POINT", "USED", {static_cast<double>(m.names.size())}));
  params.push_back(ints("POINT", "FRAMES", {static_cast<double>(std::min(nframes, 65535L))}));
  params.push_back(floats("POINT", "SCALE", {pscale}));
  params.push_back(floats("POINT", "RATE", {m.rate_hz}));
  params.push_back(strs("POINT", "UNITS", {"mm"}, false));
  std::vector<std::string> labels = m.names, descs = m.descriptions;
  descs.resize(labels.size());
  if (!labels.empty()) {
    push_strs_in_parts(params, "POINT", "LABELS", labels);
    push_strs_in_parts(params, "POINT", "DESCRIPTIONS", descs);
  }
  params.push_back(ints("ANALOG", "USED", {static_cast<double>(nchan)}));
  params.push_back(floats("ANALOG", "RATE", {m.rate_hz * spf}));
  params.push_back(floats("ANALOG", "GEN_SCALE", {1.0}));
  if (nchan > 0) {
    std::vector<std::string> al, au;
    for (int p = 0; p < nplates; ++p)
      for (const char* c : {"Fx", "Fy", "Fz", "Mx", "My", "Mz"}) {
        al.push_back(std::string(c) + std::to_string(p + 1));
        au.push_back(c[0] == 'F' ? "N" : "Nmm");
      }
    params.push_back(strs("ANALOG", "LABELS", al));
    params.push_back(strs("ANALOG", "UNITS", au));
    params.push_back(floats("ANALOG", "SCALE", ch_scale));
    params.push_back(ints("ANALOG", "OFFSET", std::vector<double>(static_cast<std::size_t>(nchan), 0.0)));
    params.push_back(strs("ANALOG", "FORMAT", {"SIGNED"}, false));
  }
  params.push_back(ints("FORCE_PLATFORM", "USED", {static_cast<double>(nplates)}));
  if (nplates > 0) {
    std::vector<double> type, corners, origin, channel;
    for (int p = 0; p < nplates; ++p) {
      const ForcePlate& fp = fpr->plates[static_cast<std::size_t>(p)];
      type.push_back(2);
      for (const auto& c : fp.corners_m)
        for (int a = 0; a < 3; ++a) corners.push_back(c(a) * 1000.0);
      for (int a = 0; a < 3; ++a) origin.push_back(fp.origin_m(a) * 1000.0);
      for (int c = 0; c < 6; ++c) channel.push_back(6 * p + c + 1);
    }
    params.push_back(ints("FORCE_PLATFORM", "TYPE", type));
    params.push_back(ints("FORCE_PLATFORM", "ZERO", {0, 0}));
    params.push_back(floats("FORCE_PLATFORM", "CORNERS", corners, {3, 4, nplates}));
    params.push_back(floats("FORCE_PLATFORM", "ORIGIN", origin, {3, nplates}));
    params.push_back(ints("FORCE_PLATFORM", "CHANNEL", channel, {6, nplates}));
  }
  if (!trial.events.empty()) {
    std::vector<std::string> el, ec;
    std::vector<double> et;
    for (const auto& e : trial.events) {
      el.push_back(e.label);
      ec.push_back(e.side == Side::Right ? "Right" : e.side == Side::Left ? "Left" : "General");
      et.push_back(0.0);
      et.push_back(e.time_s);
    }
    params.push_back(ints("EVENT", "USED", {static_cast<double>(el.size())}));
    params.push_back(strs("EVENT", "LABELS", el));
    params.push_back(strs("EVENT", "CONTEXTS", ec));
    params.push_back(floats("EVENT", "TIMES", et, {2, static_cast<int>(el.size())}));
  }
  if (trial.body_mass_kg) params.push_back(floats("PROCESSING", "Bodymass", {*trial.body_mass_kg}));
  if (trial.height_m) params.push_back(floats("PROCESSING", "Height", {*trial.height_m * 1000.0}));
  // Frame numbers as two 16-bit words (low, high): the header's 16-bit frame numbers stop at 65535,
  // and a long capture (10 minutes at 2 kHz) has more. Readers (Vicon's, ezc3d, kin2grf's) take
  // these where present.
  const long last = o.first_frame + nframes - 1;
  params.push_back(ints("TRIAL", "ACTUAL_START_FIELD", {static_cast<double>(o.first_frame % 65536), static_cast<double>(o.first_frame / 65536)}));
  params.push_back(ints("TRIAL", "ACTUAL_END_FIELD", {static_cast<double>(last % 65536), static_cast<double>(last / 65536)}));
  params.push_back(ints("POINT", "DATA_START", {0}));  // patched below

  return params;
}

/// The parameter section after the header block; returns where POINT:DATA_START's value is (to
/// patch once the data block is known).
std::size_t write_parameter_section(Writer& w, const std::vector<Param>& params) {
  w.u8(0); w.u8(0); w.u8(0); w.u8(w.proc());  // block count patched below
  std::vector<std::string> groups;
  for (const auto& p : params)
    if (std::find(groups.begin(), groups.end(), p.group) == groups.end()) groups.push_back(p.group);
  std::size_t data_start_pos = 0;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const int id = static_cast<int>(g + 1);
    w.u8(static_cast<int>(groups[g].size()));
    w.u8(-id);
    for (char c : groups[g]) w.u8(c);
    w.i16(3);
    w.u8(0);
    for (const auto& p : params) {
      if (p.group != groups[g]) continue;
      w.u8(static_cast<int>(p.name.size()));
      w.u8(id);
      for (char c : p.name) w.u8(c);
      const std::size_t off_pos = w.out.size();
      w.i16(0);
      w.u8(p.type);
      w.u8(static_cast<int>(p.dims.size()));
      for (int d : p.dims) w.u8(d);
      if (p.group == "POINT" && p.name == "DATA_START") data_start_pos = w.out.size();
      if (p.type == -1) {
        const std::size_t len = static_cast<std::size_t>(p.dims[0]);
        for (const auto& s : p.strings)
          for (std::size_t c = 0; c < len; ++c) w.u8(c < s.size() ? s[c] : ' ');
      } else {
        for (double v : p.numbers) {
          if (p.type == 4) w.f32(v);
          else w.i16(static_cast<int>(std::lround(v)));
        }
      }
      w.u8(0);  // no description
      w.put_i16_at(off_pos, static_cast<int>(w.out.size() - off_pos));
    }
  }
  w.u8(0); w.u8(0);  // terminator
  return data_start_pos;
}

}  // namespace

std::vector<std::uint8_t> write_c3d_bytes(const Trial& trial, const C3dWriteOptions& o) {
  const MarkerTrajectories& m = trial.markers;
  const auto nframes = static_cast<long>(m.frames());
  if (nframes < 1) throw InputError("write_c3d: the trial has no frames");
  if (nframes + o.first_frame > (1L << 30)) throw InputError("write_c3d: more than 2^30 frames");
  if (o.first_frame < 1 || o.first_frame > 65535) throw InputError("write_c3d: the first frame must be 1-65535");
  if (m.names.size() > 255 * 255) throw InputError("write_c3d: too many markers");
  // EVENT:TIMES is 2 x events, each dimension a byte, and no second part is read by the tools.
  if (trial.events.size() > kMaxDimension)
    throw InputError("write_c3d: " + std::to_string(trial.events.size()) + " events; the EVENT group holds at most 255");
  const int spf = o.analog_samples_per_frame;
  const ForcePlateRecording* fpr = trial.plates ? &*trial.plates : nullptr;
  const int nplates = fpr ? static_cast<int>(fpr->plates.size()) : 0;
  const int nchan = 6 * nplates;
  if (nplates > 0) {
    if (std::abs(fpr->rate_hz - m.rate_hz * spf) > 1e-6 * fpr->rate_hz ||
        fpr->samples() != nframes * spf) {
      throw InputError("write_c3d: plate rate/samples must be marker rate/frames x analog_samples_per_frame");
    }
    for (const auto& p : fpr->plates)
      if (!p.has_geometry) throw InputError("write_c3d: plate " + p.name + " has no geometry");
  }

  const auto [analog, ch_scale] = plate_channels(fpr, nframes * spf, o.float_data);
  const double pscale = o.float_data ? -std::abs(o.point_scale_mm) : std::abs(o.point_scale_mm);
  const std::vector<Param> params = c3d_parameters(trial, o, ch_scale, pscale);
  Writer w(static_cast<C3dProcessor>(o.processor));
  w.out.assign(512, 0);
  const std::size_t data_start_pos = write_parameter_section(w, params);
  w.pad_to_block();
  const std::size_t pblocks = (w.out.size() - 512) / 512;
  w.out[512 + 2] = static_cast<std::uint8_t>(pblocks);
  const int data_block = static_cast<int>(w.out.size() / 512 + 1);
  w.put_i16_at(data_start_pos, data_block);

  // Header (block 1).
  Writer h(static_cast<C3dProcessor>(o.processor));
  h.u8(2); h.u8(0x50);
  h.i16(static_cast<int>(m.names.size()));
  h.i16(nchan * spf);
  h.i16(o.first_frame);
  h.i16(static_cast<int>(std::min(o.first_frame + nframes - 1, 65535L)));  // TRIAL:ACTUAL_END_FIELD beyond
  h.i16(0);
  h.f32(pscale);
  h.i16(data_block);
  h.i16(nchan > 0 ? spf : 0);
  h.f32(m.rate_hz);
  std::copy(h.out.begin(), h.out.end(), w.out.begin());

  // Data.
  for (long i = 0; i < nframes; ++i) {
    for (const auto& P : m.positions_m) {
      const bool ok = P.row(i).allFinite();
      for (int a = 0; a < 3; ++a) {
        const double mm = ok ? P(i, a) * 1000.0 : 0.0;
        if (o.float_data) {
          w.f32(mm);
        } else {
          const double q = std::round(mm / std::abs(pscale));
          if (std::abs(q) > 32767)
            throw InputError("write_c3d: marker coordinate " + std::to_string(mm) +
                             " mm does not fit 16-bit integers with POINT:SCALE " + std::to_string(pscale));
          w.i16(static_cast<int>(q));
        }
      }
      if (o.float_data) w.f32(ok ? 0.0 : -1.0);
      else w.i16(ok ? 0 : -1);
    }
    for (int s = 0; s < spf && nchan > 0; ++s) {
      for (int c = 0; c < nchan; ++c) {
        const double v = analog(i * spf + s, c);
        if (o.float_data) w.f32(v);
        else w.i16(static_cast<int>(std::lround(v / ch_scale[static_cast<std::size_t>(c)])));
      }
    }
  }
  w.pad_to_block();
  return w.out;
}

void write_c3d(const std::string& path, const Trial& trial, const C3dWriteOptions& options) {
  const auto bytes = write_c3d_bytes(trial, options);
  write_file_text(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

}  // namespace kin2grf
