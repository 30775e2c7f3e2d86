#include "io/sample_stream.hpp"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <thread>

#include "core/errors.hpp"

namespace tt::io {

namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

std::string_view trimmed(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

/// A cell as a finite number, else NaN (empty, text, nan, inf).
double cell_value(std::string_view cell) {
  cell = trimmed(cell);
  if (cell.empty()) return nan;
  if (cell.front() == '+') cell.remove_prefix(1);
  double v = nan;
  const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v);
  if (ec != std::errc() || end != cell.data() + cell.size() || !std::isfinite(v)) return nan;
  return v;
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

BufferedWriter::BufferedWriter(int fd, std::string name) : fd_(fd), name_(std::move(name)) {
  text.reserve(1 << 17);
}

void BufferedWriter::flush() {
  std::size_t done = 0;
  while (done < text.size()) {
    const ssize_t n = ::write(fd_, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw core::IoError(name_ + ": cannot write: " + std::strerror(errno));
    done += static_cast<std::size_t>(n);
  }
  text.clear();
}

bool LineReader::fill(const std::function<void()>& before_wait) {
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
    if (::poll(&p, 1, 0) == 0 && before_wait) before_wait();
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

bool LineReader::next(std::string_view& line, const std::function<void()>& before_wait) {
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
  std::vector<std::string> fields;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = header.find(',', start);
    fields.emplace_back(trimmed(header.substr(start, comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
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
  std::size_t start = 0;
  const Eigen::Index n = values.size();
  for (Eigen::Index field = -1;; ++field) {
    const std::size_t comma = line.find(',', start);
    const double v = cell_value(line.substr(start, comma - start));
    if (field < 0)
      time = v;
    else if (field < n)
      values(field) = v;
    else
      return false;
    if (comma == std::string_view::npos) return field + 1 == n;
    start = comma + 1;
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
