#include "io/checkpoint.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>

#include "core/errors.hpp"
#include "io/atomic_dir.hpp"
#include "io/binary.hpp"
#include "io/case_reader.hpp"

namespace tt::io {

namespace fs = std::filesystem;

namespace {

constexpr char kMagic[8] = {'T', 'T', 'C', 'K', 'P', 'T', '0', '1'};

std::string key_text(const CheckpointKey& k) {
  std::ostringstream o;
  o << "case hash " << std::hex << k.case_hash << ", mesh hash " << k.mesh_hash << std::dec << ", "
    << k.nodes << " nodes, " << k.tets << " tets, order " << k.order;
  return o.str();
}

}  // namespace

CheckpointKey checkpoint_key(const core::CaseSpec& spec, const mesh::TetMesh& mesh) {
  CheckpointKey k;
  // The first line names the case file's path: a moved case is still the same case.
  const std::string toml = resolved_case_toml(spec);
  const auto body = std::string_view(toml).substr(std::min(toml.size(), toml.find('\n') + 1));
  k.case_hash = fnv1a(body.data(), body.size());
  const Eigen::MatrixXd nodes = mesh.nodes;  // column-major copy: hashed in a fixed layout
  const Eigen::MatrixXi tets = mesh.tets.cast<int>();
  k.mesh_hash = fnv1a(nodes.data(), static_cast<std::size_t>(nodes.size()) * sizeof(double));
  k.mesh_hash =
      fnv1a(tets.data(), static_cast<std::size_t>(tets.size()) * sizeof(int), k.mesh_hash);
  k.nodes = mesh.nodes.rows();
  k.tets = mesh.tets.rows();
  k.order = mesh.order;
  return k;
}

fs::path checkpoint_path(const fs::path& out_dir) {
  return sibling_path(output_path(out_dir),
                      ".checkpoint");  // "out/run/" -> "/.../out/run.checkpoint"
}

void require_writable_checkpoint(const fs::path& file) {
  const std::string hint =
      ". Hint: make it writable, move it away, or run without checkpoints (--checkpoint-every-s "
      "-1)";
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(file, ec);
  if (fs::exists(st)) {
    if (!fs::is_regular_file(st))
      throw core::IoError(file.string() +
                          ": the run's checkpoint cannot be saved here: it exists "
                          "and is not a regular file" +
                          hint);
    const bool no_write_bit = (st.permissions() & (fs::perms::owner_write | fs::perms::group_write |
                                                   fs::perms::others_write)) == fs::perms::none;
    if (no_write_bit || ::access(file.c_str(), W_OK) != 0)
      throw core::IoError(file.string() + ": the run's checkpoint is read-only" + hint);
  }
  const fs::path probe = sibling_path(file, ".tmp");
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0)
    throw core::IoError(probe.string() +
                        ": cannot write the run's checkpoint: " + std::strerror(errno) + hint);
  ::close(fd);
  fs::remove(probe, ec);
}

void write_checkpoint(const fs::path& file, const CheckpointKey& key,
                      const solvers::ThermalCheckpoint& s) {
  ByteWriter w;
  w.bytes.append(kMagic, sizeof kMagic);
  w.put(key.case_hash);
  w.put(key.mesh_hash);
  w.put(key.nodes);
  w.put(key.tets);
  w.put(key.order);
  w.put(std::int32_t(s.steps));
  w.put(s.time);
  w.put(s.speed);
  w.put(s.heat_in);
  w.put(s.lost);
  w.put(std::int64_t(s.temperature.size()));
  w.put(std::int64_t(s.outputs.cols()));
  w.put_doubles(s.temperature.data(), static_cast<std::size_t>(s.temperature.size()));
  w.put_doubles(s.outputs.data(), static_cast<std::size_t>(s.outputs.size()));
  w.seal();
  write_file_atomically(file, w.bytes);
}

solvers::ThermalCheckpoint read_checkpoint(const fs::path& file, const CheckpointKey& key) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw core::IoError(file.string() + ": cannot open the checkpoint");
  std::ostringstream buf;
  buf << in.rdbuf();
  if (in.bad()) throw core::IoError(file.string() + ": cannot read the checkpoint");
  const std::string bytes = buf.str();
  const auto corrupt = [&](const std::string& what) {
    return core::DataError(file.string() + ": " + what +
                           "; remove it and run again without --resume");
  };
  if (bytes.size() < sizeof kMagic + sizeof(std::uint64_t) ||
      std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    throw corrupt("not a thermotwin checkpoint (expected the header TTCKPT01)");
  if (!checksum_matches(bytes)) throw corrupt("checkpoint corrupted (checksum mismatch)");

  ByteReader r{std::string_view(bytes).substr(0, bytes.size() - sizeof(std::uint64_t)),
               file.string() + ": checkpoint", "remove it and run again without --resume",
               sizeof kMagic};
  CheckpointKey k;
  k.case_hash = r.get<std::uint64_t>();
  k.mesh_hash = r.get<std::uint64_t>();
  k.nodes = r.get<std::int64_t>();
  k.tets = r.get<std::int64_t>();
  k.order = r.get<std::int32_t>();
  if (!(k == key))
    throw core::DataError(file.string() + ": checkpoint written for another case or mesh (" +
                          key_text(k) + "), this run has " + key_text(key) +
                          "; remove it, or resume with the case it was written for");
  solvers::ThermalCheckpoint s;
  s.steps = r.get<std::int32_t>();
  s.time = r.get<double>();
  s.speed = r.get<double>();
  s.heat_in = r.get<double>();
  s.lost = r.get<double>();
  const auto n = r.get<std::int64_t>();
  const auto cols = r.get<std::int64_t>();
  if (n != key.nodes || cols < 1 || cols > (1 << 24))
    throw corrupt("checkpoint holds " + std::to_string(n) + " nodes x " + std::to_string(cols) +
                  " outputs, expected " + std::to_string(key.nodes) + " nodes");
  // The sizes are checked against the bytes left before anything is allocated.
  if (static_cast<std::uint64_t>(n) * static_cast<std::uint64_t>(1 + cols) * sizeof(double) !=
      r.bytes.size() - r.at)
    throw corrupt("checkpoint size does not match its " + std::to_string(n) + " x " +
                  std::to_string(cols) + " outputs");
  s.temperature.resize(n);
  r.take(s.temperature.data(), static_cast<std::size_t>(n) * sizeof(double));
  s.outputs.resize(n, cols);
  r.take(s.outputs.data(), static_cast<std::size_t>(n * cols) * sizeof(double));
  return s;
}

}  // namespace tt::io
