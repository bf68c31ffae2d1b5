#include "host/util/files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>

#include "host/util/error.h"

namespace wp {

namespace {

// What a file that is not a regular one is, for messages.
const char* file_kind(mode_t mode) {
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a plain file";
}

void check_mode(const std::string& path, mode_t mode) {
  if (!S_ISREG(mode)) throw Error(path + ": not a regular file (" + file_kind(mode) + ")");
}

// Closes a descriptor when it goes out of scope.
struct Descriptor {
  int fd;
  ~Descriptor() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

std::string cache_dir() {
  if (const char* d = std::getenv("WAVEPATH_CACHE_DIR"); d && *d) return d;
  if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x) return std::string(x) + "/wavepath";
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::string(home) + "/.cache/wavepath";
  return {};
}

bool write_file_atomically(const std::string& path, const std::function<bool(std::FILE*)>& write) {
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(path).parent_path(), ec);
  const std::string temp = path + ".tmp" + std::to_string(std::random_device{}());
  std::FILE* f = std::fopen(temp.c_str(), "wb");
  if (!f) return false;
  bool ok = write(f);
  ok &= std::fclose(f) == 0;
  if (ok) std::filesystem::rename(temp, path, ec);
  if (!ok || ec) std::filesystem::remove(temp, ec);
  return ok && !ec;
}

void require_regular_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    throw Error(path + (errno == ENOENT ? std::string(": no such file")
                                        : ": cannot open: " + std::string(std::strerror(errno))));
  check_mode(path, st.st_mode);
}

std::vector<unsigned char> read_regular_file(const std::string& path, std::uint64_t max_bytes) {
  require_regular_file(path);
  const Descriptor f{::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)};
  if (f.fd < 0) throw Error(path + ": cannot open: " + std::strerror(errno));
  struct stat st {};
  if (::fstat(f.fd, &st) != 0) throw Error(path + ": cannot open: " + std::strerror(errno));
  check_mode(path, st.st_mode);
  const std::uint64_t size = static_cast<std::uint64_t>(st.st_size);
  if (size > max_bytes)
    throw Error(path + ": " + std::to_string(size) + " bytes, more than the " +
                std::to_string(max_bytes) + " read");
  std::vector<unsigned char> bytes(static_cast<std::size_t>(size));
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(f.fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw Error(path + ": read failed: " + std::strerror(errno));
    if (n == 0) throw Error(path + ": read failed: the file shrank while it was read");
    done += static_cast<std::size_t>(n);
  }
  return bytes;
}

void check_output_folder(const std::string& out) {
  const std::filesystem::path p(out);
  const std::filesystem::path dir = p.parent_path().empty() ? "." : p.parent_path();
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    throw Error(out + ": folder " + dir.string() + " does not exist");
  // A probe named as write_files' temporary files are, removed at once; O_EXCL never touches a
  // file that is there already.
  const std::string probe = (dir / (".wavepath-probe" + std::to_string(::getpid()) + "-" +
                                    std::to_string(std::random_device{}() % 1000000)))
                                .string();
  const int fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0600);
  if (fd < 0)
    throw Error(out + ": folder " + dir.string() + " is not writable (" + std::strerror(errno) +
                ")");
  ::close(fd);
  ::unlink(probe.c_str());
}

}  // namespace wp
