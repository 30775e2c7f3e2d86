#include "mesh/tetgen/tetgen_adapter.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <tetgen.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <exception>
#include <fstream>
#include <new>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/errors.hpp"

namespace tt::mesh::tetgen {
namespace {

std::string error_text(int code) {
  switch (code) {
    case 1:
      return "out of memory";
    case 2:
      return "internal error (please report)";
    case 3:
      return "a self-intersection was detected in the input (facets cross each other)";
    case 4:
      return "a very small input feature size was detected (points or facets nearly touch)";
    case 5:
      return "two very close input facets were detected";
    case 10:
      return "an input error was detected";
    default:
      return "failure code " + std::to_string(code);
  }
}

/// Copies the PLC into TetGen's structures; tetgenio frees them with delete[].
void fill_input(const Plc& plc, tetgenio& in) {
  in.firstnumber = 0;
  in.numberofpoints = static_cast<int>(plc.vertices.size());
  in.pointlist = new REAL[3 * plc.vertices.size()];
  for (size_t i = 0; i < plc.vertices.size(); ++i)
    for (int k = 0; k < 3; ++k) in.pointlist[3 * i + k] = plc.vertices[i][k];

  in.numberoffacets = static_cast<int>(plc.facets.size());
  in.facetlist = new tetgenio::facet[plc.facets.size()];
  in.facetmarkerlist = new int[plc.facets.size()];
  for (size_t f = 0; f < plc.facets.size(); ++f) {
    const PlcFacet& src = plc.facets[f];
    tetgenio::facet& dst = in.facetlist[f];
    tetgenio::init(&dst);
    dst.numberofpolygons = static_cast<int>(src.polygons.size());
    dst.polygonlist = new tetgenio::polygon[src.polygons.size()];
    for (size_t p = 0; p < src.polygons.size(); ++p) {
      tetgenio::polygon& poly = dst.polygonlist[p];
      tetgenio::init(&poly);
      poly.numberofvertices = static_cast<int>(src.polygons[p].size());
      poly.vertexlist = new int[src.polygons[p].size()];
      for (size_t v = 0; v < src.polygons[p].size(); ++v) poly.vertexlist[v] = src.polygons[p][v];
    }
    if (!src.holes.empty()) {
      dst.numberofholes = static_cast<int>(src.holes.size());
      dst.holelist = new REAL[3 * src.holes.size()];
      for (size_t h = 0; h < src.holes.size(); ++h)
        for (int k = 0; k < 3; ++k) dst.holelist[3 * h + k] = src.holes[h][k];
    }
    in.facetmarkerlist[f] = static_cast<int>(f) + 1;
  }

  if (!plc.holes.empty()) {
    in.numberofholes = static_cast<int>(plc.holes.size());
    in.holelist = new REAL[3 * plc.holes.size()];
    for (size_t h = 0; h < plc.holes.size(); ++h)
      for (int k = 0; k < 3; ++k) in.holelist[3 * h + k] = plc.holes[h][k];
  }
  in.numberofregions = static_cast<int>(plc.regions.size());
  in.regionlist = new REAL[5 * plc.regions.size()];
  for (size_t r = 0; r < plc.regions.size(); ++r) {
    for (int k = 0; k < 3; ++k) in.regionlist[5 * r + k] = plc.regions[r].point[k];
    in.regionlist[5 * r + 3] = plc.regions[r].region + 1;  // 0 means "no region" in TetGen
    in.regionlist[5 * r + 4] = plc.regions[r].max_volume;
  }
}

std::string switches_for(const TetgenOptions& options) {
  std::ostringstream s;
  // p: PLC, z: zero-based, A: region attributes, a: region volume bounds, q: quality, Q: quiet.
  s << "pzAaQq" << options.radius_edge_ratio << "/" << options.min_dihedral_deg;
  return s.str();
}

// TetGen runs in a forked child process. Debian's TetGen 1.5.0 frees its mesh in
// terminatetetgen() and then throws its int code; unwinding runs ~tetgenmesh(), which frees the
// mesh a second time, so a failure kills whichever process runs it before any catch is reached.
// Internal errors can also crash it outright. A child process keeps both away from the caller:
//  - fork() copies the filled tetgenio without serialising it; only the result crosses a pipe.
//    A vfork() child shares the caller's memory and may only exec, and posix_spawn() or exec
//    would need a separate TetGen executable and the PLC written out for it.
//  - In the child, TetGen runs on a fresh thread whose stack holds no handler, so its throw finds
//    no catch, nothing is unwound (no second free) and std::terminate() runs first; the
//    terminate handler reads the code from the current exception and sends it back. On the
//    caller's stack a catch(...) further up (a test runner, a driver) would trigger the unwinding.
//  - The child's stdout/stderr go to a second pipe so TetGen's own explanation (which facets
//    intersect) reaches the error message, and the caller's terminal stays clean.
//  - The parent only reads both pipes until they close and then reaps the child, so it never
//    waits on a child blocked on a full pipe. It ends the child at the case's wall-time limit;
//    the child's address space is limited (RLIMIT_AS) to what it inherits plus the case's
//    memory limit, so TetGen's allocations fail (a MeshError) before the machine runs out; and
//    the child is killed when the parent dies (PR_SET_PDEATHSIG), so killing thermotwin never
//    leaves TetGen running. The child never uses OpenMP, so forking a parent
//    that has started OpenMP threads is safe; it ends with _exit() and runs no atexit handlers.

/// First bytes on the result pipe; the arrays follow in this order: #points x 3 coordinates [m]
/// (double), #tets x #corners vertex indices (int), #tets x #attributes attributes (double).
struct ResultHeader {
  std::uint64_t magic = 0;
  std::int32_t threw = 0;  /// 1 when TetGen threw `code` instead of meshing
  std::int32_t code = 0;
  std::int64_t points = 0;
  std::int64_t tets = 0;
  std::int32_t corners = 0;
  std::int32_t attributes = 0;
};
constexpr std::uint64_t kResultMagic = 0x7474746574676e31;  // "tttetgn1"
constexpr int kUnknownThrow = -1;  /// TetGen threw something other than an int

/// The child's end of the result pipe; written only in the child after fork().
int child_result_fd = -1;

bool write_all(int fd, const void* data, std::size_t bytes) {
  const char* p = static_cast<const char*>(data);
  while (bytes > 0) {
    const ssize_t n = ::write(fd, p, bytes);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    bytes -= static_cast<std::size_t>(n);
  }
  return true;
}

/// Terminate handler of the child: TetGen's exception reached it with the stack intact.
[[noreturn]] void report_thrown_and_exit() {
  ResultHeader header;
  header.magic = kResultMagic;
  header.threw = 1;
  header.code = kUnknownThrow;
  if (const std::exception_ptr thrown = std::current_exception()) {
    try {
      std::rethrow_exception(thrown);
    } catch (int code) {
      header.code = code;
    } catch (const std::bad_alloc&) {
      header.code = 1;
    } catch (...) {
    }
  }
  std::fflush(stdout);
  _exit(write_all(child_result_fd, &header, sizeof header) ? 0 : 3);
}

/// Sends the mesh in `out` on the result pipe; false when the pipe broke.
bool send_mesh(const tetgenio& out) {
  ResultHeader header;
  header.magic = kResultMagic;
  header.points = out.numberofpoints;
  header.tets = out.numberoftetrahedra;
  header.corners = out.numberofcorners;
  header.attributes = out.numberoftetrahedronattributes;
  const std::size_t n_points = static_cast<std::size_t>(std::max<std::int64_t>(header.points, 0));
  const std::size_t n_tets = static_cast<std::size_t>(std::max<std::int64_t>(header.tets, 0));
  const std::size_t corners = static_cast<std::size_t>(std::max(header.corners, 0));
  const std::size_t attributes = static_cast<std::size_t>(std::max(header.attributes, 0));
  return write_all(child_result_fd, &header, sizeof header) &&
         (n_points == 0 ||
          write_all(child_result_fd, out.pointlist, 3 * n_points * sizeof(REAL))) &&
         (n_tets * corners == 0 ||
          write_all(child_result_fd, out.tetrahedronlist, n_tets * corners * sizeof(int))) &&
         (n_tets * attributes == 0 || write_all(child_result_fd, out.tetrahedronattributelist,
                                                n_tets * attributes * sizeof(REAL)));
}

/// Body of the forked child: never returns.
[[noreturn]] void run_child(char* switches, tetgenio* in, int result_fd, int log_fd) {
  child_result_fd = result_fd;
  // Fresh, unbuffered streams on the log pipe: the inherited stdout may hold the caller's
  // unflushed text or a lock taken by another thread at fork time, and a crash must not lose
  // what TetGen printed just before it.
  if (::dup2(log_fd, STDOUT_FILENO) < 0 || ::dup2(log_fd, STDERR_FILENO) < 0) _exit(4);
  if (FILE* log = ::fdopen(STDOUT_FILENO, "w")) {
    std::setvbuf(log, nullptr, _IONBF, 0);
    stdout = log;
    stderr = log;
  }
  std::set_terminate(report_thrown_and_exit);
  try {
    std::thread worker([switches, in] {
      tetgenio out;
      ::tetrahedralize(switches, in, &out);
      _exit(send_mesh(out) ? 0 : 3);
    });
    worker.join();
  } catch (...) {
  }
  _exit(5);
}

/// What the child left behind.
struct ChildOutput {
  std::string result;      /// bytes of the result pipe
  std::string log;         /// the last bytes TetGen printed
  int status = 0;          /// from waitpid
  bool timed_out = false;  /// ended by the parent at the wall-time limit
};

/// Address space [bytes] this process holds now (/proc/self/statm's first field); 0 if unknown.
std::uint64_t address_space_bytes() {
  std::ifstream statm("/proc/self/statm");
  std::uint64_t pages = 0;
  statm >> pages;
  return pages * static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
}

/// In the child, right after fork(): die with the parent, and allocate at most `memory_bytes`
/// beyond what was inherited. Only async-signal-safe calls until run_child.
void bound_child(pid_t parent, std::uint64_t inherited_bytes, double memory_bytes) {
  if (::prctl(PR_SET_PDEATHSIG, SIGKILL) != 0) _exit(6);
  if (::getppid() != parent) _exit(6);  // the parent died before prctl took effect
  if (inherited_bytes > 0 && memory_bytes < 1e18) {
    const rlimit as{static_cast<rlim_t>(inherited_bytes + static_cast<std::uint64_t>(memory_bytes)),
                    RLIM_INFINITY};
    if (::setrlimit(RLIMIT_AS, &as) != 0) _exit(6);
  }
}

/// A pipe whose ends close with it.
struct Pipe {
  int fd[2] = {-1, -1};
  ~Pipe() {
    close_end(0);
    close_end(1);
  }
  void close_end(int k) {
    if (fd[k] >= 0) ::close(fd[k]);
    fd[k] = -1;
  }
};

/// The forked child; a parent leaving early kills and reaps it so no zombie remains.
struct Child {
  pid_t pid = -1;
  ~Child() {
    if (pid <= 0) return;
    ::kill(pid, SIGKILL);
    while (::waitpid(pid, nullptr, 0) < 0 && errno == EINTR) {
    }
  }
  int wait() {
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0) {
      if (errno != EINTR) {
        status = -1;
        break;
      }
    }
    pid = -1;
    return status;
  }
};

[[noreturn]] void throw_system_error(const std::string& what, const std::string& switches) {
  throw core::MeshError("could not run TetGen with switches '" + switches + "': " + what +
                        " failed (" + std::strerror(errno) +
                        "). Hint: the process may be out of memory or of file descriptors.");
}

/// Runs TetGen on the filled `in` in a child process and collects what it sends and prints.
ChildOutput run_isolated(const std::string& switches, tetgenio& in, const TetgenOptions& options) {
  std::vector<char> buffer(switches.begin(), switches.end());
  buffer.push_back('\0');
  Pipe result, log;
  if (::pipe2(result.fd, O_CLOEXEC) != 0 || ::pipe2(log.fd, O_CLOEXEC) != 0)
    throw_system_error("pipe2()", switches);
  const pid_t parent = ::getpid();
  const std::uint64_t inherited = address_space_bytes();
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                            std::chrono::duration<double>(std::min(options.time_limit_s, 1e9)));
  Child child;
  child.pid = ::fork();
  if (child.pid < 0) throw_system_error("fork()", switches);
  if (child.pid == 0) {
    bound_child(parent, inherited, options.memory_limit_GB * 1e9);
    ::close(result.fd[0]);
    ::close(log.fd[0]);
    run_child(buffer.data(), &in, result.fd[1], log.fd[1]);
  }
  result.close_end(1);
  log.close_end(1);

  // Both pipes are drained together: the child may fill either one while the other is read.
  ChildOutput output;
  constexpr std::size_t kChunk = 1 << 16;
  constexpr std::size_t kLogKept = 1 << 14;  // the tail of the log is what explains a failure
  bool reserved = false;
  pollfd fds[2] = {{result.fd[0], POLLIN, 0}, {log.fd[0], POLLIN, 0}};
  std::string* sinks[2] = {&output.result, &output.log};
  while (fds[0].fd >= 0 || fds[1].fd >= 0) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      ::kill(child.pid, SIGKILL);  // its pipes close with it; the loop then ends
      output.timed_out = true;
      break;
    }
    const int ready =
        ::poll(fds, 2, static_cast<int>(std::min<long long>(left.count() + 1, 60000)));
    if (ready < 0) {
      if (errno == EINTR) continue;
      throw_system_error("poll()", switches);
    }
    for (int k = 0; k < 2; ++k) {
      if (fds[k].fd < 0 || fds[k].revents == 0) continue;
      std::string& sink = *sinks[k];
      const std::size_t old = sink.size();
      sink.resize(old + kChunk);
      const ssize_t n = ::read(fds[k].fd, sink.data() + old, kChunk);
      sink.resize(old + static_cast<std::size_t>(std::max<ssize_t>(n, 0)));
      if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
      if (n <= 0) {
        fds[k].fd = -1;  // end of file (or a broken pipe): poll() skips negative descriptors
        continue;
      }
      if (k == 1 && sink.size() > 2 * kLogKept) sink.erase(0, sink.size() - kLogKept);
      if (k == 0 && !reserved && sink.size() >= sizeof(ResultHeader)) {
        ResultHeader header;
        std::memcpy(&header, sink.data(), sizeof header);
        if (header.magic == kResultMagic && header.threw == 0 && header.points >= 0 &&
            header.tets >= 0 && header.corners >= 0 && header.attributes >= 0)
          sink.reserve(sizeof header + 3 * sizeof(REAL) * header.points +
                       (header.corners * sizeof(int) + header.attributes * sizeof(REAL)) *
                           header.tets +
                       kChunk);
        reserved = true;
      }
    }
  }
  output.status = child.wait();
  return output;
}

/// The last `count` non-empty lines of `text`, joined by " | ".
std::string last_lines(const std::string& text, int count) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first != std::string::npos) lines.push_back(line.substr(first));
  }
  std::string joined;
  for (std::size_t i = lines.size() > static_cast<std::size_t>(count) ? lines.size() - count : 0;
       i < lines.size(); ++i)
    joined += (joined.empty() ? "" : " | ") + lines[i];
  return joined;
}

/// What the limits were, for a failure that may have been one of them.
std::string limits_text(const TetgenOptions& options) {
  std::ostringstream o;
  o << "mesh.memory_limit_GB = " << options.memory_limit_GB << " (memory TetGen may take)";
  return o.str();
}

/// Why the child produced no mesh, or "" when `output` holds one.
std::string failure_of(const ChildOutput& output, const TetgenOptions& options) {
  if (output.timed_out) {
    std::ostringstream o;
    o << "TetGen did not finish within mesh.time_limit_s = " << options.time_limit_s
      << " s and was ended. Hint: a radius_edge_ratio near 1 or a min_dihedral_deg near 18 can "
         "keep it refining for ever; relax them, coarsen the mesh, or raise time_limit_s under "
         "[mesh]";
    return o.str();
  }
  ResultHeader header;
  const bool has_header = output.result.size() >= sizeof header;
  if (has_header) std::memcpy(&header, output.result.data(), sizeof header);
  if (has_header && header.magic == kResultMagic && header.threw == 1)
    return error_text(header.code) + " (TetGen error code " + std::to_string(header.code) + ")" +
           (header.code == 1 ? " under " + limits_text(options) +
                                   ". Hint: coarsen the mesh, or raise memory_limit_GB under "
                                   "[mesh] when the machine has the memory"
                             : "");
  if (output.status != -1 && WIFSIGNALED(output.status)) {
    const int sig = WTERMSIG(output.status);
    const char* abbrev = ::sigabbrev_np(sig);
    return "TetGen crashed with signal " + std::to_string(sig) + " (SIG" + (abbrev ? abbrev : "?") +
           "), perhaps short of memory under " + limits_text(options);
  }
  if (output.status != -1 && WIFEXITED(output.status) && WEXITSTATUS(output.status) != 0)
    return "the TetGen process exited with status " + std::to_string(WEXITSTATUS(output.status)) +
           " after sending " + std::to_string(output.result.size()) + " bytes, perhaps short of " +
           "memory under " + limits_text(options);
  if (!has_header || header.magic != kResultMagic)
    return "the TetGen process sent " + std::to_string(output.result.size()) +
           " bytes instead of a mesh";
  return "";
}

/// Reads `count` values of T from `bytes` at `offset` (native layout: same binary, same host).
template <class T>
std::vector<T> array_at(const std::string& bytes, std::size_t offset, std::size_t count) {
  std::vector<T> values(count);
  if (count > 0) std::memcpy(values.data(), bytes.data() + offset, count * sizeof(T));
  return values;
}

/// Refuses limits and quality bounds TetGen cannot run with.
void check_options(const TetgenOptions& options) {
  if (!(options.time_limit_s > 0) || !(options.memory_limit_GB > 0))
    throw core::MeshError("mesh limits time_limit_s = " + std::to_string(options.time_limit_s) +
                          ", memory_limit_GB = " + std::to_string(options.memory_limit_GB) +
                          ": both must be > 0");
  if (!(options.radius_edge_ratio >= 1.0) || !(options.min_dihedral_deg >= 0.0) ||
      options.min_dihedral_deg > 18.0)
    throw core::MeshError(
        "mesh quality bounds radius_edge_ratio = " + std::to_string(options.radius_edge_ratio) +
        ", min_dihedral_deg = " + std::to_string(options.min_dihedral_deg) +
        ": need radius_edge_ratio >= 1 and 0 <= min_dihedral_deg <= 18");
}

/// Throws a MeshError that says what was asked and what TetGen printed unless the child sent a
/// whole result.
void require_result(const ChildOutput& output, const Plc& plc, const std::string& switches,
                    const TetgenOptions& options) {
  if (output.timed_out)
    throw core::MeshError("TetGen with switches '" + switches + "' on a PLC of " +
                          std::to_string(plc.facets.size()) +
                          " facets: " + failure_of(output, options) + ".");
  if (const std::string failure = failure_of(output, options); !failure.empty()) {
    const std::string said = last_lines(output.log, 4);
    throw core::MeshError(
        "TetGen failed with switches '" + switches + "' on a PLC of " +
        std::to_string(plc.vertices.size()) + " vertices, " +
        std::to_string(plc.interior_points.size()) + " interior points and " +
        std::to_string(plc.facets.size()) + " facets: " + failure +
        (said.empty() ? "" : ". TetGen printed (its facet #n is PLC facet n-1): \"" + said + "\"") +
        ". Hint: check that bodies do not cross or nearly touch, coarsen circle_segments or relax "
        "the quality bounds.");
  }
}

/// The arrays of a result (see ResultHeader), checked against the header's counts.
struct ResultArrays {
  std::vector<double> points;      /// #points x 3 [m]
  std::vector<int> corners;        /// #tets x 4
  std::vector<double> attributes;  /// #tets x attributes_per_tet
  std::size_t attributes_per_tet = 0;
};

ResultArrays result_arrays(const std::string& bytes, const std::string& switches) {
  ResultHeader out;
  std::memcpy(&out, bytes.data(), sizeof out);
  if (out.tets == 0 || out.corners != 4)
    throw core::MeshError("TetGen returned no tetrahedra for switches '" + switches + "'");
  if (out.attributes < 1)
    throw core::MeshError("TetGen returned tetrahedra without region attributes");
  const std::size_t n_points = static_cast<std::size_t>(out.points);
  const std::size_t n_tets = static_cast<std::size_t>(out.tets);
  const std::size_t na = static_cast<std::size_t>(out.attributes);
  const std::size_t tets_at = sizeof out + 3 * n_points * sizeof(REAL);
  const std::size_t attributes_at = tets_at + 4 * n_tets * sizeof(int);
  if (out.points < 4 || bytes.size() != attributes_at + na * n_tets * sizeof(REAL))
    throw core::MeshError("the TetGen process sent " + std::to_string(bytes.size()) +
                          " bytes for " + std::to_string(out.points) + " points and " +
                          std::to_string(out.tets) + " tets: the result is truncated");
  return {array_at<double>(bytes, sizeof out, 3 * n_points),
          array_at<int>(bytes, tets_at, 4 * n_tets),
          array_at<double>(bytes, attributes_at, na * n_tets), na};
}

/// Positively oriented tets with zero-based regions; refuses a vertex index out of range and a
/// tet outside every region.
LinearTets linear_tets(const ResultArrays& r) {
  const std::size_t n_points = r.points.size() / 3;
  const std::size_t n_tets = r.corners.size() / 4;
  LinearTets result;
  result.nodes.resize(n_points);
  for (std::size_t i = 0; i < n_points; ++i)
    result.nodes[i] = {r.points[3 * i], r.points[3 * i + 1], r.points[3 * i + 2]};
  result.tets.resize(n_tets);
  result.region.resize(n_tets);
  for (std::size_t t = 0; t < n_tets; ++t) {
    std::array<int, 4> tet;
    for (int k = 0; k < 4; ++k) {
      tet[k] = r.corners[4 * t + k];
      if (tet[k] < 0 || static_cast<std::size_t>(tet[k]) >= n_points)
        throw core::MeshError("TetGen returned tetrahedron " + std::to_string(t) + " with vertex " +
                              std::to_string(tet[k]) + " of " + std::to_string(n_points));
    }
    const Eigen::Vector3d& a = result.nodes[tet[0]];
    const double orient =
        (result.nodes[tet[1]] - a).cross(result.nodes[tet[2]] - a).dot(result.nodes[tet[3]] - a);
    if (orient < 0) std::swap(tet[2], tet[3]);
    result.tets[t] = tet;
    const int attribute = static_cast<int>(r.attributes[r.attributes_per_tet * t] + 0.5);
    if (attribute < 1)
      throw core::MeshError("TetGen produced tetrahedron " + std::to_string(t) +
                            " outside every declared body (region attribute " +
                            std::to_string(attribute) + "); a region point is missing");
    result.region[t] = attribute - 1;
  }
  return result;
}

}  // namespace

LinearTets tetrahedralize(const Plc& plc, const TetgenOptions& options) {
  check_options(options);
  // Interior points go in as isolated PLC vertices: TetGen keeps every input vertex inside the
  // domain, and its -i insertion path crashes in 1.5.0.
  Plc with_points = plc;
  with_points.vertices.insert(with_points.vertices.end(), plc.interior_points.begin(),
                              plc.interior_points.end());
  tetgenio in;
  fill_input(with_points, in);
  const std::string switches = switches_for(options);
  const ChildOutput output = run_isolated(switches, in, options);
  require_result(output, plc, switches, options);
  return linear_tets(result_arrays(output.result, switches));
}

}  // namespace tt::mesh::tetgen
