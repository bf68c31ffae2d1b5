// The film's arithmetic (merging, images) and its file format.
//
// .wpfilm, format 1:
//   line 1: "wavepath-film"
//   line 2: one JSON object of strings and whole numbers (at most kMaxHeaderLine bytes):
//     format (1), width, height, sample_begin, sample_end, spp (= end - begin), fraction_bits
//     (32), words_per_pixel (12), layout (a description of the data, for readers), data_bytes
//     (width x height x 96), nonfinite_samples, device, key (the render key), and last
//     checksum: 16 hex digits, FNV-1a 64 of the header line before `,"checksum"` and then of
//     the data bytes, so that any corrupted byte but the magic line's is found
//   then the data: the film's words (kernels/shared/film.h), each an unsigned 64-bit
//   little-endian integer, and nothing after them.
// Reading checks the header's fields and ranges, the data's size against the file's before
// allocating, the checksum, and that no sum exceeds what the header's sample count can give.
#include "host/film/film.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <memory>
#include <sstream>

#include "host/util/error.h"
#include "host/film/film_header.h"
#include "host/util/fnv1a.h"
#include "host/util/files.h"
#include "host/util/json.h"
#include "host/util/parallel.h"

namespace wp {

namespace {

constexpr const char* kLayout =
    "per pixel, rows from the top: 6 unsigned 128-bit sums, each two little-endian uint64 (low "
    "first): sum of a = round(v * 2^32) for R, G, B, then sum of floor(a^2 / 2^32) for R, G, B";
constexpr const char* kAovLayout =
    "; then 7 more: sum of round(v * 2^32) for albedo R, G, B, normal X + 1, Y + 1, Z + 1, depth";
constexpr std::size_t kMaxDevice = 1024;  // characters of a merged device list

std::string range(std::uint32_t begin, std::uint32_t end) {
  return std::to_string(begin) + ":" + std::to_string(end);
}

// The first ';'-separated field in which two render keys differ, as "a vs b".
std::string key_difference(const std::string& a, const std::string& b) {
  std::istringstream sa(a), sb(b);
  std::string fa, fb;
  while (true) {
    const bool more_a = static_cast<bool>(std::getline(sa, fa, ';'));
    const bool more_b = static_cast<bool>(std::getline(sb, fb, ';'));
    if (!more_a && !more_b) return "keys differ";
    if (!more_a) fa = "(nothing)";
    if (!more_b) fb = "(nothing)";
    if (fa != fb) return fa + " vs " + fb;
  }
}

void check_info(const FilmInfo& info) {
  if (info.width < 1 || info.width > kFilmMaxSide || info.height < 1 || info.height > kFilmMaxSide)
    throw Error("film size " + std::to_string(info.width) + "x" + std::to_string(info.height) +
                " is outside 1..16384");
  if (!(info.sample_begin < info.sample_end && info.sample_end <= WP_FILM_MAX_SAMPLES))
    throw Error("film samples " + range(info.sample_begin, info.sample_end) +
                " are not a non-empty range within 0:1048576");
}

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

// Whole pixels with and without AOVs (156 = 12 x 13 = 26 x 6): 2.4 MiB.
constexpr std::size_t kChunkWords = 156 * 2048;
static_assert(kChunkWords % WP_FILM_WORDS(0) == 0 && kChunkWords % WP_FILM_WORDS(1) == 0);

// Words [first, first + count) as little-endian bytes.
void encode(const std::uint64_t* words, std::size_t count, unsigned char* out) {
  for (std::size_t i = 0; i < count; ++i)
    for (int b = 0; b < 8; ++b) out[8 * i + b] = static_cast<unsigned char>(words[i] >> (8 * b));
}

void decode(const unsigned char* in, std::size_t count, std::uint64_t* words) {
  for (std::size_t i = 0; i < count; ++i) {
    std::uint64_t w = 0;
    for (int b = 7; b >= 0; --b) w = w << 8 | in[8 * i + b];
    words[i] = w;
  }
}

std::uint64_t data_checksum(const std::vector<std::uint64_t>& words, std::uint64_t h) {
  std::vector<unsigned char> bytes(8 * kChunkWords);
  for (std::size_t i = 0; i < words.size(); i += kChunkWords) {
    const std::size_t n = std::min(kChunkWords, words.size() - i);
    encode(words.data() + i, n, bytes.data());
    h = fnv1a64(bytes.data(), 8 * n, h);
  }
  return h;
}

// `s` with control characters made spaces: the header's reader refuses them (film_header.h).
std::string printable(std::string s) {
  for (char& c : s)
    if (static_cast<unsigned char>(c) < 0x20) c = ' ';
  return s;
}

// The header line without its checksum field and closing brace.
std::string header_prefix(const FilmInfo& info, std::uint64_t data_bytes) {
  std::ostringstream o;
  o << "{\"format\":" << kFilmFormat << ",\"width\":" << info.width << ",\"height\":" << info.height
    << ",\"sample_begin\":" << info.sample_begin << ",\"sample_end\":" << info.sample_end
    << ",\"spp\":" << info.samples() << ",\"fraction_bits\":" << WP_FILM_FRACTION_BITS
    << ",\"words_per_pixel\":" << info.words_per_pixel()
    << ",\"layout\":" << json_string(std::string(kLayout) + (info.aov ? kAovLayout : ""))
    << ",\"data_bytes\":" << data_bytes << ",\"nonfinite_samples\":" << info.nonfinite_samples
    << ",\"device\":" << json_string(printable(info.device))
    << ",\"key\":" << json_string(printable(info.key));
  return o.str();
}

// Every sum of the `pixels` pixels at `w` (`stride` words each) within what n samples can give
// (S and the AOV sums < n 2^64, Q < n 2^96): the bound the no-overflow argument of
// kernels/shared/film.h rests on. Returns the first pixel that breaks it, or -1.
long long first_implausible_pixel(const std::uint64_t* w, std::size_t pixels, std::size_t stride,
                                  std::uint64_t n) {
  for (std::size_t p = 0; p < pixels; ++p) {
    const std::uint64_t* px = w + p * stride;
    for (unsigned c = 0; c < 3; ++c)
      if (px[WP_FILM_SUM(c) + 1] >= n || (px[WP_FILM_SQUARES(c) + 1] >> 32) >= n)
        return static_cast<long long>(p);
    for (std::size_t word = WP_FILM_WORDS_PER_PIXEL; word < stride; word += 2)
      if (px[word + 1] >= n) return static_cast<long long>(p);
  }
  return -1;
}

}  // namespace

std::uint64_t film_fixed(float v) {
  const float x = v * 0x1p32f;  // exact, or infinite (which saturates below)
  if (!(x > 0.0f)) return 0;    // negative, zero or NaN
  if (x >= 0x1p64f) return std::numeric_limits<std::uint64_t>::max();
  return static_cast<std::uint64_t>(std::nearbyint(x));  // to nearest, ties to even
}

Uint128 film_square(std::uint64_t a) {
  return (Uint128(a) * a) >> 32;
}

Film::Film(FilmInfo info) : info_(std::move(info)) {
  check_info(info_);
  words_.assign(pixels() * info_.words_per_pixel(), 0);
}

std::string film_identity_problem(const FilmInfo& a, const FilmInfo& b) {
  if (a.width != b.width || a.height != b.height)
    return "different sizes (" + std::to_string(a.width) + "x" + std::to_string(a.height) +
           " and " + std::to_string(b.width) + "x" + std::to_string(b.height) + ")";
  if (a.key != b.key) return "different renders (" + key_difference(a.key, b.key) + ")";
  if (a.aov != b.aov) return "one film has AOVs, the other not";
  return "";
}

std::string film_merge_problem(const FilmInfo& a, const FilmInfo& b) {
  if (std::string identity = film_identity_problem(a, b); !identity.empty()) return identity;
  if (a.sample_begin < b.sample_end && b.sample_begin < a.sample_end)
    return "overlapping samples (" + range(a.sample_begin, a.sample_end) + " and " +
           range(b.sample_begin, b.sample_end) + ")";
  if (a.sample_end != b.sample_begin && b.sample_end != a.sample_begin) {
    const bool a_first = a.sample_end < b.sample_begin;
    return "samples " + range(a.sample_begin, a.sample_end) + " and " +
           range(b.sample_begin, b.sample_end) + " leave " +
           (a_first ? range(a.sample_end, b.sample_begin) : range(b.sample_end, a.sample_begin)) +
           " out";
  }
  return "";
}

void Film::add(const Film& other) {
  const std::string problem = film_merge_problem(info_, other.info_);
  if (!problem.empty()) throw Error("cannot merge films: " + problem);
  const auto& o = other.words_;
  for (std::size_t i = 0; i < words_.size(); i += 2) {  // 128-bit adds, as the kernel's
    const std::uint64_t lo = words_[i] + o[i];
    words_[i + 1] += o[i + 1] + (lo < o[i] ? 1u : 0u);
    words_[i] = lo;
  }
  const bool first = info_.sample_begin < other.info_.sample_begin;
  info_.device = first ? join_devices(info_.device, other.info_.device)
                       : join_devices(other.info_.device, info_.device);
  info_.sample_begin = std::min(info_.sample_begin, other.info_.sample_begin);
  info_.sample_end = std::max(info_.sample_end, other.info_.sample_end);
  info_.nonfinite_samples += other.info_.nonfinite_samples;
}

std::string join_devices(const std::string& a, const std::string& b) {
  std::vector<std::string> names;
  for (const std::string* list : {&a, &b}) {
    std::size_t start = 0;
    while (start <= list->size()) {
      std::size_t end = list->find(" + ", start);
      if (end == std::string::npos) end = list->size();
      const std::string name = list->substr(start, end - start);
      if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
      start = end + 3;
    }
  }
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : " + ") + n;
  return out.size() > kMaxDevice ? out.substr(0, kMaxDevice - 3) + "..." : out;
}

double relative_error(const FilmImages& images) {
  const std::size_t values = images.mean.size();
  if (values == 0) return 0.0;
  double total = 0.0;
  for (const float m : images.mean) total += m;
  const double eps = 0.01 * total / double(values);
  if (!(eps > 0.0)) return 0.0;  // a black image: no relative error to speak of
  double sum = 0.0;
  for (std::size_t i = 0; i + 2 < values; i += 3) {
    double var = 0.0, sq = 3.0 * eps * eps;
    for (std::size_t c = i; c < i + 3; ++c) {
      var += images.variance[c];
      sq += double(images.mean[c]) * images.mean[c];
    }
    sum += var / sq;
  }
  return std::sqrt(sum / double(values / 3));
}

FilmImages Film::images() const {
  FilmImages out;
  out.mean.resize(3 * pixels());
  out.variance.resize(3 * pixels());
  // long double: 64 significant bits, so S and Q (up to 84 and 116 bits) lose at most 2^-64 of
  // themselves, and the variance's cancellation costs less than with double.
  const long double n = info_.samples();
  // Pixels in blocks over the host's threads (x87 arithmetic: ~25 ms for 1280 x 720 on one
  // core); each pixel's values are its own, so the images do not depend on the threads.
  constexpr std::size_t kBlock = 16384;
  parallel_for((pixels() + kBlock - 1) / kBlock, [&](std::size_t b) {
    const std::size_t end = std::min(pixels(), (b + 1) * kBlock);
    for (std::size_t i = b * kBlock; i < end; ++i)
      for (int c = 0; c < 3; ++c) {
        const long double s = static_cast<long double>(sum(i, c)) * 0x1p-32L;      // sum of v
        const long double q = static_cast<long double>(squares(i, c)) * 0x1p-32L;  // sum of v^2
        const long double mean = n > 0 ? s / n : 0.0L;
        // Unbiased sample variance of one sample, divided by n: the variance of the mean.
        const long double var = n > 1 ? std::max(0.0L, (q - n * mean * mean) / (n - 1)) / n : 0.0L;
        out.mean[3 * i + c] = static_cast<float>(mean);
        out.variance[3 * i + c] = static_cast<float>(var);
      }
  });
  if (!info_.aov) return out;
  out.albedo.resize(3 * pixels());
  out.normal.resize(3 * pixels());
  out.depth.resize(pixels());
  const auto mean_of = [&](std::size_t pixel, unsigned word) {
    return n > 0 ? static_cast<long double>(at(pixel, word)) * 0x1p-32L / n : 0.0L;
  };
  for (std::size_t i = 0; i < pixels(); ++i) {
    for (int c = 0; c < 3; ++c) {
      out.albedo[3 * i + c] = static_cast<float>(mean_of(i, WP_FILM_ALBEDO(c)));
      out.normal[3 * i + c] = static_cast<float>(mean_of(i, WP_FILM_NORMAL(c)) - 1.0L);
    }
    out.depth[i] = static_cast<float>(mean_of(i, WP_FILM_DEPTH));
  }
  return out;
}

void Film::write(const std::string& path) const {
  const std::string prefix = header_prefix(info_, words_.size() * sizeof(std::uint64_t));
  const std::uint64_t checksum = data_checksum(words_, fnv1a64(prefix.data(), prefix.size()));
  const std::string head =
      std::string(kFilmMagic) + "\n" + prefix + kChecksumField + hex64(checksum) + "\"}\n";
  File f(std::fopen(path.c_str(), "wb"));
  if (!f) throw Error("cannot write " + path + ": " + std::strerror(errno));
  bool ok = std::fwrite(head.data(), 1, head.size(), f.get()) == head.size();
  std::vector<unsigned char> bytes(8 * kChunkWords);
  for (std::size_t i = 0; ok && i < words_.size(); i += kChunkWords) {
    const std::size_t n = std::min(kChunkWords, words_.size() - i);
    encode(words_.data() + i, n, bytes.data());
    ok = std::fwrite(bytes.data(), 1, 8 * n, f.get()) == 8 * n;
  }
  ok &= std::fclose(f.release()) == 0;
  if (!ok) throw Error("cannot write " + path + ": " + std::strerror(errno));
}

namespace {

// A film file opened and checked up to its data: the header parsed and checked, the data's size
// matched against the file's; `file` is positioned at the data.
struct OpenedFilm {
  File file;
  FilmHeader header;
  std::uint64_t header_hash = 0;  // FNV-1a of the header line before the checksum field
};

OpenedFilm open_film(const std::string& path) {
  const auto fail = [&](const std::string& what) { return Error(path + ": " + what); };
  require_regular_file(path);  // a FIFO must not block fopen
  std::error_code ec;
  const std::uint64_t size = std::filesystem::file_size(path, ec);
  if (ec) throw fail("cannot read: " + ec.message());
  OpenedFilm o;
  o.file.reset(std::fopen(path.c_str(), "rb"));
  if (!o.file) throw fail(std::string("cannot open: ") + std::strerror(errno));

  // The magic line and the header line, read at most kMaxHeaderLine bytes past the magic.
  const std::size_t magic = std::strlen(kFilmMagic) + 1;
  std::string head(static_cast<std::size_t>(std::min<std::uint64_t>(size, magic + kMaxHeaderLine)),
                   '\0');
  if (std::fread(head.data(), 1, head.size(), o.file.get()) != head.size())
    throw fail("read failed (truncated while reading?)");
  if (head.compare(0, magic, std::string(kFilmMagic) + "\n") != 0)
    throw fail(std::string("not a wavepath film (no \"") + kFilmMagic + "\" line at the start)");
  const std::size_t eol = head.find('\n', magic);
  if (eol == std::string::npos)
    throw fail(head.size() < magic + kMaxHeaderLine
                   ? "truncated in its header"
                   : "header line longer than " + std::to_string(kMaxHeaderLine) + " bytes");
  const std::string line = head.substr(magic, eol - magic);
  try {
    o.header = parse_film_header(line);
  } catch (const Error& e) {
    throw fail(e.what());
  }
  // parse_film_header has checked that the checksum field ends the line.
  o.header_hash = fnv1a64(line.data(), line.size() - std::strlen(kChecksumField) - 16 - 2);
  const FilmInfo& info = o.header.info;
  const std::uint64_t data_bytes =
      std::uint64_t(info.width) * std::uint64_t(info.height) * info.words_per_pixel() * 8u;
  if (o.header.data_bytes != data_bytes)
    throw fail("header's data_bytes " + std::to_string(o.header.data_bytes) + " is not " +
               std::to_string(data_bytes) + " for its size");
  const std::uint64_t offset = eol + 1, present = size - offset;
  if (present < data_bytes)
    throw fail("truncated: " + std::to_string(present) + " bytes of film data, " +
               std::to_string(data_bytes) + " expected");
  if (present > data_bytes)
    throw fail(std::to_string(present - data_bytes) + " bytes after the film data");
  if (std::fseek(o.file.get(), static_cast<long>(offset), SEEK_SET) != 0) throw fail("seek failed");
  return o;
}

// Reads the data of a film opened by open_film, chunk by chunk, into `words` (or, when null,
// nowhere), checking the checksum and then the sums' bounds.
void read_data(OpenedFilm& o, const std::string& path, std::uint64_t* words) {
  const auto fail = [&](const std::string& what) { return Error(path + ": " + what); };
  const FilmInfo& info = o.header.info;
  const std::size_t stride = info.words_per_pixel();
  const std::size_t total = std::size_t(info.width) * info.height * stride;
  std::vector<unsigned char> bytes(8 * kChunkWords);
  std::vector<std::uint64_t> scratch(words ? 0 : kChunkWords);
  std::uint64_t h = o.header_hash;
  long long bad = -1;
  for (std::size_t i = 0; i < total; i += kChunkWords) {
    const std::size_t n = std::min(kChunkWords, total - i);
    if (std::fread(bytes.data(), 1, 8 * n, o.file.get()) != 8 * n)
      throw fail("truncated while reading the film data");
    h = fnv1a64(bytes.data(), 8 * n, h);
    std::uint64_t* w = words ? words + i : scratch.data();
    decode(bytes.data(), n, w);
    const long long chunk_bad = first_implausible_pixel(w, n / stride, stride, info.samples());
    if (bad < 0 && chunk_bad >= 0) bad = static_cast<long long>(i / stride) + chunk_bad;
  }
  if (h != o.header.checksum)
    throw fail("corrupted: the checksum of its header and data is " + hex64(h) +
               ", the header says " + hex64(o.header.checksum));
  if (bad >= 0)
    throw fail("pixel " + std::to_string(bad) + " holds more than " +
               std::to_string(info.samples()) + " samples could add up to");
}

}  // namespace

FilmInfo Film::read_info(const std::string& path) {
  OpenedFilm o = open_film(path);
  read_data(o, path, nullptr);
  return o.header.info;
}

Film Film::read(const std::string& path) {
  OpenedFilm o = open_film(path);
  Film film(o.header.info);  // the file holds every byte of it: allocating is safe
  read_data(o, path, film.words_.data());
  return film;
}

}  // namespace wp
