// How a study says what it is doing: one line per stage, which the command prints on stderr
// (unless --quiet). Stepping progress is solvers::Progress.
#pragma once

#include <functional>
#include <string>

namespace tt::studies {

/// Receives a line of progress (e.g. the number of blocks, each channel as it starts).
using Progress = std::function<void(const std::string&)>;

}  // namespace tt::studies
