// SPDX-License-Identifier: Apache-2.0
// Pins a defect of the Cyclone DDS that Debian ships (0.10.2), found by fuzz_dds_samples
// (fuzz/regressions/dds_samples/xcdr2_truncated_robot_state): dds_stream_normalize, the check the receive
// path runs on every payload before a reader may take it, bounds an XCDR2 payload's 8-byte values by 4 bytes
// each, so a truncated XCDR2 sample passes and the read (and, for the other byte order, the byte swap) that
// follows runs past the buffer. Fixed upstream in 11.0 (eclipse-cyclonedds commit 9dd9e75, "Fix in cdrstream
// check_align for XCDR2"). cellmap cannot filter payloads before Cyclone normalizes them, so the harness
// decodes XCDR1 only, which is checked right (the second half). When this test fails, the installed Cyclone
// is fixed: let the harness decode XCDR2 again and delete this test.
#include <dds/ddsi/ddsi_cdrstream.h>
#include <gtest/gtest.h>

#include <vector>

#include "cellmap.h"

namespace cellmap {
namespace {

// cellmap/robot_state for cell "c", cut after half of `orientation`: string (4 + 2), stamp_ns, position[3],
// orientation[4] end at byte 72 in XCDR2 (8-byte values aligned to 4) and 72 in XCDR1 (aligned to 8).
std::vector<char> truncated_robot_state() {
  std::vector<char> bytes(56, 0);
  bytes[0] = 2;  // string length, little-endian, with its NUL
  bytes[4] = 'c';
  return bytes;
}

TEST(CycloneCdrBoundsTest, Xcdr2TruncatedEightByteArrayPassesNormalize) {
  std::vector<char> bytes = truncated_robot_state();
  std::uint32_t end = 0;
  const bool accepted =
      dds_stream_normalize_data(bytes.data(), &end, static_cast<std::uint32_t>(bytes.size()), false, 2,
                                cellmap_msg_RobotState_desc.m_ops) != nullptr;
  EXPECT_TRUE(accepted && end == 72) << "Cyclone now refuses truncated XCDR2 (end " << end
                                     << "): decode XCDR2 in fuzz/dds_samples_fuzz.cpp again";
}

TEST(CycloneCdrBoundsTest, Xcdr1TruncatedEightByteArrayIsRefused) {
  std::vector<char> bytes = truncated_robot_state();
  std::uint32_t end = 0;
  EXPECT_EQ(dds_stream_normalize_data(bytes.data(), &end, static_cast<std::uint32_t>(bytes.size()), false, 1,
                                      cellmap_msg_RobotState_desc.m_ops),
            nullptr);
}

}  // namespace
}  // namespace cellmap
