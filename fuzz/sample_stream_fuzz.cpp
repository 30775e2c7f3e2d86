// Fuzz target: any byte stream read as compensate reads its input (io::LineReader on a file
// descriptor, the header bound by io::stream_columns, each sample by io::parsed_sample) is either
// refused with a typed error at its header or read line by line, every output line written whole
// (io::BufferedWriter with a 1 KiB bound, drop_behind and write_ready on a one-page pipe that is
// drained only every 101 lines).
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <Eigen/Core>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>

#include "core/errors.hpp"
#include "core/live_step.hpp"
#include "io/sample_stream.hpp"

namespace {

/// Drains what the pipe holds without waiting; checks each line it held was whole.
void drain(int fd, std::string& partial) {
  char buffer[4096];
  for (ssize_t n; (n = ::read(fd, buffer, sizeof buffer)) > 0;) partial.append(buffer, n);
  const std::size_t end = partial.rfind('\n');
  if (end == std::string::npos) return;
  // Every complete line has a status after its last comma: never empty.
  for (std::size_t from = 0; from <= end;) {
    const std::size_t nl = partial.find('\n', from);
    const std::string_view line(partial.data() + from, nl - from);
    if (line.empty() || line.back() == ',') std::abort();
    from = nl + 1;
  }
  partial.erase(0, end + 1);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const int in = ::memfd_create("tt-fuzz-stream", MFD_CLOEXEC);
  if (in < 0) return 0;
  if (size > 0 && ::write(in, data, size) != static_cast<ssize_t>(size)) std::abort();
  ::lseek(in, 0, SEEK_SET);
  int out[2];
  if (::pipe2(out, O_NONBLOCK | O_CLOEXEC) != 0) std::abort();
  // The writer's end blocks as compensate's output may; only the test's read end does not. The
  // smallest pipe (a page), so that a short input fills it and the writer holds and drops lines.
  ::fcntl(out[1], F_SETFL, 0);
  ::fcntl(out[1], F_SETPIPE_SZ, 4096);
  tt::io::LineReader reader(in, "fuzz", tt::io::FollowOptions{});
  tt::io::BufferedWriter writer(out[1], "pipe", 1024);
  std::string_view line;
  std::string partial;
  try {
    if (reader.next(line, {})) {
      const std::vector<std::string> columns = tt::io::stream_columns(line, "fuzz");
      writer.text = tt::io::output_header(columns);
      writer.flush();
      Eigen::VectorXd values(static_cast<Eigen::Index>(columns.size()));
      long long lines = 0;
      while (reader.next(line, [&] { return writer.write_ready(); })) {
        double time = 0;
        std::string status = "malformed";
        if (tt::io::parsed_sample(line, time, values)) {
          if (std::isfinite(time) == false && !std::isnan(time)) std::abort();
          for (Eigen::Index k = 0; k < values.size(); ++k)
            if (std::isinf(values(k))) std::abort();
          status = "ok";
        }
        if (const std::size_t gap = writer.drop_behind(); gap > 0)
          status = tt::io::with_dropped(status, gap);
        tt::io::append_output_line(writer.text, time, values * 1e-6, values * 1e-6, status);
        writer.write_ready();
        if (++lines % 101 == 0) drain(out[0], partial);
      }
      drain(out[0], partial);
      writer.write_ready();
    }
  } catch (const tt::core::Error&) {
    // a refused header
  }
  ::close(out[1]);
  drain(out[0], partial);
  ::close(out[0]);
  ::close(in);
  return 0;
}
