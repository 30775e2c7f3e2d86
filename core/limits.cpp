#include "core/limits.hpp"

#include <fstream>
#include <vector>

#include "core/errors.hpp"

namespace tt::core::limits {

std::optional<std::string> file_text_up_to(const std::filesystem::path& file,
                                           std::uintmax_t max_bytes) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw IoError(file.string() + ": cannot open for reading");
  std::string text;
  std::vector<char> chunk(std::size_t(1) << 16);
  while (in) {
    in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    const auto got = static_cast<std::size_t>(in.gcount());
    if (text.size() + got > max_bytes) return std::nullopt;
    text.append(chunk.data(), got);
  }
  if (in.bad()) throw IoError(file.string() + ": cannot read");
  return text;
}

std::string bytes_text(std::uintmax_t bytes) {
  if (bytes >= (std::uintmax_t(1) << 30) && bytes % (std::uintmax_t(1) << 30) == 0)
    return std::to_string(bytes >> 30) + " GiB";
  if (bytes >= (std::uintmax_t(1) << 20) && bytes % (std::uintmax_t(1) << 20) == 0)
    return std::to_string(bytes >> 20) + " MiB";
  return std::to_string(bytes) + " bytes";
}

}  // namespace tt::core::limits
