// C3D reader, written from the C3D specification because no C3D library is packaged in Debian.
// See include/kin2grf/io/c3d.hpp for what is supported and the conventions.
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <numeric>
#include <span>
#include <sstream>

#include "kin2grf/error.hpp"
#include "kin2grf/io/c3d.hpp"
#include "kin2grf/io/force_plate.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/numeric.hpp"

namespace kin2grf {
namespace {


/// Bounds-checked decoding of the file's bytes in the file's processor encoding.
class Bytes {
 public:
  Bytes(std::span<const std::uint8_t> data, std::string path)
      : data_(data), path_(std::move(path)) {}

  void set_processor(int p) { processor_ = p; }
  [[nodiscard]] int processor() const { return processor_; }
  [[nodiscard]] std::size_t size() const { return data_.size(); }
  [[nodiscard]] const std::string& path() const { return path_; }

  void need(std::size_t offset, std::size_t n, const std::string& what) const {
    if (offset > data_.size() || n > data_.size() - offset) {
      std::ostringstream os;
      os << path_ << ": truncated file: " << what << " needs bytes " << offset << ".."
         << offset + n << " but the file has " << data_.size() << " bytes";
      throw InputError(os.str());
    }
  }
  [[nodiscard]] std::uint8_t u8(std::size_t o, const char* what) const {
    need(o, 1, what);
    return data_[o];
  }
  [[nodiscard]] std::int8_t i8(std::size_t o, const char* what) const {
    return static_cast<std::int8_t>(u8(o, what));
  }
  [[nodiscard]] std::uint16_t u16(std::size_t o, const char* what) const {
    need(o, 2, what);
    return u16_unchecked(o);
  }
  [[nodiscard]] std::int16_t i16(std::size_t o, const char* what) const {
    return static_cast<std::int16_t>(u16(o, what));
  }
  [[nodiscard]] float f32(std::size_t o, const char* what) const {
    need(o, 4, what);
    return f32_unchecked(o);
  }
  [[nodiscard]] std::uint16_t u16_unchecked(std::size_t o) const {
    if (processor_ == 86) return static_cast<std::uint16_t>((data_[o] << 8) | data_[o + 1]);
    return static_cast<std::uint16_t>(data_[o] | (data_[o + 1] << 8));
  }
  [[nodiscard]] float f32_unchecked(std::size_t o) const {
    std::uint8_t b[4];
    if (processor_ == 86) {  // SGI/MIPS: big-endian IEEE
      b[0] = data_[o + 3]; b[1] = data_[o + 2]; b[2] = data_[o + 1]; b[3] = data_[o];
    } else if (processor_ == 85) {  // DEC/VAX F-float: words swapped, value = IEEE bits / 4
      if ((data_[o + 1] & 0x7F) == 0 && (data_[o] & 0x80) == 0) return 0.0f;  // exponent 0
      b[0] = data_[o + 2]; b[1] = data_[o + 3]; b[2] = data_[o]; b[3] = data_[o + 1];
      float f;
      std::memcpy(&f, b, 4);
      return f / 4.0f;
    } else {
      std::memcpy(b, &data_[o], 4);
    }
    float f;
    std::memcpy(&f, b, 4);
    return f;
  }

 private:
  std::span<const std::uint8_t> data_;
  std::string path_;
  int processor_ = 84;
};

std::string upper(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string processor_name(int p) {
  switch (p) {
    case 84: return "Intel";
    case 85: return "DEC";
    case 86: return "SGI/MIPS";
    default: return "unknown";
  }
}

/// Parameter section: groups and parameters, resolved to "GROUP:NAME" keys.
/// One parameter's type, dimensions and data (C3D: type, dimension count, dimensions, data),
/// starting at byte q of the entry that begins at byte p; every size checked against `end`,
/// the parameter section's end.
C3dParameter read_parameter(const Bytes& b, std::size_t p, std::size_t q, std::size_t end, const std::string& name) {
  C3dParameter par;
  par.type = b.i8(q, "parameter type");
  const int ndims = b.u8(q + 1, "parameter dimension count");
  if (par.type != -1 && par.type != 1 && par.type != 2 && par.type != 4) {
    std::ostringstream os;
    os << b.path() << ": parameter '" << name << "' at byte " << p << " has invalid type "
       << par.type << " (expected -1, 1, 2 or 4)";
    throw InputError(os.str());
  }
  std::size_t count = 1;
  for (int d = 0; d < ndims; ++d) {
    const int dim = b.u8(q + 2 + d, "parameter dimension");
    par.dims.push_back(dim);
    // Checked before it can wrap: 255^8 already exceeds 2^64, and a wrapped product of 0
    // would pass the bounds check below.
    if (dim != 0 && count > (end - std::min(end, q)) / static_cast<std::size_t>(dim)) {
      std::ostringstream os;
      os << b.path() << ": parameter '" << name << "' at byte " << p << " has dimensions whose product exceeds the "
         << "parameter section";
      throw InputError(os.str());
    }
    count *= static_cast<std::size_t>(dim);
  }
  q += 2 + static_cast<std::size_t>(ndims);
  const std::size_t elem = static_cast<std::size_t>(std::abs(par.type));
  const std::size_t nbytes = count * elem;
  if (q + nbytes > end) {
    std::ostringstream os;
    os << b.path() << ": parameter '" << name << "' at byte " << p << " declares " << nbytes
       << " data bytes, past the end of the parameter section (byte " << end << ")";
    throw InputError(os.str());
  }
  if (par.type == -1) {
    const std::size_t len = ndims == 0 ? 1 : static_cast<std::size_t>(par.dims[0]);
    const std::size_t nstr = len == 0 ? 0 : count / len;
    for (std::size_t s = 0; s < nstr; ++s) {
      std::string str;
      for (std::size_t c = 0; c < len; ++c) {
        const char ch = static_cast<char>(b.u8(q + s * len + c, "parameter string"));
        str.push_back(ch == '\0' ? ' ' : ch);
      }
      par.strings.push_back(rtrim(str));
    }
  } else {
    par.numbers.reserve(count);
    for (std::size_t i = 0; i < count; ++i) {
      const std::size_t o = q + i * elem;
      double v = 0.0;
      if (par.type == 1) v = b.u8(o, "parameter byte");
      else if (par.type == 2) v = b.i16(o, "parameter int16");
      else v = b.f32(o, "parameter float");
      par.numbers.push_back(v);
    }
  }
  par.raw.assign(nbytes, 0);
  return par;
}

void parse_parameters(const Bytes& b, std::size_t start, C3dFile& file) {
  const std::size_t nblocks = b.u8(start + 2, "parameter section header (block count)");
  std::size_t end = start + std::max<std::size_t>(nblocks, 1) * 512;
  if (end > b.size()) end = b.size();  // some writers overstate the count; stay in the file
  std::map<int, std::string> groups;
  struct Pending { int group; std::string name; C3dParameter p; };
  std::vector<Pending> pending;
  std::size_t p = start + 4;
  for (int guard = 0; guard < 100000; ++guard) {
    if (p + 2 > end) break;
    const int nlen = std::abs(static_cast<int>(b.i8(p, "parameter name length")));
    const int id = b.i8(p + 1, "parameter group id");
    if (nlen == 0 || id == 0) break;
    b.need(p + 2, static_cast<std::size_t>(nlen) + 2, "parameter name");
    std::string name;
    for (int i = 0; i < nlen; ++i) name.push_back(static_cast<char>(b.u8(p + 2 + i, "parameter name")));
    name = upper(trim(name));
    std::size_t q = p + 2 + static_cast<std::size_t>(nlen);
    const int offset = b.i16(q, "parameter offset to next");
    const std::size_t next = q + static_cast<std::size_t>(offset);
    q += 2;
    if (id < 0) {
      groups[-id] = name;
    } else {
      C3dParameter par = read_parameter(b, p, q, end, name);
      pending.push_back({id, name, std::move(par)});
    }
    if (offset <= 0) break;        // 0 marks the last entry; negative would loop
    if (next <= p) break;
    p = next;
  }
  for (auto& e : pending) {
    auto g = groups.find(e.group);
    const std::string gname = g == groups.end() ? "GROUP" + std::to_string(e.group) : g->second;
    file.parameters[gname + ":" + e.name] = std::move(e.p);
  }
}

double number(const C3dFile& f, const std::string& key, double fallback, std::size_t i = 0) {
  const auto* p = f.find(key);
  if (p == nullptr || p->numbers.size() <= i) return fallback;
  return p->numbers[i];
}

/// int16 fields that are counts: stored signed, meant unsigned above 32767. A value that no int16
/// holds (a float parameter of 1e30, NaN) is -1, which every caller refuses: no cast of an
/// out-of-range float to int.
int count_value(double v) {
  if (!(v >= -32768.0 && v <= 65535.0)) return -1;
  return v < 0 ? static_cast<int>(v) + 65536 : static_cast<int>(v);
}

std::vector<std::string> strings_multi(const C3dFile& f, const std::string& group,
                                       const std::string& base) {
  std::vector<std::string> out;
  for (int k = 1; k < 100; ++k) {
    const std::string key = group + ":" + base + (k == 1 ? "" : std::to_string(k));
    const auto* p = f.find(key);
    if (p == nullptr) {
      if (k == 1) continue;
      break;
    }
    out.insert(out.end(), p->strings.begin(), p->strings.end());
  }
  return out;
}

double length_unit_scale(const std::string& unit_in, const std::string& path,
                         const std::string& field) {
  const std::string u = upper(trim(unit_in));
  if (u == "MM" || u.empty()) return 1e-3;
  if (u == "CM") return 1e-2;
  if (u == "M") return 1.0;
  throw InputError(path + ": " + field + " = '" + unit_in +
                   "' is not a length unit kin2grf knows (mm, cm, m)");
}

bool finite_all(std::initializer_list<double> v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
}

}  // namespace

const C3dParameter* C3dFile::find(const std::string& key) const {
  auto it = parameters.find(key);
  return it == parameters.end() ? nullptr : &it->second;
}

C3dFile read_c3d_header(const std::vector<std::uint8_t>& bytes, const std::string& path) {
  return read_c3d_header(std::span<const std::uint8_t>(bytes), path);
}

C3dFile read_c3d_header(std::span<const std::uint8_t> bytes, const std::string& path) {
  Bytes b(bytes, path);
  if (bytes.size() < 512) {
    throw InputError(path + ": not a C3D file: " + std::to_string(bytes.size()) +
                     " bytes, shorter than the 512-byte header");
  }
  if (bytes[1] != 0x50) {
    throw InputError(path + ": not a C3D file: header byte 2 is " + std::to_string(bytes[1]) +
                     ", expected 80 (0x50)");
  }
  C3dFile f;
  f.path = path;
  const std::size_t pblock = bytes[0];
  if (pblock < 2) {
    throw InputError(path + ": header byte 1 (first parameter block) is " +
                     std::to_string(pblock) + ", expected 2 or more");
  }
  const std::size_t pstart = (pblock - 1) * 512;
  const int proc = b.u8(pstart + 3, "parameter section header (processor type)");
  if (proc < 84 || proc > 86) {
    throw InputError(path + ": unknown processor type " + std::to_string(proc) + " at byte " +
                     std::to_string(pstart + 3) + " (expected 84 Intel, 85 DEC, 86 SGI/MIPS)");
  }
  b.set_processor(proc);
  f.processor = processor_name(proc);
  f.point_count = b.u16(2, "header: point count");
  f.analog_per_frame = b.u16(4, "header: analog values per frame");
  f.first_frame = b.u16(6, "header: first frame");
  f.last_frame = b.u16(8, "header: last frame");
  f.point_scale = b.f32(12, "header: scale");
  f.data_start_block = b.u16(16, "header: data start block");
  f.point_rate_hz = b.f32(20, "header: frame rate");
  parse_parameters(b, pstart, f);
  // The parameters are authoritative where present.
  if (const auto* p = f.find("POINT:USED"); p && !p->numbers.empty()) {
    f.point_count = count_value(p->numbers[0]);
    if (f.point_count < 0) throw InputError(path + ": POINT:USED is not a count");
  }
  if (const auto* p = f.find("POINT:SCALE"); p && !p->numbers.empty()) f.point_scale = p->numbers[0];
  if (const auto* p = f.find("POINT:RATE"); p && !p->numbers.empty()) f.point_rate_hz = p->numbers[0];
  if (const auto* p = f.find("POINT:DATA_START"); p && !p->numbers.empty())
    f.data_start_block = count_value(p->numbers[0]);  // -1 is refused below (must be 2 or more)
  const auto* s = f.find("TRIAL:ACTUAL_START_FIELD");
  const auto* e = f.find("TRIAL:ACTUAL_END_FIELD");
  if (s && e && s->numbers.size() >= 2 && e->numbers.size() >= 2) {
    const int s0 = count_value(s->numbers[0]), s1 = count_value(s->numbers[1]);
    const int e0 = count_value(e->numbers[0]), e1 = count_value(e->numbers[1]);
    const long first = s0 + 65536L * s1;
    const long last = e0 + 65536L * e1;
    if (std::min({s0, s1, e0, e1}) >= 0 && first >= 1 && last >= first && last < (1L << 30)) {
      f.first_frame = static_cast<int>(first);
      f.last_frame = static_cast<int>(last);
    }
  }
  f.float_data = f.point_scale < 0;
  if (!std::isfinite(f.point_scale) || f.point_scale == 0.0) {
    throw InputError(path + ": POINT:SCALE is " + std::to_string(f.point_scale) +
                     " (must be a finite non-zero number)");
  }
  if (!(f.point_rate_hz >= kMinMarkerRateHz && f.point_rate_hz <= kMaxMarkerRateHz)) {
    char rate[64];
    std::snprintf(rate, sizeof rate, "%g", f.point_rate_hz);
    throw InputError(path + ": POINT:RATE is " + rate + " Hz, not a motion-capture rate (1 Hz to 1 MHz)");
  }
  if (f.last_frame < f.first_frame) {
    throw InputError(path + ": last frame " + std::to_string(f.last_frame) +
                     " is before first frame " + std::to_string(f.first_frame));
  }
  if (f.data_start_block < 2) {
    throw InputError(path + ": POINT:DATA_START / header data block is " +
                     std::to_string(f.data_start_block) + " (must be 2 or more)");
  }
  return f;
}

namespace {

/// Where a C3D's frames are and how they are laid out: checked against the header, the
/// parameters and the file's size before anything is allocated.
struct C3dLayout {
  long nframes = 0;
  int npoints = 0, nchannels = 0, spf = 0;  ///< spf: analog samples per point frame
  int analog_slots = 0;                      ///< analog channels stored per sample
  double analog_rate = 0.0;
  std::size_t word = 4, frame_bytes = 0, data_start = 0;
};

C3dLayout c3d_layout(const C3dFile& f, std::size_t file_size, const std::string& path, std::vector<std::string>& warnings) {
  C3dLayout l;
  l.nframes = static_cast<long>(f.last_frame) - f.first_frame + 1;
  l.npoints = f.point_count;
  const long nframes = l.nframes;
  const int npoints = l.npoints;
  // Analog layout.
  int& nchannels = l.nchannels;
  nchannels = count_value(number(f, "ANALOG:USED", 0));
  if (nchannels < 0) throw InputError(path + ": ANALOG:USED is not a count");
  double& analog_rate = l.analog_rate;
  analog_rate = number(f, "ANALOG:RATE", 0);
  int& spf = l.spf;  // analog samples per point frame
  if (nchannels > 0) {
    if (!std::isfinite(analog_rate) || analog_rate <= 0) {
      throw InputError(path + ": ANALOG:RATE is " + std::to_string(analog_rate) +
                       " with ANALOG:USED = " + std::to_string(nchannels));
    }
    const double ratio = analog_rate / f.point_rate_hz;
    if (!(ratio <= 10000.0))  // before any cast: analog at most 10,000 samples per point frame
      throw InputError(path + ": ANALOG:RATE " + std::to_string(analog_rate) + " Hz is more than 10,000 x POINT:RATE");
    spf = static_cast<int>(std::lround(ratio));
    if (spf < 1 || std::abs(ratio - spf) > 1e-3 * ratio) {
      throw InputError(path + ": ANALOG:RATE " + std::to_string(analog_rate) +
                       " Hz is not an integer multiple of POINT:RATE " +
                       std::to_string(f.point_rate_hz) + " Hz");
    }
    if (f.analog_per_frame != nchannels * spf) {
      if (f.analog_per_frame % spf == 0 && f.analog_per_frame / spf >= nchannels) {
        warnings.push_back("header analog values per frame (" + std::to_string(f.analog_per_frame) +
                             ") differs from ANALOG:USED x samples per frame; using the header");
      } else {
        throw InputError(path + ": header analog values per frame (" +
                         std::to_string(f.analog_per_frame) + ") does not match ANALOG:USED (" +
                         std::to_string(nchannels) + ") x samples per frame (" +
                         std::to_string(spf) + ")");
      }
    }
  }
  l.analog_slots = nchannels > 0 ? f.analog_per_frame / spf : 0;  // channels stored
  l.word = f.float_data ? 4 : 2;
  const std::size_t frame_bytes = l.frame_bytes =
      (static_cast<std::size_t>(npoints) * 4 + static_cast<std::size_t>(l.analog_slots) * static_cast<std::size_t>(spf)) * l.word;
  // Frame counts are checked before anything is allocated: against the data the file holds
  // (below), and, for a file with no point or analog data (nothing to check them against), a
  // frame count that only a data section could justify.
  if (nframes > 50'000'000) throw InputError(path + ": absurd frame count " + std::to_string(nframes));
  if (frame_bytes == 0 && nframes > 1'000'000)
    throw InputError(path + ": claims " + std::to_string(nframes) + " frames but holds no point or analog data");
  const std::size_t data_start = l.data_start = (static_cast<std::size_t>(f.data_start_block) - 1) * 512;
  const std::size_t needed = frame_bytes * static_cast<std::size_t>(nframes);
  if (data_start > file_size || needed > file_size - data_start) {
    const std::size_t avail = data_start > file_size ? 0 : (file_size - data_start);
    const long complete = frame_bytes ? static_cast<long>(avail / frame_bytes) : 0;
    throw InputError(path + ": truncated file: the data section at byte " +
                     std::to_string(data_start) + " needs " + std::to_string(needed) +
                     " bytes for frames " + std::to_string(f.first_frame) + ".." +
                     std::to_string(f.last_frame) + " but only " + std::to_string(avail) +
                     " remain (the data stop in frame " +
                     std::to_string(f.first_frame + complete) + ")");
  }
  return l;
}

/// Called with byte ranges of the data section that have been read (a mapped file releases them).
using ReleaseRead = std::function<void(std::size_t, std::size_t)>;

/// Frames read at a time: the markers are taken frame block by frame block, so that the bytes
/// behind can be released as the reading goes (about 4 MB of the file at a time).
long frames_per_block(std::size_t frame_bytes) {
  return std::max<long>(1, static_cast<long>((std::size_t{4} << 20) / std::max<std::size_t>(1, frame_bytes)));
}

/// The markers (model outputs stored as points set aside by name): a negative residual or a point
/// at exactly (0, 0, 0) is missing. Returns POINT:UNITS's scale to metres.
double read_c3d_points(const C3dFile& f, const Bytes& b, const C3dLayout& l, const std::string& path, Trial& t,
                       const ReleaseRead& release) {
  const long nframes = l.nframes;
  const int npoints = l.npoints;
  const std::size_t word = l.word, frame_bytes = l.frame_bytes, data_start = l.data_start;
  // ---- Points -----------------------------------------------------------------------------
  const auto* units = f.find("POINT:UNITS");
  const std::string unit_str = units && !units->strings.empty() ? units->strings[0] : "mm";
  if (!units) t.warnings.push_back("POINT:UNITS missing; assuming mm");
  const double to_m = length_unit_scale(unit_str, path, "POINT:UNITS");

  std::vector<std::string> labels = strings_multi(f, "POINT", "LABELS");
  std::vector<std::string> descs = strings_multi(f, "POINT", "DESCRIPTIONS");
  if (static_cast<int>(labels.size()) < npoints) {
    t.warnings.push_back("POINT:LABELS has " + std::to_string(labels.size()) + " names for " +
                         std::to_string(npoints) + " points; the rest are named *<n>");
  }
  // Model outputs stored as points (Vicon Plug-in Gait angles, forces, ...) are not markers.
  std::vector<std::string> model_outputs;
  for (const char* g : {"ANGLES", "FORCES", "MOMENTS", "POWERS", "SCALARS", "REACTIONS"}) {
    for (const auto& s : strings_multi(f, "POINT", g)) model_outputs.push_back(s);
  }
  auto is_model_output = [&](const std::string& n) {
    return !n.empty() && std::find(model_outputs.begin(), model_outputs.end(), n) != model_outputs.end();
  };

  MarkerTrajectories& m = t.markers;
  m.rate_hz = f.point_rate_hz;
  m.first_frame = f.first_frame;
  m.up_axis = Axis::Z;
  m.time_s.resize(nframes);
  for (long i = 0; i < nframes; ++i) m.time_s[i] = static_cast<double>(f.first_frame - 1 + i) / f.point_rate_hz;
  std::vector<int> point_slot;
  UniqueLabels unique;
  for (int k = 0; k < npoints; ++k) {
    std::string name = k < static_cast<int>(labels.size()) ? labels[k] : "";
    if (name.empty()) name = "*" + std::to_string(k + 1);
    if (is_model_output(name)) {
      t.model_outputs.push_back(name);
      continue;
    }
    name = unique.add(name, static_cast<std::size_t>(k), &t.warnings);
    m.names.push_back(name);
    m.descriptions.push_back(k < static_cast<int>(descs.size()) ? descs[k] : "");
    m.positions_m.emplace_back(nframes, 3);
    point_slot.push_back(k);
  }
  unique.finish(&t.warnings);
  const double scale = std::abs(f.point_scale);
  const long block = frames_per_block(frame_bytes);
  for (long i0 = 0; i0 < nframes; i0 += block) {
    const long i1 = std::min(nframes, i0 + block);
    for (std::size_t mk = 0; mk < point_slot.size(); ++mk) {
      const std::size_t slot = static_cast<std::size_t>(point_slot[mk]);
      auto& P = m.positions_m[mk];
      for (long i = i0; i < i1; ++i) {
        const std::size_t o = data_start + static_cast<std::size_t>(i) * frame_bytes + slot * 4 * word;
        double x, y, z, res;
        if (f.float_data) {
          x = b.f32_unchecked(o); y = b.f32_unchecked(o + 4); z = b.f32_unchecked(o + 8);
          res = b.f32_unchecked(o + 12);
        } else {
          x = static_cast<std::int16_t>(b.u16_unchecked(o)) * scale;
          y = static_cast<std::int16_t>(b.u16_unchecked(o + 2)) * scale;
          z = static_cast<std::int16_t>(b.u16_unchecked(o + 4)) * scale;
          res = static_cast<std::int16_t>(b.u16_unchecked(o + 6));
        }
        // Missing: a negative residual (the specification), and a point at exactly (0, 0, 0),
        // which several exporters write for a gap whatever the residual (65535 included).
        if (res < 0 || !finite_all({x, y, z}) || (x == 0 && y == 0 && z == 0)) {
          P.row(i).setConstant(kNaN);
        } else {
          P(i, 0) = x * to_m; P(i, 1) = y * to_m; P(i, 2) = z * to_m;
        }
      }
    }
    if (release) release(data_start + static_cast<std::size_t>(i0) * frame_bytes, data_start + static_cast<std::size_t>(i1) * frame_bytes);
  }
  return to_m;
}

/// The analog channels, scaled (ANALOG:SCALE, OFFSET, GEN_SCALE, FORMAT), one row per sample;
/// without `samples`, their labels, units and rate only (no rows).
AnalogData read_c3d_analog(const C3dFile& f, const Bytes& b, const C3dLayout& l, const std::string& path, bool samples,
                           const ReleaseRead& release) {
  const long nframes = l.nframes;
  const int npoints = l.npoints, nchannels = l.nchannels, spf = l.spf, analog_slots = l.analog_slots;
  const double analog_rate = l.analog_rate;
  const std::size_t word = l.word, frame_bytes = l.frame_bytes, data_start = l.data_start;
  // ---- Analog ---------------------------------------------------------------------------
  AnalogData analog;
  if (nchannels > 0) {
    const long frames_read = samples ? nframes : 0;
    const long nsamples = frames_read * spf;
    analog.rate_hz = analog_rate;
    analog.first_time_s = (f.first_frame - 1) / f.point_rate_hz;
    analog.values.resize(nsamples, nchannels);
    analog.labels = strings_multi(f, "ANALOG", "LABELS");
    analog.units = strings_multi(f, "ANALOG", "UNITS");
    analog.labels.resize(static_cast<std::size_t>(nchannels));
    analog.units.resize(static_cast<std::size_t>(nchannels));
    const double gen_scale = number(f, "ANALOG:GEN_SCALE", 1.0);
    const auto* fmt = f.find("ANALOG:FORMAT");
    const bool is_unsigned = fmt && !fmt->strings.empty() && upper(fmt->strings[0]) == "UNSIGNED";
    std::vector<double> ch_scale(static_cast<std::size_t>(nchannels), 1.0);
    std::vector<double> ch_offset(static_cast<std::size_t>(nchannels), 0.0);
    if (const auto* p = f.find("ANALOG:SCALE")) {
      for (int c = 0; c < nchannels && c < static_cast<int>(p->numbers.size()); ++c)
        ch_scale[c] = p->numbers[c];
    }
    if (const auto* p = f.find("ANALOG:OFFSET")) {
      for (int c = 0; c < nchannels && c < static_cast<int>(p->numbers.size()); ++c)
        ch_offset[c] = is_unsigned ? count_value(p->numbers[c]) : p->numbers[c];
    }
    if (!std::isfinite(gen_scale)) throw InputError(path + ": ANALOG:GEN_SCALE is not finite");
    for (int c = 0; c < nchannels; ++c) {
      if (!std::isfinite(ch_scale[c]))
        throw InputError(path + ": ANALOG:SCALE[" + std::to_string(c + 1) + "] is not finite");
    }
    const std::size_t analog_off = static_cast<std::size_t>(npoints) * 4 * word;
    const long block = frames_per_block(frame_bytes);
    for (long i = 0; i < frames_read; ++i) {
      if (release && i > 0 && i % block == 0)
        release(data_start + static_cast<std::size_t>(i - block) * frame_bytes, data_start + static_cast<std::size_t>(i) * frame_bytes);
      for (int s = 0; s < spf; ++s) {
        const long row = i * spf + s;
        for (int c = 0; c < nchannels; ++c) {
          const std::size_t o = data_start + static_cast<std::size_t>(i) * frame_bytes + analog_off +
                                (static_cast<std::size_t>(s) * analog_slots + c) * word;
          double raw;
          if (f.float_data) raw = b.f32_unchecked(o);
          else if (is_unsigned) raw = b.u16_unchecked(o);
          else raw = static_cast<std::int16_t>(b.u16_unchecked(o));
          analog.values(row, c) = (raw - ch_offset[c]) * ch_scale[c] * gen_scale;
        }
      }
    }
  }
  return analog;
}

/// The force plates of FORCE_PLATFORM (types 1-4) from the analog data; none, with a note, when
/// the file describes plates but holds no analog data.
/// Plate p's description (FORCE_PLATFORM: TYPE, CORNERS and ORIGIN in m, CHANNEL, and for a
/// type-4 plate CAL_MATRIX), every entry checked; the caller has checked that TYPE, CORNERS,
/// ORIGIN and CHANNEL exist.
PlateDescription plate_description(const C3dFile& f, int p, int nchannels, double to_m, const C3dReadOptions& options,
                                   const std::string& path) {
  const auto* types = f.find("FORCE_PLATFORM:TYPE");
  const auto* corners = f.find("FORCE_PLATFORM:CORNERS");
  const auto* origin = f.find("FORCE_PLATFORM:ORIGIN");
  const auto* channel = f.find("FORCE_PLATFORM:CHANNEL");
  const auto* cal = f.find("FORCE_PLATFORM:CAL_MATRIX");
  const int chan_rows = channel->dims.empty() ? 0 : channel->dims[0];
  PlateDescription d;
  d.name = "FP" + std::to_string(p + 1);
  if (static_cast<int>(types->numbers.size()) <= p)
    throw InputError(path + ": FORCE_PLATFORM:TYPE has no entry for plate " + std::to_string(p + 1));
  d.type = count_value(types->numbers[p]);  // 1-4: the caller leaves the others out
  if (corners->numbers.size() < static_cast<std::size_t>(12 * (p + 1)))
    throw InputError(path + ": FORCE_PLATFORM:CORNERS has no entry for plate " + std::to_string(p + 1));
  for (int c = 0; c < 4; ++c)
    for (int a = 0; a < 3; ++a) d.corners(a, c) = corners->numbers[12 * p + 3 * c + a] * to_m;
  if (origin->numbers.size() < static_cast<std::size_t>(3 * (p + 1)))
    throw InputError(path + ": FORCE_PLATFORM:ORIGIN has no entry for plate " + std::to_string(p + 1));
  for (int a = 0; a < 3; ++a) d.origin(a) = origin->numbers[3 * p + a] * to_m;
  const int nch = d.type == 3 ? 8 : 6;
  if (chan_rows < nch || channel->numbers.size() < static_cast<std::size_t>(chan_rows * (p + 1))) {
    throw InputError(path + ": FORCE_PLATFORM:CHANNEL has fewer than " + std::to_string(nch) +
                     " channels for plate " + std::to_string(p + 1) + " (type " +
                     std::to_string(d.type) + ")");
  }
  for (int c = 0; c < nch; ++c) {
    const int ch = count_value(channel->numbers[static_cast<std::size_t>(chan_rows * p + c)]);
    if (ch < 1 || ch > nchannels) {
      throw InputError(path + ": FORCE_PLATFORM:CHANNEL[" + std::to_string(c + 1) + "," +
                       std::to_string(p + 1) + "] = " + std::to_string(ch) +
                       " is not an analog channel (1.." + std::to_string(nchannels) + ")");
    }
    d.channels.push_back(ch - 1);
  }
  if (d.type == 4) {
    if (!cal || cal->numbers.size() < static_cast<std::size_t>(36 * (p + 1))) {
      throw InputError(path + ": plate " + std::to_string(p + 1) +
                       " is TYPE 4 but FORCE_PLATFORM:CAL_MATRIX has no 6x6 entry for it");
    }
    for (int i = 0; i < 6; ++i)
      for (int j = 0; j < 6; ++j) {
        const std::size_t k = options.cal_matrix_first_index_fastest
                                  ? static_cast<std::size_t>(36 * p + i + 6 * j)
                                  : static_cast<std::size_t>(36 * p + 6 * i + j);
        d.cal_matrix(i, j) = cal->numbers[k];
      }
  }
  if (!d.corners.allFinite() || !d.origin.allFinite())
    throw InputError(path + ": FORCE_PLATFORM CORNERS/ORIGIN of plate " + std::to_string(p + 1) +
                     " contain NaN or infinity");
  return d;
}

void read_c3d_plates(const C3dFile& f, const C3dLayout& l, const AnalogData& analog, double to_m, const C3dReadOptions& options,
                     const std::string& path, Trial& t) {
  const int nchannels = l.nchannels, spf = l.spf;
  // ---- Force plates -----------------------------------------------------------------------
  const int nplates = count_value(number(f, "FORCE_PLATFORM:USED", 0));
  if (nplates < 0) throw InputError(path + ": FORCE_PLATFORM:USED is not a count");
  // From the layout, not from `analog`, which has no rows when the samples are not read.
  const bool no_analog_data = nchannels <= 0 || spf <= 0 || l.nframes <= 0;
  if (nplates > 0 && no_analog_data) {
    // A static or marker-only export often keeps the lab's FORCE_PLATFORM description with no
    // analog data (e.g. RBDS001static.c3d). The markers are still good: no plates, and a note.
    t.warnings.push_back(path + ": FORCE_PLATFORM:USED = " + std::to_string(nplates) +
                         " but the file holds no analog data (ANALOG:USED = " +
                         std::to_string(nchannels) + "); the force plates are not read");
  } else if (nplates > 0) {
    std::vector<PlateDescription> descs_fp;
    const auto* types = f.find("FORCE_PLATFORM:TYPE");
    const auto* corners = f.find("FORCE_PLATFORM:CORNERS");
    const auto* origin = f.find("FORCE_PLATFORM:ORIGIN");
    const auto* channel = f.find("FORCE_PLATFORM:CHANNEL");
    if (!types || !corners || !origin || !channel) {
      throw InputError(path + ": FORCE_PLATFORM:USED = " + std::to_string(nplates) +
                       " but TYPE, CORNERS, ORIGIN or CHANNEL is missing");
    }
    for (int p = 0; p < nplates; ++p) {
      // A plate of a type kin2grf cannot compute (5-7 with their calibration matrices, the
      // treadmills' 11 and 12, AMTI's stairs 21) is left out with its name, as a plate whose
      // calibration is broken is: the markers, and the other plates, are still good, and
      // `estimate` does not need the plates at all.
      if (static_cast<int>(types->numbers.size()) > p) {
        const int type = count_value(types->numbers[p]);
        if (type < 1 || type > 4) {
          t.warnings.push_back(path + ": FP" + std::to_string(p + 1) + ": FORCE_PLATFORM:TYPE[" + std::to_string(p + 1) + "] = " +
                               std::to_string(type) + " is not supported (types 1-4 are); this plate is left out");
          continue;
        }
      }
      descs_fp.push_back(plate_description(f, p, nchannels, to_m, options, path));
    }
    PlateProcessing proc;
    proc.cop_threshold_N = options.cop_threshold_N;
    proc.zero_offset = options.zero_offset;
    proc.unloaded_threshold_N = options.unloaded_threshold_N;
    if (const auto* z = f.find("FORCE_PLATFORM:ZERO"); z && z->numbers.size() >= 2 && count_value(z->numbers[0]) >= 0 &&
                                                        count_value(z->numbers[1]) >= 0) {
      proc.zero_first_sample = static_cast<long>((z->numbers[0] - 1) * spf);
      proc.zero_last_sample = static_cast<long>(z->numbers[1] * spf) - 1;
    }
    t.plates = compute_plates(analog, descs_fp, proc, path, t.warnings);
    t.plates->up_axis = Axis::Z;
  }
}

/// EVENT times, and the body mass and height where labs store them.
void read_c3d_events_and_subject(const C3dFile& f, Trial& t) {
  // ---- Events, subject ----------------------------------------------------------------------
  if (const auto* times = f.find("EVENT:TIMES")) {
    const int used = count_value(number(f, "EVENT:USED", static_cast<double>(times->numbers.size() / 2)));
    const std::vector<std::string> ev_labels = strings_multi(f, "EVENT", "LABELS");
    const std::vector<std::string> ev_ctx = strings_multi(f, "EVENT", "CONTEXTS");
    for (int e = 0; e < used && static_cast<std::size_t>(2 * e + 1) < times->numbers.size(); ++e) {
      Event ev;
      ev.label = e < static_cast<int>(ev_labels.size()) ? ev_labels[e] : "";
      const std::string ctx = e < static_cast<int>(ev_ctx.size()) ? upper(ev_ctx[e]) : "";
      ev.side = ctx == "RIGHT" ? Side::Right : ctx == "LEFT" ? Side::Left : Side::General;
      ev.time_s = 60.0 * times->numbers[2 * e] + times->numbers[2 * e + 1];
      if (std::isfinite(ev.time_s)) t.events.push_back(ev);
    }
    std::sort(t.events.begin(), t.events.end(),
              [](const Event& a, const Event& c) { return a.time_s < c.time_s; });
  }
  // Body mass where labs store it: Vicon's PROCESSING:Bodymass, then SUBJECT(S):WEIGHT or MASS
  // (kg). The first positive finite value is taken; its plausibility is the estimate's to judge.
  for (const char* key : {"PROCESSING:BODYMASS", "PROCESSING:WEIGHT", "SUBJECT:WEIGHT", "SUBJECT:MASS", "SUBJECT:BODYMASS",
                          "SUBJECTS:WEIGHT", "SUBJECTS:MASS", "SUBJECTS:BODYMASS"}) {
    const auto* bm = f.find(key);
    if (bm && !bm->numbers.empty() && std::isfinite(bm->numbers[0]) && bm->numbers[0] > 0) {
      t.body_mass_kg = bm->numbers[0];
      if (std::string(key) != "PROCESSING:BODYMASS") t.warnings.push_back(std::string("body mass from ") + key + " (kg)");
      break;
    }
  }
  if (const auto* h = f.find("PROCESSING:HEIGHT"); h && !h->numbers.empty() &&
                                                     std::isfinite(h->numbers[0]) && h->numbers[0] > 0) {
    t.height_m = h->numbers[0] > 10 ? h->numbers[0] / 1000.0 : h->numbers[0];  // stored in mm
  }
  // Plug-in Gait's subject measurements (mm). A value outside a human joint's width (a 0 left
  // unmeasured, a value in metres) is not taken: the anthropometric fallback is used instead.
  const auto width_mm = [&](const char* key, double lo, double hi) -> std::optional<double> {
    const auto* p = f.find(key);
    if (p && !p->numbers.empty() && p->numbers[0] >= lo && p->numbers[0] <= hi) return p->numbers[0] / 1000.0;
    return std::nullopt;
  };
  t.knee_width_m = {width_mm("PROCESSING:RKNEEWIDTH", 50, 200), width_mm("PROCESSING:LKNEEWIDTH", 50, 200)};
  t.ankle_width_m = {width_mm("PROCESSING:RANKLEWIDTH", 30, 150), width_mm("PROCESSING:LANKLEWIDTH", 30, 150)};
  t.marker_diameter_m = width_mm("PROCESSING:MARKERDIAMETER", 3, 40);
}

}  // namespace

namespace {

Trial read_c3d_span(std::span<const std::uint8_t> bytes, const std::string& path, const C3dReadOptions& options,
                    const ReleaseRead& release) {
  const C3dFile f = read_c3d_header(bytes, path);
  Bytes b(bytes, path);
  b.set_processor(f.processor == "Intel" ? 84 : f.processor == "DEC" ? 85 : 86);
  Trial t;
  t.path = path;
  t.format = "C3D";
  t.encoding = f.processor + (f.float_data ? ", float" : ", integer");
  const C3dLayout layout = c3d_layout(f, bytes.size(), path, t.warnings);
  const double to_m = read_c3d_points(f, b, layout, path, t, release);
  const AnalogData analog = read_c3d_analog(f, b, layout, path, options.plate_samples, release);
  read_c3d_plates(f, layout, analog, to_m, options, path, t);
  read_c3d_events_and_subject(f, t);
  return t;
}

}  // namespace

Trial read_c3d_bytes(const std::vector<std::uint8_t>& bytes, const std::string& path, const C3dReadOptions& options) {
  return read_c3d_span(bytes, path, options, nullptr);
}

Trial read_c3d(const std::string& path, const C3dReadOptions& options) {
  // Mapped, not read into memory: the frames are read front to back and each block's bytes are
  // released behind (memory: a 10-minute capture is 0.5 GB, mostly analog samples).
  const MappedFile file(path, /*populate=*/false);
  return file.read([&] {
    return read_c3d_span(file.bytes(), path, options, [&](std::size_t begin, std::size_t end) { file.release(begin, end); });
  });
}

}  // namespace kin2grf
