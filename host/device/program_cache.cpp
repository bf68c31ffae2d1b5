#include "host/device/program_cache.h"

#include <cstdio>
#include <cstring>
#include <filesystem>

#include "host/util/files.h"
#include "host/device/cl_runtime.h"
#include "host/util/fnv1a.h"

namespace wp {
namespace {

constexpr char kMagic[8] = {'W', 'P', 'P', 'R', 'O', 'G', '0', '1'};

struct Header {
  char magic[8];
  std::uint64_t key;
  std::uint64_t size;      // bytes of binary after the header
  std::uint64_t checksum;  // fnv1a64 of those bytes
};
static_assert(sizeof(Header) == 32, "Header has no implicit padding");

// Most bytes of a binary read back (a kernel program is a few MiB at most); a larger size in a
// header is taken as corruption before anything is allocated.
constexpr std::uint64_t kMaxBinary = std::uint64_t(1) << 30;

std::uint64_t hash_string(const std::string& s, std::uint64_t h) {
  const std::uint64_t n = s.size();
  h = fnv1a64(&n, sizeof n, h);  // lengths first: ("ab", "c") and ("a", "bc") differ
  return fnv1a64(s.data(), s.size(), h);
}

}  // namespace

std::uint64_t program_cache_key(const DeviceEntry& device, const std::string& driver_version,
                                const std::string& source, const std::string& options) {
  std::uint64_t h = fnv1a64(kMagic, sizeof kMagic);
  for (const std::string* s :
       {&device.platform_name, &device.name, &device.version, &driver_version, &options, &source})
    h = hash_string(*s, h);
  return h;
}

std::string program_cache_path(const std::string& dir, std::uint64_t key) {
  return dir + "/program-" + hex64(key) + ".bin";
}

std::optional<std::vector<unsigned char>> program_cache_load(const std::string& dir,
                                                             std::uint64_t key) {
  if (dir.empty()) return std::nullopt;
  const std::string path = program_cache_path(dir, key);
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) return std::nullopt;
  std::optional<std::vector<unsigned char>> out;
  Header h{};
  // The size must be the file's (checked before anything is allocated), the checksum the bytes'.
  std::error_code ec;
  const std::uintmax_t file_bytes = std::filesystem::file_size(path, ec);
  if (!ec && std::fread(&h, sizeof h, 1, f) == 1 && std::memcmp(h.magic, kMagic, 8) == 0 &&
      h.key == key && h.size > 0 && h.size <= kMaxBinary && file_bytes == sizeof h + h.size) {
    std::vector<unsigned char> bytes(h.size);
    if (std::fread(bytes.data(), 1, bytes.size(), f) == bytes.size() &&
        fnv1a64(bytes.data(), bytes.size()) == h.checksum)
      out = std::move(bytes);
  }
  std::fclose(f);
  return out;
}

void program_cache_store(const std::string& dir, std::uint64_t key,
                         const std::vector<unsigned char>& binary) {
  if (dir.empty() || binary.empty() || binary.size() > kMaxBinary) return;
  Header h{};
  std::memcpy(h.magic, kMagic, 8);
  h.key = key;
  h.size = binary.size();
  h.checksum = fnv1a64(binary.data(), binary.size());
  write_file_atomically(program_cache_path(dir, key), [&](std::FILE* f) {
    return std::fwrite(&h, sizeof h, 1, f) == 1 &&
           std::fwrite(binary.data(), 1, binary.size(), f) == binary.size();
  });
}

}  // namespace wp
