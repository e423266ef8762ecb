// SPDX-License-Identifier: Apache-2.0
// config_keys: reads config files with cellmap's own readers, as cellmapd and `cellmap segment` read them,
// and prints every key path each reader read or asked about (YamlKeyLog), one "<reader> <path>" line each,
// e.g. "daemon source.openni2.uri". Exit 1 with the reader's message when a file is refused: the keys a
// reader accepts and the check that a shipped file is accepted come from the same code the programs run.
//
//   config_keys daemon|scene|segment FILE...
// A daemon config's simulated scene (sources[i].scene) is read too, as cellmapd would at start.
#include <exception>
#include <iostream>
#include <set>
#include <string>

#include "cellmap/config/yaml_map.hpp"
#include "cellmap/segment/pipeline.hpp"
#include "cellmap/sim/scene.hpp"
#include "daemon_config.hpp"

namespace {

using cellmap::YamlKeyLog;

void print(const char* reader, const YamlKeyLog& log) {
  for (const std::string& key : log.keys()) std::cout << reader << ' ' << key << '\n';
}

void read_scene(const std::string& file) {
  const YamlKeyLog log;
  (void)cellmap::sim::load_scene(file);
  print("scene", log);
}

void read_daemon_config(const std::string& file) {
  std::set<std::string> scenes;
  {
    const YamlKeyLog log;
    const auto config = cellmap::daemon::DaemonConfig::load(file);
    print("daemon", log);
    for (const auto& source : config.sources) {
      if (!source.is_camera() && !source.scene.empty()) scenes.insert(source.scene.string());
    }
  }
  for (const std::string& scene : scenes) read_scene(scene);
}

void read_segment_config(const std::string& file) {
  const YamlKeyLog log;
  (void)cellmap::SegmentConfig::load(file);
  print("segment", log);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: config_keys daemon|scene|segment FILE...\n";
    return 2;
  }
  const std::string reader = argv[1];
  if (reader != "daemon" && reader != "scene" && reader != "segment") {
    std::cerr << "config_keys: unknown reader '" << reader << "' (daemon, scene or segment)\n";
    return 2;
  }
  try {
    for (int i = 2; i < argc; ++i) {
      if (reader == "daemon") read_daemon_config(argv[i]);
      if (reader == "scene") read_scene(argv[i]);
      if (reader == "segment") read_segment_config(argv[i]);
    }
  } catch (const std::exception& e) {  // cellmap::Error, and whatever a reader lets through
    std::cerr << e.what() << '\n';
    return 1;
  }
  return 0;
}
