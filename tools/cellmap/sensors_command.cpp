// SPDX-License-Identifier: Apache-2.0
// cellmap sensors: lists the OpenNI2 and V4L2 depth devices on this machine with their depth modes.
#include <algorithm>
#include <iostream>

#include "cellmap/common/error.hpp"
#include "cellmap/sensor/openni2_source.hpp"
#include "cellmap/sensor/v4l2_source.hpp"
#include "commands.hpp"

namespace cellmap::cli {
namespace {

void print_devices(const std::string& title, const std::vector<DepthDeviceInfo>& devices) {
  std::cout << title << ": " << devices.size() << (devices.size() == 1 ? " device" : " devices") << "\n";
  for (const DepthDeviceInfo& device : devices) {
    std::cout << "  " << device.uri << "  " << device.name << "\n";
    if (device.modes.empty()) std::cout << "    (no depth modes reported)\n";
    for (const DepthMode& mode : device.modes) std::cout << "    " << mode.to_string() << "\n";
  }
}

}  // namespace

void add_sensors_command(CLI::App& app) {
  auto* command =
      app.add_subcommand("sensors", "List the OpenNI2 and V4L2 depth devices found, with their depth modes");
  auto dev_dir = std::make_shared<std::string>("/dev");
  command->add_option("--dev", *dev_dir, "Folder searched for V4L2 video devices")->capture_default_str();
  auto uris = std::make_shared<std::vector<std::string>>();
  command->add_option("--openni2-uri", *uris,
                      "Also open this OpenNI2 URI (an .oni recording, a named device) and list its modes");
  command->callback([dev_dir, uris] {
    std::size_t found = 0;
    if (!uris->empty()) {
      std::vector<DepthDeviceInfo> probed;
      for (const std::string& uri : *uris) probed.push_back(probe_openni2_device(uri));
      print_devices("OpenNI2 devices opened by URI", probed);
      found += probed.size();
    }
    try {
      std::vector<DepthDeviceInfo> devices = list_openni2_devices();
      // A URI opened above can show up in the enumeration afterwards (a driver's virtual device): list it
      // once.
      devices.erase(std::remove_if(devices.begin(), devices.end(),
                                   [&](const DepthDeviceInfo& d) {
                                     return std::find(uris->begin(), uris->end(), d.uri) != uris->end();
                                   }),
                    devices.end());
      print_devices("OpenNI2 depth devices", devices);
      found += devices.size();
    } catch (const Error& e) {
      // OpenNI2 itself unavailable (no drivers): still list V4L2 devices.
      std::cout << "OpenNI2 depth devices: unavailable (" << e.what() << ")\n";
    }
    const std::vector<DepthDeviceInfo> devices = list_v4l2_devices(*dev_dir);
    print_devices("V4L2 depth devices (Z16) in " + *dev_dir, devices);
    found += devices.size();
    if (found == 0) std::cout << "No depth sensors found.\n";
  });
}

}  // namespace cellmap::cli
