#include "io/reduced_model_io.hpp"

#include <fstream>
#include <map>
#include <sstream>

#include "core/errors.hpp"
#include "io/atomic_dir.hpp"
#include "io/binary.hpp"
#include "io/case_reader.hpp"
#include "io/checkpoint.hpp"

namespace tt::io {

namespace fs = std::filesystem;

namespace {

constexpr char kMagic[8] = {'T', 'T', 'R', 'O', 'M', '0', '0', '1'};
constexpr const char* kJson = "reduced_model.json";
constexpr const char* kBin = "reduced_model.bin";
constexpr const char* kFormat = "thermotwin reduced model";
constexpr int kVersion = 1;

/// The case with everything that is an input of the reduced model set to fixed values.
core::CaseSpec machine_only(core::CaseSpec s) {
  s.source = "/machine.toml";  // the resolved TOML names its source on its first line
  s.name = "machine";
  s.seed = 1;
  s.duty_cycle = core::DutyCycle{{{0.0, 0.0}}, 1.0, {}};
  for (auto& seg : s.feed_axis.segments)
    seg = {0.0, s.feed_axis.segments.front().from, s.feed_axis.segments.front().from, 0.0};
  if (!s.feed_axis.segments.empty()) s.feed_axis.segments.resize(1);
  s.thermal.initial_temperature_c = 20;
  s.thermal.scheme = core::TimeScheme::backward_euler;
  s.thermal.step = 1;
  s.thermal.output_interval = 1;
  for (auto& c : s.thermal.convection) c.sink = core::TimeTable{{0.0}, {20.0}};
  s.outputs = core::OutputSpec{};
  s.placement = core::PlacementSpec{};
  return s;
}

using Named = std::map<std::string, Eigen::MatrixXd>;

void put(ByteWriter& w, const std::string& name, const Eigen::MatrixXd& m) {
  w.put(std::int32_t(name.size()));
  w.bytes.append(name);
  w.put(std::int64_t(m.rows()));
  w.put(std::int64_t(m.cols()));
  w.put_doubles(m.data(), static_cast<std::size_t>(m.size()));
}

Eigen::MatrixXd column(const Eigen::VectorXd& v) {
  return v;
}

std::string indexed(const char* what, std::size_t k) {
  return what + std::to_string(k);
}

Named read_named(const std::string& bytes, const fs::path& file) {
  const std::string hint = "rebuild it with `thermotwin reduce`";
  if (bytes.size() < sizeof kMagic + sizeof(std::uint64_t) ||
      std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    throw core::DataError(file.string() +
                          ": not a thermotwin reduced model (expected the header "
                          "TTROM001); " +
                          hint);
  if (!checksum_matches(bytes))
    throw core::DataError(file.string() + ": reduced model corrupted (checksum mismatch); " + hint);
  ByteReader r{std::string_view(bytes).substr(0, bytes.size() - sizeof(std::uint64_t)),
               file.string() + ": reduced model", hint, sizeof kMagic};
  Named out;
  while (r.left() > 0) {
    const auto len = r.get<std::int32_t>();
    if (len < 1 || len > 64 || static_cast<std::size_t>(len) > r.left())
      throw core::DataError(file.string() + ": reduced model: a matrix name of " +
                            std::to_string(len) + " bytes at byte " + std::to_string(r.at) + "; " +
                            hint);
    std::string name(static_cast<std::size_t>(len), '\0');
    r.take(name.data(), name.size());
    const auto rows = r.get<std::int64_t>();
    const auto cols = r.get<std::int64_t>();
    // Sizes are checked against the bytes left before anything is allocated.
    if (rows < 0 || cols < 0 ||
        (rows > 0 && static_cast<std::uint64_t>(cols) > r.left() / sizeof(double) / rows))
      throw core::DataError(file.string() + ": reduced model: matrix '" + name + "' of " +
                            std::to_string(rows) + " x " + std::to_string(cols) +
                            " does not fit the file; " + hint);
    Eigen::MatrixXd m(rows, cols);
    r.take(m.data(), static_cast<std::size_t>(m.size()) * sizeof(double));
    out[name] = std::move(m);
  }
  return out;
}

std::string read_all(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec))
    throw core::IoError(file.string() +
                        ": not found or not a file; expected a folder written by "
                        "`thermotwin reduce CASE --out DIR`");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw core::IoError(file.string() + ": cannot open");
  std::ostringstream buf;
  buf << in.rdbuf();
  if (in.bad()) throw core::IoError(file.string() + ": cannot read");
  return buf.str();
}

std::string hex(std::uint64_t v) {
  std::ostringstream o;
  o << std::hex << v;
  return o.str();
}

std::uint64_t from_hex(const nlohmann::json& j, const char* key, const fs::path& file) {
  if (!j.contains(key) || !j[key].is_string())
    throw core::DataError(file.string() + ": key '" + key + "' missing or not a string");
  try {
    std::size_t used = 0;
    const std::string s = j[key].get<std::string>();
    const std::uint64_t v = std::stoull(s, &used, 16);
    if (used != s.size()) throw std::invalid_argument(s);
    return v;
  } catch (const std::exception&) {
    throw core::DataError(file.string() + ": key '" + key + "' = " + j[key].dump() +
                          ": expected a hexadecimal hash");
  }
}

}  // namespace

ReducedModelKey reduced_model_key(const core::CaseSpec& spec, const mesh::TetMesh& mesh) {
  ReducedModelKey k;
  const std::string toml = resolved_case_toml(machine_only(spec));
  const auto body = std::string_view(toml).substr(std::min(toml.size(), toml.find('\n') + 1));
  k.model_hash = fnv1a(body.data(), body.size());
  k.mesh_hash = checkpoint_key(spec, mesh).mesh_hash;
  k.nodes = mesh.nodes.rows();
  return k;
}

void write_reduced_model(const fs::path& dir, const ReducedModelFile& f) {
  const auto& s = f.twin.model.system;
  const auto& out = f.twin.outputs;
  ByteWriter w;
  w.bytes.append(kMagic, sizeof kMagic);
  put(w, "capacity", s.capacity);
  put(w, "conduction", s.conduction);
  put(w, "uniform", column(s.uniform));
  put(w, "basis", f.twin.model.basis);
  put(w, "outputs", out.rows);
  for (std::size_t k = 0; k < out.expansion.size(); ++k)
    put(w, indexed("expansion", k), out.expansion[k]);
  for (std::size_t k = 0; k < s.film.size(); ++k) {
    put(w, indexed("film", k), s.film[k]);
    put(w, indexed("film_area", k), column(s.film_area[k]));
  }
  for (std::size_t k = 0; k < s.source_shape.size(); ++k)
    put(w, indexed("source_shape", k), column(s.source_shape[k]));
  for (std::size_t k = 0; k < s.flux_area.size(); ++k)
    put(w, indexed("flux_area", k), column(s.flux_area[k]));
  for (std::size_t k = 0; k < s.moving.size(); ++k) {
    const auto& p = s.moving_pieces[k];
    put(w, indexed("moving", k), s.moving[k]);
    put(w, indexed("moving_source", k), Eigen::MatrixXd::Constant(1, 1, s.moving_source[k]));
    put(w, indexed("piece_source", k), Eigen::MatrixXd::Constant(1, 1, p.source));
    put(w, indexed("piece_centre", k), column(p.centre));
    put(w, indexed("piece_volume", k), column(p.volume));
    put(w, indexed("piece_nodes", k), p.nodes.cast<double>());
    put(w, indexed("piece_weight", k), p.weight);
  }
  w.seal();
  write_file_atomically(dir / kBin, w.bytes);

  nlohmann::json j = f.info;
  j["format"] = kFormat;
  j["version"] = kVersion;
  j["order"] = f.twin.model.states();
  j["nodes"] = f.key.nodes;
  j["case"] = {{"name", f.case_name}, {"file", f.case_file}};
  j["model_hash"] = hex(f.key.model_hash);
  j["mesh_hash"] = hex(f.key.mesh_hash);
  j["counts"] = {{"films", s.film.size()},
                 {"sources", s.source_shape.size()},
                 {"fluxes", s.flux_area.size()},
                 {"moving_sources", s.moving.size()}};
  j["outputs"] = {{"names", out.names},
                  {"temperatures", out.temperatures},
                  {"tcp", out.tcp},
                  {"reference_K", out.reference_k},
                  {"probe_distance_m", out.probe_distance},
                  {"expansion_materials", out.materials}};
  const auto& st = f.twin.model.stats;
  j["basis"] = {{"method", "block rational Krylov (moment matching), capacity-orthonormal"},
                {"shifts_per_s", st.shifts_per_s},
                {"film_states_W_m2K", st.film_states},
                {"input_columns", st.input_columns},
                {"candidate_columns", st.candidate_columns},
                {"deflated_columns", st.deflated_columns},
                {"factorizations", st.factorizations},
                {"build_s", st.build_s}};
  write_file_atomically(dir / kJson, j.dump(2) + "\n");
}

namespace {

/// reduced_model.json: format and version checked; the key, the case and the outputs' names.
nlohmann::json read_header(const fs::path& json_file, ReducedModelFile& f) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(read_all(json_file));
  } catch (const nlohmann::json::exception& e) {
    throw core::DataError(json_file.string() + ": not valid JSON (" + e.what() + ")");
  }
  if (!j.is_object() || j.value("format", "") != kFormat)
    throw core::DataError(json_file.string() + ": key 'format' is not \"" + kFormat +
                          "\"; expected a folder written by `thermotwin reduce`");
  if (j.value("version", 0) != kVersion)
    throw core::DataError(json_file.string() + ": version " +
                          j.value("version", nlohmann::json()).dump() +
                          ", this thermotwin reads version " + std::to_string(kVersion) +
                          "; rebuild it with `thermotwin reduce`");
  f.key.model_hash = from_hex(j, "model_hash", json_file);
  f.key.mesh_hash = from_hex(j, "mesh_hash", json_file);
  f.key.nodes = j.value("nodes", std::int64_t(-1));
  f.case_name = j["case"].value("name", "");
  f.case_file = j["case"].value("file", "");
  auto& out = f.twin.outputs;
  const auto& jo = j.value("outputs", nlohmann::json::object());
  out.names = jo.value("names", std::vector<std::string>{});
  out.temperatures = jo.value("temperatures", 0);
  out.tcp = jo.value("tcp", false);
  out.reference_k = jo.value("reference_K", 0.0);
  out.probe_distance = jo.value("probe_distance_m", 0.0);
  out.materials = jo.value("expansion_materials", std::vector<std::string>{});
  if (out.temperatures < 0 || static_cast<std::size_t>(out.temperatures) > out.names.size() ||
      (out.tcp && static_cast<std::size_t>(out.temperatures) + 9 > out.names.size()))
    throw core::DataError(json_file.string() + ": outputs: " + std::to_string(out.temperatures) +
                          " temperatures and " + (out.tcp ? "9" : "0") + " TCP rows in " +
                          std::to_string(out.names.size()) + " names; rebuild it");
  return j;
}

/// reduced_model.bin's matrices, taken out one by one with their sizes checked.
struct Matrices {
  Named m;
  fs::path file;
  /// The matrix `name`, rows x cols (-1: any); DataError naming the file when absent or
  /// of another size.
  Eigen::MatrixXd need(const std::string& name, Eigen::Index rows, Eigen::Index cols) {
    const auto it = m.find(name);
    if (it == m.end())
      throw core::DataError(file.string() + ": reduced model has no matrix '" + name +
                            "'; rebuild it with `thermotwin reduce`");
    if ((rows >= 0 && it->second.rows() != rows) || (cols >= 0 && it->second.cols() != cols))
      throw core::DataError(file.string() + ": matrix '" + name + "' is " +
                            std::to_string(it->second.rows()) + " x " +
                            std::to_string(it->second.cols()) + ", expected " +
                            (rows >= 0 ? std::to_string(rows) : "any") + " x " +
                            (cols >= 0 ? std::to_string(cols) : "any"));
    return std::move(it->second);
  }
};

/// counts.`key` of reduced_model.json, checked to be a count.
std::size_t count_of(const nlohmann::json& j, const char* key, const fs::path& json_file) {
  const auto v = j["counts"].value(key, -1);
  if (v < 0 || v > 100000)
    throw core::DataError(json_file.string() + ": counts." + key + " = " + std::to_string(v) +
                          ": expected a count");
  return static_cast<std::size_t>(v);
}

/// Moving source k's columns and pieces into `s`.
void read_moving(Matrices& m, std::size_t k, Eigen::Index r, std::int64_t nodes,
                 solvers::ReducedThermalSystem& s) {
  s.moving.push_back(m.need(indexed("moving", k), r, -1));
  const Eigen::Index pieces = s.moving.back().cols();
  s.moving_source.push_back(static_cast<int>(m.need(indexed("moving_source", k), 1, 1)(0, 0)));
  solvers::MovingSourceShape p;
  p.source = static_cast<int>(m.need(indexed("piece_source", k), 1, 1)(0, 0));
  p.centre = m.need(indexed("piece_centre", k), pieces, 1);
  p.volume = m.need(indexed("piece_volume", k), pieces, 1);
  p.nodes = m.need(indexed("piece_nodes", k), pieces, -1).cast<int>();
  p.weight = m.need(indexed("piece_weight", k), pieces, p.nodes.cols());
  if (p.nodes.size() > 0 && (p.nodes.minCoeff() < 0 || p.nodes.maxCoeff() >= nodes))
    throw core::DataError(m.file.string() + ": moving source " + std::to_string(k) +
                          " names nodes outside the model's " + std::to_string(nodes));
  s.moving_pieces.push_back(std::move(p));
}

}  // namespace

ReducedModelFile read_reduced_model(const fs::path& dir) {
  const fs::path json_file = dir / kJson, bin_file = dir / kBin;
  ReducedModelFile f;
  const nlohmann::json j = read_header(json_file, f);
  f.info = j;
  Matrices m{read_named(read_all(bin_file), bin_file), bin_file};
  auto& model = f.twin.model;
  auto& s = model.system;
  model.basis = m.need("basis", f.key.nodes, -1);
  const Eigen::Index r = model.basis.cols();
  s.capacity = m.need("capacity", r, r);
  s.conduction = m.need("conduction", r, r);
  s.uniform = m.need("uniform", r, 1);
  auto& out = f.twin.outputs;
  out.rows = m.need("outputs", static_cast<Eigen::Index>(out.names.size()), r);
  for (std::size_t k = 0; k < out.materials.size(); ++k)
    out.expansion.push_back(m.need(indexed("expansion", k), out.rows.rows() - out.temperatures, r));
  for (std::size_t k = 0, n = count_of(j, "films", json_file); k < n; ++k) {
    s.film.push_back(m.need(indexed("film", k), r, r));
    s.film_area.push_back(m.need(indexed("film_area", k), r, 1));
  }
  for (std::size_t k = 0, n = count_of(j, "sources", json_file); k < n; ++k)
    s.source_shape.push_back(m.need(indexed("source_shape", k), r, 1));
  for (std::size_t k = 0, n = count_of(j, "fluxes", json_file); k < n; ++k)
    s.flux_area.push_back(m.need(indexed("flux_area", k), r, 1));
  for (std::size_t k = 0, n = count_of(j, "moving_sources", json_file); k < n; ++k)
    read_moving(m, k, r, f.key.nodes, s);
  s = solvers::with_moving_prefix(std::move(s));
  const auto& b = j.value("basis", nlohmann::json::object());
  model.stats.shifts_per_s = b.value("shifts_per_s", std::vector<double>{});
  model.stats.film_states = b.value("film_states_W_m2K", std::vector<std::vector<double>>{});
  model.stats.input_columns = b.value("input_columns", 0);
  model.stats.candidate_columns = b.value("candidate_columns", 0);
  model.stats.deflated_columns = b.value("deflated_columns", 0);
  model.stats.factorizations = b.value("factorizations", 0);
  model.stats.build_s = b.value("build_s", 0.0);
  return f;
}

void check_reduced_model_fits(const ReducedModelFile& file, const ReducedModelKey& key,
                              const fs::path& dir) {
  if (file.key.nodes != key.nodes || file.key.mesh_hash != key.mesh_hash)
    throw core::DataError(dir.string() + ": reduced model built on another mesh (" +
                          std::to_string(file.key.nodes) + " nodes, mesh hash " +
                          hex(file.key.mesh_hash) + "), this case meshes to " +
                          std::to_string(key.nodes) + " nodes, mesh hash " + hex(key.mesh_hash) +
                          "; rebuild it with `thermotwin reduce CASE --out " + dir.string() + "`");
  if (file.key.model_hash != key.model_hash)
    throw core::DataError(dir.string() + ": reduced model built from another machine (case '" +
                          file.case_name + "', model hash " + hex(file.key.model_hash) +
                          "): this case differs in geometry, materials, films or sources (model "
                          "hash " +
                          hex(key.model_hash) + "); rebuild it with `thermotwin reduce`");
}

}  // namespace tt::io
