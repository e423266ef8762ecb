// SPDX-License-Identifier: Apache-2.0
// `cellmap view [--domain N] [--cell C] [--bind ADDR] [--port P] [--three DIR] [--allow-origin O]...
// [--security DIR [--role R]]`:
// follows the cell(s) over DDS as a planner does (with a planner's credentials under DDS Security) and serves
// a live 3D view of them at http://ADDR:P/ until SIGINT or SIGTERM.
#include <csignal>
#include <iostream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>

#include "cellmap/common/error.hpp"
#include "cellmap/common/text.hpp"
#include "cellmap/view/cell_follower.hpp"
#include "cellmap/view/web_server.hpp"
#include "commands.hpp"
#include "security_options.hpp"

namespace cellmap::cli {
namespace {

volatile std::sig_atomic_t stop_requested = 0;

void request_stop(int) {
  stop_requested = 1;
}

struct ViewOptions {
  std::uint32_t domain = 0;
  std::string cell;
  view::WebServerOptions server;
  SecurityOptions security;
};

using Layers = std::set<transport::Layer>;

// Which layers each page shows; a layer is read from DDS while at least one page shows it.
class PageLayers {
 public:
  /// Records what `page` shows now; returns the layers it newly turned on.
  Layers set(view::PageId page, Layers shown) {
    const std::lock_guard<std::mutex> lock(mutex_);
    Layers turned_on;
    for (const transport::Layer layer : shown)
      if (pages_[page].count(layer) == 0) turned_on.insert(layer);
    pages_[page] = std::move(shown);
    return turned_on;
  }
  void forget(view::PageId page) {
    const std::lock_guard<std::mutex> lock(mutex_);
    pages_.erase(page);
  }
  [[nodiscard]] Layers any() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    Layers out;
    for (const auto& [page, shown] : pages_) out.insert(shown.begin(), shown.end());
    return out;
  }

 private:
  mutable std::mutex mutex_;
  std::map<view::PageId, Layers> pages_;
};

// {"type":"layers", NAME: bool...}: the layers a page shows (a missing name is not shown).
Layers layers_shown(const nlohmann::json& message) {
  Layers shown;
  for (const transport::Layer layer : transport::kLayers)
    if (message.value(view::layer_name(layer), false)) shown.insert(layer);
  return shown;
}

void run_view(const ViewOptions& options) {
  std::signal(SIGINT, request_stop);
  std::signal(SIGTERM, request_stop);
  const dds::Participant participant(options.domain, options.security.setting());
  view::ViewState state(options.domain, options.cell);
  PageLayers layers;
  std::mutex server_mutex;            // DDS and page callbacks may come before the server is set, or after
  view::WebServer* server = nullptr;  // guarded by server_mutex

  view::WebServer::Callbacks callbacks;
  callbacks.state = [&state] { return state.state(); };
  callbacks.on_message = [&](view::PageId page, const std::string& text) {
    // A page only asks to see things; anything malformed is ignored.
    std::string type;
    Layers turned_on;
    try {
      const nlohmann::json message = nlohmann::json::parse(text);
      type = message.at("type").get<std::string>();
      if (type == "layers") turned_on = layers.set(page, layers_shown(message));
    } catch (const nlohmann::json::exception&) {
      return;
    }
    const std::lock_guard<std::mutex> lock(server_mutex);
    if (server == nullptr) return;
    if (type == "resync") server->send_state(page);
    // A page that turns a layer on gets the latest one at once, if there is one; later ones come with
    // everyone's.
    for (const transport::Layer layer : turned_on)
      for (std::string& message : state.layers(layer)) server->send(page, std::move(message));
  };
  callbacks.on_close = [&layers](view::PageId page) { layers.forget(page); };
  callbacks.on_refused = [](const std::string& origin) {
    std::cerr << "cellmap view: refused a page from " << single_line(origin, 256)
              << ": not this viewer's origin (--allow-origin lets one in)" << std::endl;
  };

  const auto publish = [&](std::string message) {
    const std::lock_guard<std::mutex> lock(server_mutex);
    if (server != nullptr) server->broadcast(std::move(message));
  };
  view::CellFollower follower(participant, options.cell, state, publish);
  view::WebServer web(options.server, callbacks);
  {
    const std::lock_guard<std::mutex> lock(server_mutex);
    server = &web;
  }
  std::cout << "cellmap view: " << web.url() << " (DDS domain " << options.domain << ", "
            << (options.cell.empty() ? std::string("every cell") : "cell " + options.cell) << "; read-only)"
            << std::endl;
  while (stop_requested == 0) {
    follower.want_layers(layers.any());
    follower.poll(std::chrono::milliseconds(100));
  }
  const std::lock_guard<std::mutex> lock(server_mutex);
  server = nullptr;
}

}  // namespace

void add_view_command(CLI::App& app) {
  auto options = std::make_shared<ViewOptions>();
  CLI::App* command = app.add_subcommand(
      "view", "Serve a live 3D view of the cell(s) on a DDS domain as a web page (read-only)");
  command->add_option("--domain", options->domain, "DDS domain id")->check(CLI::Range(0, 232));
  command->add_option("--cell", options->cell, "the cell to show (default: every cell on the domain)");
  command->add_option(
      "--bind", options->server.bind,
      "address to listen on (default 127.0.0.1: this machine only; 0.0.0.0: every interface)");
  command->add_option("--port", options->server.port, "TCP port (default 8080)")->check(CLI::Range(1, 65535));
  command->add_option("--three", options->server.three_dir,
                      "folder of three.js (default: Debian's libjs-three, /usr/share/javascript/three)");
  command->add_option(
      "--allow-origin", options->server.allowed_origins,
      "an origin whose pages may connect besides the viewer's own, e.g. http://cellpc:8080 when "
      "browsers reach it by that name (repeatable)");
  add_security_options(command, options->security, security::Role::kPlanner);
  command->callback([options] { run_view(*options); });
}

}  // namespace cellmap::cli
