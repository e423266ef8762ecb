// SPDX-License-Identifier: Apache-2.0
#pragma once
// What every harness shares: the input as a file (for readers that take a path) and the rule that a reader
// either accepts its input or refuses it with cellmap::Error whose message is one line. Any other exception,
// a crash, a hang (-timeout) or a huge allocation (-malloc_limit_mb) is a finding.

#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "cellmap/common/error.hpp"

namespace cellmap::fuzz {

/// The input as text.
inline std::string text(const std::uint8_t* data, std::size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

/// A directory of this process (removed at exit), for readers that take paths.
inline const std::filesystem::path& scratch_directory() {
  static const std::filesystem::path dir = [] {
    const std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("cellmap_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(path);
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(
          std::filesystem::temp_directory_path() / ("cellmap_fuzz_" + std::to_string(::getpid())), ec);
    });
    return path;
  }();
  return dir;
}

/// Writes `bytes` to `name` in the scratch directory (replacing it) and returns the path.
inline std::filesystem::path write_input(const std::string& name, const std::string& bytes) {
  const std::filesystem::path path = scratch_directory() / name;
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

/// Runs `read`; a cellmap::Error is the expected refusal, but its message must be one line.
template <typename Read>
void accept_or_refuse(Read&& read) {
  try {
    read();
  } catch (const Error& e) {
    if (std::strchr(e.what(), '\n') != nullptr) {
      std::fprintf(stderr, "refusal is not one line: %s\n", e.what());
      std::abort();
    }
  }
}

}  // namespace cellmap::fuzz
