// thermotwin compensate: live compensation from a fitted model. Reads sensor samples as they
// arrive and writes, per sample, the predicted thermal drift of every target with its uncertainty
// and a status.
//   thermotwin compensate --model FIT.json [--in FILE [--until-eof | --idle-s S]] [--out FILE]
//                         [--flush] [--poll-ms MS]
// Input: CSV lines in the measured-data format (docs/measured-data.md): a header time_s,<ids...>,
// then one sample per line; on standard input (to its end) or from FILE, followed as it grows.
// Output (stdout or FILE): time_s, <target>_predicted_um, <target>_sigma_um per target, status.
// See docs/compensate.md for the statuses, the stop conditions and what is not covered.
// 1. The chosen model of each target from fit.json (io::read_deployed_models).
// 2. The stream's header bound to the models' sensors and inputs by name (fitting::Compensator):
//    a column a model reads that the header lacks refuses the stream, naming it.
// 3. Sample by sample: parse, step the models, write one line; output is buffered and flushed when
//    the input pauses, per line with --flush or on a terminal.
#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <limits>
#include <optional>

#include "app/commands.hpp"
#include "core/errors.hpp"
#include "fitting/compensation.hpp"
#include "io/fit_model_in.hpp"
#include "io/sample_stream.hpp"

namespace tt::app {
namespace {

volatile std::sig_atomic_t stop_requested = 0;

extern "C" void request_stop(int) {
  stop_requested = 1;
}

/// Ctrl-C, SIGTERM and SIGHUP end the stream after the current line, with every line written.
/// No SA_RESTART: a blocking read returns, so the reader sees the request at once.
void stop_on_signals() {
  for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction on {};
    on.sa_handler = request_stop;
    sigemptyset(&on.sa_mask);
    ::sigaction(sig, &on, nullptr);
  }
}

/// Buffered writes to a file descriptor; flush() writes everything held.
class Output {
 public:
  Output(int fd, std::string name) : fd_(fd), name_(std::move(name)) { text.reserve(1 << 17); }
  std::string text;
  void flush() {
    std::size_t done = 0;
    while (done < text.size()) {
      const ssize_t n = ::write(fd_, text.data() + done, text.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) throw core::IoError(name_ + ": cannot write: " + std::strerror(errno));
      done += static_cast<std::size_t>(n);
    }
    text.clear();
  }

 private:
  int fd_;
  std::string name_;
};

/// A file descriptor closed when it goes out of scope.
struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd > 2) ::close(fd);
  }
};

}  // namespace

int compensate_command(const CompensateArgs& args) {
  // 1. The models.
  const std::vector<io::DeployedModel> deployed = io::read_deployed_models(args.model);
  std::vector<fitting::FittedModel> models;
  std::vector<std::string> targets;
  Eigen::VectorXd sigma(static_cast<Eigen::Index>(deployed.size()));
  for (std::size_t t = 0; t < deployed.size(); ++t) {
    models.push_back(deployed[t].model);
    targets.push_back(deployed[t].model.target_name);
    sigma(static_cast<Eigen::Index>(t)) = deployed[t].uncertainty;
  }

  // 2. The stream and its header.
  Fd in, out;
  const std::string in_name = args.in.empty() ? "standard input" : args.in.string();
  if (args.in.empty()) {
    in.fd = 0;
  } else {
    in.fd = ::open(args.in.c_str(), O_RDONLY | O_CLOEXEC);
    if (in.fd < 0) throw core::IoError(in_name + ": cannot open: " + std::strerror(errno));
  }
  io::FollowOptions follow;
  follow.follow = !args.in.empty() && !args.until_eof;
  follow.idle_s = args.idle_s;
  follow.poll_ms = args.poll_ms;
  stop_on_signals();
  io::LineReader reader(in.fd, in_name, follow, &stop_requested);
  std::string_view line;
  if (!reader.next(line, {}))
    throw core::DataError(in_name + ": no header line; expected time_s and the sensor ids");
  const std::vector<std::string> columns = io::stream_columns(line, in_name);
  std::optional<fitting::Compensator> compensator;
  try {
    compensator.emplace(models, columns);
  } catch (const core::DataError& e) {
    throw core::DataError(in_name + ": header refused: " + e.what());
  }
  if (args.out.empty()) {
    out.fd = 1;
  } else {
    out.fd = ::open(args.out.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (out.fd < 0)
      throw core::IoError(args.out.string() + ": cannot open for writing: " + std::strerror(errno));
  }
  Output output(out.fd, args.out.empty() ? "standard output" : args.out.string());
  const bool per_line = args.flush || ::isatty(out.fd);
  output.text = io::output_header(targets);
  output.flush();

  // 3. Sample by sample.
  const auto n = static_cast<Eigen::Index>(columns.size());
  Eigen::VectorXd values(n);
  Eigen::VectorXd last = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(models.size()),
                                                   std::numeric_limits<double>::quiet_NaN());
  const auto flush_held = [&] { output.flush(); };
  while (reader.next(line, flush_held)) {
    if (line.empty()) continue;
    double time = 0.0;
    if (!io::parsed_sample(line, time, values)) {
      // A torn or foreign line: skipped, the last prediction repeated.
      io::append_output_line(output.text, time, last, sigma, "malformed");
    } else {
      const fitting::LiveStep& step = compensator->next(time, values);
      if (step.status != fitting::SampleStatus::late) last = step.predicted;
      io::append_output_line(output.text, time, last, sigma, io::status_text(step, columns));
    }
    if (per_line || output.text.size() >= (std::size_t(1) << 16)) output.flush();
  }
  output.flush();
  return 0;
}

}  // namespace tt::app
