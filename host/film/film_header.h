// The header line of a .wpfilm file (format in film.cpp): a flat JSON object, parsed and checked
// here by a strict reader of its own (strings and whole numbers only, bounded by the line).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "host/film/film.h"

namespace wp {

constexpr const char* kFilmMagic = "wavepath-film";  // the file's first line
constexpr int kFilmFormat = 1;
constexpr std::size_t kMaxHeaderLine = 16384;  // bytes of the header line, newline included
// The header's last field (then 16 hex digits, a quote and the closing brace).
constexpr const char* kChecksumField = ",\"checksum\":\"";

struct FilmHeader {
  FilmInfo info;
  std::uint64_t data_bytes = 0;
  std::uint64_t checksum = 0;  // FNV-1a 64 of the header line before kChecksumField, then the data
};

// Parses and checks the header line (without its newline): JSON syntax, every field present with
// its type, format 1, the fixed-point layout, the size and the sample range in bounds, spp equal
// to the range's length, the checksum field last. Throws wp::Error with a one-line cause (without
// a file name).
FilmHeader parse_film_header(const std::string& line);

}  // namespace wp
