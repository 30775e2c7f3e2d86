// network.hpp's free functions: each loads the engine (libthermotwin_torch.so) on its first call
// and calls the engine's own. Looked for beside the running executable (build/thermotwin's
// folder, where the build writes it), then where this build wrote it (the tests' and benches'
// executables live in sub-folders).
#include <dlfcn.h>

#include <string>
#include <system_error>

#include "core/errors.hpp"
#include "fitting/torch/engine.hpp"
#include "fitting/torch/network.hpp"

namespace tt::torchnet {

namespace {

namespace fs = std::filesystem;

std::vector<fs::path> engine_places() {
  std::vector<fs::path> places;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) places.push_back(exe.parent_path() / TT_TORCH_ENGINE_NAME);
  const fs::path built(TT_TORCH_ENGINE_BUILT);
  if (places.empty() || built != places.front()) places.push_back(built);
  return places;
}

/// The engine's functions from the first place that holds a module of this build's table; throws
/// core::IoError naming every place tried and why it failed.
const EngineFunctions* loaded_engine() {
  std::string why;
  for (const fs::path& place : engine_places()) {
    std::error_code ec;
    if (!fs::is_regular_file(place, ec)) {
      why += "\n  " + place.string() + ": no such file";
      continue;
    }
    void* handle = dlopen(place.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (handle == nullptr) {
      const char* error = dlerror();
      why += "\n  " + place.string() + ": " + (error ? error : "cannot be loaded");
      continue;
    }
    using Entry = const EngineFunctions* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(handle, engine_entry));
    const EngineFunctions* functions = entry ? entry() : nullptr;
    // A module that is not this build's engine is left loaded: unloading a library that may have
    // started libtorch is not safe.
    if (functions == nullptr) {
      why += "\n  " + place.string() + ": not this build's engine (no " + engine_entry + ")";
    } else if (functions->abi != engine_abi) {
      why += "\n  " + place.string() + ": not this build's engine (table version " +
             std::to_string(functions->abi) + ", expected " + std::to_string(engine_abi) + ")";
    } else {
      return functions;
    }
  }
  throw core::IoError("the network needs its libtorch engine " + std::string(TT_TORCH_ENGINE_NAME) +
                      ", which could not be loaded:" + why +
                      "\n  hint: build the target tt_torch_engine (every build of thermotwin "
                      "builds it) and keep it beside the thermotwin executable");
}

/// Loaded once per process; a failed load is tried again on the next call.
const EngineFunctions& engine() {
  static const EngineFunctions* const functions = loaded_engine();
  return *functions;
}

}  // namespace

Network trained_network(const Sequences& fit, const Sequences& validation,
                        const NetworkOptions& options, const std::optional<LinearSkip>& skip) {
  return engine().trained_network(fit, validation, options, skip);
}

Network loaded_network(const std::filesystem::path& file) {
  return engine().loaded_network(file);
}

Eigen::MatrixXd torchscript_prediction(const std::filesystem::path& file,
                                       const std::vector<Eigen::MatrixXd>& windows) {
  return engine().torchscript_prediction(file, windows);
}

std::string parallel_info() {
  return engine().parallel_info();
}

}  // namespace tt::torchnet
