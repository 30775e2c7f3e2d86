#pragma once
// One table per enum for its stable names in files, reports and command lines: the name of a
// value and the value of a name both come from the same table, so the two directions cannot
// drift apart. A table sits beside its enum:
//
//   inline constexpr std::array<core::Named<Colour>, 2> kColourNames{{
//       {Colour::red, "red"}, {Colour::green, "green"}}};
//   static_assert(core::one_to_one(kColourNames));

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

namespace tt::core {

/// An enumerator and its name.
template <class Enum>
struct Named {
  Enum value;
  std::string_view name;
};

/// True when no value and no name appears twice (checked at compile time beside each table).
template <class Enum, std::size_t N>
constexpr bool one_to_one(const std::array<Named<Enum>, N>& table) {
  for (std::size_t i = 0; i < N; ++i)
    for (std::size_t j = i + 1; j < N; ++j)
      if (table[i].value == table[j].value || table[i].name == table[j].name) return false;
  return true;
}

/// The name of `value`; "unknown" for a value the table lacks (an enum cast from a bad integer).
template <class Enum, std::size_t N>
constexpr std::string_view name_in(const std::array<Named<Enum>, N>& table, Enum value) {
  for (const auto& entry : table)
    if (entry.value == value) return entry.name;
  return "unknown";
}

/// The value named `name`, or nothing.
template <class Enum, std::size_t N>
constexpr std::optional<Enum> value_in(const std::array<Named<Enum>, N>& table,
                                       std::string_view name) {
  for (const auto& entry : table)
    if (entry.name == name) return entry.value;
  return std::nullopt;
}

/// The names for an error message: "a, b or c".
template <class Enum, std::size_t N>
std::string names_list(const std::array<Named<Enum>, N>& table) {
  std::string out;
  for (std::size_t i = 0; i < N; ++i) {
    if (i > 0) out += i + 1 == N ? " or " : ", ";
    out += table[i].name;
  }
  return out;
}

}  // namespace tt::core
