// SPDX-License-Identifier: Apache-2.0
#include "cellmap/view/web_server.hpp"

#include <arpa/inet.h>
#include <civetweb.h>

#include <algorithm>
#include <cstring>

#include "cellmap/common/error.hpp"

namespace cellmap::view {
namespace {

// What the page loads from libjs-three; checked at start so a missing package is one clear error.
constexpr const char* kThreeFiles[] = {"build/three.module.js", "examples/jsm/controls/OrbitControls.js"};
constexpr const char* kThreePrefix = "/three/";
constexpr const char* kSocketPath = "/ws";

WebServer& server_of(const mg_connection* conn) {
  return *static_cast<WebServer*>(mg_get_user_data(mg_get_context(conn)));
}

int on_request(mg_connection* conn, void*) {
  return server_of(conn).handle_request(conn);
}

int on_socket_connect(const mg_connection* conn, void*) {
  return server_of(conn).page_allowed(conn) ? 0 : 1;
}

void on_socket_ready(mg_connection* conn, void*) {
  server_of(conn).page_opened(conn);
}

int on_socket_data(mg_connection* conn, int bits, char* data, size_t size, void*) {
  return server_of(conn).page_data(conn, bits, data, size);
}

void on_socket_close(const mg_connection* conn, void*) {
  server_of(conn).page_closed(conn);
}

int on_log(const mg_connection*, const char*) {
  return 1;  // start-up errors come back through mg_start2; nothing else is worth a line on stderr
}

std::string listening_port(const std::string& bind, int port) {
  const bool ipv6 = bind.find(':') != std::string::npos;
  return (ipv6 ? "[" + bind + "]" : bind) + ":" + std::to_string(port);
}

std::filesystem::path three_dir_checked(const std::filesystem::path& dir) {
  for (const char* file : kThreeFiles) {
    if (!std::filesystem::is_regular_file(dir / file))
      throw Error("view: three.js not found: " + (dir / file).string() +
                  " is missing (install Debian's libjs-three, or give --three DIR)");
  }
  return std::filesystem::canonical(dir);
}

// The host name of a Host header ("127.0.0.1:8080", "[::1]:8080", "localhost").
std::string host_name(const std::string& host) {
  if (!host.empty() && host.front() == '[') return host.substr(1, host.find(']') - 1);
  return host.substr(0, host.find(':'));
}

// Whether `name` can only mean this machine as the browser reached it: an address, or localhost. A DNS
// name could be rebound to this address by another site.
bool names_this_machine(const std::string& name) {
  unsigned char address[sizeof(in6_addr)];
  return name == "localhost" || ::inet_pton(AF_INET, name.c_str(), address) == 1 ||
         ::inet_pton(AF_INET6, name.c_str(), address) == 1;
}

}  // namespace

WebServer::WebServer(WebServerOptions options, Callbacks callbacks)
    : options_(std::move(options)),
      callbacks_(std::move(callbacks)),
      three_dir_(three_dir_checked(options_.three_dir)) {
  if ((mg_check_feature(MG_FEATURES_WEBSOCKET) & MG_FEATURES_WEBSOCKET) == 0)
    throw Error("view: this civetweb was built without WebSocket support");
  mg_init_library(0);
  const std::string ports = listening_port(options_.bind, options_.port);
  // Each open page holds one worker thread for its WebSocket; a few more serve the files.
  const char* config[] = {"listening_ports",
                          ports.c_str(),
                          "num_threads",
                          "24",
                          "enable_websocket_ping_pong",
                          "yes",
                          "websocket_timeout_ms",
                          "5000",
                          "request_timeout_ms",
                          "10000",
                          nullptr};
  mg_callbacks hooks{};
  hooks.log_message = on_log;
  mg_init_data init{&hooks, this, config};
  char reason[256] = "";
  unsigned code = 0;
  mg_error_data error{&code, reason, sizeof(reason)};
  sender_ = std::thread([this] { run_sender(); });
  context_ = mg_start2(&init, &error);
  if (context_ == nullptr) {
    {
      const std::lock_guard<std::mutex> lock(queue_mutex_);
      stopping_ = true;
    }
    queued_.notify_all();
    sender_.join();
    mg_exit_library();
    throw Error("view: cannot serve on " + ports + ": " + (*reason != '\0' ? reason : "civetweb failed"));
  }
  mg_set_request_handler(context_, "/", on_request, nullptr);
  mg_set_websocket_handler(context_, kSocketPath, on_socket_connect, on_socket_ready, on_socket_data,
                           on_socket_close, nullptr);
}

WebServer::~WebServer() {
  mg_stop(context_);  // closes the connections (page_closed for each) and joins civetweb's threads
  {
    const std::lock_guard<std::mutex> lock(queue_mutex_);
    stopping_ = true;
  }
  queued_.notify_all();
  sender_.join();
  mg_exit_library();
}

bool WebServer::page_allowed(const mg_connection* conn) const {
  const char* origin = mg_get_header(conn, "Origin");
  if (origin == nullptr) return true;
  const std::vector<std::string>& allowed = options_.allowed_origins;
  if (std::find(allowed.begin(), allowed.end(), origin) != allowed.end()) return true;
  const char* host = mg_get_header(conn, "Host");
  if (host != nullptr && origin == "http://" + std::string(host) && names_this_machine(host_name(host)))
    return true;
  if (callbacks_.on_refused) callbacks_.on_refused(origin);
  return false;
}

int WebServer::handle_request(mg_connection* conn) {
  const mg_request_info* request = mg_get_request_info(conn);
  const std::string method = request->request_method ? request->request_method : "";
  const std::string uri = request->local_uri ? request->local_uri : "/";
  if (method != "GET" && method != "HEAD") {
    mg_send_http_error(conn, 405, "cellmap view is read-only");
    return 405;
  }
  if (uri.rfind(kThreePrefix, 0) == 0) {
    if (!serve_three(conn, uri)) mg_send_http_error(conn, 404, "not found");
    return 200;
  }
  const std::string path = uri == "/" ? "/index.html" : uri;
  for (const PageFile& file : options_.files) {
    if (file.path != path) continue;
    mg_printf(conn,
              "HTTP/1.1 200 OK\r\nContent-Type: %.*s\r\nContent-Length: %zu\r\nCache-Control: no-cache\r\n"
              "Connection: close\r\n\r\n",
              static_cast<int>(file.mime.size()), file.mime.data(), file.body.size());
    if (method == "GET") mg_write(conn, file.body.data(), file.body.size());
    return 200;
  }
  mg_send_http_error(conn, 404, "not found");
  return 404;
}

bool WebServer::serve_three(mg_connection* conn, const std::string& uri) {
  // local_uri is already cleaned of "..", and the canonical path must still lie inside the folder (the
  // package's build/ links point into it).
  std::error_code error;
  const std::filesystem::path file =
      std::filesystem::canonical(three_dir_ / uri.substr(std::strlen(kThreePrefix)), error);
  if (error || !std::filesystem::is_regular_file(file)) return false;
  const std::string inside = three_dir_.string() + "/";
  if (file.string().rfind(inside, 0) != 0) return false;
  mg_send_mime_file(conn, file.c_str(), nullptr);
  return true;
}

void WebServer::page_opened(mg_connection* conn) {
  PageId page = 0;
  {
    const std::lock_guard<std::mutex> lock(pages_mutex_);
    page = next_page_++;
    opened_[conn] = page;
  }
  enqueue({page, std::nullopt});
}

int WebServer::page_data(mg_connection* conn, int bits, const char* data, std::size_t size) {
  const int opcode = bits & 0x0f;
  if (opcode == MG_WEBSOCKET_OPCODE_CONNECTION_CLOSE) return 0;
  if (opcode != MG_WEBSOCKET_OPCODE_TEXT || !callbacks_.on_message) return 1;
  PageId page = 0;
  {
    const std::lock_guard<std::mutex> lock(pages_mutex_);
    const auto found = opened_.find(conn);
    if (found == opened_.end()) return 1;
    page = found->second;
  }
  callbacks_.on_message(page, std::string(data, size));
  return 1;
}

void WebServer::page_closed(const mg_connection* conn) {
  PageId page = 0;
  {
    const std::lock_guard<std::mutex> lock(pages_mutex_);
    const auto found = opened_.find(conn);
    if (found == opened_.end()) return;
    page = found->second;
    opened_.erase(found);
    live_.erase(page);
  }
  if (callbacks_.on_close) callbacks_.on_close(page);
}

void WebServer::broadcast(std::string message) {
  enqueue({std::nullopt, std::move(message)});
}

void WebServer::send(PageId page, std::string message) {
  enqueue({page, std::move(message)});
}

void WebServer::send_state(PageId page) {
  enqueue({page, std::nullopt});
}

void WebServer::enqueue(Outgoing outgoing) {
  {
    const std::lock_guard<std::mutex> lock(queue_mutex_);
    queue_.push_back(std::move(outgoing));
  }
  queued_.notify_one();
}

void WebServer::run_sender() {
  for (;;) {
    Outgoing outgoing;
    {
      std::unique_lock<std::mutex> lock(queue_mutex_);
      queued_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      outgoing = std::move(queue_.front());
      queue_.pop_front();
    }
    deliver(outgoing);
  }
}

void WebServer::deliver(const Outgoing& outgoing) {
  const std::lock_guard<std::mutex> lock(pages_mutex_);
  const auto write = [](mg_connection* conn, const std::string& text) {
    return mg_websocket_write(conn, MG_WEBSOCKET_OPCODE_TEXT, text.data(), text.size()) > 0;
  };
  if (!outgoing.page) {
    for (const auto& [page, conn] : live_) write(conn, *outgoing.text);
    return;
  }
  mg_connection* conn = nullptr;
  for (const auto& [c, page] : opened_) {
    if (page == *outgoing.page) conn = const_cast<mg_connection*>(c);
  }
  if (conn == nullptr) return;  // it has gone
  if (outgoing.text) {
    write(conn, *outgoing.text);
    return;
  }
  // The state as it is now already holds every change queued before this point.
  if (write(conn, callbacks_.state ? callbacks_.state() : std::string("{}"))) live_[*outgoing.page] = conn;
}

std::string WebServer::url() const {
  const bool any = options_.bind == "0.0.0.0" || options_.bind == "::";
  const std::string host = any ? "127.0.0.1" : options_.bind;
  const bool ipv6 = host.find(':') != std::string::npos;
  return "http://" + (ipv6 ? "[" + host + "]" : host) + ":" + std::to_string(options_.port) + "/";
}

std::size_t WebServer::pages() const {
  const std::lock_guard<std::mutex> lock(pages_mutex_);
  return opened_.size();
}

}  // namespace cellmap::view
