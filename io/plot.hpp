// Figures: the one plotting entry point. app/plot.py run by Debian's /usr/bin/python3 (where
// matplotlib imports), started from an argument vector (io::run_program), never a shell string.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace tt::io {

/// Runs `script` under /usr/bin/python3 with these arguments, from an argument vector (no shell);
/// true when it exits 0. Its output is discarded.
bool run_python(const std::filesystem::path& script, const std::vector<std::string>& args);

/// Runs app/plot.py with these arguments; a missing matplotlib only skips the figure (a note on
/// stderr). Values that come from the user (titles, labels, column names) are passed as
/// "--option=value", so that one starting with '-' is not read as an option.
void plot(const std::vector<std::string>& args);

}  // namespace tt::io
