#include "kin2grf/io/opensim.hpp"

#include <algorithm>
#include <atomic>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <span>
#include <sstream>

#include "kin2grf/error.hpp"
#include "kin2grf/io/output_file.hpp"
#include "kin2grf/io/text.hpp"
#include "kin2grf/parallel.hpp"
#include "kin2grf/numeric.hpp"

namespace kin2grf {
namespace {


/// The lines of a text, views into it (no copy), without their '\r'.
std::vector<std::string_view> lines_of(std::string_view text) {
  std::vector<std::string_view> lines;
  // A UTF-8 byte-order mark (Windows editors) is no part of the first line; a file of lone CRs
  // (old Mac editors) is split on them.
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  const bool cr_only = text.find('\n') == std::string_view::npos && text.find('\r') != std::string_view::npos;
  split_views(text, cr_only ? '\r' : '\n', lines);
  for (auto& l : lines)
    if (!l.empty() && l.back() == '\r') l.remove_suffix(1);
  return lines;
}

std::string fmt(double v) {
  if (!std::isfinite(v)) return "NaN";
  char buf[64];  // printf's %.8g (to_chars is specified to match it), without the format parsing
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 8);
  return std::string(buf, r.ptr);
}

std::string where(const std::string& path, std::size_t line) {
  return path + ":" + std::to_string(line + 1);
}

}  // namespace

int Table::column(const std::string& label) const {
  for (std::size_t i = 0; i < labels.size(); ++i)
    if (labels[i] == label) return static_cast<int>(i);
  return -1;
}

MarkerTrajectories read_trc(const std::string& path, std::vector<std::string>* warnings) {
  // The rows' text is released as they are parsed (memory: a long trial's text and its
  // markers are not held whole together).
  const MappedFile file(path, /*populate=*/false);
  return file.read([&] {
    return parse_trc(file.text(), path, warnings, [&](std::size_t begin, std::size_t end) { file.release(begin, end); });
  });
}

namespace {

/// A TRC's five header lines: rate, units, declared counts and the marker names (a name used
/// twice made unique, with a warning).
struct TrcHeader {
  double rate_hz = 0.0, frames_declared = 0.0, to_m = 1e-3;
  std::vector<std::string> names;
};

TrcHeader parse_trc_header(const std::vector<std::string_view>& lines, const std::string& path, std::vector<std::string>* warnings) {
  if (lines.size() < 5 || lines[0].rfind("PathFileType", 0) != 0) {
    throw InputError(path + ": not a TRC file (the first line must start with 'PathFileType' and the "
                            "header has 5 lines)");
  }
  const auto keys = split(lines[1], " \t", false);
  const auto vals = split(lines[2], " \t", false);
  if (keys.size() != vals.size()) {
    throw InputError(where(path, 2) + ": the header has " + std::to_string(keys.size()) +
                     " keys on line 2 but " + std::to_string(vals.size()) + " values on line 3");
  }
  std::map<std::string, std::string> h;
  for (std::size_t i = 0; i < keys.size(); ++i) h[keys[i]] = vals[i];
  auto num = [&](const std::string& k) {
    auto it = h.find(k);
    double v = kNaN;
    if (it == h.end() || !parse_double(it->second, v) || !std::isfinite(v))
      throw InputError(where(path, 2) + ": header field " + k + " is missing or not a number");
    return v;
  };
  TrcHeader th;
  th.rate_hz = num("DataRate");
  if (th.rate_hz <= 0) throw InputError(where(path, 2) + ": DataRate must be positive");
  const double nmark_decl = num("NumMarkers");
  th.frames_declared = num("NumFrames");
  const std::string units = h.count("Units") ? to_lower(h["Units"]) : "mm";
  if (units == "m") th.to_m = 1.0;
  else if (units == "cm") th.to_m = 1e-2;
  else if (units != "mm") throw InputError(where(path, 2) + ": Units '" + h["Units"] + "' is not mm, cm or m");

  const auto name_cells = split(lines[3], "\t", true);
  std::vector<std::string> names;
  for (std::size_t i = 2; i < name_cells.size(); ++i) {
    const std::string n = trim(name_cells[i]);
    if (!n.empty()) names.push_back(n);
  }
  if (name_cells.size() < 2 || trim(name_cells[0]) != "Frame#") {
    throw InputError(where(path, 3) + ": expected 'Frame#<tab>Time<tab>names...'");
  }
  {
    std::vector<std::string> unique;  // a label used twice: the k-th is NAME#k
    UniqueLabels labels;
    for (std::size_t i = 0; i < names.size(); ++i) unique.push_back(labels.add(names[i], i, warnings));
    labels.finish(warnings);
    th.names = std::move(unique);
  }
  if (static_cast<double>(th.names.size()) != nmark_decl) {
    throw InputError(where(path, 3) + ": NumMarkers says " + fmt(nmark_decl) + " but " +
                     std::to_string(th.names.size()) + " marker names follow");
  }
  return th;
}

/// One data row (line `li`) into row i of `m` (time, positions in metres, NaN for a marker with
/// a blank cell) and its Frame#. A row with spaces for tabs is read too; returns true when the
/// row ends early (its trailing markers are missing). `cells` and `values` are reused.
bool read_trc_row(std::string_view line, std::size_t li, const TrcHeader& th, const std::string& path,
                  std::vector<std::string_view>& cells, std::vector<double>& values, MarkerTrajectories& m,
                  Eigen::Index i, int& frame) {
  const std::size_t nm = th.names.size(), width = nm * 3 + 2;
  values.resize(width);
  if (parse_plain_fields(line, '\t', values) && std::abs(values[0]) <= 1e9) {  // the usual row: every cell a number
    frame = static_cast<int>(values[0]);
    m.time_s[i] = values[1];
    for (std::size_t k = 0; k < nm; ++k)
      m.positions_m[k].row(i) << values[2 + 3 * k] * th.to_m, values[3 + 3 * k] * th.to_m, values[4 + 3 * k] * th.to_m;
    return false;
  }
  split_views(line, '\t', cells);
  std::vector<std::string> ws;  // some writers separate by spaces
  if (cells.size() < width) {
    ws = split(line, " \t", false);
    if (ws.size() == width) cells.assign(ws.begin(), ws.end());
  }
  while (cells.size() > width && is_blank(cells.back())) cells.pop_back();
  if (cells.size() > width) {
    throw InputError(where(path, li) + ": " + std::to_string(cells.size()) + " columns, but " + std::to_string(nm) +
                     " markers make " + std::to_string(width));
  }
  double fr = kNaN;
  if (!parse_double(cells[0], fr) || !std::isfinite(fr) || std::abs(fr) > 1e9)
    throw InputError(where(path, li) + ": Frame# '" + std::string(cells[0]) + "' is not a frame number");
  if (cells.size() < 2 || !parse_double(cells[1], m.time_s[i]) || !std::isfinite(m.time_s[i]))
    throw InputError(where(path, li) + ": Time is missing or not a number");
  frame = static_cast<int>(fr);
  for (std::size_t k = 0; k < nm; ++k) {
    double v[3] = {kNaN, kNaN, kNaN};
    for (std::size_t a = 0; a < 3; ++a) {
      const std::size_t c = 2 + 3 * k + a;
      if (c >= cells.size() || is_blank(cells[c])) continue;
      if (!parse_double(cells[c], v[a]))
        throw InputError(where(path, li) + ": marker " + th.names[k] + " " + "XYZ"[a] + " = '" + trim(cells[c]) +
                         "' is not a number");
    }
    auto P = m.positions_m[k].row(i);
    if (std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])) P << v[0] * th.to_m, v[1] * th.to_m, v[2] * th.to_m;
    else P.setConstant(kNaN);
  }
  return cells.size() < width;
}

/// Every data row (line 6 on, blank lines skipped) straight into `m` and `frames`; returns the
/// number of rows that end early. Rows are independent: chunks of them are read on the
/// machine's cores, each into its own rows (no second copy of the data).
std::size_t parse_trc_rows(const std::vector<std::string_view>& lines, std::string_view text, const TrcHeader& th,
                           const std::string& path, MarkerTrajectories& m, std::vector<int>& frames,
                           const std::function<void(std::size_t, std::size_t)>& release) {
  const std::size_t text_bytes = text.size();
  std::vector<std::size_t> data_lines;
  data_lines.reserve(lines.size());
  for (std::size_t li = std::min<std::size_t>(5, lines.size()); li < lines.size(); ++li)
    if (!is_blank(lines[li])) data_lines.push_back(li);
  const auto n = static_cast<Eigen::Index>(data_lines.size());
  // Limits before allocation: a complete row holds fewer values than bytes; rows that end early
  // hold fewer, but a file whose header's markers over its rows would need far more memory than
  // the file's size is refused, not allocated.
  const double values = static_cast<double>(n) * static_cast<double>(th.names.size()) * 3.0;
  if (values > 8.0 * static_cast<double>(text_bytes) + 1e7)
    throw InputError(path + ": " + std::to_string(th.names.size()) + " markers over " + std::to_string(n) + " rows make " +
                     fmt(values) + " values, more than a file of " + std::to_string(text_bytes) + " bytes holds");
  m.time_s.resize(n);
  frames.resize(data_lines.size());
  m.positions_m.clear();
  m.positions_m.reserve(th.names.size());
  for (std::size_t k = 0; k < th.names.size(); ++k) m.positions_m.emplace_back(n, 3);
  std::atomic<std::size_t> short_rows{0};
  // About 5 ns a byte of text (splitting and parsing).
  const double bytes_per_row = static_cast<double>(text_bytes) / static_cast<double>(std::max<std::size_t>(1, data_lines.size()));
  for_chunks(data_lines.size(), min_chunk_for(5e-9 * bytes_per_row), [&](std::size_t, std::size_t begin, std::size_t end) {
    std::vector<std::string_view> cells;
    std::vector<double> row_values;
    std::size_t short_here = 0;
    // Each chunk of rows is one thread's: it releases its own rows' text every 4 MB or so.
    const auto offset = [&](std::size_t r) { return static_cast<std::size_t>(lines[data_lines[r]].data() - text.data()); };
    std::size_t released = offset(begin);
    for (std::size_t r = begin; r < end; ++r) {
      short_here += read_trc_row(lines[data_lines[r]], data_lines[r], th, path, cells, row_values, m, static_cast<Eigen::Index>(r),
                                 frames[r]);
      if (release && r + 1 < end && offset(r + 1) - released >= (std::size_t{4} << 20)) {
        release(released, offset(r + 1));
        released = offset(r + 1);
      }
    }
    if (release) release(released, end < data_lines.size() ? offset(end) : text.size());
    short_rows += short_here;
  });
  return short_rows;
}

}  // namespace

MarkerTrajectories parse_trc(std::string_view text, const std::string& path, std::vector<std::string>* warnings,
                             const std::function<void(std::size_t, std::size_t)>& release) {
  const auto lines = lines_of(text);
  const TrcHeader th = parse_trc_header(lines, path, warnings);
  MarkerTrajectories m;
  std::vector<int> frames;
  const std::size_t short_rows = parse_trc_rows(lines, text, th, path, m, frames, release);
  const auto n = m.frames();
  m.rate_hz = th.rate_hz;
  m.up_axis = Axis::Y;
  if (n == 0) throw InputError(path + ": no data rows after the header");
  if (static_cast<double>(n) != th.frames_declared && warnings)
    warnings->push_back("NumFrames says " + fmt(th.frames_declared) + " but " + std::to_string(n) + " data rows were read");
  if (short_rows && warnings)
    warnings->push_back(std::to_string(short_rows) + " rows end early; their trailing markers are treated as missing");
  // A marker at exactly (0, 0, 0) is a gap some exporters write as zeros (as C3D files' points at
  // the origin): no marker sits exactly on the lab's origin to the last digit in all three axes.
  long at_origin = 0;
  for (auto& P : m.positions_m)
    for (Eigen::Index i = 0; i < n; ++i)
      if (P(i, 0) == 0.0 && P(i, 1) == 0.0 && P(i, 2) == 0.0) P.row(i).setConstant(kNaN), ++at_origin;
  if (at_origin && warnings)
    warnings->push_back(std::to_string(at_origin) + " marker samples at exactly (0, 0, 0) are read as missing (an exporter's gap)");
  m.first_frame = frames.front();
  m.names = th.names;
  m.descriptions.assign(th.names.size(), "");
  for (Eigen::Index i = 1; i < n; ++i)
    if (!(m.time_s[i] > m.time_s[i - 1]))
      throw InputError(path + ": Time does not increase at frame " + std::to_string(frames[static_cast<std::size_t>(i)]));
  if (n >= 3) {
    // DataRate against the Time column: the samples' own spacing wins (a wrong DataRate scales
    // every derivative), with a warning. The spacing over the whole column, not a median step:
    // times written with 3 decimals (0.017 s at 60 Hz) would fake a 58.8 Hz rate.
    const double rate = static_cast<double>(n - 1) / (m.time_s[n - 1] - m.time_s[0]);
    if (std::isfinite(rate) && std::abs(1000.0 * rate - m.rate_hz) <= 0.01 * m.rate_hz) {
      // The Time column in milliseconds (some exporters): read as seconds it would make a
      // 100 Hz trial 0.1 Hz. Its spacing is DataRate's exactly when divided by 1000.
      m.time_s /= 1000.0;
      if (warnings)
        warnings->push_back("the Time column is in milliseconds (its spacing is DataRate's " + fmt(m.rate_hz) +
                            " Hz times 1000); read as seconds");
    } else if (std::isfinite(rate) && std::abs(rate - m.rate_hz) > 0.01 * rate) {
      if (warnings)
        warnings->push_back("DataRate says " + fmt(m.rate_hz) + " Hz but the Time column spans " + std::to_string(n) +
                            " frames at " + fmt(rate) + " Hz; the Time column's rate is used");
      m.rate_hz = rate;
    }
  }
  if (!(m.rate_hz >= kMinMarkerRateHz && m.rate_hz <= kMaxMarkerRateHz))
    throw InputError(where(path, 2) + ": a rate of " + fmt(m.rate_hz) + " Hz (DataRate, or the Time column's spacing) is not a " +
                     "motion-capture rate (1 Hz to 1 MHz); is the Time column in seconds?");
  return m;
}

std::string format_trc(const MarkerTrajectories& m, const std::string& file_name) {
  std::ostringstream os;
  const auto n = m.frames();
  os << "PathFileType\t4\t(X/Y/Z)\t" << file_name << "\n";
  os << "DataRate\tCameraRate\tNumFrames\tNumMarkers\tUnits\tOrigDataRate\tOrigDataStartFrame\tOrigNumFrames\n";
  os << fmt(m.rate_hz) << "\t" << fmt(m.rate_hz) << "\t" << n << "\t" << m.names.size() << "\tmm\t"
     << fmt(m.rate_hz) << "\t" << m.first_frame << "\t" << n << "\n";
  os << "Frame#\tTime";
  for (const auto& name : m.names) os << "\t" << name << "\t\t";
  os << "\n\t";
  for (std::size_t k = 0; k < m.names.size(); ++k) os << "\tX" << k + 1 << "\tY" << k + 1 << "\tZ" << k + 1;
  os << "\n\n";
  // A missing coordinate is written NaN, never left empty: OpenSim's TRC reader (FileAdapter::
  // tokenize) drops empty fields, so a row with a gap came out short and was refused
  // (RowLengthMismatch); "NaN" is a field of its own that it reads as missing, as it writes them.
  for (Eigen::Index i = 0; i < n; ++i) {
    os << m.first_frame + i << "\t" << fmt(m.time_s[i]);
    for (const auto& P : m.positions_m) {
      for (int a = 0; a < 3; ++a) {
        os << "\t";
        if (std::isfinite(P(i, a))) os << fmt(P(i, a) * 1000.0);
        else os << "NaN";
      }
    }
    os << "\n";
  }
  return os.str();
}

void write_trc(const std::string& path, const MarkerTrajectories& m) {
  write_file_text(path, format_trc(m, std::filesystem::path(path).filename().string()));
}

Table read_sto(const std::string& path) {
  const MappedFile file(path);
  return file.read([&] { return parse_sto(file.text(), path); });
}

namespace {
/// The header up to `endheader` into t (its name, its key=value or key value fields); the index
/// of the line after it.
std::size_t read_sto_header(const std::vector<std::string_view>& lines, Table& t, const std::string& path) {
  for (std::size_t li = 0; li < lines.size(); ++li) {
    const std::string l = trim(lines[li]);
    if (l == "endheader") return li + 1;
    if (li == 0 && l.find('=') == std::string::npos) {
      t.name = l.rfind("name ", 0) == 0 ? trim(l.substr(5)) : l;
      continue;
    }
    const auto eq = l.find('=');
    if (eq != std::string::npos) {
      t.header[trim(l.substr(0, eq))] = trim(l.substr(eq + 1));
    } else {
      const auto sp = l.find_first_of(" \t");
      if (sp != std::string::npos) t.header[l.substr(0, sp)] = trim(l.substr(sp + 1));
    }
  }
  throw InputError(path + ": not a MOT/STO file: no 'endheader' line");
}

/// A count the header declares under either key (OpenSim's and SIMM's names); -1 when absent.
long header_count(const Table& t, const char* k1, const char* k2, const std::string& path) {
  for (const char* k : {k1, k2}) {
    auto it = t.header.find(k);
    if (it == t.header.end()) continue;
    double v;
    if (!parse_double(it->second, v) || !std::isfinite(v) || v < 0 || v > 1e9 || v != std::floor(v))
      throw InputError(path + ": header field " + std::string(k) + " = '" + it->second + "' is not a count");
    return static_cast<long>(v);
  }
  return -1;
}
}  // namespace

Table parse_sto(std::string_view text, const std::string& path) {
  const auto lines = lines_of(text);
  Table t;
  std::size_t li = read_sto_header(lines, t, path);
  while (li < lines.size() && trim(lines[li]).empty()) ++li;
  if (li >= lines.size()) throw InputError(path + ": no column labels after 'endheader'");
  for (const auto& s : split(lines[li], "\t", false)) {
    const std::string c = trim(s);
    if (!c.empty()) t.labels.push_back(c);
  }
  if (t.labels.size() <= 1) {
    t.labels.clear();
    for (const auto& s : split(lines[li], " \t", false)) t.labels.push_back(s);
  }
  const std::size_t label_line = li;
  const std::size_t ncol = t.labels.size();
  const long ncol_decl = header_count(t, "nColumns", "datacolumns", path);
  const long nrow_decl = header_count(t, "nRows", "datarows", path);
  if (ncol_decl >= 0 && static_cast<std::size_t>(ncol_decl) != ncol) {
    throw InputError(where(path, label_line) + ": header says " + std::to_string(ncol_decl) +
                     " columns but " + std::to_string(ncol) + " labels follow");
  }
  if (auto it = t.header.find("inDegrees"); it != t.header.end()) t.in_degrees = to_lower(it->second) == "yes";
  std::vector<double> values;
  long nrows = 0;
  for (++li; li < lines.size(); ++li) {
    if (trim(lines[li]).empty()) continue;
    const std::size_t at = values.size();
    values.resize(at + ncol);
    if (parse_plain_fields(lines[li], '\t', std::span<double>(values).subspan(at))) {  // the usual row
      ++nrows;
      continue;
    }
    values.resize(at);
    const auto cells = split(lines[li], " \t", false);
    if (cells.size() != ncol) {
      throw InputError(where(path, li) + ": " + std::to_string(cells.size()) + " values but " +
                       std::to_string(ncol) + " columns");
    }
    for (std::size_t c = 0; c < ncol; ++c) {
      double v;
      if (!parse_double(cells[c], v))
        throw InputError(where(path, li) + ": column " + t.labels[c] + " = '" + cells[c] + "' is not a number");
      values.push_back(v);
    }
    ++nrows;
  }
  if (nrow_decl >= 0 && nrow_decl != nrows) {
    // OpenSim's own example files have such headers (datarows 901 over 601 rows): the rows are
    // what the file holds; the header is noted, not trusted.
    t.warnings.push_back(path + ": header says " + std::to_string(nrow_decl) + " rows but " + std::to_string(nrows) +
                         " data rows follow; the rows are read");
  }
  t.data.resize(nrows, static_cast<Eigen::Index>(ncol));
  for (long r = 0; r < nrows; ++r)
    for (std::size_t c = 0; c < ncol; ++c) t.data(r, static_cast<Eigen::Index>(c)) = values[static_cast<std::size_t>(r) * ncol + c];
  return t;
}

std::string sto_header(const Table& t, Eigen::Index rows) {
  std::ostringstream os;
  os << (t.name.empty() ? "kin2grf" : t.name) << "\nversion=1\nnRows=" << rows
     << "\nnColumns=" << t.labels.size() << "\ninDegrees=" << (t.in_degrees ? "yes" : "no");
  for (const auto& [k, v] : t.header) {
    if (k == "version" || k == "nRows" || k == "nColumns" || k == "inDegrees") continue;
    os << "\n" << k << "=" << v;
  }
  os << "\nendheader\n";
  for (std::size_t c = 0; c < t.labels.size(); ++c) os << (c ? "\t" : "") << t.labels[c];
  os << "\n";
  return os.str();
}

void append_sto_row(std::string& out, std::span<const double> values) {
  // The numbers straight into the text (as fmt() writes them), not through a stream.
  char buf[64];
  for (std::size_t c = 0; c < values.size(); ++c) {
    if (c) out += '\t';
    const double v = values[c];
    if (!std::isfinite(v)) {
      out += "NaN";
      continue;
    }
    out.append(buf, std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 8).ptr);
  }
  out += '\n';
}

std::string format_sto(const Table& t) {
  std::string out = sto_header(t, t.data.rows());
  out.reserve(out.size() + static_cast<std::size_t>(t.data.size()) * 14);
  std::vector<double> row(static_cast<std::size_t>(t.data.cols()));
  for (Eigen::Index r = 0; r < t.data.rows(); ++r) {
    for (Eigen::Index c = 0; c < t.data.cols(); ++c) row[static_cast<std::size_t>(c)] = t.data(r, c);
    append_sto_row(out, row);
  }
  return out;
}

void write_sto(const std::string& path, const Table& t) { write_file_text(path, format_sto(t)); }

namespace {
/// One GRF column set: PREFIXground_force_SIDEv*, p*, and ground_torque_SIDE* when present.
struct GrfSet {
  std::string prefix, side;
};

/// The table's time column as a uniform grid (its rate and times into rec); refused when it does
/// not increase or strays by half a sample, noted when it deviates by rounding.
void grf_time_grid(const Table& t, const std::string& path, std::vector<std::string>& warnings, ForcePlateRecording& rec) {
  const Eigen::Index n = t.data.rows();
  const Eigen::VectorXd time = t.data.col(0);
  const double t0 = time[0];
  const double dt = (time[n - 1] - t0) / static_cast<double>(n - 1);
  if (!(dt > 0) || !std::isfinite(dt)) throw InputError(path + ": time column does not increase");
  double worst = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) worst = std::max(worst, std::abs(time[i] - (t0 + static_cast<double>(i) * dt)));
  if (worst > 0.5 * dt) {
    throw InputError(path + ": time column is not uniformly sampled (deviation " + fmt(worst) +
                     " s from a uniform grid of " + fmt(dt) + " s)");
  }
  if (worst > 1e-9 * std::max(1.0, std::abs(time[n - 1]))) {
    warnings.push_back("time column deviates up to " + fmt(worst * 1e3) +
                       " ms from a uniform grid (rounded times); using a uniform " + fmt(1.0 / dt) + " Hz grid");
  }
  rec.rate_hz = 1.0 / dt;
  rec.time_s.resize(n);
  for (Eigen::Index i = 0; i < n; ++i) rec.time_s[i] = t0 + static_cast<double>(i) * dt;
}

/// One column set as a plate without geometry (force, COP, free moment; a zero free moment, with
/// a warning, when the torque columns are absent).
ForcePlate grf_plate(const Table& t, const GrfSet& s, const std::string& path, std::vector<std::string>& warnings) {
  const Eigen::Index n = t.data.rows();
  ForcePlate fp;
  fp.name = s.prefix + "ground_force" + (s.side.empty() ? "" : "_" + s.side.substr(0, s.side.size() - 1));
  const std::string tag = to_lower(s.prefix + s.side);
  if (tag == "r_" || tag.rfind("r_", 0) == 0 || s.side == "r_") fp.side_hint = Side::Right;
  if (tag == "l_" || tag.rfind("l_", 0) == 0 || s.side == "l_") fp.side_hint = Side::Left;
  fp.force_N.resize(n, 3);
  fp.cop_m.resize(n, 3);
  fp.free_moment_Nm.resize(n, 3);
  fp.moment_centre_Nm = Eigen::MatrixX3d::Constant(n, 3, kNaN);
  bool has_torque = true;
  for (int a = 0; a < 3; ++a) {
    const std::string ax(1, "xyz"[a]);
    const int cv = t.column(s.prefix + "ground_force_" + s.side + "v" + ax);
    const int cp = t.column(s.prefix + "ground_force_" + s.side + "p" + ax);
    const int ct = t.column(s.prefix + "ground_torque_" + s.side + ax);
    if (cv < 0 || cp < 0) throw InputError(path + ": GRF column set '" + fp.name + "' lacks " + (cv < 0 ? "v" : "p") + ax);
    fp.force_N.col(a) = t.data.col(cv);
    fp.cop_m.col(a) = t.data.col(cp);
    if (ct < 0) has_torque = false;
    else fp.free_moment_Nm.col(a) = t.data.col(ct);
  }
  if (!has_torque) {
    fp.free_moment_Nm.setZero();
    warnings.push_back(fp.name + ": no ground_torque columns; free moment taken as zero");
  }
  if (!fp.force_N.allFinite()) throw InputError(path + ": GRF column set '" + fp.name + "' has NaN forces");
  return fp;
}

/// The vertical is OpenSim's Y, unless the forces say otherwise: a ground reaction is mostly
/// vertical (the body's weight against at most a third of it fore-aft), so the axis that carries
/// the most force, twice the next, is up (a .mot written in a Z-up lab's frame, e.g. kin2grf's
/// own -o from a C3D, had its COPs dropped as unloaded and its plates read sideways).
Eigen::Index grf_up_axis(const ForcePlateRecording& rec, Eigen::Index n, std::vector<std::string>& warnings) {
  Eigen::Vector3d load = Eigen::Vector3d::Zero();
  for (const auto& fp : rec.plates) load += fp.force_N.cwiseAbs().colwise().sum().transpose();
  Eigen::Index up = 1;
  const double most = load.maxCoeff(&up);
  double next = 0;
  for (Eigen::Index a = 0; a < 3; ++a)
    if (a != up) next = std::max(next, load[a]);
  if (!(most > 0) || most < 2 * next) up = 1;
  if (up != 1)
    warnings.push_back(std::string("up axis: the forces are largest along ") + "XYZ"[up] + " (" + fmt(most / static_cast<double>(n)) +
                       " N a sample against at most " + fmt(next / static_cast<double>(n)) + "), not OpenSim's Y: " + "XYZ"[up] +
                       " is taken as up");
  return up;
}

/// OpenSim's GRF is the force on the body: its vertical points up while a foot stands. A column
/// set whose load points down holds the force on the plate (another tool's convention); read as
/// it is, every stance was "never loaded": it is negated, with a warning. Then the COP and free
/// moment of unloaded samples become NaN.
void grf_orient_and_mask(ForcePlate& fp, const ForcePlateRecording& rec, Eigen::Index up, double cop_threshold_N,
                         const std::string& path, std::vector<std::string>& warnings) {
  const Eigen::Index n = fp.force_N.rows();
  double down = 0, upward = 0;
  Eigen::Index first = -1, last = -1;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double v = fp.force_N(i, up);
    if (std::abs(v) < cop_threshold_N) continue;
    (v < 0 ? down : upward) += std::abs(v);
    if (v < 0) last = i, first = first < 0 ? i : first;
  }
  if (down > 2 * upward && first >= 0) {
    fp.force_N = -fp.force_N;
    fp.free_moment_Nm = -fp.free_moment_Nm;
    warnings.push_back(path + ": " + fp.name + ": its vertical force points down (loaded from " + fmt(rec.time_s[first]) + " to " +
                       fmt(rec.time_s[last]) + " s): it is the force on the plate, not on the body as OpenSim's GRF files hold; " +
                       "read negated");
  }
  for (Eigen::Index i = 0; i < n; ++i) {
    if (std::abs(fp.force_N(i, up)) < cop_threshold_N) {
      fp.cop_m.row(i).setConstant(kNaN);  // stale or undefined COP of an unloaded plate
      fp.free_moment_Nm.row(i).setConstant(kNaN);
    }
  }
}
}  // namespace

std::optional<ForcePlateRecording> grf_from_table(const Table& t, const std::string& path,
                                                  double cop_threshold_N,
                                                  std::vector<std::string>& warnings) {
  // Labels PREFIXground_force_SIDEvx (OpenSim's convention, e.g. "ground_force_vx",
  // "1_ground_force_vx", "ground_force_1_vx"). Parsed by hand: a regex match recurses per
  // character and overflowed the stack on a 30 KB label.
  std::vector<GrfSet> sets;
  static const std::string key = "ground_force_";
  for (const auto& l : t.labels) {
    const std::size_t pos = l.rfind(key);
    if (pos == std::string::npos || l.size() < pos + key.size() + 2 || l.compare(l.size() - 2, 2, "vx") != 0) continue;
    sets.push_back({l.substr(0, pos), l.substr(pos + key.size(), l.size() - 2 - pos - key.size())});
  }
  if (sets.empty()) return std::nullopt;
  if (t.data.rows() < 2) throw InputError(path + ": a GRF table needs at least 2 rows");
  ForcePlateRecording rec;
  rec.cop_threshold_N = cop_threshold_N;
  grf_time_grid(t, path, warnings, rec);
  for (const auto& s : sets) rec.plates.push_back(grf_plate(t, s, path, warnings));
  const Eigen::Index up = grf_up_axis(rec, t.data.rows(), warnings);
  rec.up_axis = static_cast<Axis>(up);
  for (auto& fp : rec.plates) grf_orient_and_mask(fp, rec, up, cop_threshold_N, path, warnings);
  return rec;
}

std::vector<std::string> grf_labels() {
  std::vector<std::string> labels = {"time"};
  const char* ax = "xyz";
  for (const std::string prefix : {"", "1_"}) {
    for (int a = 0; a < 3; ++a) labels.push_back(prefix + "ground_force_v" + ax[a]);
    for (int a = 0; a < 3; ++a) labels.push_back(prefix + "ground_force_p" + ax[a]);
  }
  for (const std::string prefix : {"", "1_"})
    for (int a = 0; a < 3; ++a) labels.push_back(prefix + "ground_torque_" + ax[a]);
  return labels;
}

Table grf_table(const Eigen::VectorXd& time_s, const ForcePlate& right, const ForcePlate& left) {
  Table t;
  t.name = "kin2grf_grf";
  t.labels = grf_labels();
  const Eigen::Index n = time_s.size();
  t.data.resize(n, static_cast<Eigen::Index>(t.labels.size()));
  for (Eigen::Index i = 0; i < n; ++i) {
    Eigen::Index c = 0;
    t.data(i, c++) = time_s[i];
    for (const ForcePlate* p : {&right, &left}) {
      for (int a = 0; a < 3; ++a) t.data(i, c++) = p->force_N(i, a);
      for (int a = 0; a < 3; ++a) t.data(i, c++) = std::isfinite(p->cop_m(i, a)) ? p->cop_m(i, a) : 0.0;
    }
    for (const ForcePlate* p : {&right, &left})
      for (int a = 0; a < 3; ++a)
        t.data(i, c++) = std::isfinite(p->free_moment_Nm(i, a)) ? p->free_moment_Nm(i, a) : 0.0;
  }
  return t;
}

}  // namespace kin2grf
