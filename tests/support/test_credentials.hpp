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
    setup.ca_valid_until = setup.valid_until + std::chrono::hours(24);
    setup.grants = transport::role_grants(setup.cell);
    setup.existing_ca = plant_ca != nullptr;
    setup.ca = ca_ = plant_ca ? plant_ca->ca() : security::CaFolder{ca_dir_.path(), "test passphrase"};
    security::write_cell_credentials(setup);
  }
  /// The runtime folder.
  [[nodiscard]] const std::filesystem::path& directory() const { return dir_.path(); }
  /// The CAs that issued it (a plant's: the first cell's).
  [[nodiscard]] const security::CaFolder& ca() const { return ca_; }
  [[nodiscard]] security::Setting as(security::Role role) const { return {dir_.path(), role}; }
  /// `--security DIR --role R` for our programs.
  [[nodiscard]] std::vector<std::string> flags(security::Role role) const {
    return {"--security", dir_.path().string(), "--role", security::to_string(role)};
  }

 private:
  TempDir dir_{"cellmap-credentials"};
  TempDir ca_dir_{"cellmap-ca"};
  security::CaFolder ca_;
};

}  // namespace cellmap::test
