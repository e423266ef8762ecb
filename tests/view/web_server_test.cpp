// SPDX-License-Identifier: Apache-2.0
// The viewer's web server as a browser meets it, over real TCP on loopback: which pages may open the live
// connection (/ws). A page of another site open in a browser on the viewing machine must not read the cell.
#include "cellmap/view/web_server.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <optional>
#include <string>
#include <vector>

namespace cellmap::view {
namespace {

// The status line the server answers a WebSocket upgrade of /ws with ("HTTP/1.1 101 ..."), or "" when it
// closed the connection without one. `host` is the Host header; `origin` the Origin header, if any.
std::string upgrade_status(int port, const std::string& host, const std::optional<std::string>& origin) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  ::inet_pton(AF_INET, "127.0.0.1", &address.sin_addr);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    ::close(fd);
    return "no connection";
  }
  std::string request = "GET /ws HTTP/1.1\r\nHost: " + host +
                        "\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                        "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n";
  if (origin) request += "Origin: " + *origin + "\r\n";
  request += "\r\n";
  (void)::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
  std::string answer;
  char buffer[512];
  while (answer.find("\r\n") == std::string::npos) {
    const ssize_t got = ::recv(fd, buffer, sizeof buffer, 0);
    if (got <= 0) break;
    answer.append(buffer, static_cast<std::size_t>(got));
  }
  ::close(fd);
  return answer.substr(0, answer.find("\r\n"));
}

int free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  ::inet_pton(AF_INET, "127.0.0.1", &address.sin_addr);
  socklen_t size = sizeof address;
  ::bind(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address);
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size);
  ::close(fd);
  return ntohs(address.sin_port);
}

TEST(WebServerTest, OnlyTheViewersOwnPagesAndAllowedOriginsOpenTheLiveConnection) {
  WebServerOptions options;
  options.port = free_port();
  options.allowed_origins = {"http://cellpc:8080"};
  std::vector<std::string> refused;
  WebServer::Callbacks callbacks;
  callbacks.state = [] { return std::string("{}"); };
  callbacks.on_refused = [&](const std::string& origin) { refused.push_back(origin); };
  const WebServer server(options, callbacks);
  const std::string own = "127.0.0.1:" + std::to_string(options.port);
  const std::string upgraded = "HTTP/1.1 101 Switching Protocols";

  EXPECT_EQ(upgrade_status(options.port, own, "http://" + own), upgraded);
  EXPECT_EQ(upgrade_status(options.port, "localhost:8080", "http://localhost:8080"), upgraded);
  EXPECT_EQ(upgrade_status(options.port, "[::1]:8080", "http://[::1]:8080"), upgraded);
  EXPECT_EQ(upgrade_status(options.port, own, std::nullopt), upgraded) << "a client that is not a browser";
  EXPECT_EQ(upgrade_status(options.port, "cellpc:8080", "http://cellpc:8080"), upgraded) << "--allow-origin";

  EXPECT_NE(upgrade_status(options.port, own, "http://evil.example.com"), upgraded);
  // DNS rebinding: another site's name made to point here; Host and Origin agree, but name no address.
  EXPECT_NE(upgrade_status(options.port, "evil.example.com:8080", "http://evil.example.com:8080"), upgraded);
  EXPECT_NE(upgrade_status(options.port, own, "null"), upgraded) << "a sandboxed or file:// page";
  EXPECT_NE(upgrade_status(options.port, own, "https://" + own), upgraded);
  EXPECT_EQ(refused, (std::vector<std::string>{"http://evil.example.com", "http://evil.example.com:8080",
                                               "null", "https://" + own}));
}

}  // namespace
}  // namespace cellmap::view
