// SPDX-License-Identifier: Apache-2.0
#include "cellmap/common/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <utility>

#include "cellmap/common/error.hpp"

namespace cellmap {
namespace {

[[noreturn]] void fail(const std::filesystem::path& path, const char* what, int error) {
  throw Error(path.string() + ": " + what + ": " + std::strerror(error));
}

// Owns a POSIX descriptor so every exit path closes it.
class Descriptor {
 public:
  explicit Descriptor(int fd) : fd_(fd) {}
  ~Descriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;
  int get() const { return fd_; }
  int release() { return std::exchange(fd_, -1); }

 private:
  int fd_;
};

}  // namespace

void write_file_atomically(const std::filesystem::path& path, std::string_view contents) {
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error(dir.string() + ": cannot create directory: " + ec.message());

  // Errors name `path`, not the temporary file: its random name would make every retry's message differ.
  std::string tmp_name = (dir / ("." + path.filename().string() + ".XXXXXX")).string();
  Descriptor fd(::mkstemp(tmp_name.data()));
  if (fd.get() < 0) fail(path, "cannot create a temporary file", errno);
  const std::filesystem::path tmp(tmp_name);
  auto fail_and_remove_tmp = [&](const char* what) {
    const int error = errno;
    std::filesystem::remove(tmp, ec);
    fail(path, what, error);
  };

  const char* data = contents.data();
  std::size_t left = contents.size();
  while (left > 0) {
    const ssize_t n = ::write(fd.get(), data, left);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) fail_and_remove_tmp("write failed");
    data += n;
    left -= static_cast<std::size_t>(n);
  }
  if (::fchmod(fd.get(), 0644) != 0 || ::fsync(fd.get()) != 0) fail_and_remove_tmp("fsync failed");
  if (::close(fd.release()) != 0) fail_and_remove_tmp("close failed");
  if (::rename(tmp.c_str(), path.c_str()) != 0) fail_and_remove_tmp("rename failed");
  // The rename itself is durable only once the directory entry is on disk.
  Descriptor dir_fd(::open(dir.c_str(), O_RDONLY | O_DIRECTORY));
  if (dir_fd.get() < 0 || ::fsync(dir_fd.get()) != 0) fail(dir, "directory fsync failed", errno);
}

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path.string() + ": cannot open: " + std::strerror(errno));
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw Error(path.string() + ": read failed");
  return buffer.str();
}

}  // namespace cellmap
