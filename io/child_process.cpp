#include "io/child_process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <cstring>

#include "core/errors.hpp"

extern char** environ;

namespace tt::io {

namespace {

std::string name_of(const std::string& entry) {
  return entry.substr(0, entry.find('='));
}

/// This process's environment with `overrides` ("NAME=VALUE") added or replacing.
std::vector<std::string> environment_with(const std::vector<std::string>& overrides) {
  std::vector<std::string> out;
  for (char** e = environ; e && *e; ++e) {
    const std::string entry(*e);
    bool replaced = false;
    for (const auto& o : overrides) replaced = replaced || name_of(o) == name_of(entry);
    if (!replaced) out.push_back(entry);
  }
  out.insert(out.end(), overrides.begin(), overrides.end());
  return out;
}

std::vector<char*> c_strings(std::vector<std::string>& strings) {
  std::vector<char*> out;
  for (auto& s : strings) out.push_back(s.data());
  out.push_back(nullptr);
  return out;
}

/// posix_spawn's attribute and file-action objects, destroyed on every path.
struct SpawnSetup {
  posix_spawnattr_t attr;
  posix_spawn_file_actions_t actions;
  SpawnSetup() {
    posix_spawnattr_init(&attr);
    posix_spawn_file_actions_init(&actions);
  }
  ~SpawnSetup() {
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attr);
  }
  SpawnSetup(const SpawnSetup&) = delete;
  SpawnSetup& operator=(const SpawnSetup&) = delete;
};

}  // namespace

pid_t start_program(const std::vector<std::string>& argv, const std::vector<std::string>& env,
                    const std::filesystem::path& output) {
  if (argv.empty() || argv[0].empty())
    throw core::IoError("start_program: no program given: expected its path as argv[0]");
  std::vector<std::string> args = argv;
  std::vector<std::string> envs = environment_with(env);
  std::vector<char*> cargv = c_strings(args), cenv = c_strings(envs);
  SpawnSetup setup;
  // A signal blocked or ignored here (by a caller, or by a shell that started it in the
  // background) must not stay so in the child: Ctrl-C and kill end it as they would end a program
  // started from a terminal.
  sigset_t none, interrupts;
  sigemptyset(&none);
  sigemptyset(&interrupts);
  sigaddset(&interrupts, SIGINT);
  sigaddset(&interrupts, SIGTERM);
  posix_spawnattr_setsigmask(&setup.attr, &none);
  posix_spawnattr_setsigdefault(&setup.attr, &interrupts);
  posix_spawnattr_setflags(&setup.attr, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETSIGDEF);
  if (!output.empty()) {
    posix_spawn_file_actions_addopen(&setup.actions, 1, output.c_str(),
                                     O_WRONLY | O_CREAT | O_APPEND, 0644);
    posix_spawn_file_actions_adddup2(&setup.actions, 1, 2);
  }
  pid_t pid = 0;
  const int rc =
      posix_spawn(&pid, cargv[0], &setup.actions, &setup.attr, cargv.data(), cenv.data());
  if (rc != 0)
    throw core::IoError(argv[0] + ": cannot start: " + std::strerror(rc) +
                        (output.empty() ? "" : " (output to " + output.string() + ")"));
  return pid;
}

int wait_program(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return 127;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

int run_program(const std::vector<std::string>& argv, const std::vector<std::string>& env,
                const std::filesystem::path& output) {
  pid_t pid = 0;
  try {
    pid = start_program(argv, env, output);
  } catch (const core::IoError&) {
    return 127;
  }
  return wait_program(pid);
}

}  // namespace tt::io
