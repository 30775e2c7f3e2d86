// Pieces of case-file text from which tests build their small cases: the header, a structural
// steel and box bodies. Numbers are passed as the text they should read as in the file.
#pragma once

#include <string>

namespace tt::test_toml {

/// `[case]` named `name` (plus `case_lines`, e.g. "seed = 7\n") and `[geometry]` in metres.
inline std::string header(const std::string& name, const std::string& case_lines = "") {
  return "[case]\nname = \"" + name + "\"\n" + case_lines + "[geometry]\nlength_unit = \"m\"\n";
}

/// `[materials.steel]`: a structural steel.
inline std::string steel() {
  return "[materials.steel]\ndensity_kg_m3 = 7850.0\nspecific_heat_J_kgK = 460.0\n"
         "conductivity_W_mK = 42.0\nyoungs_modulus_Pa = 2.1e11\npoisson_ratio = 0.3\n"
         "expansion_per_K = 1.2e-5\n";
}

/// A `[[bodies]]` entry of one box from `min` to `max` (each "[x, y, z]").
inline std::string box_body(const std::string& name, const std::string& material,
                            const std::string& max_edge, const std::string& min,
                            const std::string& max) {
  return "[[bodies]]\nname = \"" + name + "\"\nmaterial = \"" + material +
         "\"\nmax_edge = " + max_edge + "\nadd = [ { box = { min = " + min + ", max = " + max +
         " } } ]\n";
}

}  // namespace tt::test_toml
