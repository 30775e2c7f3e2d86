// Every bound on a size that input decides, in one place: a case, a data file or a command-line
// option may ask for any number, and each count below is checked before anything of that size is
// allocated, with an error that names the key and the limit. docs/reliability.md ("Limits") lists
// them with how to raise each one.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "core/units.hpp"

namespace tt::core::limits {

/// Bytes of a case file (TOML). The largest shipped case is about 12 kB.
inline constexpr std::uintmax_t kCaseFileBytes = std::uintmax_t(16) << 20;
/// Bytes of a duty-cycle CSV named by a case (duty_cycle.csv): a row per speed change.
inline constexpr std::uintmax_t kDutyCycleFileBytes = std::uintmax_t(64) << 20;
/// Bytes of a raw probe CSV (probes --in) or a drift history CSV (--truth): 10 kHz samples.
inline constexpr std::uintmax_t kProbeFileBytes = std::uintmax_t(1) << 30;

/// Time steps of one thermal run: duty_cycle.end_s / thermal.step_s (also fit --hours).
/// 20 h at 1 s is 72 000; each step holds no memory, but each costs a solve.
inline constexpr std::int64_t kTimeSteps = 5'000'000;
/// Output times of one run: duty_cycle.end_s / thermal.output_interval_s. The whole field is
/// kept at each of them (#nodes doubles, four times that with displacements).
inline constexpr std::int64_t kOutputTimes = 200'000;
/// Bytes of the histories kept in memory: (#output times + 1) x #nodes x (1 temperature + 3
/// displacements) doubles.
inline constexpr std::uintmax_t kHistoryBytes = std::uintmax_t(16) << 30;

/// Absolute zero [degC]: no temperature given in degC may lie below it.
inline constexpr double kAbsoluteZeroDegC = -kCelsiusOffset;

// Defaults of the meshing bounds that a case may raise under [mesh].
/// mesh.max_tets: tetrahedra estimated before TetGen starts. SB-1 refined is about 254 000.
inline constexpr double kDefaultMaxTets = 5'000'000;
/// mesh.time_limit_s: wall time of the TetGen child.
inline constexpr double kDefaultMeshTimeLimitS = 3600;
/// mesh.memory_limit_GB: address space the TetGen child may add to what it inherits.
inline constexpr double kDefaultMeshMemoryLimitGB = 8;

/// The bytes of `file`, read in chunks whatever it is (a regular file, a device, a pipe); nullopt
/// as soon as it holds more than `max_bytes`. Throws IoError when it cannot be opened or read.
std::optional<std::string> file_text_up_to(const std::filesystem::path& file,
                                           std::uintmax_t max_bytes);

/// "16 MiB", "1 GiB", "123 bytes": a byte limit for messages.
std::string bytes_text(std::uintmax_t bytes);

}  // namespace tt::core::limits
