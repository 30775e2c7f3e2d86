// What the network's engine (the module libthermotwin_torch.so, network.cpp) gives the rest of
// the program: a table of its functions, which engine_loader.cpp reads on the first call of one of
// network.hpp's free functions. Torch-free: both sides include it.
#pragma once

#include "fitting/torch/network.hpp"

namespace tt::torchnet {

/// Changed whenever this table or network.hpp's types change, so that a module from another
/// build is refused rather than called.
inline constexpr int engine_abi = 1;
/// The module's one exported symbol: extern "C" const EngineFunctions* tt_torchnet_engine().
inline constexpr const char* engine_entry = "tt_torchnet_engine";

/// network.hpp's free functions, as the engine defines them: the types are those declarations'.
struct EngineFunctions {
  int abi;
  decltype(&::tt::torchnet::trained_network) trained_network;
  decltype(&::tt::torchnet::loaded_network) loaded_network;
  decltype(&::tt::torchnet::torchscript_prediction) torchscript_prediction;
  decltype(&::tt::torchnet::parallel_info) parallel_info;
};

}  // namespace tt::torchnet
