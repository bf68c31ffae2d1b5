// Image output: linear float OpenEXR with the render settings as header attributes, an 8-bit
// sRGB PNG preview, and linear float PFM (Portable FloatMap, simple to read from any language).
// Writes are atomic: each file is written beside its destination under a temporary name and renamed
// into place only when every file of the set is complete, so a failed run leaves no partial file
// and overwrites nothing.
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "host/film/tonemap.h"

namespace wp {

struct ImageRgb {
  int width = 0, height = 0;
  std::vector<float> rgb;  // linear, row by row from the top, 3 floats per pixel
};

// The file name's extension, lower case, with its dot (".exr"), or "".
std::string extension_of(const std::string& path);

// One output file: `write` writes its content to the path it is given (a temporary name beside
// `path`), throwing on failure.
struct OutputFile {
  std::string path;
  std::function<void(const std::string& temp_path)> write;
};

// Writes `files` atomically as a set: each under a temporary name beside its destination, then,
// once all are complete, renamed into place (with SIGINT, SIGTERM and SIGHUP blocked). On failure
// the temporary files are removed and nothing is replaced; so too on one of those signals, after
// which the process dies of it, unless `signals_remove_and_exit` is false: then the caller's
// handlers stay in charge (one that only records the signal lets the set complete). Throws
// wp::Error naming the file.
void write_files(const std::vector<OutputFile>& files, bool signals_remove_and_exit = true);

// An image beside the main one (the variance, an AOV): channels.size() floats per pixel (1 or 3),
// rows from the top, at the main image's size. EXR outputs hold it as the layer `name` (channels
// name.C for each C in `channels`); a PFM output X.pfm gets X.name.pfm beside it (a colour PFM
// for 3 channels, a greyscale one for 1); PNG outputs leave it out.
struct ImageLayer {
  std::string name;
  std::vector<std::string> channels;
  std::vector<float> data;
};

// The image outputs among `paths` (.exr, .png, .pfm, with `layers` as above) as OutputFiles for
// write_files. Throws wp::Error for any other extension.
std::vector<OutputFile> image_files(const std::vector<std::string>& paths, const ImageRgb& image,
                                    const std::map<std::string, std::string>& exr_attributes,
                                    const PngOptions& png = {},
                                    const std::vector<ImageLayer>& layers = {});

// Writes each of `paths` (by extension: .exr, .png or .pfm; `layers` as above) atomically as a
// set. Throws wp::Error naming the file on failure (an unknown extension, an unwritable folder),
// after removing what it wrote.
void write_images(const std::vector<std::string>& paths, const ImageRgb& image,
                  const std::map<std::string, std::string>& exr_attributes,
                  const PngOptions& png = {}, const std::vector<ImageLayer>& layers = {});

// Reads an OpenEXR file's R, G, B channels (of `layer`, e.g. "variance", when given) as linear
// float. Throws wp::Error on failure, a missing layer included.
ImageRgb read_exr(const std::string& path, const std::string& layer = "");
// Reads the string attributes of an OpenEXR header.
std::map<std::string, std::string> read_exr_attributes(const std::string& path);

}  // namespace wp
