// SPDX-License-Identifier: Apache-2.0
// Runs the real `cellmap distance` program and checks its JSON and its refusals.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "support/test_support.hpp"

namespace {

struct ToolRun {
  std::string output;
  int status = -1;  ///< exit code, -1 when a signal ended the tool
};

ToolRun run_tool(const std::string& arguments) {
  const std::string command = std::string(CELLMAP_TOOL) + " distance " + arguments + " 2>&1";
  ToolRun run;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  std::array<char, 4096> buffer{};
  while (fgets(buffer.data(), buffer.size(), pipe) != nullptr) run.output += buffer.data();
  run.status = cellmap::test::exit_code(pclose(pipe));
  return run;
}

TEST(DistanceCommandTest, PrintsSignedDistanceAndWitnessPoints) {
  const ToolRun run = run_tool("0,0,0,3,5,1 25,20,5,1,1,1");
  ASSERT_EQ(run.status, 0) << run.output;
  const auto json = nlohmann::json::parse(run.output);
  EXPECT_NEAR(json.at("distance").get<double>(), std::sqrt(21.0 * 21 + 14 * 14 + 3 * 3), 1e-9);
  EXPECT_EQ(json.at("point_a"), nlohmann::json::parse("[3.0, 5.0, 1.0]"));
  EXPECT_EQ(json.at("point_b"), nlohmann::json::parse("[24.0, 19.0, 4.0]"));
  EXPECT_NEAR(json.at("normal")[0].get<double>(), 21 / std::sqrt(21.0 * 21 + 14 * 14 + 3 * 3), 1e-12);
}

TEST(DistanceCommandTest, PenetrationIsNegativeWithRotation) {
  // B turned 90 degrees about z is the same unit cube: centre offset 0.99 → −0.01.
  const double s = std::sqrt(0.5);
  const ToolRun run =
      run_tool("0,0,0,.5,.5,.5 0.99,0,0,.5,.5,.5," + std::to_string(s) + ",0,0," + std::to_string(s));
  ASSERT_EQ(run.status, 0) << run.output;
  const auto json = nlohmann::json::parse(run.output);
  EXPECT_NEAR(json.at("distance").get<double>(), -0.01, 1e-6);  // the quaternion is printed to 6 digits
  EXPECT_NEAR(json.at("normal")[0].get<double>(), 1.0, 1e-6);
}

TEST(DistanceCommandTest, RefusesBadBoxesWithOneLineReason) {
  for (const std::string& arguments :
       {std::string("0,0,0,.5 1,1,1,.5,.5,.5"), std::string("0,0,0,.5,.5,.5 1,1,1,.5,.5,x"),
        std::string("0,0,0,.5,.5,-.5 1,1,1,.5,.5,.5"),
        std::string("0,0,0,.5,.5,.5 1,1,1,.5,.5,.5,1,1,0,0")}) {
    SCOPED_TRACE(arguments);
    const ToolRun run = run_tool(arguments);
    EXPECT_EQ(run.status, 1) << run.output;  // refused, not crashed
    EXPECT_FALSE(run.output.empty());
    EXPECT_EQ(run.output.find('\n'), run.output.size() - 1) << run.output;  // exactly one line
  }
}

TEST(DistanceCommandTest, MissingBoxIsAnError) {
  EXPECT_NE(run_tool("0,0,0,.5,.5,.5").status, 0);
}

}  // namespace
