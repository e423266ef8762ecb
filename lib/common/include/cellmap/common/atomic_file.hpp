// SPDX-License-Identifier: Apache-2.0
#pragma once
// Crash-safe file output.

#include <filesystem>
#include <string_view>

namespace cellmap {

/// Replaces `path` with `contents` so that after a crash at any instant the file holds either the old or the
/// new contents, never a mix: writes a temporary file beside it, fsyncs it, renames it over `path` and fsyncs
/// the directory. Creates missing parent directories.
/// @throws Error naming the path and the system's reason if any step fails (the old file is then untouched).
void write_file_atomically(const std::filesystem::path& path, std::string_view contents);

/// Reads a whole file. @throws Error naming the path if it cannot be opened or read.
[[nodiscard]] std::string read_file(const std::filesystem::path& path);

}  // namespace cellmap
