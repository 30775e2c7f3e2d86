#include "probes/raw_csv.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>
#include <vector>

#include "core/errors.hpp"
#include "core/limits.hpp"

namespace tt::probes {
namespace {

const std::vector<std::string> raw_columns = {"reading", "time_s", "sample", "s1_um",
                                              "s2_um",   "s3_um",  "s4_um"};

std::string trimmed(const std::string& s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> out;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) out.push_back(trimmed(field));
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

bool parse_double(const std::string& s, double& v) {
  if (s.empty()) return false;
  const char* first = s.data();
  if (*first == '+') ++first;
  const auto [ptr, ec] = std::from_chars(first, s.data() + s.size(), v);
  return ec == std::errc() && ptr == s.data() + s.size() && std::isfinite(v);
}

bool parse_integer(const std::string& s, long long& v) {
  if (s.empty()) return false;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  return ec == std::errc() && ptr == s.data() + s.size();
}

std::string fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

struct FieldContext {
  const std::string& file;
  int line;
  const std::vector<std::string>& names;
};

std::string field_error(const FieldContext& c, std::size_t column, const std::string& value,
                        const std::string& expected) {
  return core::located(c.file, c.line,
                       "column " + std::to_string(column + 1) + " (" + c.names[column] + "): '" +
                           value + "' is not " + expected);
}

double number_field(const FieldContext& c, const std::vector<std::string>& f, std::size_t column,
                    const std::string& expected) {
  double v = 0.0;
  if (!parse_double(f[column], v))
    throw core::DataError(field_error(c, column, f[column], expected));
  return v;
}

long long integer_field(const FieldContext& c, const std::vector<std::string>& f,
                        std::size_t column, const std::string& expected) {
  long long v = 0;
  if (!parse_integer(f[column], v))
    throw core::DataError(field_error(c, column, f[column], expected));
  return v;
}

/// A constant from the header comment, with the line it came from.
struct HeaderValue {
  double value = 0.0;
  int line = 0;
};

double resolved_constant(const std::string& file, const std::string& key,
                         const std::map<std::string, HeaderValue>& header,
                         const std::optional<double>& given) {
  const auto it = header.find(key);
  if (it != header.end() && given &&
      std::abs(it->second.value - *given) > 1e-9 * std::max(1.0, std::abs(*given)))
    throw core::DataError(core::located(
        file, it->second.line,
        key + "=" + fmt("%.10g", it->second.value) + " in the header but " + fmt("%.10g", *given) +
            " given as an option: they must agree; drop one of them"));
  if (given) return *given;
  if (it != header.end()) return it->second.value;
  throw core::DataError(
      core::located(file, 0,
                    key + " is missing: add a header comment line such as '# speed_rpm=3000 "
                          "sample_rate_hz=10000 probe_distance_mm=150' or give it as an option"));
}

/// The whole file, refused beyond core::limits::kProbeFileBytes whatever it is (a device too).
std::string bounded_text(const std::filesystem::path& path, const std::string& what) {
  std::optional<std::string> text;
  try {
    text = core::limits::file_text_up_to(path, core::limits::kProbeFileBytes);
  } catch (const core::IoError&) {
    throw core::IoError(
        core::located(path.string(), 0, "cannot open the " + what + " for reading"));
  }
  if (!text)
    throw core::DataError(
        core::located(path.string(), 0,
                      "holds more than " + core::limits::bytes_text(core::limits::kProbeFileBytes) +
                          ", the limit for a " + what + "; split the recording"));
  return std::move(*text);
}

/// The known constants of one header comment line ('# speed_rpm=3000 sample_rate_hz=10000 ...'),
/// added to `header`; other tokens are free text. A constant given twice must agree.
void add_header_constants(const std::string& file, int line, const std::string& comment,
                          std::map<std::string, HeaderValue>& header) {
  std::string token;
  std::istringstream tokens(comment);
  while (tokens >> token) {
    while (!token.empty() && token.back() == ',') token.pop_back();
    const auto eq = token.find('=');
    if (eq == std::string::npos) continue;
    const std::string key = token.substr(0, eq);
    if (key != "speed_rpm" && key != "sample_rate_hz" && key != "probe_distance_mm") continue;
    HeaderValue hv{0.0, line};
    if (!parse_double(token.substr(eq + 1), hv.value) || !(hv.value > 0.0))
      throw core::DataError(core::located(
          file, line,
          key + "='" + token.substr(eq + 1) + "' in the header: expected a number > 0"));
    const auto seen = header.find(key);
    if (seen != header.end() && seen->second.value != hv.value)
      throw core::DataError(core::located(file, line,
                                          key +
                                              " given twice with different values (first on line " +
                                              std::to_string(seen->second.line) + "); keep one"));
    header[key] = hv;
  }
}

/// Refuses a column line other than reading,time_s,sample,s1_um..s4_um[,s5_um].
void check_column_line(const std::string& file, int line, const std::vector<std::string>& names) {
  const bool axial = names.size() == raw_columns.size() + 1;
  for (std::size_t c = 0; c < std::max(names.size(), raw_columns.size() + 1); ++c) {
    const std::string want = c < raw_columns.size() ? raw_columns[c] : "s5_um";
    const std::string got = c < names.size() ? names[c] : "";
    if ((c < raw_columns.size() || axial) && got != want)
      throw core::DataError(core::located(
          file, line,
          "column " + std::to_string(c + 1) + ": header '" + got + "', expected '" + want +
              "'; the column line must be reading,time_s,sample,s1_um,s2_um,s3_um,s4_um with "
              "an optional s5_um"));
    if (c >= raw_columns.size() && !axial && c < names.size())
      throw core::DataError(core::located(file, line,
                                          "column " + std::to_string(c + 1) +
                                              ": unexpected header '" + names[c] +
                                              "'; only s5_um may follow s4_um"));
  }
}

/// One data row as written in the file (displacements in µm).
struct RawRow {
  long long reading = 0;
  double time_s = 0.0;
  long long sample = 0;
  std::vector<double> values_um;
};

/// The fields of one data row, parsed; every field must match the column line.
RawRow raw_row(const FieldContext& ctx, const std::vector<std::string>& fields) {
  const std::vector<std::string>& names = ctx.names;
  if (fields.size() != names.size())
    throw core::DataError(core::located(
        ctx.file, ctx.line,
        "column " + std::to_string(std::min(fields.size(), names.size()) + 1) + ": " +
            std::to_string(fields.size()) + " fields, expected " + std::to_string(names.size()) +
            " (" + (names.size() > raw_columns.size() ? "s1_um..s5_um" : "s1_um..s4_um") + ")"));
  RawRow row;
  row.reading = integer_field(ctx, fields, 0, "an integer reading number");
  row.time_s = number_field(ctx, fields, 1, "a time in seconds");
  row.sample = integer_field(ctx, fields, 2, "an integer sample index");
  row.values_um.resize(names.size() - 3);
  for (std::size_t c = 3; c < names.size(); ++c)
    row.values_um[c - 3] = number_field(ctx, fields, c, "a displacement in µm");
  return row;
}

/// Gathers consecutive rows into readings: a reading's rows are together, its samples numbered
/// from 0, its start time on every row; reading numbers and start times increase.
class ReadingAssembler {
 public:
  void add(const FieldContext& ctx, const std::vector<std::string>& fields, RawRow row) {
    if (readings_.empty() || row.reading != reading_id_)
      start_reading(ctx, fields, row);
    else
      check_continues(ctx, fields, row);
    rows_.push_back(std::move(row.values_um));
    last_line_ = ctx.line;
  }

  /// The readings read, and the line of each one's last sample (for length errors).
  struct Finished {
    std::vector<Reading> readings;
    std::vector<int> last_lines;
  };
  Finished finished() && {
    close_reading();
    return {std::move(readings_), std::move(last_lines_)};
  }

 private:
  void start_reading(const FieldContext& ctx, const std::vector<std::string>& fields,
                     const RawRow& row) {
    if (!readings_.empty() && row.reading < reading_id_)
      throw core::DataError(
          field_error(ctx, 0, fields[0],
                      "after reading " + std::to_string(reading_id_) +
                          ": reading numbers must increase, each reading's rows together"));
    if (!readings_.empty() && !(row.time_s > readings_.back().start_time_s))
      throw core::DataError(field_error(ctx, 1, fields[1],
                                        "after the previous reading's start " +
                                            fmt("%.10g", readings_.back().start_time_s) +
                                            " s: reading start times must increase"));
    if (row.sample != 0)
      throw core::DataError(field_error(ctx, 2, fields[2], "0: every reading starts at sample 0"));
    close_reading();
    reading_id_ = row.reading;
    readings_.push_back(Reading{row.time_s, {}});
  }

  void check_continues(const FieldContext& ctx, const std::vector<std::string>& fields,
                       const RawRow& row) const {
    if (row.time_s != readings_.back().start_time_s)
      throw core::DataError(
          field_error(ctx, 1, fields[1],
                      fmt("%.10g", readings_.back().start_time_s) +
                          ": time_s is the reading's start time, the same on all its rows"));
    if (row.sample != static_cast<long long>(rows_.size()))
      throw core::DataError(
          field_error(ctx, 2, fields[2],
                      std::to_string(rows_.size()) + ": samples must be consecutive from 0"));
  }

  /// Moves the gathered rows (µm) into the last reading's sample matrix (m).
  void close_reading() {
    if (rows_.empty()) return;
    Reading& r = readings_.back();
    r.samples_m.resize(static_cast<Eigen::Index>(rows_.size()),
                       static_cast<Eigen::Index>(rows_.front().size()));
    for (std::size_t j = 0; j < rows_.size(); ++j)
      for (std::size_t p = 0; p < rows_[j].size(); ++p)
        r.samples_m(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(p)) =
            rows_[j][p] * 1e-6;
    last_lines_.push_back(last_line_);
    rows_.clear();
  }

  std::vector<Reading> readings_;
  std::vector<std::vector<double>> rows_;  // samples of the reading being read, µm
  long long reading_id_ = 0;
  int last_line_ = 0;
  std::vector<int> last_lines_;
};

/// The record's constants (SI) from the header comment and the options, which must agree.
void set_constants(const std::string& file, const std::map<std::string, HeaderValue>& header,
                   const RawCsvConstants& given, ProbeRecord& record) {
  record.speed_rev_per_s = resolved_constant(file, "speed_rpm", header, given.speed_rpm) / 60.0;
  record.sample_rate_hz = resolved_constant(file, "sample_rate_hz", header, given.sample_rate_hz);
  record.probe_distance_m =
      resolved_constant(file, "probe_distance_mm", header, given.probe_distance_mm) * 1e-3;
  for (double v : {record.speed_rev_per_s, record.sample_rate_hz, record.probe_distance_m})
    if (!(v > 0.0))
      throw core::DataError(
          core::located(file, 0, "speed_rpm, sample_rate_hz and probe_distance_mm must be > 0"));
}

/// Refuses a reading that does not cover more than one revolution: it may miss the reference
/// angle. `last_lines` holds the line of each reading's last sample.
void check_readings_cover_a_revolution(const std::string& file, const ProbeRecord& record,
                                       const std::vector<int>& last_lines) {
  const double per_rev = record.samples_per_revolution();
  for (std::size_t i = 0; i < record.readings.size(); ++i) {
    const auto n = static_cast<double>(record.readings[i].samples_m.rows());
    if (n <= per_rev)
      throw core::DataError(core::located(
          file, last_lines[i],
          "column 3 (sample): reading " + std::to_string(i + 1) + " ends after " + fmt("%.0f", n) +
              " samples = " + fmt("%.3g", n / per_rev) + " revolutions at " +
              fmt("%.6g", record.speed_rev_per_s * 60.0) + " rpm and " +
              fmt("%.6g", record.sample_rate_hz) +
              " Hz: every reading must cover more than one revolution (> " + fmt("%.6g", per_rev) +
              " samples) so that it contains the reference angle; record longer readings"));
  }
}

}  // namespace

ProbeRecord read_raw_csv(const std::filesystem::path& path, const RawCsvConstants& given) {
  const std::string file = path.string();
  std::istringstream in(bounded_text(path, "raw probe CSV"));

  std::map<std::string, HeaderValue> header;
  std::vector<std::string> names;
  ReadingAssembler readings;
  std::string raw_line;
  int line = 0;
  while (std::getline(in, raw_line)) {
    ++line;
    const std::string text = trimmed(raw_line);
    if (text.empty()) continue;
    if (text.front() == '#') {
      add_header_constants(file, line, text.substr(1), header);
    } else if (names.empty()) {
      names = split_fields(text);
      check_column_line(file, line, names);
    } else {
      const std::vector<std::string> fields = split_fields(text);
      const FieldContext ctx{file, line, names};
      readings.add(ctx, fields, raw_row(ctx, fields));
    }
  }
  auto assembled = std::move(readings).finished();
  ProbeRecord record;
  record.readings = std::move(assembled.readings);
  if (names.empty())
    throw core::DataError(core::located(file, line, "no column line: the file holds no data"));
  if (record.readings.empty())
    throw core::DataError(core::located(file, line, "no readings after the column line"));
  set_constants(file, header, given, record);
  check_readings_cover_a_revolution(file, record, assembled.last_lines);
  return record;
}

std::string raw_csv_text(const ProbeRecord& record) {
  const bool axial = record.has_axial_probe();
  std::string out;
  out += "# thermotwin probe raw v1: s1,s2 read Y at planes 1,2; s3,s4 read X at planes 1,2";
  out += axial ? "; s5 reads Z\n" : "\n";
  out += "# speed_rpm=" + fmt("%.10g", record.speed_rev_per_s * 60.0) +
         " sample_rate_hz=" + fmt("%.10g", record.sample_rate_hz) +
         " probe_distance_mm=" + fmt("%.10g", record.probe_distance_m * 1e3) + "\n";
  out += "reading,time_s,sample,s1_um,s2_um,s3_um,s4_um";
  out += axial ? ",s5_um\n" : "\n";
  char buf[64];
  for (std::size_t i = 0; i < record.readings.size(); ++i) {
    const Reading& r = record.readings[i];
    const std::string prefix = std::to_string(i + 1) + "," + fmt("%.10g", r.start_time_s) + ",";
    for (Eigen::Index j = 0; j < r.samples_m.rows(); ++j) {
      out += prefix;
      out += std::to_string(j);
      for (Eigen::Index p = 0; p < r.samples_m.cols(); ++p) {
        std::snprintf(buf, sizeof buf, ",%.6f", r.samples_m(j, p) * 1e6);
        out += buf;
      }
      out += '\n';
    }
  }
  return out;
}

std::string drift_csv_text(const DriftSeries& series) {
  std::string out = "time_s,x1_um,y1_um,x2_um,y2_um,tilt_x_urad,tilt_y_urad";
  out += series.has_axial ? ",z_um\n" : "\n";
  char buf[256];
  for (const DriftPoint& p : series.points) {
    std::snprintf(buf, sizeof buf, "%.10g,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f", p.time_s,
                  p.drift.x1_m * 1e6, p.drift.y1_m * 1e6, p.drift.x2_m * 1e6, p.drift.y2_m * 1e6,
                  p.tilt_x_rad * 1e6, p.tilt_y_rad * 1e6);
    out += buf;
    if (series.has_axial) {
      std::snprintf(buf, sizeof buf, ",%.6f", p.drift.z_m * 1e6);
      out += buf;
    }
    out += '\n';
  }
  return out;
}

DriftHistory read_drift_history_csv(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::istringstream in(bounded_text(path, "drift history CSV"));
  std::vector<std::string> names;
  std::map<std::string, std::size_t> column;
  DriftHistory out;
  std::string raw_line;
  int line = 0;
  while (std::getline(in, raw_line)) {
    ++line;
    const std::string text = trimmed(raw_line);
    if (text.empty() || text.front() == '#') continue;
    const std::vector<std::string> fields = split_fields(text);
    if (names.empty()) {
      names = fields;
      for (std::size_t c = 0; c < names.size(); ++c) column[names[c]] = c;
      for (const char* need : {"time_s", "x1_um", "y1_um", "x2_um", "y2_um"})
        if (!column.count(need))
          throw core::DataError(
              core::located(file, line,
                            std::string("no column '") + need +
                                "': a drift history needs time_s,x1_um,y1_um,x2_um,y2_um "
                                "(z_um optional)"));
      continue;
    }
    if (fields.size() != names.size())
      throw core::DataError(core::located(
          file, line,
          "column " + std::to_string(std::min(fields.size(), names.size()) + 1) + ": " +
              std::to_string(fields.size()) + " fields, expected " + std::to_string(names.size())));
    const FieldContext ctx{file, line, names};
    DriftSample s;
    s.time_s = number_field(ctx, fields, column["time_s"], "a time in seconds");
    s.drift.x1_m = number_field(ctx, fields, column["x1_um"], "a displacement in µm") * 1e-6;
    s.drift.y1_m = number_field(ctx, fields, column["y1_um"], "a displacement in µm") * 1e-6;
    s.drift.x2_m = number_field(ctx, fields, column["x2_um"], "a displacement in µm") * 1e-6;
    s.drift.y2_m = number_field(ctx, fields, column["y2_um"], "a displacement in µm") * 1e-6;
    if (column.count("z_um"))
      s.drift.z_m = number_field(ctx, fields, column["z_um"], "a displacement in µm") * 1e-6;
    if (!out.empty() && !(s.time_s > out.back().time_s))
      throw core::DataError(
          field_error(ctx, column["time_s"], fields[column["time_s"]],
                      "after " + fmt("%.10g", out.back().time_s) + ": times must increase"));
    out.push_back(s);
  }
  if (out.empty())
    throw core::DataError(
        core::located(file, line, "no drift samples: the file holds no data rows"));
  return out;
}

void write_text_atomically(const std::filesystem::path& file, const std::string& text) {
  std::filesystem::path partial = file;
  partial += ".partial";
  {
    std::ofstream out(partial, std::ios::binary | std::ios::trunc);
    if (!out) throw core::IoError(core::located(partial.string(), 0, "cannot open for writing"));
    out << text;
    out.flush();
    if (!out) throw core::IoError(core::located(partial.string(), 0, "write failed (disk full?)"));
  }
  std::error_code ec;
  std::filesystem::rename(partial, file, ec);
  if (ec)
    throw core::IoError(
        core::located(file.string(), 0, "cannot rename " + partial.string() + ": " + ec.message()));
}

}  // namespace tt::probes
