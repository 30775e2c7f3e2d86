// The CSV stream that `thermotwin compensate` reads and writes: lines of a file descriptor taken as
// they arrive (a pipe, or a file that still grows, followed like tail -f), the header and samples
// of the measured-data format (docs/measured-data.md: time_s, then inputs and sensor ids), and the
// output lines. Strings stop here: a sample leaves as a time and a vector of values, NaN where a
// cell is empty or not a finite number.
#pragma once

#include <Eigen/Dense>
#include <csignal>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "core/live_step.hpp"

namespace tt::io {

/// A file descriptor closed when it goes out of scope (standard input and output are not).
class StreamFd {
 public:
  /// `path` opened for reading; empty: standard input. Throws IoError naming it.
  static StreamFd reading(const std::filesystem::path& path);
  /// `path` created or truncated for writing; empty: standard output. Throws IoError naming it.
  static StreamFd writing(const std::filesystem::path& path);
  StreamFd(StreamFd&& other) noexcept : fd_(other.fd_), name_(std::move(other.name_)) {
    other.fd_ = -1;
  }
  StreamFd(const StreamFd&) = delete;
  StreamFd& operator=(const StreamFd&) = delete;
  ~StreamFd();
  int fd() const { return fd_; }
  /// the file's name, or "standard input" / "standard output"
  const std::string& name() const { return name_; }

 private:
  StreamFd(int fd, std::string name) : fd_(fd), name_(std::move(name)) {}
  int fd_;
  std::string name_;
};

/// Lines held in `text` and written to a file descriptor without waiting for a slow reader:
/// write_ready() writes what the output takes now and holds the rest; once more than max_behind
/// bytes are held, drop_behind() drops the lines not yet begun (a line is never torn), so a reader
/// that falls behind loses lines instead of slowing the stream that feeds the writer.
class BufferedWriter {
 public:
  /// fd stays owned by the caller; name is used in messages; max_behind: the bytes held before
  /// lines are dropped (0: never).
  BufferedWriter(int fd, std::string name, std::size_t max_behind = 0);
  /// Lines to write, appended by the caller; the first `written` bytes are out already.
  std::string text;
  /// The bytes held: appended and not yet written.
  std::size_t held() const { return text.size() - written_; }
  /// Writes what the output takes without waiting: a pipe, socket or terminal in pieces of at
  /// most PIPE_BUF while poll says it takes them, a regular file whole. true when nothing is held.
  /// Throws IoError naming the output when a write fails.
  bool write_ready();
  /// Writes everything held, waiting for the output as long as it takes (the stream's end).
  void flush();
  /// When more than max_behind bytes are held: drops every line not yet begun and returns the
  /// gap the next line appended follows: the lines dropped now and, when the last gap's line is
  /// among them, that gap's lines. 0 when nothing is dropped.
  std::size_t drop_behind();

 private:
  int fd_;
  std::string name_;
  std::size_t max_behind_;
  std::size_t written_ = 0;
  bool polled_ = false;  /// not a regular file: poll before each piece
  /// the last gap's lines, and where in text the line after it starts while it is not begun
  std::size_t gap_ = 0, gap_at_ = std::string::npos;
};

/// How a LineReader treats the end of what has been written so far.
struct FollowOptions {
  /// wait for more lines at the end of the data (a file that grows); false: the end is the end
  bool follow = false;
  /// with follow: stop when nothing new arrived for this long [s]; <= 0: never
  double idle_s = 0.0;
  /// with follow: how often to look for new data at the end [ms]
  int poll_ms = 5;
};

/// Complete lines of a file descriptor, read in large blocks as they arrive.
class LineReader {
 public:
  /// fd stays owned by the caller; name is used in messages; stop (may be null) ends reading at
  /// the next line or wait when it becomes nonzero (a signal handler sets it).
  LineReader(int fd, std::string name, FollowOptions options,
             const volatile std::sig_atomic_t* stop = nullptr);

  /// The next line without its line break ("\r\n" too). false at the end: end of data (not
  /// following), the idle time passed, or stop was set. A last line with no line break is returned
  /// at the end of data when not following; when following it waits for its line break.
  /// before_wait is called whenever no data is ready and the reader is about to block or sleep;
  /// while it returns false (output still held), the reader looks at the input again every
  /// poll_ms and calls it again, instead of blocking.
  bool next(std::string_view& line, const std::function<bool()>& before_wait);

 private:
  bool fill(const std::function<bool()>& before_wait);
  int fd_;
  std::string name_;
  FollowOptions options_;
  const volatile std::sig_atomic_t* stop_;
  std::vector<char> buffer_;
  std::size_t begin_ = 0, end_ = 0;
  long long offset_ = 0;
  bool eof_ = false;
};

/// The columns after time_s of a stream's header line (after a UTF-8 byte-order mark, which a
/// spreadsheet may write). Throws DataError naming `origin` when the first column is not time_s,
/// or a column name is empty or repeated.
std::vector<std::string> stream_columns(std::string_view header, const std::string& origin);

/// One sample line: false when it does not have 1 + values.size() fields. Otherwise time [s] (NaN
/// when not a finite number) and values (NaN where a cell is empty or not a finite number).
bool parsed_sample(std::string_view line, double& time, Eigen::Ref<Eigen::VectorXd> values);

/// The output header: time_s, then per target <target>_predicted_um and <target>_sigma_um, then
/// status.
std::string output_header(const std::vector<std::string>& targets);

/// What the observer says of the machine and its sensors: "recalibrate", "sensor_fault:T07;T11"
/// (the sensors found off by an offset, by name), both joined by '|', or "" when neither.
std::string model_status(bool recalibrate, const std::vector<std::string>& faulty);

/// The status field of a step: "ok", "late", "held:T07;T08" or "waiting:T07" (the columns held
/// or still missing, by name); model_status in place of "ok" and before any other
/// ("recalibrate|held:T07", "sensor_fault:T11", "recalibrate|sensor_fault:T11|late").
/// columns: the stream's columns.
std::string status_text(const core::LiveStep& step, const std::vector<std::string>& columns);

/// `status` with "dropped:N" added (in place of "ok"): N output lines before this one were dropped
/// because the output's reader fell behind (BufferedWriter::drop_behind).
std::string with_dropped(const std::string& status, std::size_t lines);

/// Appends one output line: the time, predicted errors and their 1-σ [µm] (empty fields where
/// predicted is NaN, as while waiting), and the status. predicted, sigma: #targets [m].
void append_output_line(std::string& out, double time, const Eigen::VectorXd& predicted,
                        const Eigen::VectorXd& sigma, std::string_view status);

}  // namespace tt::io
