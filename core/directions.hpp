// The three directions of a displacement (x, y, z in the machine's frame) by their names in
// targets, files and reports: "dx", "dy", "dz" (a TCP target, "<point>_dy" an axis point's).
#pragma once

namespace tt::core {

inline constexpr const char* kDirectionNames[3] = {"dx", "dy", "dz"};

}  // namespace tt::core
