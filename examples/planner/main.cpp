// SPDX-License-Identifier: Apache-2.0
// An example planner built on cellmap's client library (cellmap::client): it holds one path, follows a cell's
// environment over DDS, re-checks the path with the collision library on every new version, and prints one
// line each time the path's state changes ("path free", "path blocked by box <id> at ...", or "path blocked
// by unknown region <id> at ..." when space no sensor has observed is in the way).
//
// The path is that of a box the robot carries (a gripper with its part): a cubic B-spline over control points
// of the box centre in the cell frame C (it starts at the first and ends at the last). It is modelled as a
// gantry whose tool frame is the box centre (q = p_CB), so the library's path check (planning::path_blocked)
// applies unchanged; a planner with a real robot builds its RobotBoxes from its URDF instead.
//
//   cellmap_example_planner [--domain N] [--cell ID] [--control-points "x,y,z;x,y,z;..."]
//                           [--half-extents A,B,C] [--margin M] [--checkpoints N] [--ignore-unknown]
//                           [--json] [--every] [--security DIR [--role planner]]
#include <signal.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"
#include "cellmap/planning/path_check.hpp"
#include "cellmap/transport/environment_subscriber.hpp"

namespace {

using cellmap::Environment;
using cellmap::EnvironmentDelta;
using cellmap::Error;

// The path's state in one environment version.
struct PathState {
  bool blocked = false;
  std::uint64_t box = 0;  // id of the first environment box closer than the margin
  cellmap::BoxSpace space = cellmap::BoxSpace::kOccupied;  // an obstacle box, or an unknown box
  int checkpoint = -1;
  double t = 0.0;                                  // path parameter of that checkpoint, [0, 1]
  Eigen::Vector3d p_CB = Eigen::Vector3d::Zero();  // where the carried box's centre is then
  double distance = 0.0;                           // signed distance of that pair, metres
};

// "x,y,z;x,y,z;..." → points. @throws Error naming the option.
std::vector<Eigen::VectorXd> parse_points(const std::string& text, const std::string& option) {
  std::vector<Eigen::VectorXd> points;
  for (const std::string& item : cellmap::split(text, ';')) {
    const std::vector<std::string> values = cellmap::split(item, ',');
    if (values.size() != 3) throw Error(option + ": '" + item + "' is not x,y,z");
    Eigen::VectorXd p(3);
    for (int i = 0; i < 3; ++i) p[i] = cellmap::parse_finite(values[static_cast<std::size_t>(i)], option);
    points.push_back(p);
  }
  return points;
}

class PathWatch {
 public:
  PathWatch(const std::vector<Eigen::VectorXd>& control_points, const Eigen::Vector3d& half_extents,
            double margin, int checkpoints, cellmap::planning::PathCheckOptions options)
      : robot_(carried_box(half_extents)),
        path_(control_points),
        margin_(margin),
        checkpoints_(checkpoints),
        options_(options) {
    if (!(margin >= 0.0)) throw Error("--margin: must be >= 0");
    if (checkpoints < 2) throw Error("--checkpoints: must be >= 2");
  }

  [[nodiscard]] PathState check(const Environment& environment) const {
    const cellmap::planning::PathEnvironment boxes(environment.boxes(), options_);
    const cellmap::planning::Blocking blocking =
        cellmap::planning::path_blocked(robot_, path_, checkpoints_, boxes, margin_);
    PathState state;
    if (!blocking.blocked) return state;
    state.blocked = true;
    state.box = blocking.box_id;
    state.space = blocking.space;
    state.checkpoint = blocking.checkpoint;
    state.t = blocking.t;
    state.p_CB = path_.at(state.t);
    state.distance = blocking.distance;
    return state;
  }

 private:
  // A gantry whose tool frame is the carried box's centre; wide limits: the path is the user's choice.
  static cellmap::collision::RobotBoxes carried_box(const Eigen::Vector3d& half_extents) {
    const Eigen::Vector3d reach = Eigen::Vector3d::Constant(1e3);
    cellmap::Robot robot = cellmap::Robot::gantry(-reach, reach);
    cellmap::LinkBox box;
    box.link = robot.link_names().back();
    box.half_extents = half_extents;
    return cellmap::collision::RobotBoxes(std::move(robot), {box});
  }

  cellmap::collision::RobotBoxes robot_;
  cellmap::planning::BSplinePath path_;
  double margin_;
  int checkpoints_;
  cellmap::planning::PathCheckOptions options_;
};

std::string describe(const PathState& state, const Environment& env, const EnvironmentDelta& delta,
                     bool json) {
  if (json) {
    nlohmann::json line = {{"cell", env.cell()},
                           {"version", env.version()},
                           {"stamp_ns", env.stamp_ns()},
                           {"boxes", env.boxes().size()},
                           {"added", delta.added.size()},
                           {"modified", delta.modified.size()},
                           {"removed", delta.removed.size()},
                           {"state", state.blocked ? "blocked" : "free"}};
    if (state.blocked) {
      line["box"] = state.box;
      line["space"] = cellmap::space_name(state.space);
      line["checkpoint"] = state.checkpoint;
      line["t"] = state.t;
      line["position"] = {state.p_CB.x(), state.p_CB.y(), state.p_CB.z()};
      line["distance"] = state.distance;
    }
    return line.dump();
  }
  std::ostringstream line;
  line << "version " << env.version() << " (+" << delta.added.size() << " ~" << delta.modified.size() << " -"
       << delta.removed.size() << "): ";
  if (!state.blocked) {
    line << "path free";
  } else {
    char where[160];
    std::snprintf(where, sizeof where, "checkpoint %d (t %.3f, x %.3f y %.3f z %.3f), distance %.3f m",
                  state.checkpoint, state.t, state.p_CB.x(), state.p_CB.y(), state.p_CB.z(), state.distance);
    const bool unknown = state.space == cellmap::BoxSpace::kUnknown;
    line << "path blocked by " << (unknown ? "unknown region " : "box ") << state.box << " at " << where;
  }
  return line.str();
}

struct Options {
  int domain = 0;
  std::string cell = "cell-1";
  // Defaults fit the simulated cell (config/cell.yaml): 0.15 m above the table, between the fixture and the
  // drum, clear of every obstacle and of the unknown space the gantry's camera never sees at the table's
  // front edge (below z = 1.02 only within y < 0.26).
  std::string control_points = "2.12,0.45,0.9;2.12,0.62,0.9;2.12,0.8,0.9";
  std::string half_extents = "0.05,0.05,0.05";
  double margin = 0.02;
  int checkpoints = 50;
  bool ignore_unknown = false;
  bool json = false;
  bool every = false;
  std::string security_dir;  // DDS Security credentials (`cellmap security init`); empty: off
  std::string role = "planner";
};

void add_options(CLI::App& app, Options& o) {
  app.add_option("--domain", o.domain, "DDS domain id")->check(CLI::Range(0, 232));
  app.add_option("--cell", o.cell, "cell id to follow");
  app.add_option(
      "--control-points", o.control_points,
      "B-spline control points of the carried box's centre, x,y,z;x,y,z;... in the cell frame (m)");
  app.add_option("--half-extents", o.half_extents, "half extents A,B,C of the carried box (m)");
  app.add_option("--margin", o.margin, "safety margin: closer than this counts as blocked (m)");
  app.add_option("--checkpoints", o.checkpoints, "checkpoints along the path");
  app.add_flag("--ignore-unknown", o.ignore_unknown,
               "take unknown regions (space no sensor has observed) for free; by default they block the path "
               "as obstacles do");
  app.add_flag("--json", o.json, "one JSON object per line instead of text");
  app.add_flag("--every", o.every, "one line per new version, not only when the path's state changes");
  auto* security_option =
      app.add_option("--security", o.security_dir, "DDS Security on, with the credentials in DIR");
  app.add_option("--role", o.role, "the role whose credentials to use")
      ->needs(security_option)
      ->capture_default_str();
}

// Prints the path's state for every new version of the cell until SIGINT or SIGTERM (`stop_signals`).
void follow(const Options& o, const sigset_t& stop_signals) {
  const std::vector<Eigen::VectorXd> extents = parse_points(o.half_extents, "--half-extents");
  if (extents.size() != 1 || (extents[0].array() < 0.0).any())
    throw Error("--half-extents: expected one A,B,C >= 0");
  const PathWatch watch(parse_points(o.control_points, "--control-points"), extents[0], o.margin,
                        o.checkpoints, cellmap::planning::PathCheckOptions{o.ignore_unknown});

  std::optional<PathState> last;  // touched only by the subscriber's thread
  const auto on_change = [&](const Environment& env, const EnvironmentDelta& delta) {
    const PathState state = watch.check(env);
    const bool changed =
        !last || last->blocked != state.blocked || last->box != state.box || last->space != state.space;
    last = state;
    if (changed || o.every)
      std::cout << describe(state, env, delta, o.json) << std::endl;  // flushed: read by scripts
  };
  std::optional<cellmap::security::Setting> security;
  if (!o.security_dir.empty())
    security = cellmap::security::Setting{o.security_dir, cellmap::security::parse_role(o.role)};
  const cellmap::dds::Participant participant(static_cast<std::uint32_t>(o.domain), security);
  const cellmap::transport::EnvironmentSubscriber subscriber(participant, o.cell, on_change);
  std::cerr << "following cell '" << o.cell << "' on DDS domain " << o.domain << std::endl;

  int signal = 0;
  sigwait(&stop_signals, &signal);
  if (!subscriber.last_error().empty()) std::cerr << "last problem: " << subscriber.last_error() << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Example planner: re-checks a path against every new environment version of a cell"};
  Options options;
  add_options(app, options);
  CLI11_PARSE(app, argc, argv);

  // SIGINT/SIGTERM are taken by sigwait in follow(); blocked before the DDS threads start so they inherit it.
  sigset_t stop_signals;
  sigemptyset(&stop_signals);
  sigaddset(&stop_signals, SIGINT);
  sigaddset(&stop_signals, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &stop_signals, nullptr);

  try {
    follow(options, stop_signals);
  } catch (const Error& e) {
    std::cerr << "cellmap_example_planner: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
