// SPDX-License-Identifier: Apache-2.0
#pragma once
// Checks of what a PCD or PLY header claims, made before PCL's readers see the file: PCL sizes its buffers by
// the header (a 5 KB PLY claiming 1e11 vertices made it allocate 14 GB), so the header must be well-formed,
// self-consistent, within cellmap's limits and backed by enough bytes in the file. Internal to lib/io.

#include <cstdint>
#include <string_view>

namespace cellmap::cloud_header {

/// PCL's header parsers stop after this many bytes at most; a longer header is refused.
inline constexpr std::size_t kMaxHeaderBytes = 64 * 1024;
/// One point's record (PCD) or one vertex (PLY), bytes: far above any real point type (a VFH descriptor
/// point is 1.3 KB).
inline constexpr std::uint64_t kMaxPointBytes = 64 * 1024;
/// Fields per point (PCD) or properties per element (PLY).
inline constexpr std::size_t kMaxFields = 256;

/// Checks a PCD header. `head` is the file's first bytes (kMaxHeaderBytes, or the whole file if shorter);
/// `file_size` the file's size. Accepts the header PCL writes: VERSION? FIELDS|COLUMNS SIZE TYPE COUNT? WIDTH
/// HEIGHT VIEWPOINT? POINTS DATA in this order, each once, with x, y and z among the fields.
/// @throws Error with a one-line reason (without the file name) if the header is malformed, claims more than
/// kMaxCloudPoints points or kMaxCloudBytes bytes, or more data than the file holds.
void check_pcd(std::string_view head, std::uint64_t file_size);

/// Checks a PLY header as check_pcd does: "ply", one format line, element and property lines (a `vertex`
/// element with scalar x, y and z; no `range_grid` element, no list in `vertex`), comments, obj_info, and
/// end_header; every element's claimed count must fit in the bytes after the header.
/// @throws Error with a one-line reason (without the file name) otherwise.
void check_ply(std::string_view head, std::uint64_t file_size);

}  // namespace cellmap::cloud_header
