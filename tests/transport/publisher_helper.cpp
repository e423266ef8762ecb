// SPDX-License-Identifier: Apache-2.0
// Test helper for the transport end-to-end tests: a minimal "daemon" that publishes the test sequence of
// environments for cell "cell-e2e", persisting each version in a VersionStore before publishing it.
//   transport_publisher_helper DOMAIN STATE_DIR VERSIONS INTERVAL_MS
// Prints "publishing V" before each publication (so a parent that kills it knows every version that may be
// out), "republished V" for the snapshot it resumes with, "done V" at the end, then waits for SIGTERM.
#include <signal.h>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <string>
#include <thread>

#include "cellmap/common/wall_clock.hpp"
#include "cellmap/environment/version_store.hpp"
#include "cellmap/transport/environment_publisher.hpp"
#include "scene_steps.hpp"

namespace {}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::cerr << "usage: transport_publisher_helper DOMAIN STATE_DIR VERSIONS INTERVAL_MS\n";
    return 2;
  }
  // Block SIGTERM before any DDS thread exists so that only sigwait below receives it.
  sigset_t term;
  sigemptyset(&term);
  sigaddset(&term, SIGTERM);
  pthread_sigmask(SIG_BLOCK, &term, nullptr);
  try {
    const auto domain = static_cast<std::uint32_t>(std::stoul(argv[1]));
    const int versions = std::stoi(argv[3]);
    const auto interval = std::chrono::milliseconds(std::stoi(argv[4]));
    cellmap::VersionStore store(argv[2], "cell-e2e");
    for (const std::string& problem : store.recovered().problems) std::cerr << "helper: " << problem << "\n";
    cellmap::Environment env = store.recovered().environment;

    const cellmap::dds::Participant participant(domain);
    cellmap::transport::EnvironmentPublisher publisher(participant, "cell-e2e");
    if (env.version() > 0) {
      env = store.resume(cellmap::wall_clock_ns());
      std::cout << "republished " << env.version() << std::endl;
      publisher.publish(env);
    }
    for (int i = 0; i < versions; ++i) {
      const std::uint64_t v = store.next_version();
      const cellmap::Environment next = cellmap::test::next_environment(env, v, cellmap::wall_clock_ns());
      store.save(next);
      std::cout << "publishing " << v << std::endl;
      publisher.publish(next, cellmap::diff(env, next));
      env = next;
      std::this_thread::sleep_for(interval);
    }
    std::cout << "done " << env.version() << std::endl;
    int sig = 0;
    sigwait(&term, &sig);
  } catch (const std::exception& e) {
    std::cerr << "helper: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
