// What the network's engine (the module libthermotwin_torch.so, network.cpp) gives the rest of
// the program: a table of its functions, which engine_loader.cpp reads on the first call of one of
// network.hpp's free functions. Torch-free: both sides include it.
#pragma once

#include <Eigen/Dense>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "fitting/torch/network.hpp"

namespace tt::torchnet {

/// Changed whenever this table or network.hpp's types change, so that a module from another
/// build is refused rather than called.
inline constexpr int engine_abi = 1;
/// The module's one exported symbol: extern "C" const EngineFunctions* tt_torchnet_engine().
inline constexpr const char* engine_entry = "tt_torchnet_engine";

struct EngineFunctions {
  int abi;
  Network (*trained_network)(const Sequences& fit, const Sequences& validation,
                             const NetworkOptions& options, const std::optional<LinearSkip>& skip);
  Network (*loaded_network)(const std::filesystem::path& file);
  Eigen::MatrixXd (*torchscript_prediction)(const std::filesystem::path& file,
                                            const std::vector<Eigen::MatrixXd>& windows);
  std::string (*parallel_info)();
};

}  // namespace tt::torchnet
