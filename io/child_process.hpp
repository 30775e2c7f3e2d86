// Child programs (the plotter, the tests' runs of the CLI) start from an argument vector with
// posix_spawn, never through a shell: no argument (a case's name, a channel id, a path) is ever
// parsed as a command, whatever quotes, `$(...)`, backticks or newlines it holds.
#pragma once

#include <sys/types.h>

#include <filesystem>
#include <string>
#include <vector>

namespace tt::io {

/// Starts the program at argv[0] (a path, not looked up in PATH) with the arguments argv, as
/// they are. `env` entries "NAME=VALUE" are added to the environment or override it; stdout and
/// stderr are appended to `output` (created when missing) or inherited when it is empty. The
/// child starts with no signal blocked and SIGINT and SIGTERM at their default action. Throws
/// core::IoError when the program cannot start.
pid_t start_program(const std::vector<std::string>& argv, const std::vector<std::string>& env = {},
                    const std::filesystem::path& output = {});

/// The exit status of a child started by start_program, or 128 + the signal that ended it.
int wait_program(pid_t pid);

/// start_program, then wait_program: the exit status (127 when the program could not be run).
int run_program(const std::vector<std::string>& argv, const std::vector<std::string>& env = {},
                const std::filesystem::path& output = {});

}  // namespace tt::io
