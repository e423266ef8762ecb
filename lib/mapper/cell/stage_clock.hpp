// SPDX-License-Identifier: Apache-2.0
#pragma once
// Timing of the cell pipeline's stages (internal): wall time, and CPU time of the calling thread with the
// helper threads it split its work onto.

#include <chrono>

#include "cellmap/common/parallel.hpp"

namespace cellmap {

class StageClock {
 public:
  StageClock() : wall_(std::chrono::steady_clock::now()), cpu_(cpu_seconds_with_helpers()) {}
  // Adds the seconds since construction (wall, then CPU) to `wall` and `cpu`.
  void add_to(double& wall, double& cpu) const {
    wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_).count();
    cpu += cpu_seconds_with_helpers() - cpu_;
  }

 private:
  std::chrono::steady_clock::time_point wall_;
  double cpu_;
};

}  // namespace cellmap
