// SPDX-License-Identifier: Apache-2.0
// `cellmap security init|export|issue|revoke`: a cell's DDS Security credentials, issued by CAs kept in a
// folder of their own (docs/security.md).
#include <openssl/ui.h>
#include <unistd.h>

#include <chrono>
#include <iostream>

#include "cellmap/common/atomic_file.hpp"
#include "cellmap/common/error.hpp"
#include "cellmap/security/cell_setup.hpp"
#include "cellmap/transport/topics.hpp"
#include "commands.hpp"

namespace cellmap::cli {
namespace {

namespace fs = std::filesystem;
using SystemClock = std::chrono::system_clock;

// Certificates longer than ten years outlive every key size and signature algorithm decision made today.
constexpr int kMaxDays = 3650;

struct PassphraseSource {
  std::string file;  // empty: ask on the terminal
};

struct InitOptions {
  std::string directory;
  std::string cell;
  std::uint32_t domain = 0;
  int days = 365;
  int ca_days = kMaxDays;
  std::string ca;
  std::string plant_ca;
  PassphraseSource passphrase;
};

struct ExportOptions {
  std::string directory;
  std::string role;
  std::string out;
};

struct IssueOptions {
  std::string directory;
  std::string role;
  std::string host;
  std::string out;
  std::string ca;
  int days = 365;
  PassphraseSource passphrase;
};

struct RevokeOptions {
  std::string certificate;
  std::string ca;
  std::vector<std::string> into;
  PassphraseSource passphrase;
};

// The CA passphrase: the first line of a file (kept out of argv, where `ps` shows it), or asked on the
// terminal (twice for new CAs).
std::string passphrase_from(const PassphraseSource& source, bool new_ca) {
  if (!source.file.empty()) {
    std::string text = read_file(source.file);
    text = text.substr(0, text.find('\n'));
    if (text.empty()) throw Error("--ca-passphrase-file: " + source.file + ": the first line is empty");
    return text;
  }
  if (::isatty(STDIN_FILENO) == 0) {
    throw Error(
        "the CA keys are encrypted: give --ca-passphrase-file FILE, or run on a terminal to be asked");
  }
  char buffer[1024] = {};
  if (EVP_read_pw_string(buffer, sizeof buffer, "CA passphrase: ", new_ca ? 1 : 0) != 0)
    throw Error("CA passphrase: not given or the two entries differ");
  std::string text(buffer);
  OPENSSL_cleanse(buffer, sizeof buffer);
  return text;
}

SystemClock::time_point days_from(SystemClock::time_point start, int days) {
  return start + std::chrono::hours(24) * days;
}

// An hour back: a plant machine whose clock is a little behind still accepts fresh credentials.
SystemClock::time_point valid_from_now() {
  return SystemClock::now() - std::chrono::hours(1);
}

// "DIR-ca" beside DIR: never inside it, so copying DIR to a host never copies the CA keys.
std::string default_ca_folder(const std::string& directory) {
  const fs::path path = fs::absolute(directory).lexically_normal();
  const fs::path named = path.has_filename() ? path : path.parent_path();
  return named.string() + "-ca";
}

void init(const InitOptions& options) {
  security::CellSetup setup;
  setup.directory = options.directory;
  setup.cell = options.cell;
  setup.domain = options.domain;
  setup.valid_from = valid_from_now();
  setup.valid_until = days_from(SystemClock::now(), options.days);
  setup.ca_valid_until = days_from(SystemClock::now(), options.ca_days);
  setup.grants = transport::role_grants(setup.cell);
  setup.existing_ca = !options.plant_ca.empty();
  setup.ca.directory = setup.existing_ca    ? options.plant_ca
                       : options.ca.empty() ? default_ca_folder(options.directory)
                                            : options.ca;
  setup.ca.passphrase = passphrase_from(options.passphrase, !setup.existing_ca);
  security::write_cell_credentials(setup);
  std::cout << "wrote the DDS Security credentials of cell '" << setup.cell << "' on DDS domain "
            << setup.domain << " into " << setup.directory.string() << "\n"
            << "  roles: daemon, planner, robot, tool (each in its folder; private keys mode 0600), in DDS "
            << "partition " << transport::cell_partition(setup.cell) << " only; give each host only its "
            << "role's: cellmap security export\n"
            << "  issued by the CAs in " << setup.ca.directory.string()
            << (setup.existing_ca ? " (the plant's)" : " (new; keys encrypted with the passphrase)")
            << ": needed only to issue and revoke, keep that folder off the cell's hosts\n"
            << "  certificates and permissions expire " << security::utc_text(setup.valid_until) << " (in "
            << options.days << " days)" << std::endl;
}

void export_role(const ExportOptions& options) {
  const security::Role role = security::parse_role(options.role);
  security::export_role(options.directory, role, options.out);
  std::cout << "wrote what a host of role " << options.role << " needs into " << options.out
            << " (no other role's key, no CA key): copy it to that host as it is, e.g. scp -rp" << std::endl;
}

void issue(const IssueOptions& options) {
  security::HostIdentity request;
  request.directory = options.directory;
  request.role = security::parse_role(options.role);
  request.host = options.host;
  request.grants = transport::role_grants(security::read_cell_of(options.directory).cell).at(request.role);
  request.valid_from = valid_from_now();
  request.valid_until = days_from(SystemClock::now(), options.days);
  request.ca = {options.ca, passphrase_from(options.passphrase, false)};
  request.out = options.out;
  security::issue_host_identity(request);
  std::cout << "wrote the identity " << options.role << "@" << options.host << " into " << options.out
            << " (run there with --security DIR --role " << options.role << "); it expires "
            << security::utc_text(request.valid_until) << "; revoke it alone with: cellmap security revoke "
            << (fs::path(options.out) / options.role / "identity.pem").string() << " --ca " << options.ca
            << std::endl;
}

void revoke(const RevokeOptions& options) {
  const std::vector<fs::path> into(options.into.begin(), options.into.end());
  const std::string subject =
      security::revoke(options.certificate, {options.ca, passphrase_from(options.passphrase, false)}, into);
  std::cout << "revoked " << subject << " in " << (fs::path(options.ca) / "revoked.crl").string();
  for (const fs::path& directory : into) std::cout << ", copied into " << directory.string();
  std::cout << "\n  every host must get the new revoked.crl (export again, or copy it beside governance.p7s) "
            << "and restart: a participant checks the list when it starts" << std::endl;
}

void add_passphrase_option(CLI::App* command, PassphraseSource& source) {
  command
      ->add_option("--ca-passphrase-file", source.file,
                   "the CA passphrase is this file's first line; default: asked on the terminal")
      ->check(CLI::ExistingFile);
}

void add_days_option(CLI::App* command, int& days, const char* what) {
  command->add_option("--days", days, what)->check(CLI::Range(1, kMaxDays))->capture_default_str();
}

void add_init(CLI::App* security) {
  auto options = std::make_shared<InitOptions>();
  CLI::App* command = security->add_subcommand(
      "init",
      "Create a cell's credentials: one identity per role, the governance and permissions documents, "
      "issued by new CAs (or the plant's)");
  command->add_option("directory", options->directory, "new (or empty) runtime folder to write")->required();
  command->add_option("--cell", options->cell, "the cell id")->required();
  command->add_option("--domain", options->domain, "the DDS domain id the credentials allow")
      ->check(CLI::Range(0, 232))
      ->capture_default_str();
  add_days_option(command, options->days, "days the certificates and permissions stay valid");
  command->add_option("--ca-days", options->ca_days, "days new CAs stay valid (at least --days)")
      ->check(CLI::Range(1, kMaxDays))
      ->capture_default_str();
  CLI::Option* ca =
      command->add_option("--ca", options->ca,
                          "new (or empty) folder for the new CAs; default: DIR-ca beside the runtime folder");
  command
      ->add_option("--plant-ca", options->plant_ca,
                   "issue with the CAs of this CA folder (another cell's), so that the plant's cells "
                   "authenticate each other; default: new CAs")
      ->check(CLI::ExistingDirectory)
      ->excludes(ca);
  add_passphrase_option(command, options->passphrase);
  command->callback([options] { init(*options); });
}

void add_export(CLI::App* security) {
  auto options = std::make_shared<ExportOptions>();
  CLI::App* command = security->add_subcommand(
      "export", "Copy what one host of a role needs, and nothing else, into a folder");
  command->add_option("directory", options->directory, "the cell's runtime folder (security init)")
      ->required()
      ->check(CLI::ExistingDirectory);
  command->add_option("--role", options->role, "daemon, planner, robot or tool")->required();
  command->add_option("-o,--out", options->out, "new (or empty) folder to write")->required();
  command->callback([options] { export_role(*options); });
}

void add_issue(CLI::App* security) {
  auto options = std::make_shared<IssueOptions>();
  CLI::App* command = security->add_subcommand(
      "issue",
      "A host's own identity of a role (CN=<role>@<host>), to revoke alone, in a folder for that host");
  command->add_option("directory", options->directory, "the cell's runtime folder (security init)")
      ->required()
      ->check(CLI::ExistingDirectory);
  command->add_option("--role", options->role, "daemon, planner, robot or tool")->required();
  command->add_option("--host", options->host, "the host's name (1-64 of A-Z a-z 0-9 . _ -)")->required();
  command->add_option("-o,--out", options->out, "new (or empty) folder to write")->required();
  command->add_option("--ca", options->ca, "the CA folder that issued the cell")
      ->required()
      ->check(CLI::ExistingDirectory);
  add_days_option(command, options->days, "days the certificate and permissions stay valid");
  add_passphrase_option(command, options->passphrase);
  command->callback([options] { issue(*options); });
}

void add_revoke(CLI::App* security) {
  auto options = std::make_shared<RevokeOptions>();
  CLI::App* command = security->add_subcommand(
      "revoke", "Revoke an identity: add its certificate to the CA's revocation list");
  command->add_option("certificate", options->certificate, "the identity's certificate (<role>/identity.pem)")
      ->required()
      ->check(CLI::ExistingFile);
  command->add_option("--ca", options->ca, "the CA folder that issued it")
      ->required()
      ->check(CLI::ExistingDirectory);
  command->add_option("--into", options->into, "runtime folders to copy the new list into (repeatable)")
      ->check(CLI::ExistingDirectory);
  add_passphrase_option(command, options->passphrase);
  command->callback([options] { revoke(*options); });
}

}  // namespace

void add_security_command(CLI::App& app) {
  CLI::App* command = app.add_subcommand("security", "DDS Security credentials of a cell");
  command->require_subcommand(1);
  add_init(command);
  add_export(command);
  add_issue(command);
  add_revoke(command);
}

}  // namespace cellmap::cli
