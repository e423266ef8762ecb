// SPDX-License-Identifier: Apache-2.0
#pragma once
// The viewer's web server (civetweb): serves the page's own files (embedded in the program) and three.js from
// the installed libjs-three, and pushes messages to every open page over one WebSocket endpoint, /ws.
// Read-only: it answers GET only, and what a page sends is a request to see something, never a change.

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

struct mg_context;
struct mg_connection;

namespace cellmap::view {

/// One file of the page, served at `path` (e.g. "/view.js").
struct PageFile final {
  std::string_view path;
  std::string_view mime;
  std::string_view body;
};

/// The page's files as built into the program: "/" (index.html), the script and the style sheet.
[[nodiscard]] const std::vector<PageFile>& page_files();

/// The folder of Debian's libjs-three, where the page's three.js comes from.
inline constexpr const char* kDefaultThreeDir = "/usr/share/javascript/three";

/// Each page gets an id when its WebSocket opens; ids are never reused.
using PageId = std::uint64_t;

struct WebServerOptions final {
  std::string bind = "127.0.0.1";  ///< address to listen on ("0.0.0.0": every interface)
  int port = 8080;
  std::filesystem::path three_dir = kDefaultThreeDir;  ///< served under /three/
  std::vector<PageFile> files = page_files();          ///< served at their paths
  /// Origins ("http://cellpc:8080") whose pages may open the WebSocket besides the viewer's own. The own
  /// origin is the one whose host is the request's Host and names this machine by address or "localhost":
  /// a page from any other site (or a DNS name rebound to this address) is refused, so a web page open in a
  /// browser here cannot read the cell. Requests without an Origin (not from a browser) are served.
  std::vector<std::string> allowed_origins;
};

/// Thread-safe. Messages to pages go through one sending thread in the order given, so a slow page never
/// blocks the caller (a DDS callback). A page that connects first gets `state()` as it is when its turn
/// comes, then every message queued after it connected.
class WebServer final {
 public:
  struct Callbacks {
    std::function<std::string()> state;                               ///< the first message for a new page
    std::function<void(PageId, const std::string& text)> on_message;  ///< a text frame from a page
    std::function<void(PageId)> on_close;                             ///< a page went away
    std::function<void(const std::string& origin)> on_refused;  ///< a page of another origin was refused
  };

  /// Starts listening. @throws Error if three.js is missing from `options.three_dir` (naming the Debian
  /// package) or the address cannot be bound (civetweb's reason).
  WebServer(WebServerOptions options, Callbacks callbacks);
  /// Closes every connection and stops the threads.
  ~WebServer();
  WebServer(const WebServer&) = delete;
  WebServer& operator=(const WebServer&) = delete;

  /// Queues `message` for every page.
  void broadcast(std::string message);
  /// Queues `message` for one page (dropped if it has gone).
  void send(PageId page, std::string message);
  /// Queues a fresh state() for one page.
  void send_state(PageId page);

  /// The page's address, e.g. "http://127.0.0.1:8080/".
  [[nodiscard]] std::string url() const;
  /// Pages connected now.
  [[nodiscard]] std::size_t pages() const;

  // civetweb's callbacks (C functions) enter through these; not for other use.
  int handle_request(mg_connection* conn);
  [[nodiscard]] bool page_allowed(const mg_connection* conn) const;
  void page_opened(mg_connection* conn);
  int page_data(mg_connection* conn, int bits, const char* data, std::size_t size);
  void page_closed(const mg_connection* conn);

 private:
  struct Outgoing {
    std::optional<PageId> page;       // nullopt: every page
    std::optional<std::string> text;  // nullopt: state() at sending time
  };
  void run_sender();
  void deliver(const Outgoing& outgoing);
  void enqueue(Outgoing outgoing);
  bool serve_three(mg_connection* conn, const std::string& uri);

  WebServerOptions options_;
  Callbacks callbacks_;
  std::filesystem::path three_dir_;  // canonical

  mutable std::mutex pages_mutex_;  // held while writing to a connection, so it cannot close meanwhile
  std::map<const mg_connection*, PageId> opened_;  // every open WebSocket
  std::map<PageId, mg_connection*> live_;          // those that got their state: broadcasts go to them
  PageId next_page_ = 1;

  std::mutex queue_mutex_;
  std::condition_variable queued_;
  std::deque<Outgoing> queue_;
  bool stopping_ = false;
  std::thread sender_;
  mg_context* context_ = nullptr;
};

}  // namespace cellmap::view
