// SPDX-License-Identifier: Apache-2.0
#pragma once
// DDS Security credentials for one test cell and domain, written as `cellmap security init` writes them.

#include <chrono>
#include <string>
#include <vector>

#include "cellmap/security/cell_setup.hpp"
#include "cellmap/transport/topics.hpp"
#include "support/test_support.hpp"

namespace cellmap::test {

class TestCredentials {
 public:
  /// `plant_ca`: another cell's credentials, whose CAs issue these (a plant), instead of new CAs.
  TestCredentials(const std::string& cell, int domain, const TestCredentials* plant_ca = nullptr) {
    security::CellSetup setup;
    setup.directory = dir_.path();
    setup.cell = cell;
    setup.domain = static_cast<std::uint32_t>(domain);
    setup.valid_from = std::chrono::system_clock::now() - std::chrono::hours(1);
    setup.valid_until = setup.valid_from + std::chrono::hours(24);
    setup.grants = transport::role_grants(setup.cell);
    if (plant_ca) setup.plant_ca = plant_ca->directory();
    security::write_cell_credentials(setup);
  }
  [[nodiscard]] const std::filesystem::path& directory() const { return dir_.path(); }
  [[nodiscard]] security::Setting as(security::Role role) const { return {dir_.path(), role}; }
  /// `--security DIR --role R` for our programs.
  [[nodiscard]] std::vector<std::string> flags(security::Role role) const {
    return {"--security", dir_.path().string(), "--role", security::to_string(role)};
  }

 private:
  TempDir dir_{"cellmap-credentials"};
};

}  // namespace cellmap::test
