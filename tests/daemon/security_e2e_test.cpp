// SPDX-License-Identifier: Apache-2.0
// DDS Security as an attacker meets it, with real processes on loopback: a participant without credentials
// (a forging process, and our own tools without --security, as anyone on the plant network can run them)
// on a secured cell's domain reaches nobody and receives nothing; each role can create only the writers and
// readers its permissions grant; an identity of another CA is refused by the peers; bad credentials stop a
// program at start with one line. Every role is a process of its own, as in a plant (and as Cyclone DDS
// requires: one security setting per domain and process).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <functional>
#include <map>
#include <optional>
#include <regex>
#include <set>

#include <nlohmann/json.hpp>

#include "cellmap/transport/status_reader.hpp"
#include "daemon/service_e2e.hpp"
#include "support/dds_domains.hpp"

namespace cellmap {
namespace {

using namespace std::chrono_literals;
using security::Role;

// The daemon's status once `done` holds for it, or a failure after the patience.
transport::CellStatus wait_for_status(transport::StatusReader& reader,
                                      const std::function<bool(const transport::CellStatus&)>& done) {
  transport::CellStatus last;
  const auto deadline = std::chrono::steady_clock::now() + test::kDaemonPatience;
  while (std::chrono::steady_clock::now() < deadline) {
    for (const transport::CellStatus& status : reader.take(200ms)) {
      last = status;
      if (done(status)) return status;
    }
  }
  ADD_FAILURE() << "the daemon's status never got there (last: version " << last.version << ", "
                << last.sweeps << " sweeps, " << last.refused_inputs << " refused)";
  return last;
}

// The status after `sweeps` more sweeps than `now`: a window in which anything sent before would have acted.
transport::CellStatus after_sweeps(transport::StatusReader& reader, const transport::CellStatus& now,
                                   std::uint64_t sweeps) {
  return wait_for_status(reader,
                         [&](const transport::CellStatus& s) { return s.sweeps >= now.sweeps + sweeps; });
}

// A program with stderr on stdout.
std::unique_ptr<test::ChildProcess> start(std::vector<std::string> argv) {
  argv.insert(argv.begin(), {"/bin/sh", "-c", "exec \"$0\" \"$@\" 2>&1"});
  return std::make_unique<test::ChildProcess>(argv);
}

// Cyclone DDS prints some of its own warnings on stdout ("1796061733.000847 [193] dq.builtin: Remote secure
// participant ... not allowed"); they are not the probe's lines.
bool is_cyclone_log(const std::string& line) {
  static const std::regex kCycloneLog(R"(^\d+\.\d+ \[\d+\] )");
  return std::regex_search(line, kCycloneLog);
}

std::optional<std::string> read_probe_line(test::ChildProcess& process,
                                           std::chrono::milliseconds timeout = test::kDaemonPatience) {
  std::optional<std::string> line;
  do {
    line = process.read_line(timeout);
  } while (line && is_cyclone_log(*line));
  return line;
}

// Every line the program printed until it ended, and its exit code.
std::vector<std::string> finish(test::ChildProcess& process, int* exit_code) {
  std::vector<std::string> lines;
  while (std::optional<std::string> line = read_probe_line(process)) lines.push_back(*line);
  const int status = process.wait();
  *exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return lines;
}

std::vector<std::string> run(const std::vector<std::string>& argv, int* exit_code) {
  return finish(*start(argv), exit_code);
}

// A security_probe process (one participant: `role` from `credentials`, or none without them).
std::vector<std::string> probe(int domain, const std::string& cell, std::vector<std::string> mode,
                               const test::TestCredentials* credentials = nullptr,
                               Role role = Role::kDaemon) {
  std::vector<std::string> argv{SECURITY_PROBE, std::to_string(domain), cell};
  argv.insert(argv.end(), mode.begin(), mode.end());
  if (credentials) {
    const std::vector<std::string> flags = credentials->flags(role);
    argv.insert(argv.end(), flags.begin(), flags.end());
  }
  return argv;
}

// Stops a serving or forging probe and returns its last line as JSON.
nlohmann::json stop(test::ChildProcess& process) {
  process.signal(SIGTERM);
  int code = 0;
  const std::vector<std::string> lines = finish(process, &code);
  EXPECT_EQ(code, 0);
  if (lines.empty()) {
    ADD_FAILURE() << "the probe printed nothing at the end";
    return nlohmann::json::object();
  }
  return nlohmann::json::parse(lines.back());
}

std::string last_line(const std::vector<std::string>& lines) {
  return lines.empty() ? "" : lines.back();
}

void expect_line(test::ChildProcess& process, const std::string& line) {
  EXPECT_EQ(read_probe_line(process).value_or("(nothing)"), line);
}

TEST(SecurityE2eTest, AParticipantWithoutCredentialsReachesNobodyAndReceivesNothing) {
  test::use_secure_loopback();
  const test::ServiceFixture service("secure", test::domain::kAttack);
  const test::TestCredentials& credentials = *service.credentials();
  auto daemon = service.start_daemon(test::domain::kAttack);
  const dds::Participant participant = service.participant(test::domain::kAttack);  // this process: a planner
  transport::EnvironmentSubscriber planner(participant, "secure");
  transport::StatusReader status(participant, "secure");
  // Where robot poses would go (the simulating daemon reads none): a reader with the daemon's credentials.
  auto poses = start(probe(test::domain::kAttack, "secure", {"serve"}, &credentials, Role::kDaemon));
  expect_line(*poses, "ready");
  ASSERT_TRUE(planner.wait_for_version(1, test::kDaemonPatience)) << "no first version over DDS Security";
  const Environment before = test::settled(planner, status, "secure");
  const transport::TrackerStats stats_before = planner.stats();

  // The outsider, first reading: our own tools without --security, which is what anyone on the plant
  // network runs, and readers of the environment, its deltas and the status.
  const std::string domain = std::to_string(test::domain::kAttack);
  auto spy = start(probe(test::domain::kAttack, "secure", {"spy", "3"}));
  auto echo = start({CELLMAP_TOOL, "echo", "--domain", domain, "--count", "1", "--timeout", "3"});
  auto inject = start({CELLMAP_TOOL, "inject", "--domain", domain, "--wait", "3", "add-box", "--center",
                       "2.12,0.45,0.9", "--half-extents", "0.1,0.1,0.15"});
  auto pose = start({CELLMAP_TOOL, "robot-pose", "--domain", domain, "--cell", "secure", "--pose", "1,1,1",
                     "--wait", "3", "--duration", "0.2"});
  int code = 0;
  EXPECT_EQ(finish(*spy, &code), std::vector<std::string>{R"({"received":0})"})
      << "the outsider read something";
  EXPECT_EQ(finish(*echo, &code),
            std::vector<std::string>{"cellmap: echo: timed out after 3 s with 0 of 1 messages"});
  EXPECT_EQ(code, 1);
  EXPECT_EQ(finish(*inject, &code),
            std::vector<std::string>{"cellmap: inject: no simulating cellmapd on domain " + domain +
                                     " within 3 s"});
  EXPECT_EQ(code, 1);
  const std::vector<std::string> pose_lines = finish(*pose, &code);
  ASSERT_EQ(pose_lines.size(), 1u);
  EXPECT_NE(pose_lines[0].find("robot-pose: no cellmapd reading robot poses"), std::string::npos)
      << pose_lines[0];
  EXPECT_EQ(code, 1);

  // Then writing (alone: outsiders would read each other): a fake delta removing every box from the
  // planner's version, a fake snapshot of an empty cell, scene edits and robot poses every 100 ms.
  std::string ids;
  for (const Box& box : before.boxes()) ids += (ids.empty() ? "" : ",") + std::to_string(box.id);
  auto outsider =
      start(probe(test::domain::kAttack, "secure", {"forge", std::to_string(before.version()), ids}));
  expect_line(*outsider, "forging");
  // Six sweeps of the daemon (over a second): plain participants on loopback match in milliseconds, so
  // anything forged would have acted by then.
  const transport::CellStatus start_status =
      wait_for_status(status, [](const transport::CellStatus&) { return true; });
  const transport::CellStatus after = after_sweeps(status, start_status, 6);
  const nlohmann::json forged = stop(*outsider);
  EXPECT_EQ(forged, (nlohmann::json{
                        {"reached_environment", false}, {"reached_edits", false}, {"reached_poses", false}}))
      << "a secured reader matched the outsider's writer";
  EXPECT_EQ(after.version, before.version()) << "the daemon made a version";
  EXPECT_EQ(after.refused_inputs, 0u) << "nothing of the outsider's should even arrive";
  EXPECT_EQ(*planner.environment(), before) << "the planner's environment changed";
  const transport::TrackerStats stats_after = planner.stats();
  EXPECT_EQ(stats_after.deltas_applied, stats_before.deltas_applied);
  EXPECT_EQ(stats_after.snapshots_applied, stats_before.snapshots_applied);
  EXPECT_EQ(stats_after.rejected, stats_before.rejected);
  EXPECT_EQ(read_probe_line(*poses, 0ms), std::nullopt) << "an outsider's robot pose arrived";

  // The robot's credentials do reach the pose reader.
  EXPECT_EQ(
      run({CELLMAP_TOOL, "robot-pose", "--domain", domain, "--cell", "secure", "--pose", "1,1,1", "--rate",
           "50", "--duration", "0.2", "--security", credentials.directory().string(), "--role", "robot"},
          &code)
          .size(),
      1u);
  EXPECT_EQ(code, 0) << "a robot identity could not write robot state";
  EXPECT_GT(stop(*poses).value("poses", 0), 0);

  // A credentialed tool's edit with a centre of 1e300 is refused and counted, and never enters the scene: a
  // move of that obstacle afterwards finds none.
  const std::string far = service.inject(
      test::domain::kAttack, {"add-box", "--center", "1e300,0.45,0.9", "--half-extents", "0.1,0.1,0.15"});
  ASSERT_FALSE(far.empty());
  wait_for_status(status, [](const transport::CellStatus& s) { return s.refused_inputs == 1; });
  service.inject(test::domain::kAttack, {"move", "--name", far, "--center", "2.12,0.45,0.9"});
  const transport::CellStatus moved =
      wait_for_status(status, [](const transport::CellStatus& s) { return s.refused_inputs == 2; });
  const transport::CellStatus later = after_sweeps(status, moved, 6);
  EXPECT_EQ(later.version, before.version());
  EXPECT_EQ(later.refused_inputs, 2u);
  EXPECT_EQ(*planner.environment(), before);

  daemon->signal(SIGTERM);
  EXPECT_EQ(daemon->wait(), 0);
}

TEST(SecurityE2eTest, EachRoleCreatesOnlyTheWritersAndReadersItsPermissionsGrant) {
  test::use_secure_loopback();
  const test::TestCredentials credentials("roles", test::domain::kRoles);
  const auto grants_of = [&](Role role) {
    int code = 0;
    const std::vector<std::string> lines =
        run(probe(test::domain::kRoles, "roles", {"writers"}, &credentials, role), &code);
    EXPECT_EQ(code, 0);
    return lines.size() == 1 ? nlohmann::json::parse(lines[0]) : nlohmann::json::object();
  };
  // What each role may create in its cell's partition; the probe tries seven writers and readers there and
  // three outside it (another cell's, every cell's), the others must be refused.
  const std::map<Role, std::set<std::string>> created{
      {Role::kPlanner, {"environment_subscriber", "status_reader"}},
      {Role::kRobot, {"robot_state_writer"}},
      {Role::kTool, {"scene_edit_writer", "environment_subscriber", "status_reader"}},
      {Role::kDaemon, {"environment_publisher", "scene_edit_reader", "robot_state_reader"}}};
  for (const auto& [role, allowed] : created) {
    const nlohmann::json got = grants_of(role);
    EXPECT_EQ(got.size(), 10u) << got.dump();
    for (const auto& [entity, result] : got.items()) {
      EXPECT_EQ(result, allowed.count(entity) ? "created" : "refused")
          << security::to_string(role) << ": " << entity;
    }
  }
}

// A plant: cells plant-a and plant-b on one domain, each a daemon publishing its cell; secured, with
// credentials of one plant's CAs (plant-b's issued with plant-a's), so that every participant authenticates
// every other and only the partitions keep the cells apart.
class PlantPartitionsTest : public ::testing::TestWithParam<bool> {};

TEST_P(PlantPartitionsTest, APlannerOfOneCellReceivesNothingOfAnother) {
  const bool secured = GetParam();
  const int domain = secured ? test::domain::kSecurePlant : test::domain::kPlainPlant;
  if (secured) {
    test::use_secure_loopback();
  } else {
    test::use_loopback();
  }
  std::optional<test::TestCredentials> a, b;
  if (secured) {
    a.emplace("plant-a", domain);
    b.emplace("plant-b", domain, &*a);
  }
  const auto of = [&](const std::optional<test::TestCredentials>& credentials) {
    return credentials ? &*credentials : nullptr;
  };
  auto daemon_b = start(probe(domain, "plant-b", {"serve", "--publish"}, of(b), Role::kDaemon));
  expect_line(*daemon_b, "ready");
  auto daemon_a = start(probe(domain, "plant-a", {"serve", "--publish"}, of(a), Role::kDaemon));
  expect_line(*daemon_a, "ready");
  const dds::Participant participant(static_cast<std::uint32_t>(domain),
                                     a ? std::optional(a->as(Role::kPlanner)) : std::nullopt);
  transport::EnvironmentSubscriber planner(participant, "plant-a");
  ASSERT_TRUE(planner.wait_for_version(1, test::kDaemonPatience)) << "no version of its own cell";

  // plant-b's data is on the domain: a tool of plant-b (its own process) receives its delta and snapshot.
  std::vector<std::string> echo{CELLMAP_TOOL, "echo",    "--domain", std::to_string(domain),
                                "--cell",     "plant-b", "--count",  "2",
                                "--timeout",  "60"};
  if (b) {
    const std::vector<std::string> flags = b->flags(Role::kTool);
    echo.insert(echo.end(), flags.begin(), flags.end());
  }
  int code = 0;
  const std::vector<std::string> lines = run(echo, &code);
  EXPECT_EQ(code, 0);
  ASSERT_EQ(lines.size(), 2u);
  for (const std::string& line : lines) EXPECT_EQ(nlohmann::json::parse(line)["cell"], "plant-b") << line;

  EXPECT_EQ(planner.stats().other_cells, 0u) << "plant-b's samples reached plant-a's planner";
  if (secured) {
    // plant-a's planner credentials grant plant-a's partition only: no reader of plant-b's, nor of every
    // cell.
    EXPECT_NE(test::error_of([&] {
                transport::EnvironmentSubscriber x(participant, "plant-b");
              }).find("Not Allowed By Security"),
              std::string::npos);
    EXPECT_NE(test::error_of([&] {
                transport::StatusReader x(participant, transport::kEveryCell);
              }).find("Not Allowed By Security"),
              std::string::npos);
  }
  // plant-b's writers never matched plant-a's planner: their only reader was the echo's.
  EXPECT_EQ(stop(*daemon_b)["subscribers_joined"], 1);
  EXPECT_EQ(stop(*daemon_a)["subscribers_joined"], 1);
}

INSTANTIATE_TEST_SUITE_P(PlainAndSecure, PlantPartitionsTest, ::testing::Bool(), test::security_name);

TEST(SecurityE2eTest, AParticipantOfAnotherCaIsRefusedByThePeers) {
  test::use_secure_loopback();
  const test::TestCredentials ours("ca", test::domain::kOtherCa);
  const test::TestCredentials theirs("ca", test::domain::kOtherCa);  // valid in itself, but of other CAs
  auto daemon = start(probe(test::domain::kOtherCa, "ca", {"serve", "--publish"}, &ours, Role::kDaemon));
  expect_line(*daemon, "ready");
  const dds::Participant participant(test::domain::kOtherCa, ours.as(Role::kPlanner));
  transport::EnvironmentSubscriber planner(participant, "ca");
  ASSERT_TRUE(planner.wait_for_version(1, test::kDaemonPatience)) << "our own peers never matched";

  const std::string domain = std::to_string(test::domain::kOtherCa);
  const auto as_theirs = [&](std::vector<std::string> argv, Role role) {
    const std::vector<std::string> flags = theirs.flags(role);
    argv.insert(argv.end(), flags.begin(), flags.end());
    return start(argv);
  };
  auto echo =
      as_theirs({CELLMAP_TOOL, "echo", "--domain", domain, "--count", "1", "--timeout", "3"}, Role::kTool);
  auto inject = as_theirs(
      {CELLMAP_TOOL, "inject", "--domain", domain, "--wait", "3", "remove", "--name", "x"}, Role::kTool);
  auto pose = as_theirs({CELLMAP_TOOL, "robot-pose", "--domain", domain, "--cell", "ca", "--pose", "1,1,1",
                         "--wait", "3", "--duration", "0.2"},
                        Role::kRobot);
  // Their programs end as without any peer (Cyclone DDS also logs each failed handshake on stderr).
  int code = 0;
  EXPECT_EQ(last_line(finish(*echo, &code)), "cellmap: echo: timed out after 3 s with 0 of 1 messages");
  EXPECT_EQ(code, 1);
  EXPECT_EQ(last_line(finish(*inject, &code)),
            "cellmap: inject: no simulating cellmapd on domain " + domain + " within 3 s");
  EXPECT_EQ(code, 1) << "a tool of another CA reached the daemon's scene-edit reader";
  EXPECT_NE(last_line(finish(*pose, &code)).find("robot-pose: no cellmapd reading robot poses"),
            std::string::npos);
  EXPECT_EQ(code, 1) << "a robot of another CA reached the daemon's robot-state reader";
  const nlohmann::json served = stop(*daemon);
  EXPECT_EQ(served,
            (nlohmann::json{{"edits", 0}, {"poses", 0}, {"subscribers", 1}, {"subscribers_joined", 1}}))
      << "only our own planner may have matched";
}

// Several planners, each with an identity of its own: a stolen one is revoked alone. The revoked host never
// got the new list (as a thief would not): the daemon's list is what keeps it out.
TEST(SecurityE2eTest, ARevokedHostIdentityIsRefusedByTheDaemonWhileAnotherPlannerOfTheRoleStaysIn) {
  test::use_secure_loopback();
  const test::TestCredentials cell("revoked", test::domain::kRevoked);
  test::TempDir hosts("cellmap-hosts");
  const auto issue = [&](const std::string& host) {
    security::HostIdentity request;
    request.directory = cell.directory();
    request.role = Role::kPlanner;
    request.host = host;
    request.grants = transport::role_grants("revoked").at(Role::kPlanner);
    request.valid_from = std::chrono::system_clock::now() - 1h;
    request.valid_until = request.valid_from + 24h;
    request.ca = cell.ca();
    request.out = hosts.path() / host;
    security::issue_host_identity(request);
    return request.out;
  };
  const std::filesystem::path kept = issue("planner-kept");
  const std::filesystem::path stolen = issue("planner-stolen");
  EXPECT_EQ(security::revoke(stolen / "planner" / "identity.pem", cell.ca(), {cell.directory()}),
            "CN=planner@planner-stolen,OU=revoked,O=cellmap");

  auto daemon = start(probe(test::domain::kRevoked, "revoked", {"serve", "--publish"}, &cell, Role::kDaemon));
  expect_line(*daemon, "ready");
  const std::string domain = std::to_string(test::domain::kRevoked);
  auto thief = start({CELLMAP_TOOL, "echo", "--domain", domain, "--count", "1", "--timeout", "4",
                      "--security", stolen.string(), "--role", "planner"});
  const dds::Participant participant(test::domain::kRevoked, security::Setting{kept, Role::kPlanner});
  transport::EnvironmentSubscriber planner(participant, "revoked");
  EXPECT_TRUE(planner.wait_for_version(1, test::kDaemonPatience)) << "the kept planner never matched";
  int code = 0;
  EXPECT_EQ(last_line(finish(*thief, &code)), "cellmap: echo: timed out after 4 s with 0 of 1 messages");
  EXPECT_EQ(code, 1) << "the revoked identity received the environment";
  const nlohmann::json served = stop(*daemon);
  EXPECT_EQ(served["subscribers_joined"], 1) << served.dump() << ": only the kept planner may have matched";
}

TEST(SecurityE2eTest, BadCredentialsStopAProgramAtStartWithOneLine) {
  const test::TestCredentials credentials("refusal", test::domain::kRefusal);
  const test::TempDir state;
  const security::RoleFiles daemon = security::role_files(credentials.directory(), Role::kDaemon);
  ASSERT_EQ(::chmod(daemon.private_key.c_str(), 0640), 0);
  int code = 0;
  std::vector<std::string> lines =
      run({CELLMAPD, "--domain", std::to_string(test::domain::kRefusal), "--state-dir", state.path().string(),
           "--security", credentials.directory().string()},
          &code);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find(" critical " + daemon.private_key.string() +
                          ": group or others have access (mode 0640); chmod 600 it"),
            std::string::npos)
      << lines[0];
  EXPECT_EQ(code, 1);

  // Valid credentials of another cell ("refusal"; the daemon's cell is cell-1 by default).
  ASSERT_EQ(::chmod(daemon.private_key.c_str(), 0600), 0);
  lines = run({CELLMAPD, "--domain", std::to_string(test::domain::kRefusal), "--state-dir",
               state.path().string(), "--security", credentials.directory().string()},
              &code);
  ASSERT_EQ(lines.size(), 1u);
  EXPECT_NE(lines[0].find(" critical " + daemon.certificate.string() +
                          ": issued for cell 'refusal', not this daemon's cell 'cell-1'"),
            std::string::npos)
      << lines[0];
  EXPECT_EQ(code, 1);

  lines = run({CELLMAP_TOOL, "echo", "--domain", std::to_string(test::domain::kRefusal + 1), "--security",
               credentials.directory().string()},
              &code);
  EXPECT_EQ(lines,
            std::vector<std::string>{"cellmap: " + (credentials.directory() / "governance.p7s").string() +
                                     ": made for DDS domain 196, not 197"});
  EXPECT_EQ(code, 1);
  lines = run({CELLMAP_TOOL, "inject", "--security", "/nonexistent", "remove", "--name", "x"}, &code);
  EXPECT_EQ(lines, std::vector<std::string>{"cellmap: /nonexistent/identity_ca.pem: missing"});
  EXPECT_EQ(code, 1);
}

TEST(SecurityE2eTest, TheDaemonSaysOnceAtStartWhetherDdsSecurityIsOn) {
  test::use_secure_loopback();
  const test::TestCredentials credentials("cell-1", test::domain::kRefusal);
  const auto log_of = [&](std::vector<std::string> extra) {
    const test::TempDir state;
    std::vector<std::string> argv{
        CELLMAPD,   "--domain", std::to_string(test::domain::kRefusal), "--state-dir", state.path().string(),
        "--sweeps", "1"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    int code = 0;
    std::vector<std::string> lines = run(argv, &code);
    EXPECT_EQ(code, 0);
    return lines;
  };
  const auto count = [](const std::vector<std::string>& lines, const std::string& text) {
    return std::count_if(lines.begin(), lines.end(),
                         [&](const std::string& line) { return line.find(text) != std::string::npos; });
  };
  const std::vector<std::string> plain = log_of({});
  EXPECT_EQ(count(plain, " warning DDS Security off: any participant on DDS domain 196 can publish"), 1);
  const std::vector<std::string> secured = log_of({"--security", credentials.directory().string()});
  EXPECT_EQ(count(secured, " info DDS Security on: CN=daemon,OU=cell-1,O=cellmap ("), 1);
  EXPECT_EQ(count(secured, "DDS Security off"), 0);
}

}  // namespace
}  // namespace cellmap
