#include "io/plot.hpp"

#include <iostream>

#include "io/child_process.hpp"

namespace tt::io {

bool run_python(const std::filesystem::path& script, const std::vector<std::string>& args) {
  std::vector<std::string> argv{"/usr/bin/python3", script.string()};
  argv.insert(argv.end(), args.begin(), args.end());
  // The script's own messages (a missing matplotlib) are not the command's: only the note below.
  return run_program(argv, {"MPLBACKEND=Agg"}, "/dev/null") == 0;
}

void plot(const std::vector<std::string>& args) {
  if (!run_python(std::filesystem::path(TT_SOURCE_DIR) / "app" / "plot.py", args))
    std::cerr << "thermotwin: note: plot skipped (" << args[0] << ")\n";
}

}  // namespace tt::io
