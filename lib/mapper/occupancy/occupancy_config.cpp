// SPDX-License-Identifier: Apache-2.0
#include "cellmap/occupancy/occupancy_config.hpp"

#include <cmath>
#include <sstream>
#include <string>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

double logodds(double p) {
  return std::log(p / (1.0 - p));
}

[[noreturn]] void bad(const std::string& field, const std::string& rule, double value) {
  std::ostringstream msg;
  msg << "occupancy." << field << ": " << rule << ", got " << value;
  throw Error(msg.str());
}

}  // namespace

void OccupancyConfig::validate() const {
  if (!(resolution >= 0.001 && resolution <= 1.0)) bad("resolution", "must be in [0.001, 1] m", resolution);
  if (!(hit > 0.5 && hit < 1.0)) bad("hit", "must be in (0.5, 1)", hit);
  if (!(miss > 0.0 && miss < 0.5)) bad("miss", "must be in (0, 0.5)", miss);
  if (!(clamp_min > 0.0 && clamp_min < occupied_threshold)) {
    bad("clamp_min", "must be in (0, occupied_threshold)", clamp_min);
  }
  if (!(occupied_threshold > 0.0 && occupied_threshold < 1.0)) {
    bad("occupied_threshold", "must be in (0, 1)", occupied_threshold);
  }
  if (!(clamp_max > occupied_threshold && clamp_max < 1.0)) {
    bad("clamp_max", "must be in (occupied_threshold, 1)", clamp_max);
  }
  if (!(max_range > 0.0 && max_range <= 100.0)) bad("max_range", "must be in (0, 100] m", max_range);
  if (threads < 1 || threads > 64) bad("threads", "must be an integer in [1, 64]", threads);
}

int OccupancyConfig::sweeps_to_clear() const {
  // The tree stores single-precision log-odds; follow its arithmetic so the count is exact.
  const float miss_log = static_cast<float>(logodds(miss));
  const float threshold = static_cast<float>(logodds(occupied_threshold));
  float value = static_cast<float>(logodds(clamp_max));
  int sweeps = 0;
  while (value >= threshold) {
    value += miss_log;
    ++sweeps;
  }
  return sweeps;
}

int OccupancyConfig::sweeps_to_occupy() const {
  const float hit_log = static_cast<float>(logodds(hit));
  const float threshold = static_cast<float>(logodds(occupied_threshold));
  float value = static_cast<float>(logodds(clamp_min));
  int sweeps = 0;
  while (value < threshold) {
    value += hit_log;
    ++sweeps;
  }
  return sweeps;
}

OccupancyConfig OccupancyConfig::from_yaml(YamlMap section) {
  OccupancyConfig c;
  // Coarse ranges here so the message names the key; validate() then checks the relations between fields.
  c.resolution = section.number("resolution", c.resolution, 0.001, 1.0);
  c.hit = section.number("hit", c.hit, 0.5, 1.0);
  c.miss = section.number("miss", c.miss, 0.0, 0.5);
  c.clamp_min = section.number("clamp_min", c.clamp_min, 0.0, 1.0);
  c.clamp_max = section.number("clamp_max", c.clamp_max, 0.0, 1.0);
  c.occupied_threshold = section.number("occupied_threshold", c.occupied_threshold, 0.0, 1.0);
  c.max_range = section.number("max_range", c.max_range, 0.0, 100.0);
  c.threads = static_cast<int>(section.integer("threads", c.threads, 1, 64));
  section.expect_all_read();
  try {
    c.validate();
  } catch (const Error& e) {
    // Keep the file name in front when the section came from a file.
    if (section.source().empty()) throw;
    throw Error(section.source() + ": " + e.what());
  }
  return c;
}

}  // namespace cellmap
