// Plain binary files of the project's own (checkpoints, reduced models): values appended to a byte
// string in native byte order, an FNV-1a checksum last, and a reader that refuses to run past the
// end. Native byte order: such a file is for the machine family that wrote it.
#pragma once

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <string_view>

#include "core/errors.hpp"

namespace tt::io {

/// FNV-1a over bytes, continuing from `h`.
inline std::uint64_t fnv1a(const void* data, std::size_t size,
                           std::uint64_t h = 0xcbf29ce484222325ull) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < size; ++i) h = (h ^ p[i]) * 0x100000001b3ull;
  return h;
}

/// Appends plain values and arrays of doubles to a byte string.
struct ByteWriter {
  std::string bytes;
  template <class T>
  void put(const T& v) {
    bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void put_doubles(const double* p, std::size_t n) {
    bytes.append(reinterpret_cast<const char*>(p), n * sizeof(double));
  }
  /// The checksum of everything so far, appended.
  void seal() { put(fnv1a(bytes.data(), bytes.size())); }
};

/// Reads them back. A short file is a DataError: "<what> truncated at byte N; <hint>".
struct ByteReader {
  std::string_view bytes;
  std::string what;  /// e.g. "run.checkpoint: checkpoint"
  std::string hint;  /// what to do about it
  std::size_t at = 0;
  void take(void* out, std::size_t n) {
    if (n > bytes.size() - at)
      throw core::DataError(what + " truncated at byte " + std::to_string(at) + "; " + hint);
    std::memcpy(out, bytes.data() + at, n);
    at += n;
  }
  template <class T>
  T get() {
    T v;
    take(&v, sizeof v);
    return v;
  }
  std::size_t left() const { return bytes.size() - at; }
};

/// Whether the trailing FNV-1a checksum matches the bytes before it.
inline bool checksum_matches(std::string_view bytes) {
  if (bytes.size() < sizeof(std::uint64_t)) return false;
  std::uint64_t stored;
  std::memcpy(&stored, bytes.data() + bytes.size() - sizeof stored, sizeof stored);
  return fnv1a(bytes.data(), bytes.size() - sizeof stored) == stored;
}

}  // namespace tt::io
