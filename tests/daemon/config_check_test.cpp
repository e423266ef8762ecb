// SPDX-License-Identifier: Apache-2.0
// `cellmapd --check` as a process: every cellmapd config shipped in config/ passes; a broken config prints
// each of its problems with its key and exits 1, without joining DDS.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>

#include "cellmap/environment/version_store.hpp"
#include "support/test_credentials.hpp"
#include "support/test_support.hpp"

namespace cellmap {
namespace {

using test::CommandRun;

// `cellmapd --check ARGS` with a private state directory; stderr too unless `with_stderr` is false.
CommandRun check(const std::string& args, const test::TempDir& dir, bool with_stderr = true) {
  return test::run_command(std::string(CELLMAPD) + " --check --state-dir '" +
                           (dir.path() / "state").string() + "' " + args +
                           (with_stderr ? " 2>&1" : " 2>/dev/null"));
}

std::filesystem::path write_config(const test::TempDir& dir, const std::string& yaml) {
  const std::filesystem::path file = dir.path() / "cellmapd.yaml";
  std::ofstream(file) << yaml;
  return file;
}

TEST(ConfigCheckTest, EveryShippedCellmapdConfigPasses) {
  // config/ also holds what is not a cellmapd config: the default scene and the points pipeline's keys.
  const std::set<std::string> not_cellmapd{"cell.yaml", "segment.yaml"};
  const test::TempDir dir;
  int checked = 0;
  for (const auto& entry : std::filesystem::directory_iterator(CELLMAP_SOURCE_DIR "/config")) {
    const std::filesystem::path file = entry.path();
    if (file.extension() != ".yaml" || not_cellmapd.count(file.filename().string()) > 0) continue;
    SCOPED_TRACE(file.string());
    const CommandRun run = check("--config '" + file.string() + "'", dir, false);
    EXPECT_EQ(run.status, 0) << check("--config '" + file.string() + "'", dir).output;
    EXPECT_EQ(run.output, file.string() + ": ok\n");
    ++checked;
  }
  EXPECT_GE(checked, 3);  // cellmapd.yaml, arm-cell.yaml, ros2-cell.yaml at least
}

TEST(ConfigCheckTest, BuiltInDefaultsPass) {
  const test::TempDir dir;
  const CommandRun run = check("", dir, false);
  EXPECT_EQ(run.status, 0);
  EXPECT_EQ(run.output, "built-in defaults: ok\n");
}

TEST(ConfigCheckTest, EachProblemIsReportedWithItsKey) {
  const test::TempDir dir;
  const std::filesystem::path config =
      write_config(dir,
                   "log_level: loud\n"
                   "cel: typo\n"
                   "source: {scene: missing/scene.yaml}\n"
                   "robot: {urdf: {file: /nonexistent/arm.urdf, tool_link: tool0}}\n"
                   "security: {directory: no-credentials}\n");
  const CommandRun run = check("--config '" + config.string() + "'", dir);
  EXPECT_EQ(run.status, 1) << run.output;
  const std::string name = config.string() + ": ";
  for (const std::string& line :
       {name + "log_level: must be one of trace, debug, info, warn, error\n", name + "cel: unknown key\n",
        name + "robot.urdf: /nonexistent/arm.urdf: ",
        name + "source.scene: " + (dir.path() / "missing/scene.yaml").string() + ": ",
        name + "security: " + (dir.path() / "no-credentials").string(), name + "5 problems\n"}) {
    EXPECT_NE(run.output.find(line), std::string::npos) << "missing: " << line << "\nin:\n" << run.output;
  }
}

TEST(ConfigCheckTest, ABadValueInOneSourceLeavesTheOthersChecked) {
  const test::TempDir dir;
  std::filesystem::create_directory(dir.path() / "replay");
  const std::filesystem::path config =
      write_config(dir,
                   "sources:\n"
                   "  - {kind: replay, sensor: post, mount: cell, pose: {}, replay: {directory: replay}}\n"
                   "  - {kind: replay, sensor: wrist, mount: tol}\n"
                   "  - {kind: replay, sensor: side, mount: cell, pose: {}, replay: {directory: gone}}\n");
  const CommandRun run = check("--config '" + config.string() + "'", dir);
  EXPECT_EQ(run.status, 1) << run.output;
  EXPECT_NE(
      run.output.find(config.string() + ": sources[1].mount: must be tool, cell or a pose, got 'tol'\n"),
      std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find(config.string() + ": sources[2].replay.directory: " +
                            (dir.path() / "gone").string() + ": no such replay directory"),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("2 problems"), std::string::npos) << run.output;
}

TEST(ConfigCheckTest, AStateDirectoryOfAnotherCellIsAProblem) {
  const test::TempDir dir;
  const std::filesystem::path state = dir.path() / "state";
  VersionStore(state, "press-3").save(Environment("press-3", 1, 0, {}));
  const std::filesystem::path config = write_config(dir, "cell: press-4\n");
  const CommandRun run = check("--config '" + config.string() + "'", dir);
  EXPECT_EQ(run.status, 1);
  EXPECT_NE(run.output.find(config.string() + ": --state-dir: " + state.string() +
                            ": holds the versions of cell 'press-3', not 'press-4'\n"),
            std::string::npos)
      << run.output;
  write_config(dir, "cell: press-3\n");
  EXPECT_EQ(check("--config '" + config.string() + "'", dir).output, config.string() + ": ok\n");
}

TEST(ConfigCheckTest, CredentialsAreCheckedForTheConfigsCell) {
  const test::TempDir dir;
  const test::TestCredentials credentials("press-3", 0);
  const std::filesystem::path config = write_config(dir, "cell: press-3\n");
  const std::string flags =
      "--config '" + config.string() + "' --security '" + credentials.directory().string() + "'";
  EXPECT_EQ(check(flags, dir).output, config.string() + ": ok\n");

  write_config(dir, "cell: press-4\n");
  const CommandRun other_cell = check(flags, dir);
  EXPECT_EQ(other_cell.status, 1);
  EXPECT_NE(other_cell.output.find(config.string() + ": --security: "), std::string::npos)
      << other_cell.output;
  EXPECT_NE(other_cell.output.find("issued for cell 'press-3', not the config's cell 'press-4'"),
            std::string::npos)
      << other_cell.output;

  write_config(dir, "cell: press-3\n");
  const std::filesystem::path permissions = credentials.directory() / "daemon" / "permissions.p7s";
  std::filesystem::remove(permissions);
  const CommandRun missing = check(flags, dir);
  EXPECT_EQ(missing.status, 1);
  EXPECT_NE(missing.output.find(permissions.string()), std::string::npos) << missing.output;
}

}  // namespace
}  // namespace cellmap
