#include "host/scene/image_decode.h"

#include <cmath>
#include <csetjmp>
#include <cstdint>
#include <cstdio>  // before jpeglib.h, which uses FILE and size_t without including them
#include <cstring>
#include <string>
#include <vector>

#include <jerror.h>
#include <jpeglib.h>
#include <png.h>
#include <webp/decode.h>

#include "host/util/error.h"

// libpng and libjpeg report errors through a callback that must not return: here it longjmps back
// to the function that called setjmp, which returns false, and the caller turns the message into a
// wp::Error. C++ allows that longjmp only where no object with a destructor would be skipped, so
// the functions that call setjmp (png_start, png_pixels, jpeg_start, jpeg_pixels) and the
// callbacks hold plain C data only, and return at once after a longjmp (none of their locals is
// read after one, so none needs to be volatile). The libraries' structs, the output vector and the
// wp::Error live in the callers, which own the structs through guards that destroy them whichever
// way the decoding ends.

namespace wp {
namespace {

// At most 2^28 texels (16384 x 16384; 1 GiB as RGBA), checked before the texels are allocated.
void check_texels(double width, double height, const std::string& what) {
  if (width * height > double(1u << 28)) {
    char size[64];
    std::snprintf(size, sizeof size, "%.0f x %.0f", width, height);
    throw Error(what + ": " + size + " pixels, more than the 16384 x 16384 a texture may have");
  }
}

// ---------------------------------------------------------------------------------------------
// PNG through libpng's low-level API. No gamma or colour-space transform is asked for, so libpng
// does none (its simplified png_image API would convert by gAMA, sRGB and iCCP).

constexpr unsigned char kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

bool is_png(const unsigned char* bytes, std::size_t size) {
  return size >= 8 && std::memcmp(bytes, kPngSignature, 8) == 0;
}

// What libpng's callbacks reach through their pointers: the bytes, how far libpng has read them,
// and where an error jumps to with its message.
struct PngJob {
  const unsigned char* bytes;
  std::size_t size, at;
  std::jmp_buf jump;
  char message[256];
};

void png_failed(png_structp png, png_const_charp message) {
  PngJob* job = static_cast<PngJob*>(png_get_error_ptr(png));
  std::snprintf(job->message, sizeof job->message, "%s", message);
  std::longjmp(job->jump, 1);
}

// libpng's warnings, and its benign errors (which libpng 1.6 makes warnings when reading), are
// about chunks it skips or repairs: an extra byte after the image data, an ancillary chunk out of
// place or with a bad CRC. The texels are whole; the image loads, as it does in viewers.
void png_warned(png_structp, png_const_charp) {}

void png_read_bytes(png_structp png, png_bytep data, std::size_t length) {
  PngJob* job = static_cast<PngJob*>(png_get_io_ptr(png));
  if (length > job->size - job->at) png_error(png, "the data ends early (truncated)");
  std::memcpy(data, job->bytes + job->at, length);
  job->at += length;
}

struct PngHeader {
  png_uint_32 width, height;
  int depth, color, interlace;
  bool trns;
};

// libpng's structs, destroyed with the decoding's end.
struct PngStructs {
  png_structp png = nullptr;
  png_infop info = nullptr;
  PngStructs() = default;
  PngStructs(const PngStructs&) = delete;
  PngStructs& operator=(const PngStructs&) = delete;
  ~PngStructs() {
    if (png) png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
  }
};

// Creates libpng's structs with their limits and reads the chunks before the image data
// (png_read_info) into `header`. False, with job.message, where libpng fails.
bool png_start(PngJob& job, PngStructs& s, PngHeader& header) {
  if (setjmp(job.jump)) return false;
  s.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &job, png_failed, png_warned);
  if (!s.png) {
    std::snprintf(job.message, sizeof job.message, "libpng cannot start (out of memory?)");
    return false;
  }
  s.info = png_create_info_struct(s.png);
  if (!s.info) png_error(s.png, "out of memory");
  // A side of up to 2^24 pixels, stb_image's limit before (check_texels bounds their product).
  png_set_user_limits(s.png, 1u << 24, 1u << 24);
  // Only IHDR, PLTE, tRNS, IDAT and IEND are read; every other chunk is skipped unparsed (text,
  // ICC profiles: compressed data that would be inflated for nothing). What libpng then still
  // allocates for a chunk (a palette, tRNS) is small: 1 MiB at most, 100 chunks.
  png_set_keep_unknown_chunks(s.png, PNG_HANDLE_CHUNK_NEVER, nullptr, -1);
  png_set_chunk_malloc_max(s.png, 1u << 20);
  png_set_chunk_cache_max(s.png, 100);
  png_set_read_fn(s.png, &job, png_read_bytes);
  png_read_info(s.png, s.info);
  png_get_IHDR(s.png, s.info, &header.width, &header.height, &header.depth, &header.color,
               &header.interlace, nullptr, nullptr);
  header.trns = png_get_valid(s.png, s.info, PNG_INFO_tRNS) != 0;
  return true;
}

// The transforms to RGBA8, then every row of every interlace pass into `rgba` (4 x width bytes a
// row), then the chunks after the image data (png_read_end checks the last IDAT's CRC and the end).
bool png_pixels(PngJob& job, const PngStructs& s, const PngHeader& header, png_bytep rgba) {
  if (setjmp(job.jump)) return false;
  png_structp png = s.png;
  if (header.color == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
  if (header.color == PNG_COLOR_TYPE_GRAY && header.depth < 8)
    png_set_expand_gray_1_2_4_to_8(png);          // bit replication: x 255, 85, 17
  if (header.trns) png_set_tRNS_to_alpha(png);    // compared at the file's bit depth
  if (header.depth == 16) png_set_strip_16(png);  // the high byte (png_set_scale_16 rounds)
  if (!(header.color & PNG_COLOR_MASK_COLOR)) png_set_gray_to_rgb(png);
  if (!(header.color & PNG_COLOR_MASK_ALPHA) && !header.trns)
    png_set_add_alpha(png, 0xff, PNG_FILLER_AFTER);
  const int passes = png_set_interlace_handling(png);
  png_read_update_info(png, s.info);
  const std::size_t row = 4 * std::size_t(header.width);
  if (png_get_rowbytes(png, s.info) != row) png_error(png, "not RGBA8 after the transforms");
  for (int pass = 0; pass < passes; ++pass)  // each pass writes its own pixels of the rows
    for (png_uint_32 y = 0; y < header.height; ++y) png_read_row(png, rgba + y * row, nullptr);
  png_read_end(png, nullptr);
  return true;
}

// The filtered rows (a filter byte and the packed samples each) against the compressed bytes left
// once libpng has read up to the image data, before the texels are allocated: deflate expands at
// most 1,032-fold, so a 42 KB file cannot hold a 60000 x 60000 image (fuzzing: IHDR's size alone
// made the decoder before this one allocate 1 GiB). An interlaced image's passes add filter bytes
// of their own, fewer than 8 a row; those and 64 KiB are slack.
void check_png_rows(const PngHeader& header, std::size_t compressed, const std::string& what) {
  const unsigned samples = header.color == PNG_COLOR_TYPE_RGB          ? 3
                           : header.color == PNG_COLOR_TYPE_GRAY_ALPHA ? 2
                           : header.color == PNG_COLOR_TYPE_RGB_ALPHA  ? 4
                                                                       : 1;
  const double rows = header.height;
  const double filtered =
      rows * (1.0 + std::ceil(double(header.width) * samples * header.depth / 8.0));
  if (filtered > 1032.0 * double(compressed) + 8.0 * rows + 65536.0) {
    // As text from the doubles: the rows' size may exceed any integer type.
    char message[128];
    std::snprintf(message, sizeof message,
                  "PNG image data of at most %.0f bytes cannot hold its %.0f bytes of rows",
                  double(compressed), filtered);
    throw Error(what + ": " + message);
  }
}

void decode_png(const unsigned char* bytes, std::size_t size, const std::string& what, Image& out) {
  PngJob job{bytes, size, 0, {}, ""};
  PngStructs s;
  PngHeader header{};
  const auto fail = [&] { return Error(what + ": cannot decode the PNG: " + job.message); };
  if (!png_start(job, s, header)) throw fail();
  check_texels(header.width, header.height, what);
  check_png_rows(header, size - job.at, what);
  out.rgba.assign(4 * std::size_t(header.width) * header.height, 0);
  if (!png_pixels(job, s, header, out.rgba.data())) {
    out.rgba.clear();
    throw fail();
  }
  out.width = static_cast<int>(header.width);
  out.height = static_cast<int>(header.height);
}

// ---------------------------------------------------------------------------------------------
// JPEG through libjpeg-turbo's libjpeg API.

bool is_jpeg(const unsigned char* bytes, std::size_t size) {
  return size >= 3 && bytes[0] == 0xff && bytes[1] == 0xd8 && bytes[2] == 0xff;
}

// A progressive JPEG's scans are each a pass over the whole image: thousands of tiny scans make a
// small file take minutes. libjpeg-turbo's TurboJPEG API stops at 500 (TJFLAG_LIMITSCANS, which
// its fuzzers use); real files have about 10.
constexpr int kMaxJpegScans = 500;
// libjpeg's own memory, the progressive coefficient buffers above all (2 bytes a sample): a
// 16384 x 16384 4:2:0 image takes 768 MiB. Past the bound it fails (no backing store).
constexpr long kMaxJpegMemory = 1L << 30;

// What libjpeg's callbacks reach through cinfo.client_data.
struct JpegJob {
  jpeg_decompress_struct cinfo;
  jpeg_error_mgr errors;
  jpeg_progress_mgr progress;
  std::jmp_buf jump;
  char message[JMSG_LENGTH_MAX];
};

[[noreturn]] void jpeg_failed(j_common_ptr cinfo) {
  JpegJob* job = static_cast<JpegJob*>(cinfo->client_data);
  (*cinfo->err->format_message)(cinfo, job->message);
  std::longjmp(job->jump, 1);
}

// Warnings (msg_level -1) where libjpeg made texels up are errors: corrupt or missing entropy-coded
// data, a file cut short (libjpeg would fill the rest with grey), a broken progression. Those
// about markers around the image data are not: bytes before a marker that libjpeg skips, an
// unknown JFIF version or Adobe transform code (read as YCbCr, as before), a bad ICC marker (not
// read). Trace messages (msg_level >= 0) are dropped.
void jpeg_warned(j_common_ptr cinfo, int msg_level) {
  if (msg_level >= 0) return;
  const int code = cinfo->err->msg_code;
  if (code == JWRN_EXTRANEOUS_DATA || code == JWRN_JFIF_MAJOR || code == JWRN_ADOBE_XFORM ||
      code == JWRN_BOGUS_ICC)
    return;
  jpeg_failed(cinfo);
}

void jpeg_silent(j_common_ptr) {}  // output_message: nothing goes to stderr

void jpeg_count_scans(j_common_ptr cinfo) {
  const j_decompress_ptr d = reinterpret_cast<j_decompress_ptr>(cinfo);
  if (d->input_scan_number > kMaxJpegScans) {
    JpegJob* job = static_cast<JpegJob*>(cinfo->client_data);
    std::snprintf(job->message, sizeof job->message, "more than %d progressive scans",
                  kMaxJpegScans);
    std::longjmp(job->jump, 1);
  }
}

// libjpeg's struct, destroyed with the decoding's end (jpeg_destroy_decompress does nothing for
// a struct never created: cinfo.mem is null).
struct JpegGuard {
  JpegJob& job;
  ~JpegGuard() { jpeg_destroy_decompress(&job.cinfo); }
};

// Creates the decompressor with its error handling, memory bound and scan count, and reads the
// markers up to the first scan (jpeg_read_header). False, with job.message, where libjpeg fails.
bool jpeg_start(JpegJob& job, const unsigned char* bytes, std::size_t size) {
  if (setjmp(job.jump)) return false;
  job.cinfo.err = jpeg_std_error(&job.errors);
  job.errors.error_exit = jpeg_failed;
  job.errors.emit_message = jpeg_warned;
  job.errors.output_message = jpeg_silent;
  job.cinfo.client_data = &job;  // kept by jpeg_create_decompress
  jpeg_create_decompress(&job.cinfo);
  job.cinfo.mem->max_memory_to_use = kMaxJpegMemory;
  job.progress.progress_monitor = jpeg_count_scans;
  job.cinfo.progress = &job.progress;
  jpeg_mem_src(&job.cinfo, bytes, static_cast<unsigned long>(size));
  jpeg_read_header(&job.cinfo, TRUE);
  return true;
}

// Decodes every scanline into `rgba` (4 x width bytes a row) and reads the file to its end.
bool jpeg_pixels(JpegJob& job, JSAMPLE* rgba) {
  if (setjmp(job.jump)) return false;
  jpeg_start_decompress(&job.cinfo);
  const std::size_t row = 4 * std::size_t(job.cinfo.output_width);
  if (job.cinfo.output_components != 4 || job.cinfo.output_width != job.cinfo.image_width ||
      job.cinfo.output_height != job.cinfo.image_height) {
    std::snprintf(job.message, sizeof job.message, "unexpected output format");
    return false;
  }
  while (job.cinfo.output_scanline < job.cinfo.output_height) {
    JSAMPROW line = rgba + job.cinfo.output_scanline * row;
    if (jpeg_read_scanlines(&job.cinfo, &line, 1) != 1) {  // only a suspending source returns 0
      std::snprintf(job.message, sizeof job.message, "no scanline read");
      return false;
    }
  }
  jpeg_finish_decompress(&job.cinfo);
  return true;
}

// A JPEG's size against its bytes, before the pixels are allocated (a 613-byte JPEG claiming
// 16000 x 16000 pixels made the decoder before this one allocate 1 GiB and spend 2 s). Every 8 x 8
// block of every component is coded: a baseline scan spends at least 2 bits on a block (a DC
// difference and an end-of-block code, each at least 1 bit), so at most 256 pixels a byte of luma;
// a progressive file's first DC scan at least 1 bit (512 pixels a byte). More than 1024 pixels a
// byte, past the first 2^16, cannot be a whole image.
void check_jpeg_size(std::size_t size, double width, double height, const std::string& what) {
  if (width * height > 1024.0 * double(size) + 65536.0) {
    char message[160];
    std::snprintf(message, sizeof message,
                  "JPEG data of %zu bytes cannot hold its %.0f x %.0f pixels (at most 1024 a byte)",
                  size, width, height);
    throw Error(what + ": " + message);
  }
}

// Adobe's CMYK (as Photoshop writes it, and libjpeg hands it over) stores 255 - ink, so the light
// left is c x k / 255 for each of R, G, B (rounded; what stb_image made of these files before).
void cmyk_to_rgba(std::vector<std::uint8_t>& pixels) {
  for (std::size_t i = 0; i < pixels.size(); i += 4) {
    const unsigned k = pixels[i + 3];
    for (std::size_t c = 0; c < 3; ++c)
      pixels[i + c] = static_cast<std::uint8_t>((pixels[i + c] * k + 127) / 255);
    pixels[i + 3] = 255;
  }
}

void decode_jpeg(const unsigned char* bytes, std::size_t size, const std::string& what,
                 Image& out) {
  JpegJob job{};  // zeroed: cinfo.mem null until jpeg_create_decompress
  JpegGuard guard{job};
  const auto fail = [&] { return Error(what + ": cannot decode the JPEG: " + job.message); };
  if (!jpeg_start(job, bytes, size)) throw fail();
  jpeg_decompress_struct& cinfo = job.cinfo;
  check_texels(cinfo.image_width, cinfo.image_height, what);
  check_jpeg_size(size, cinfo.image_width, cinfo.image_height, what);
  // Grey, YCbCr and RGB straight to RGBA (libjpeg-turbo's extension: the fourth byte 255); CMYK
  // and YCCK (which libjpeg turns into CMYK) as CMYK, then RGBA.
  const J_COLOR_SPACE space = cinfo.jpeg_color_space;
  const bool cmyk = space == JCS_CMYK || space == JCS_YCCK;
  if (space != JCS_GRAYSCALE && space != JCS_YCbCr && space != JCS_RGB && !cmyk)
    throw Error(what + ": a JPEG of " + std::to_string(cinfo.num_components) +
                " components in no colour space a texture can have (grey, YCbCr, RGB, CMYK)");
  cinfo.out_color_space = cmyk ? JCS_CMYK : JCS_EXT_RGBA;
  out.rgba.assign(4 * std::size_t(cinfo.image_width) * cinfo.image_height, 0);
  if (!jpeg_pixels(job, out.rgba.data())) {
    out.rgba.clear();
    throw fail();
  }
  if (cmyk) cmyk_to_rgba(out.rgba);
  out.width = static_cast<int>(cinfo.image_width);
  out.height = static_cast<int>(cinfo.image_height);
}

// ---------------------------------------------------------------------------------------------
// WebP through libwebp.

bool is_webp(const unsigned char* bytes, std::size_t size) {
  return size >= 12 && std::memcmp(bytes, "RIFF", 4) == 0 && std::memcmp(bytes + 8, "WEBP", 4) == 0;
}

// Its header read and its size checked before the texels are allocated, then decoded into them.
// An animation is refused (a texture is one image).
void decode_webp(const unsigned char* bytes, std::size_t size, const std::string& what,
                 Image& out) {
  int width = 0, height = 0;
  if (!WebPGetInfo(bytes, size, &width, &height))
    throw Error(what + ": not a WebP image libwebp can read (bad or truncated header)");
  WebPBitstreamFeatures features;
  if (WebPGetFeatures(bytes, size, &features) != VP8_STATUS_OK)
    throw Error(what + ": not a WebP image libwebp can read (bad or truncated header)");
  if (features.has_animation)
    throw Error(what + ": an animated WebP image (a texture is one still image)");
  if (width <= 0 || height <= 0)
    throw Error(what + ": WebP image of " + std::to_string(width) + " x " + std::to_string(height) +
                " pixels");
  check_texels(width, height, what);
  const std::size_t row = 4 * std::size_t(width);
  out.rgba.assign(row * std::size_t(height), 0);
  if (!WebPDecodeRGBAInto(bytes, size, out.rgba.data(), out.rgba.size(), static_cast<int>(row)))
    throw Error(what + ": cannot decode the WebP data (corrupt or truncated)");
  out.width = width;
  out.height = height;
}

}  // namespace

void decode_image(const unsigned char* bytes, std::size_t size, const std::string& what,
                  Image& out) {
  if (is_webp(bytes, size))
    decode_webp(bytes, size, what, out);
  else if (is_png(bytes, size))
    decode_png(bytes, size, what, out);
  else if (is_jpeg(bytes, size))
    decode_jpeg(bytes, size, what, out);
  else
    throw Error(what +
                ": not a PNG, JPEG or WebP image (the formats glTF and EXT_texture_webp allow)");
}

}  // namespace wp
