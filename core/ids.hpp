// Strong ids, so that a region id, a boundary group id and a node index cannot be mixed.
#pragma once

#include <cstdint>

namespace tt::core {

enum class RegionId : std::int32_t {};
enum class BoundaryId : std::int32_t {};
enum class SensorId : std::int32_t {};

template <class Id>
constexpr std::int32_t index_of(Id id) {
  return static_cast<std::int32_t>(id);
}

}  // namespace tt::core
