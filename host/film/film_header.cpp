#include "host/film/film_header.h"

#include <cstring>
#include <limits>
#include <map>

#include "host/util/error.h"

namespace wp {

namespace {

// A flat JSON object whose values are strings or whole numbers (no signs, fractions or
// exponents): all a film header holds. Strings may not hold control characters, escaped or not,
// so that a field quoted in an error message stays on one line.
class FlatJson {
 public:
  explicit FlatJson(const std::string& text) : s_(text) {}

  void parse() {
    skip_space();
    expect('{');
    skip_space();
    if (peek() == '}') {
      ++i_;
    } else {
      while (true) {
        skip_space();
        const std::string key = string();
        skip_space();
        expect(':');
        skip_space();
        if (strings.count(key) || numbers.count(key)) fail("duplicate field \"" + key + "\"");
        if (peek() == '"')
          strings[key] = string();
        else
          numbers[key] = number();
        skip_space();
        if (peek() != ',') break;
        ++i_;
      }
      expect('}');
    }
    skip_space();
    if (i_ != s_.size()) fail("text after the header's object");
  }

  std::map<std::string, std::string> strings;
  std::map<std::string, std::uint64_t> numbers;

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw Error("malformed header: " + what + " (at byte " + std::to_string(i_) + ")");
  }
  char peek() const { return i_ < s_.size() ? s_[i_] : '\0'; }
  void skip_space() {
    while (peek() == ' ' || peek() == '\t' || peek() == '\r') ++i_;
  }
  void expect(char c) {
    if (peek() != c) fail(std::string("expected '") + c + "'");
    ++i_;
  }
  unsigned hex_digit() {
    const char c = peek();
    ++i_;
    if (c >= '0' && c <= '9') return unsigned(c - '0');
    if (c >= 'a' && c <= 'f') return unsigned(c - 'a' + 10);
    if (c >= 'A' && c <= 'F') return unsigned(c - 'A' + 10);
    fail("bad \\u escape");
  }
  // A \uXXXX escape (after the \u) as UTF-8; surrogates and control characters are refused.
  void unicode(std::string& out) {
    unsigned cp = 0;
    for (int k = 0; k < 4; ++k) cp = cp << 4 | hex_digit();
    if (cp < 0x20 || (cp >= 0xd800 && cp <= 0xdfff)) fail("unsupported \\u escape");
    if (cp < 0x80) {
      out += static_cast<char>(cp);
    } else if (cp < 0x800) {
      out += static_cast<char>(0xc0 | cp >> 6);
      out += static_cast<char>(0x80 | (cp & 0x3f));
    } else {
      out += static_cast<char>(0xe0 | cp >> 12);
      out += static_cast<char>(0x80 | (cp >> 6 & 0x3f));
      out += static_cast<char>(0x80 | (cp & 0x3f));
    }
  }
  std::string string() {
    expect('"');
    std::string out;
    while (true) {
      if (i_ >= s_.size()) fail("unterminated string");
      const char c = s_[i_++];
      if (c == '"') return out;
      if (static_cast<unsigned char>(c) < 0x20) fail("control character in a string");
      if (c != '\\') {
        out += c;
        continue;
      }
      const char e = peek();
      ++i_;
      switch (e) {
        case '"':
        case '\\':
        case '/':
          out += e;
          break;
        case 'u':
          unicode(out);
          break;
        default:
          fail("unsupported escape in a string");
      }
    }
  }
  std::uint64_t number() {
    const std::size_t start = i_;
    std::uint64_t v = 0;
    while (peek() >= '0' && peek() <= '9') {
      const unsigned d = unsigned(peek() - '0');
      if (v > (std::numeric_limits<std::uint64_t>::max() - d) / 10) fail("number too large");
      v = v * 10 + d;
      ++i_;
    }
    if (i_ == start) fail("expected a string or a whole number");
    if (s_[start] == '0' && i_ - start > 1) fail("number with a leading zero");
    return v;
  }

  const std::string& s_;
  std::size_t i_ = 0;
};

class Fields {
 public:
  explicit Fields(const FlatJson& json) : json_(json) {}
  std::uint64_t number(const char* name) const {
    const auto it = json_.numbers.find(name);
    if (it != json_.numbers.end()) return it->second;
    throw Error(std::string("header field \"") + name +
                (json_.strings.count(name) ? "\" is not a whole number" : "\" is missing"));
  }
  std::string string(const char* name) const {
    const auto it = json_.strings.find(name);
    if (it != json_.strings.end()) return it->second;
    throw Error(std::string("header field \"") + name +
                (json_.numbers.count(name) ? "\" is not a string" : "\" is missing"));
  }
  // A number that must lie in [lo, hi].
  std::uint64_t in(const char* name, std::uint64_t lo, std::uint64_t hi) const {
    const std::uint64_t v = number(name);
    if (v < lo || v > hi)
      throw Error(std::string("header field \"") + name + "\" is " + std::to_string(v) +
                  ", outside " + std::to_string(lo) + ".." + std::to_string(hi));
    return v;
  }

 private:
  const FlatJson& json_;
};

std::uint64_t parse_hex64(const std::string& s) {
  if (s.size() != 16) throw Error("header field \"checksum\" is not 16 hex digits");
  std::uint64_t v = 0;
  for (const char c : s) {
    unsigned d;
    if (c >= '0' && c <= '9')
      d = unsigned(c - '0');
    else if (c >= 'a' && c <= 'f')
      d = unsigned(c - 'a' + 10);
    else
      throw Error("header field \"checksum\" is not 16 hex digits");
    v = v << 4 | d;
  }
  return v;
}

}  // namespace

FilmHeader parse_film_header(const std::string& line) {
  FlatJson json(line);
  json.parse();
  const Fields f(json);
  const std::uint64_t format = f.number("format");
  if (format != kFilmFormat)
    throw Error("film format " + std::to_string(format) +
                " is not supported (this wavepath reads " + std::to_string(kFilmFormat) + ")");
  f.in("fraction_bits", WP_FILM_FRACTION_BITS, WP_FILM_FRACTION_BITS);
  const std::uint64_t words = f.in("words_per_pixel", WP_FILM_WORDS(0), WP_FILM_WORDS(1));
  if (words != WP_FILM_WORDS(0) && words != WP_FILM_WORDS(1))
    throw Error("header field \"words_per_pixel\" is " + std::to_string(words) + ", not " +
                std::to_string(WP_FILM_WORDS(0)) + " or " + std::to_string(WP_FILM_WORDS(1)));
  FilmHeader h;
  h.info.aov = words == WP_FILM_WORDS(1);
  h.info.width = static_cast<int>(f.in("width", 1, kFilmMaxSide));
  h.info.height = static_cast<int>(f.in("height", 1, kFilmMaxSide));
  h.info.sample_begin =
      static_cast<std::uint32_t>(f.in("sample_begin", 0, WP_FILM_MAX_SAMPLES - 1));
  h.info.sample_end =
      static_cast<std::uint32_t>(f.in("sample_end", h.info.sample_begin + 1, WP_FILM_MAX_SAMPLES));
  f.in("spp", h.info.samples(), h.info.samples());
  h.info.nonfinite_samples = f.number("nonfinite_samples");
  h.info.device = f.string("device");
  h.info.key = f.string("key");
  if (h.info.key.empty()) throw Error("header field \"key\" is empty");
  h.data_bytes = f.number("data_bytes");
  h.checksum = parse_hex64(f.string("checksum"));
  const std::size_t at = line.rfind(kChecksumField);
  if (at == std::string::npos || at + std::strlen(kChecksumField) + 16 + 2 != line.size())
    throw Error("header field \"checksum\" is not the last");
  return h;
}

}  // namespace wp
