// Fuzz target: any surface file is either read as a solid or rejected with a typed error. The
// first byte picks the format (STL, OFF, PLY), the rest is the file; it goes to a file of this
// process under /dev/shm because the reader takes a path.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/errors.hpp"
#include "mesh/cgal/surface_body.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  static const char* const extensions[] = {".stl", ".off", ".ply"};
  const std::string base = "/dev/shm/tt-fuzz-surface-" + std::to_string(::getpid());
  const std::filesystem::path file = base + extensions[data[0] % 3];
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), static_cast<std::streamsize>(size - 1));
  }
  try {
    const auto solid = tt::mesh::cgal::surface_solid(file, 1e-3, "fuzz body");
    // What the header promises of an accepted solid.
    if (!(solid.volume > 0) || !std::isfinite(solid.volume) || solid.surface.triangles.empty())
      std::abort();
    const int nv = static_cast<int>(solid.surface.vertices.size());
    for (const auto& t : solid.surface.triangles)
      for (int v : t)
        if (v < 0 || v >= nv) std::abort();
  } catch (const tt::core::Error&) {
    // a typed rejection is the expected answer to most inputs
  }
  std::filesystem::remove(file);
  return 0;
}
