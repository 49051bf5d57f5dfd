// See adb/file_io.hpp.
#include "adb/file_io.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

namespace bvhlab::file_io {

std::vector<std::byte> read_all(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FileError(path, "cannot open for reading");
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw FileError(path, "cannot read its size: " + ec.message());
  std::vector<std::byte> bytes(size);
  if (!in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(size)) ||
      in.gcount() != static_cast<std::streamsize>(size))
    throw FileError(path, "read error");
  return bytes;
}

void write_atomically(const std::filesystem::path& path, std::span<const std::byte> bytes) {
  const std::filesystem::path dir = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  std::string temp_name = path.filename().string();
  temp_name.insert(temp_name.begin(), '.');  // hidden, beside the target: the rename stays on one filesystem
  temp_name += ".tmp-XXXXXX";
  std::string temp = (dir / temp_name).string();
  const int fd = ::mkstemp(temp.data());
  if (fd < 0)
    throw FileError(path, "cannot create a temporary file in " + dir.string() + ": " + std::strerror(errno));
  auto abandon = [&](const std::string& problem) {
    ::close(fd);
    ::unlink(temp.c_str());
    throw FileError(path, problem);
  };
  ::fchmod(fd, 0644);
  std::size_t written = 0;
  while (written < bytes.size()) {
    const ::ssize_t r = ::write(fd, bytes.data() + written, bytes.size() - written);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) abandon(std::string("write failed: ") + std::strerror(errno));
    written += static_cast<std::size_t>(r);
  }
  if (::fsync(fd) != 0) abandon(std::string("fsync failed: ") + std::strerror(errno));
  if (::close(fd) != 0) {
    ::unlink(temp.c_str());
    throw FileError(path, std::string("close failed: ") + std::strerror(errno));
  }
  std::error_code ec;
  std::filesystem::rename(temp, path, ec);
  if (ec) {
    ::unlink(temp.c_str());
    throw FileError(path, "cannot move the written file into place: " + ec.message());
  }
}

}  // namespace bvhlab::file_io
