#include "io/measured_data.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>

#include "core/csv_cells.hpp"
#include "core/errors.hpp"
#include "core/limits.hpp"
#include "core/units.hpp"
#include "io/atomic_dir.hpp"

namespace tt::io {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kFormat = "thermal-measurement/1";

/// What a data.csv column holds, once the header has been matched against meta.json.
enum class ColumnRole { time, input, sensor, probe };

struct ColumnSlot {
  ColumnRole role = ColumnRole::time;
  int index = 0;  /// into inputs, sensors or displacements
};

[[noreturn]] void meta_error(const fs::path& file, const std::string& key,
                             const std::string& message) {
  throw core::DataError(core::located(file.string(), 0, "key " + key + ": " + message));
}

std::string json_text(const json& value) {
  const std::string text = value.dump();
  return text.size() > 60 ? text.substr(0, 57) + "..." : text;
}

const json& required_key(const fs::path& file, const json& object, const std::string& key,
                         const std::string& path) {
  const auto it = object.find(key);
  if (it == object.end())
    meta_error(file, path, "missing: expected it (see docs/measured-data.md)");
  return *it;
}

std::string string_value(const fs::path& file, const json& value, const std::string& key) {
  if (!value.is_string()) meta_error(file, key, json_text(value) + " is not a string");
  return value.get<std::string>();
}

/// A string unit key that must equal the one unit the format allows.
void require_unit(const fs::path& file, const json& meta, const std::string& key,
                  const std::string& expected) {
  const std::string unit = string_value(file, required_key(file, meta, key, key), key);
  if (unit != expected)
    meta_error(file, key,
               "unknown unit '" + unit + "': expected '" + expected +
                   "' (values are converted before they are written in this format)");
}

std::optional<double> optional_number(const fs::path& file, const json& meta,
                                      const std::string& key) {
  const auto it = meta.find(key);
  if (it == meta.end() || it->is_null()) return std::nullopt;
  if (!it->is_number() || !std::isfinite(it->get<double>()))
    meta_error(file, key, json_text(*it) + ": expected a finite number or null");
  return it->get<double>();
}

/// A temperature in degC, not below absolute zero, or nothing for null.
std::optional<double> optional_temperature(const fs::path& file, const json& meta,
                                           const std::string& key) {
  const auto t = optional_number(file, meta, key);
  if (t && *t < core::limits::kAbsoluteZeroDegC)
    meta_error(file, key, json_text(meta[key]) + ": below absolute zero (-273.15 degC)");
  return t;
}

/// A [x, y, z] triple, or nothing for null.
std::optional<Eigen::Vector3d> optional_vector(const fs::path& file, const json& object,
                                               const std::string& key, const std::string& path) {
  const auto it = object.find(key);
  if (it == object.end() || it->is_null()) return std::nullopt;
  if (!it->is_array() || it->size() != 3)
    meta_error(file, path, json_text(*it) + ": expected [x, y, z] in metres or null");
  Eigen::Vector3d v;
  for (int i = 0; i < 3; ++i) {
    const json& c = (*it)[static_cast<std::size_t>(i)];
    if (!c.is_number() || !std::isfinite(c.get<double>()))
      meta_error(file, path,
                 json_text(*it) + ": component " + std::to_string(i) + " is not a finite number");
    v(i) = c.get<double>();
  }
  return v;
}

/// {"min": [x, y, z], "max": [x, y, z]} in metres with min <= max, or nothing when absent or null.
std::optional<Eigen::AlignedBox3d> optional_box(const fs::path& file, const json& meta,
                                                const std::string& key) {
  const auto it = meta.find(key);
  if (it == meta.end() || it->is_null()) return std::nullopt;
  if (!it->is_object() || !it->contains("min") || !it->contains("max"))
    meta_error(file, key, json_text(*it) + ": expected {\"min\": [x, y, z], \"max\": [x, y, z]}");
  const auto lo = optional_vector(file, *it, "min", key + ".min");
  const auto hi = optional_vector(file, *it, "max", key + ".max");
  if (!lo || !hi || !(lo->array() <= hi->array()).all())
    meta_error(file, key, json_text(*it) + ": min must be at most max in every coordinate");
  return Eigen::AlignedBox3d(*lo, *hi);
}

void require_inside(const fs::path& file, const std::optional<Eigen::AlignedBox3d>& box,
                    const std::optional<Eigen::Vector3d>& p, const std::string& path,
                    const std::string& machine) {
  if (!box || !p) return;
  constexpr double slack = 1e-9;  // points on the box faces are inside
  if ((p->array() >= box->min().array() - slack).all() &&
      (p->array() <= box->max().array() + slack).all())
    return;
  char text[256];
  std::snprintf(text, sizeof text,
                "position (%g, %g, %g) m is outside machine %s's bounding box x in [%g, %g], y in "
                "[%g, %g], z in "
                "[%g, %g] m; hint: positions are in metres in the machine's frame",
                (*p)(0), (*p)(1), (*p)(2), machine.c_str(), box->min()(0), box->max()(0),
                box->min()(1), box->max()(1), box->min()(2), box->max()(2));
  meta_error(file, path, text);
}

const json& id_list(const fs::path& file, const json& meta, const std::string& key, bool required) {
  static const json empty = json::array();
  const auto it = meta.find(key);
  if (it == meta.end()) {
    if (required) meta_error(file, key, "missing: expected a list of {\"id\": ...} objects");
    return empty;
  }
  if (!it->is_array())
    meta_error(file, key, json_text(*it) + ": expected a list of {\"id\": ...} objects");
  return *it;
}

std::string item_id(const fs::path& file, const json& item, const std::string& path) {
  if (!item.is_object())
    meta_error(file, path, json_text(item) + ": expected an object with an \"id\"");
  const std::string id =
      string_value(file, required_key(file, item, "id", path + ".id"), path + ".id");
  if (id.empty() || id.find_first_of(",\"\r\n") != std::string::npos || id == "time_s")
    meta_error(file, path + ".id", "'" + id + "' cannot name a data.csv column");
  return id;
}

/// An object of finite numbers keyed by displacement ids [um].
std::map<std::string, double> mae_table(const fs::path& file, const json& object,
                                        const std::string& path, const MeasuredRun& run) {
  if (!object.is_object())
    meta_error(file, path, json_text(object) + ": expected {\"<displacement id>\": MAE in um}");
  std::map<std::string, double> table;
  for (const auto& [id, value] : object.items()) {
    bool known = false;
    for (const auto& p : run.displacements) known = known || p.id == id;
    if (!known) meta_error(file, path + "." + id, "'" + id + "' is not the id of a displacement");
    if (!value.is_number() || !std::isfinite(value.get<double>()) || value.get<double>() < 0)
      meta_error(file, path + "." + id, json_text(value) + ": expected a number >= 0 [um]");
    table[id] = value.get<double>();
  }
  return table;
}

/// meta.json's `published`, or nothing when absent or null.
std::optional<PublishedFigure> published_figure(const fs::path& file, const json& meta,
                                                const MeasuredRun& run) {
  const auto it = meta.find("published");
  if (it == meta.end() || it->is_null()) return std::nullopt;
  if (!it->is_object()) meta_error(file, "published", json_text(*it) + ": expected an object");
  const json& p = *it;
  PublishedFigure f;
  f.model =
      string_value(file, required_key(file, p, "model", "published.model"), "published.model");
  f.source =
      string_value(file, required_key(file, p, "source", "published.source"), "published.source");
  if (p.contains("note")) f.note = string_value(file, p["note"], "published.note");
  const json& window = required_key(file, p, "test_window_s", "published.test_window_s");
  if (!window.is_array() || window.size() != 2 || !window[0].is_number() ||
      !window[1].is_number() || !(window[0].get<double>() < window[1].get<double>()))
    meta_error(file, "published.test_window_s",
               json_text(window) + ": expected [from, to] in seconds with from < to");
  f.from_s = window[0].get<double>();
  f.to_s = window[1].get<double>();
  f.mae_um =
      mae_table(file, required_key(file, p, "mae_um", "published.mae_um"), "published.mae_um", run);
  if (const auto o = p.find("others_mae_um"); o != p.end()) {
    if (!o->is_object())
      meta_error(file, "published.others_mae_um",
                 json_text(*o) + ": expected {\"<model>\": {\"<displacement id>\": MAE}}");
    for (const auto& [model, table] : o->items())
      f.others_mae_um[model] = mae_table(file, table, "published.others_mae_um." + model, run);
  }
  return f;
}

/// meta.json parsed; it must be a JSON object.
json parsed_meta(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in)
    throw core::IoError(file.string() +
                        ": cannot open for reading; expected meta.json beside data.csv");
  json meta;
  try {
    meta = json::parse(in);
  } catch (const json::exception& e) {
    // parse_error, and out_of_range for numbers too large for a double (found by fuzzing).
    throw core::DataError(
        core::located(file.string(), 0, std::string("not valid JSON: ") + e.what()));
  }
  if (!meta.is_object())
    throw core::DataError(core::located(file.string(), 0, "expected a JSON object"));
  return meta;
}

/// The column ids met so far: inputs, sensors and displacements share one name space.
class ColumnIds {
 public:
  explicit ColumnIds(const fs::path& file) : file_(file) {}
  void add(const std::string& id, const std::string& path) {
    if (!ids_.insert(id).second)
      meta_error(file_, path, "id '" + id + "' is used twice; every column id must be unique");
  }

 private:
  const fs::path& file_;
  std::set<std::string> ids_;
};

/// meta.json's inputs: ids of speed columns in rpm.
std::vector<std::string> meta_inputs(const fs::path& file, const json& meta, ColumnIds& ids) {
  std::vector<std::string> out;
  const json& inputs = id_list(file, meta, "inputs", false);
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    const std::string path = "inputs[" + std::to_string(i) + "]";
    const std::string id = item_id(file, inputs[i], path);
    ids.add(id, path + ".id");
    const std::string unit =
        string_value(file, required_key(file, inputs[i], "unit", path + ".unit"), path + ".unit");
    if (unit != "rpm")
      meta_error(file, path + ".unit", "unknown unit '" + unit + "': expected 'rpm'");
    out.push_back(id);
  }
  return out;
}

/// meta.json's sensors; a position must lie in `box` when there is one.
std::vector<MeasuredSensor> meta_sensors(const fs::path& file, const json& meta,
                                         const std::optional<Eigen::AlignedBox3d>& box,
                                         const std::string& machine, ColumnIds& ids) {
  std::vector<MeasuredSensor> out;
  const json& sensors = id_list(file, meta, "sensors", true);
  for (std::size_t i = 0; i < sensors.size(); ++i) {
    const std::string path = "sensors[" + std::to_string(i) + "]";
    MeasuredSensor s;
    s.id = item_id(file, sensors[i], path);
    ids.add(s.id, path + ".id");
    s.position = optional_vector(file, sensors[i], "position", path + ".position");
    require_inside(file, box, s.position, path + ".position", machine);
    out.push_back(std::move(s));
  }
  return out;
}

/// meta.json's displacements; a point must lie in `box`, a direction becomes a unit vector.
std::vector<MeasuredProbe> meta_probes(const fs::path& file, const json& meta,
                                       const std::optional<Eigen::AlignedBox3d>& box,
                                       const std::string& machine, ColumnIds& ids) {
  std::vector<MeasuredProbe> out;
  const json& probes = id_list(file, meta, "displacements", true);
  for (std::size_t i = 0; i < probes.size(); ++i) {
    const std::string path = "displacements[" + std::to_string(i) + "]";
    MeasuredProbe p;
    p.id = item_id(file, probes[i], path);
    ids.add(p.id, path + ".id");
    p.point = optional_vector(file, probes[i], "point", path + ".point");
    require_inside(file, box, p.point, path + ".point", machine);
    p.direction = optional_vector(file, probes[i], "direction", path + ".direction");
    if (p.direction) {
      const double norm = p.direction->norm();
      if (!(norm > 0)) meta_error(file, path + ".direction", "[0, 0, 0]: expected a unit vector");
      *p.direction /= norm;
    }
    out.push_back(std::move(p));
  }
  return out;
}

/// meta.json's ambient_sensor, when given (not null): the id of one of `sensors`.
std::optional<std::string> meta_ambient_sensor(const fs::path& file, const json& meta,
                                               const std::vector<MeasuredSensor>& sensors) {
  const auto it = meta.find("ambient_sensor");
  if (it == meta.end() || it->is_null()) return std::nullopt;
  const std::string id = string_value(file, *it, "ambient_sensor");
  bool found = false;
  for (const auto& s : sensors) found = found || s.id == id;
  if (!found) meta_error(file, "ambient_sensor", "'" + id + "' is not the id of one of sensors");
  return id;
}

/// meta.json as a run with no samples yet.
MeasuredRun run_from_meta(const fs::path& file, const MeasuredReadLimits& limits) {
  json meta = parsed_meta(file);
  MeasuredRun run;
  run.folder = file.parent_path();
  const std::string format =
      string_value(file, required_key(file, meta, "format", "format"), "format");
  if (format != kFormat)
    meta_error(file, "format", "unknown format '" + format + "': expected '" + kFormat + "'");
  run.machine = string_value(file, required_key(file, meta, "machine", "machine"), "machine");
  // The machine's bounding box, when the data carry it; the caller's box checks in its place.
  run.machine_box = optional_box(file, meta, "machine_box_m");
  const std::optional<Eigen::AlignedBox3d> box =
      limits.machine_box ? limits.machine_box : run.machine_box;
  if (meta.contains("run")) run.run = string_value(file, meta["run"], "run");
  require_unit(file, meta, "time_unit", "s");
  require_unit(file, meta, "temperature_unit", "degC");
  require_unit(file, meta, "displacement_unit", "um");
  run.initial_temperature_c = optional_temperature(file, meta, "initial_temperature_degC");
  run.nominal_ambient_c = optional_temperature(file, meta, "nominal_ambient_degC");

  ColumnIds ids(file);
  run.inputs = meta_inputs(file, meta, ids);
  run.sensors = meta_sensors(file, meta, box, run.machine, ids);
  run.displacements = meta_probes(file, meta, box, run.machine, ids);
  run.ambient_sensor = meta_ambient_sensor(file, meta, run.sensors);
  run.published = published_figure(file, meta, run);
  run.meta = std::move(meta);
  return run;
}

/// Streams data.csv line by line through a fixed buffer, so memory holds one chunk and the values.
class LineReader {
 public:
  explicit LineReader(const fs::path& file)
      : in_(file, std::ios::binary), buffer_(std::size_t(1) << 20) {}
  bool is_open() const { return static_cast<bool>(in_); }

  /// The next line without its end, or false at the end of the file.
  bool next(std::string_view& line) {
    while (true) {
      const auto newline = std::string_view(buffer_.data() + begin_, end_ - begin_).find('\n');
      if (newline != std::string_view::npos) {
        line = std::string_view(buffer_.data() + begin_, newline);
        begin_ += newline + 1;
        ++number_;
        return true;
      }
      if (eof_) {
        if (begin_ == end_) return false;
        line = std::string_view(buffer_.data() + begin_, end_ - begin_);
        begin_ = end_;
        ++number_;
        return true;
      }
      refill();
    }
  }
  int line_number() const { return number_; }

 private:
  void refill() {
    const std::size_t rest = end_ - begin_;
    if (begin_ > 0) std::copy(buffer_.begin() + begin_, buffer_.begin() + end_, buffer_.begin());
    begin_ = 0;
    end_ = rest;
    if (end_ == buffer_.size())
      buffer_.resize(buffer_.size() * 2);  // a line longer than the buffer
    in_.read(buffer_.data() + end_, static_cast<std::streamsize>(buffer_.size() - end_));
    end_ += static_cast<std::size_t>(in_.gcount());
    if (!in_) eof_ = true;
  }

  std::ifstream in_;
  std::vector<char> buffer_;
  std::size_t begin_ = 0, end_ = 0;
  bool eof_ = false;
  int number_ = 0;
};

std::string cell_text(std::string_view cell) {
  return cell.size() > 40 ? std::string(cell.substr(0, 37)) + "..." : std::string(cell);
}

/// The header's columns matched against meta.json's ids; every rejection names the column.
std::vector<ColumnSlot> header_slots(const fs::path& file, std::string_view line,
                                     const MeasuredRun& run, std::vector<std::string>& names) {
  line = core::without_byte_order_mark(line);
  std::map<std::string, ColumnSlot, std::less<>> expected{{"time_s", {ColumnRole::time, 0}}};
  for (std::size_t i = 0; i < run.inputs.size(); ++i)
    expected[run.inputs[i]] = {ColumnRole::input, static_cast<int>(i)};
  for (std::size_t i = 0; i < run.sensors.size(); ++i)
    expected[run.sensors[i].id] = {ColumnRole::sensor, static_cast<int>(i)};
  for (std::size_t i = 0; i < run.displacements.size(); ++i)
    expected[run.displacements[i].id] = {ColumnRole::probe, static_cast<int>(i)};
  std::vector<ColumnSlot> slots;
  std::map<std::string, int> seen;
  for (std::size_t at = 0; at != std::string_view::npos;) {
    const std::string name(core::next_cell(line, at));
    const int column = static_cast<int>(slots.size()) + 1;
    const std::string where = "column " + std::to_string(column) + " '" + name + "'";
    if (const auto it = seen.find(name); it != seen.end())
      throw core::DataError(core::located(file.string(), 1,
                                          where + ": duplicated column (also column " +
                                              std::to_string(it->second) +
                                              "); every id appears once"));
    const auto it = expected.find(name);
    if (it == expected.end())
      throw core::DataError(core::located(
          file.string(), 1,
          where + ": unknown column; expected time_s or an id of inputs, sensors or displacements "
                  "in meta.json"));
    if (column == 1 && it->second.role != ColumnRole::time)
      throw core::DataError(
          core::located(file.string(), 1, where + ": the first column must be time_s"));
    if (column > 1 && it->second.role == ColumnRole::time)
      throw core::DataError(
          core::located(file.string(), 1, where + ": time_s must be the first column"));
    seen[name] = column;
    slots.push_back(it->second);
    names.push_back(name);
  }
  for (const auto& [name, slot] : expected)
    if (!seen.contains(name))
      throw core::DataError(core::located(
          file.string(), 1, "missing column '" + name + "': every id of meta.json needs a column"));
  return slots;
}

/// data.csv's size, refused beyond limits.max_bytes.
std::uintmax_t checked_size(const fs::path& file, const MeasuredReadLimits& limits) {
  std::error_code ec;
  const auto bytes = fs::file_size(file, ec);
  if (ec) throw core::IoError(file.string() + ": cannot read: " + ec.message());
  if (bytes > limits.max_bytes)
    throw core::DataError(
        core::located(file.string(), 0,
                      "file size " + std::to_string(bytes) + " bytes exceeds the limit of " +
                          std::to_string(limits.max_bytes) + " bytes; raise max_bytes to read it"));
  return bytes;
}

/// The header of data.csv as matched by header_slots: each column's role and name.
struct Columns {
  std::vector<ColumnSlot> slots;
  std::vector<std::string> names;
};

/// One cell's value in the file's unit; an empty cell is a missing reading (NaN), except a time.
double cell_value(const fs::path& file, int number, const std::string& where, std::string_view cell,
                  ColumnRole role, bool first_column) {
  double value = std::numeric_limits<double>::quiet_NaN();
  if (!cell.empty()) {
    const std::optional<double> parsed = core::cell_number(cell);
    if (!parsed)
      throw core::DataError(core::located(file.string(), number,
                                          where + ": '" + cell_text(cell) + "' is not a number"));
    value = *parsed;
    if (!std::isfinite(value))
      throw core::DataError(
          core::located(file.string(), number,
                        where + ": '" + cell_text(cell) +
                            "' is not a finite number; leave the cell empty for a missing "
                            "reading"));
    if (role == ColumnRole::sensor && value < core::limits::kAbsoluteZeroDegC)
      throw core::DataError(core::located(
          file.string(), number,
          where + ": " + cell_text(cell) +
              " degC is below absolute zero (-273.15 degC); temperatures are in degC"));
  } else if (first_column) {
    throw core::DataError(
        core::located(file.string(), number, where + ": empty time; every row needs one"));
  }
  return value;
}

/// Appends the cells of data row `line` (line `number`) to `values`; its time must exceed
/// `last_time`, which becomes it.
void append_row(const fs::path& file, int number, std::string_view line, const Columns& header,
                double& last_time, std::vector<double>& values) {
  const std::size_t columns = header.slots.size();
  std::size_t column = 0;
  for (std::size_t at = 0; at != std::string_view::npos;) {
    if (column >= columns)
      throw core::DataError(core::located(file.string(), number,
                                          "column " + std::to_string(column + 1) +
                                              ": more cells than the " + std::to_string(columns) +
                                              " columns of the header"));
    const std::string_view cell = core::next_cell(line, at);
    const std::string where =
        "column " + std::to_string(column + 1) + " '" + header.names[column] + "'";
    const double value =
        cell_value(file, number, where, cell, header.slots[column].role, column == 0);
    if (column == 0) {
      if (!(value > last_time)) {
        char text[160];
        std::snprintf(text, sizeof text,
                      "%s: time %.17g s does not increase (previous row: %.17g s)", where.c_str(),
                      value, last_time);
        throw core::DataError(core::located(file.string(), number, text));
      }
      last_time = value;
    }
    values.push_back(value);
    ++column;
  }
  if (column != columns)
    throw core::DataError(core::located(file.string(), number,
                                        "column " + std::to_string(column + 1) + ": row has " +
                                            std::to_string(column) + " cells: expected " +
                                            std::to_string(columns)));
}

/// Row-major `values` in the file's columns into run's matrices, converted to SI.
void fill_samples(const std::vector<double>& values, std::size_t rows,
                  const std::vector<ColumnSlot>& slots, MeasuredRun& run) {
  const std::size_t columns = slots.size();
  const auto n = static_cast<Eigen::Index>(rows);
  run.time.resize(n);
  run.input_values.resize(n, static_cast<Eigen::Index>(run.inputs.size()));
  run.temperature.resize(n, static_cast<Eigen::Index>(run.sensors.size()));
  run.displacement.resize(n, static_cast<Eigen::Index>(run.displacements.size()));
  for (std::size_t c = 0; c < columns; ++c) {
    const ColumnSlot slot = slots[c];
    for (Eigen::Index r = 0; r < n; ++r) {
      const double v = values[static_cast<std::size_t>(r) * columns + c];
      switch (slot.role) {
        case ColumnRole::time:
          run.time(r) = v;
          break;
        case ColumnRole::input:
          run.input_values(r, slot.index) = v;
          break;
        case ColumnRole::sensor:
          run.temperature(r, slot.index) = v + core::kCelsiusOffset;
          break;
        case ColumnRole::probe:
          run.displacement(r, slot.index) = v * core::kMetresPerMicrometre;
          break;
      }
    }
  }
}

/// data.csv into run's matrices, converted to SI.
void read_samples(const fs::path& file, const MeasuredReadLimits& limits, MeasuredRun& run) {
  const auto bytes = checked_size(file, limits);
  LineReader reader(file);
  if (!reader.is_open()) throw core::IoError(file.string() + ": cannot open for reading");
  std::string_view line;
  if (!reader.next(line))
    throw core::DataError(
        core::located(file.string(), 1, "empty file: expected a header row starting with time_s"));
  Columns header;
  header.slots = header_slots(file, line, run, header.names);
  // Row-major values in the file's column order; reshaped once at the end.
  std::vector<double> values;
  values.reserve(std::min<std::size_t>(bytes / 4, std::size_t(1) << 26));
  std::size_t rows = 0;
  double last_time = -std::numeric_limits<double>::infinity();
  while (reader.next(line)) {
    if (core::trimmed(line).empty()) continue;
    const int number = reader.line_number();
    if (++rows > limits.max_rows)
      throw core::DataError(core::located(file.string(), number,
                                          "more than " + std::to_string(limits.max_rows) +
                                              " rows; raise max_rows to read this file"));
    append_row(file, number, line, header, last_time, values);
  }
  fill_samples(values, rows, header.slots, run);
}

json vector_json(const std::optional<Eigen::Vector3d>& v) {
  if (!v) return nullptr;
  return json::array({(*v)(0), (*v)(1), (*v)(2)});
}

/// Shortest text that reads back to the same double; empty for NaN (a missing reading).
void append_number(std::string& out, double value) {
  if (std::isnan(value)) return;
  char text[32];
  const auto result = std::to_chars(text, text + sizeof text, value);
  out.append(text, result.ptr);
}

void require_shape(const MeasuredRun& run) {
  const Eigen::Index n = run.time.size();
  const auto bad = [&](const std::string& what, Eigen::Index rows, Eigen::Index cols,
                       std::size_t expected) {
    if (rows != n || cols != static_cast<Eigen::Index>(expected))
      throw core::DataError("write_measured_run: " + what + " is " + std::to_string(rows) + " x " +
                            std::to_string(cols) + ": expected " + std::to_string(n) + " x " +
                            std::to_string(expected) + " (#samples x #ids)");
  };
  bad("input_values", run.input_values.rows(), run.input_values.cols(), run.inputs.size());
  bad("temperature", run.temperature.rows(), run.temperature.cols(), run.sensors.size());
  bad("displacement", run.displacement.rows(), run.displacement.cols(), run.displacements.size());
  for (Eigen::Index i = 0; i < n; ++i)
    if (!std::isfinite(run.time(i)) || (i > 0 && !(run.time(i) > run.time(i - 1))))
      throw core::DataError("write_measured_run: time[" + std::to_string(i) +
                            "] = " + std::to_string(run.time(i)) +
                            " s: times must be finite and strictly increasing");
}

/// A run's file must be a regular file: a folder of that name would fail deep in the stream
/// library with a message that names no file.
void require_regular_file(const fs::path& file) {
  std::error_code ec;
  const fs::file_status st = fs::status(file, ec);
  if (fs::exists(st) && !fs::is_regular_file(st))
    throw core::DataError(
        file.string() + ": " + (fs::is_directory(st) ? "a folder" : "not a regular file") +
        ": expected the run's " + file.filename().string() + " file (docs/measured-data.md)");
}

}  // namespace

bool same_run(const fs::path& a, const fs::path& b) {
  std::error_code ea, eb;
  const fs::path ra = fs::weakly_canonical(fs::absolute(a), ea);
  const fs::path rb = fs::weakly_canonical(fs::absolute(b), eb);
  if (ea || eb) return fs::absolute(a).lexically_normal() == fs::absolute(b).lexically_normal();
  return (ra / "").lexically_normal() == (rb / "").lexically_normal();
}

void require_distinct_runs(const std::vector<fs::path>& folders, const std::string& option) {
  for (std::size_t i = 0; i < folders.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (same_run(folders[i], folders[j]))
        throw core::DataError(
            folders[i].string() + ": given twice as " + option +
            (folders[i] == folders[j] ? "" : " (also as " + folders[j].string() + ")") +
            ": a run counted twice would weigh double in the fit and its "
            "figures. Hint: give each run once");
}

void require_disjoint_runs(const std::vector<fs::path>& a, const std::vector<fs::path>& b,
                           const std::string& a_option, const std::string& b_option,
                           const std::string& why) {
  for (const auto& x : a)
    for (const auto& y : b)
      if (same_run(x, y))
        throw core::DataError(x.string() + ": given as " + b_option + " and as " + a_option +
                              ": a run tested on what it was trained on gives a figure too good "
                              "to be true; " +
                              why);
}

MeasuredRun read_measured_run(const fs::path& folder, const MeasuredReadLimits& limits) {
  require_regular_file(folder / "meta.json");
  require_regular_file(folder / "data.csv");
  MeasuredRun run = run_from_meta(folder / "meta.json", limits);
  run.folder = folder;
  read_samples(folder / "data.csv", limits, run);
  return run;
}

MeasuredRun read_measured_meta(const fs::path& meta_json, const MeasuredReadLimits& limits) {
  require_regular_file(meta_json);
  MeasuredRun run = run_from_meta(meta_json, limits);
  run.folder = meta_json.parent_path();
  return run;
}

void write_measured_run(const fs::path& folder, const MeasuredRun& run) {
  require_shape(run);
  json meta = run.meta.is_object() ? run.meta : json::object();
  meta["format"] = kFormat;
  meta["machine"] = run.machine;
  meta["run"] = run.run;
  meta["time_unit"] = "s";
  meta["temperature_unit"] = "degC";
  meta["displacement_unit"] = "um";
  meta["sensors"] = json::array();
  for (const auto& s : run.sensors)
    meta["sensors"].push_back({{"id", s.id}, {"position", vector_json(s.position)}});
  meta["displacements"] = json::array();
  for (const auto& p : run.displacements)
    meta["displacements"].push_back(
        {{"id", p.id}, {"point", vector_json(p.point)}, {"direction", vector_json(p.direction)}});
  meta["inputs"] = json::array();
  for (const auto& id : run.inputs) meta["inputs"].push_back({{"id", id}, {"unit", "rpm"}});
  if (run.machine_box)
    meta["machine_box_m"] = {{"min", vector_json(run.machine_box->min())},
                             {"max", vector_json(run.machine_box->max())}};
  else
    meta.erase("machine_box_m");
  if (run.ambient_sensor)
    meta["ambient_sensor"] = *run.ambient_sensor;
  else
    meta.erase("ambient_sensor");
  meta["initial_temperature_degC"] =
      run.initial_temperature_c ? json(*run.initial_temperature_c) : json(nullptr);
  meta["nominal_ambient_degC"] =
      run.nominal_ambient_c ? json(*run.nominal_ambient_c) : json(nullptr);

  std::string csv = "time_s";
  for (const auto& id : run.inputs) csv += "," + id;
  for (const auto& s : run.sensors) csv += "," + s.id;
  for (const auto& p : run.displacements) csv += "," + p.id;
  csv += '\n';
  for (Eigen::Index r = 0; r < run.time.size(); ++r) {
    append_number(csv, run.time(r));
    for (Eigen::Index c = 0; c < run.input_values.cols(); ++c) {
      csv += ',';
      append_number(csv, run.input_values(r, c));
    }
    for (Eigen::Index c = 0; c < run.temperature.cols(); ++c) {
      csv += ',';
      append_number(csv, run.temperature(r, c) - core::kCelsiusOffset);
    }
    for (Eigen::Index c = 0; c < run.displacement.cols(); ++c) {
      csv += ',';
      append_number(csv, run.displacement(r, c) / core::kMetresPerMicrometre);
    }
    csv += '\n';
  }
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (ec) throw core::IoError(folder.string() + ": cannot create the folder: " + ec.message());
  write_file_atomically(folder / "data.csv", csv);
  write_file_atomically(folder / "meta.json", meta.dump(1) + "\n");
}

}  // namespace tt::io
