// The CLI's commands. Each is a thin driver: numbered steps that follow the data flow, from
// reading inputs to writing one output directory atomically.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace tt::app {

struct MeshArgs {
  std::filesystem::path case_file, out;
};
struct RunArgs {
  std::filesystem::path case_file, out;
  bool quiet = false;
};

int mesh_command(const MeshArgs& args);
int run_command(const RunArgs& args);

/// Progress on stderr, at most every 10 % of the simulated time.
void report_progress(const std::string& stage, double done, double total);

}  // namespace tt::app
