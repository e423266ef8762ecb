// SPDX-License-Identifier: Apache-2.0
// `cellmap security init DIR --cell C [--domain N] [--days D] [--plant-ca DIR0]`: the DDS Security
// credentials of one cell (with new CAs, or with those of another cell of the plant).
#include <chrono>
#include <iostream>

#include "cellmap/common/error.hpp"
#include "cellmap/security/cell_setup.hpp"
#include "cellmap/transport/topics.hpp"
#include "commands.hpp"

namespace cellmap::cli {
namespace {

struct InitOptions {
  std::string directory;
  std::string cell;
  std::uint32_t domain = 0;
  int days = 365;
  std::string plant_ca;
};

void init(const InitOptions& options) {
  security::CellSetup setup;
  setup.directory = options.directory;
  setup.cell = options.cell;
  setup.domain = options.domain;
  // An hour back: a plant machine whose clock is a little behind still accepts fresh credentials.
  const auto now = std::chrono::system_clock::now();
  setup.valid_from = now - std::chrono::hours(1);
  setup.valid_until = now + std::chrono::hours(24) * options.days;
  setup.grants = transport::role_grants(setup.cell);
  setup.plant_ca = options.plant_ca;
  security::write_cell_credentials(setup);
  std::cout << "wrote the DDS Security credentials of cell '" << setup.cell << "' on DDS domain "
            << setup.domain << " into " << setup.directory.string() << "\n"
            << "  roles: daemon, planner, robot, tool (each in its folder; private keys mode 0600), in DDS "
            << "partition " << transport::cell_partition(setup.cell) << " only\n"
            << "  CA private keys: " << ((setup.plant_ca.empty() ? setup.directory : setup.plant_ca) / "ca").string()
            << " (needed only to issue credentials: keep them offline)\n"
            << "  certificates and permissions expire " << security::utc_text(setup.valid_until) << " (in "
            << options.days << " days)" << std::endl;
}

}  // namespace

void add_security_command(CLI::App& app) {
  CLI::App* command = app.add_subcommand("security", "DDS Security credentials of a cell");
  command->require_subcommand(1);
  auto options = std::make_shared<InitOptions>();
  CLI::App* init_command = command->add_subcommand(
      "init", "Create a cell's CAs, one identity per role, the governance and permissions documents");
  init_command->add_option("directory", options->directory, "new (or empty) directory to write")->required();
  init_command->add_option("--cell", options->cell, "the cell id")->required();
  init_command->add_option("--domain", options->domain, "the DDS domain id the credentials allow")
      ->check(CLI::Range(0, 232))
      ->capture_default_str();
  init_command->add_option("--days", options->days, "days the certificates and permissions stay valid")
      ->check(CLI::Range(1, 36500))
      ->capture_default_str();
  init_command->add_option("--plant-ca", options->plant_ca,
                           "issue with the CAs of this credentials directory of another cell (its ca/ "
                           "keys), so that the plant's cells authenticate each other; default: new CAs")
      ->check(CLI::ExistingDirectory);
  init_command->callback([options] { init(*options); });
}

}  // namespace cellmap::cli
