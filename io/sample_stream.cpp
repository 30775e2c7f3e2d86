#include "io/sample_stream.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <set>
#include <thread>

#include "core/csv_cells.hpp"
#include "core/errors.hpp"

namespace tt::io {

namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

/// A cell as a finite number, else NaN (empty, text, nan, inf).
double cell_value(std::string_view content) {
  const std::optional<double> v = core::cell_number(content);
  return v && std::isfinite(*v) ? *v : nan;
}

void append_number(std::string& out, double v) {
  char text[32];
  const auto [end, ec] = std::to_chars(text, text + sizeof text, v);
  out.append(text, ec == std::errc() ? static_cast<std::size_t>(end - text) : 0);
}

}  // namespace

LineReader::LineReader(int fd, std::string name, FollowOptions options,
                       const volatile std::sig_atomic_t* stop)
    : fd_(fd),
      name_(std::move(name)),
      options_(options),
      stop_(stop),
      buffer_(std::size_t(1) << 20) {}

StreamFd StreamFd::reading(const std::filesystem::path& path) {
  if (path.empty()) return StreamFd(0, "standard input");
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw core::IoError(path.string() + ": cannot open: " + std::strerror(errno));
  return StreamFd(fd, path.string());
}

StreamFd StreamFd::writing(const std::filesystem::path& path) {
  if (path.empty()) return StreamFd(1, "standard output");
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0)
    throw core::IoError(path.string() + ": cannot open for writing: " + std::strerror(errno));
  return StreamFd(fd, path.string());
}

StreamFd::~StreamFd() {
  if (fd_ > 2) ::close(fd_);
}

BufferedWriter::BufferedWriter(int fd, std::string name, std::size_t max_behind)
    : fd_(fd), name_(std::move(name)), max_behind_(max_behind) {
  text.reserve(1 << 17);
  struct stat st {};
  polled_ = ::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode);
}

bool BufferedWriter::write_ready() {
  while (written_ < text.size()) {
    std::size_t piece = text.size() - written_;
    if (polled_) {
      // POLLOUT on a pipe is a free buffer of at least PIPE_BUF bytes: a piece of that size is
      // taken without waiting. An error or a closed reader is left to write() to report.
      pollfd p{fd_, POLLOUT, 0};
      const int ready = ::poll(&p, 1, 0);
      if (ready < 0 && errno == EINTR) continue;
      if (ready == 0) break;
      piece = std::min<std::size_t>(piece, PIPE_BUF);
    }
    const ssize_t n = ::write(fd_, text.data() + written_, piece);
    if (n < 0 && (errno == EINTR || errno == EAGAIN)) continue;
    if (n < 0) throw core::IoError(name_ + ": cannot write: " + std::strerror(errno));
    written_ += static_cast<std::size_t>(n);
  }
  if (written_ == text.size()) {
    text.clear();
    written_ = 0;
    gap_at_ = std::string::npos;
    return true;
  }
  // Keep the held text from the start of the line being written.
  if (written_ >= (std::size_t(1) << 20)) {
    const std::size_t line = text.rfind('\n', written_ - 1);
    if (line != std::string::npos) {
      text.erase(0, line + 1);
      written_ -= line + 1;
      gap_at_ =
          gap_at_ != std::string::npos && gap_at_ > line ? gap_at_ - (line + 1) : std::string::npos;
    }
  }
  return false;
}

void BufferedWriter::flush() {
  while (written_ < text.size()) {
    const ssize_t n = ::write(fd_, text.data() + written_, text.size() - written_);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0 && errno == EAGAIN) {
      pollfd p{fd_, POLLOUT, 0};
      ::poll(&p, 1, -1);
      continue;
    }
    if (n < 0) throw core::IoError(name_ + ": cannot write: " + std::strerror(errno));
    written_ += static_cast<std::size_t>(n);
  }
  text.clear();
  written_ = 0;
  gap_at_ = std::string::npos;
}

std::size_t BufferedWriter::drop_behind() {
  if (max_behind_ == 0 || held() <= max_behind_) return 0;
  // The line being written is finished; every line after it goes.
  std::size_t from = written_;
  if (from > 0 && text[from - 1] != '\n') {
    const std::size_t end = text.find('\n', from);
    from = end == std::string::npos ? text.size() : end + 1;
  }
  auto gap = static_cast<std::size_t>(
      std::count(text.begin() + static_cast<std::ptrdiff_t>(from), text.end(), '\n'));
  // The last gap's line goes too: its gap joins this one.
  if (gap_at_ != std::string::npos && gap_at_ >= from) gap += gap_;
  text.resize(from);
  gap_ = gap;
  gap_at_ = from;
  return gap;
}

bool LineReader::fill(const std::function<bool()>& before_wait) {
  // Move the partial line to the front; grow when a line fills the buffer.
  if (begin_ > 0) {
    std::memmove(buffer_.data(), buffer_.data() + begin_, end_ - begin_);
    end_ -= begin_;
    begin_ = 0;
  }
  if (end_ == buffer_.size()) buffer_.resize(buffer_.size() * 2);
  auto idle_since = std::chrono::steady_clock::now();
  while (!(stop_ && *stop_)) {
    pollfd p{fd_, POLLIN, 0};
    // No input ready: write what the output takes; while it holds lines, look at the input again
    // every poll_ms instead of blocking on it, so that the output's reader is served meanwhile.
    if (::poll(&p, 1, 0) == 0 && before_wait)
      while (!before_wait() && !(stop_ && *stop_) && ::poll(&p, 1, options_.poll_ms) == 0) {
      }
    const ssize_t got = ::read(fd_, buffer_.data() + end_, buffer_.size() - end_);
    if (got > 0) {
      end_ += static_cast<std::size_t>(got);
      offset_ += got;
      return true;
    }
    if (got < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      throw core::IoError(name_ + ": cannot read: " + std::strerror(errno));
    }
    if (!options_.follow) {
      eof_ = true;
      return false;
    }
    // At the end of a growing file: wait for more, unless it shrank (truncated or replaced).
    struct stat st {};
    if (::fstat(fd_, &st) == 0 && S_ISREG(st.st_mode) && st.st_size < offset_)
      throw core::IoError(name_ + ": shrank from " + std::to_string(offset_) + " to " +
                          std::to_string(st.st_size) +
                          " bytes while followed; compensate follows a file that only grows");
    if (before_wait) before_wait();
    if (options_.idle_s > 0.0 &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - idle_since).count() >=
            options_.idle_s)
      return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(options_.poll_ms));
  }
  return false;
}

bool LineReader::next(std::string_view& line, const std::function<bool()>& before_wait) {
  for (;;) {
    if (stop_ && *stop_) return false;
    const char* from = buffer_.data() + begin_;
    const void* nl = std::memchr(from, '\n', end_ - begin_);
    if (nl) {
      const auto length = static_cast<std::size_t>(static_cast<const char*>(nl) - from);
      line = std::string_view(from, length);
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      begin_ += length + 1;
      return true;
    }
    if (eof_ || !fill(before_wait)) {
      if (!eof_ || begin_ == end_) return false;
      // The last line of a finished stream, with no line break.
      line = std::string_view(buffer_.data() + begin_, end_ - begin_);
      if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
      begin_ = end_;
      return true;
    }
  }
}

std::vector<std::string> stream_columns(std::string_view header, const std::string& origin) {
  header = core::without_byte_order_mark(header);
  std::vector<std::string> fields;
  for (std::size_t at = 0; at != std::string_view::npos;)
    fields.emplace_back(core::next_cell(header, at));
  if (fields.front() != "time_s")
    throw core::DataError(origin + ": header line 1 column 1 is '" + fields.front() +
                          "'; expected time_s (docs/measured-data.md)");
  std::set<std::string> seen;
  for (std::size_t c = 1; c < fields.size(); ++c) {
    if (fields[c].empty())
      throw core::DataError(origin + ": header line 1 column " + std::to_string(c + 1) +
                            " has no name");
    if (!seen.insert(fields[c]).second || fields[c] == "time_s")
      throw core::DataError(origin + ": header line 1 column " + std::to_string(c + 1) + " '" +
                            fields[c] + "' appears twice");
  }
  return {fields.begin() + 1, fields.end()};
}

bool parsed_sample(std::string_view line, double& time, Eigen::Ref<Eigen::VectorXd> values) {
  std::size_t at = 0;
  const Eigen::Index n = values.size();
  for (Eigen::Index field = -1;; ++field) {
    const double v = cell_value(core::next_cell(line, at));
    if (field < 0)
      time = v;
    else if (field < n)
      values(field) = v;
    else
      return false;
    if (at == std::string_view::npos) return field + 1 == n;
  }
}

std::string output_header(const std::vector<std::string>& targets) {
  std::string h = "time_s";
  for (const std::string& t : targets) h += "," + t + "_predicted_um," + t + "_sigma_um";
  return h + ",status\n";
}

std::string model_status(bool recalibrate, const std::vector<std::string>& faulty) {
  std::string s = recalibrate ? "recalibrate" : "";
  for (std::size_t k = 0; k < faulty.size(); ++k)
    s += (k ? ";" : (s.empty() ? "sensor_fault:" : "|sensor_fault:")) + faulty[k];
  return s;
}

std::string status_text(const core::LiveStep& step, const std::vector<std::string>& columns) {
  std::string s = core::status_name(step.status);
  for (std::size_t k = 0; k < step.held.size(); ++k)
    s += (k ? ";" : ":") + columns[static_cast<std::size_t>(step.held[k])];
  std::vector<std::string> faulty;
  for (int c : step.faulty) faulty.push_back(columns[static_cast<std::size_t>(c)]);
  const std::string model = model_status(step.recalibrate, faulty);
  if (model.empty()) return s;
  return step.status == core::SampleStatus::ok ? model : model + "|" + s;
}

std::string with_dropped(const std::string& status, std::size_t lines) {
  const std::string dropped = "dropped:" + std::to_string(lines);
  return status == "ok" ? dropped : status + "|" + dropped;
}

void append_output_line(std::string& out, double time, const Eigen::VectorXd& predicted,
                        const Eigen::VectorXd& sigma, std::string_view status) {
  if (std::isfinite(time)) append_number(out, time);
  for (Eigen::Index t = 0; t < predicted.size(); ++t) {
    out += ',';
    if (std::isfinite(predicted(t))) append_number(out, predicted(t) * 1e6);
    out += ',';
    if (std::isfinite(predicted(t))) append_number(out, sigma(t) * 1e6);
  }
  out += ',';
  out.append(status);
  out += '\n';
}

}  // namespace tt::io
