// libFuzzer targets for the compressed-data decoders, one per codec (tests/fuzz/CMakeLists.txt
// builds this file three times): the input is the compressed payload (after a small header of the
// parameters the glTF JSON would give), placed in a fixed .glb around it and loaded with
// wp::load_gltf, so that every input reaches the decoder through the loader's own checks, and
// mutations are spent on the payload rather than on JSON syntax.
//
//   fuzz_draco    u32 points, u32 indices (the accessors' counts), u8 ids of POSITION, NORMAL,
//                 TEXCOORD_0 (255: none), u8 0; then the KHR_draco_mesh_compression bytes
//   fuzz_meshopt  u8 mode (0-2), u8 filter (0-3), u16 byteStride, u32 count; then the
//                 EXT_meshopt_compression stream (the decoded view feeds POSITION when it can)
//   fuzz_webp     the EXT_texture_webp image of a textured quad
//
// Findings as for fuzz_gltf: a crash, a sanitizer report, an exception other than wp::Error.
// Draco, meshoptimizer and libwebp are Debian's libraries, not instrumented: the fuzzer sees
// coverage only in wavepath's code around them, and ASan checks only the buffers wavepath owns.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "host/scene/gltf_loader.h"
#include "host/util/error.h"
#include "tests/fuzz/fuzz_file.h"

namespace {

std::uint32_t u32(const std::uint8_t* p) {
  std::uint32_t v = 0;
  std::memcpy(&v, p, 4);
  return v;
}

// A .glb of `json` and `bin`.
std::vector<std::uint8_t> glb(std::string json, std::vector<std::uint8_t> bin) {
  while (json.size() % 4) json += ' ';
  while (bin.size() % 4) bin.push_back(0);
  std::vector<std::uint8_t> out;
  const auto put = [&](std::uint32_t v) {
    const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
    out.insert(out.end(), p, p + 4);
  };
  out.insert(out.end(), {'g', 'l', 'T', 'F'});
  put(2);
  put(static_cast<std::uint32_t>(28 + json.size() + bin.size()));
  put(static_cast<std::uint32_t>(json.size()));
  out.insert(out.end(), {'J', 'S', 'O', 'N'});
  out.insert(out.end(), json.begin(), json.end());
  put(static_cast<std::uint32_t>(bin.size()));
  out.insert(out.end(), {'B', 'I', 'N', 0});
  out.insert(out.end(), bin.begin(), bin.end());
  return out;
}

const char* const kAsset = R"("asset":{"version":"2.0"},"scene":0,)";

std::string num(std::uint64_t v) {
  return std::to_string(v);
}

#if defined(WP_FUZZ_DRACO)
std::vector<std::uint8_t> wrap(const std::uint8_t* data, std::size_t size) {
  if (size < 12) return {};
  const std::uint32_t points = u32(data) % (1u << 24), indices = u32(data + 4) % (1u << 24);
  static const char* const kNames[] = {"POSITION", "NORMAL", "TEXCOORD_0"};
  static const char* const kTypes[] = {"VEC3", "VEC3", "VEC2"};
  std::string attributes, ids, accessors;
  for (int k = 0; k < 3; ++k) {
    const int id = data[8 + k];
    if (id == 255 && k > 0) continue;
    const std::string a =
        num(accessors.empty() ? 0 : std::count(accessors.begin(), accessors.end(), '{'));
    accessors += std::string(accessors.empty() ? "" : ",") + R"({"componentType":5126,"count":)" +
                 num(points) + R"(,"type":")" + kTypes[k] + "\"}";
    attributes += std::string(attributes.empty() ? "" : ",") + "\"" + kNames[k] + "\":" + a;
    ids += std::string(ids.empty() ? "" : ",") + "\"" + kNames[k] + "\":" + num(id == 255 ? 0 : id);
  }
  const std::string index = num(std::count(accessors.begin(), accessors.end(), '{'));
  accessors += R"(,{"componentType":5125,"count":)" + num(indices) + R"(,"type":"SCALAR"})";
  const std::string json =
      std::string("{") + kAsset + R"("scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)" +
      R"("meshes":[{"primitives":[{"attributes":{)" + attributes + R"(},"indices":)" + index +
      R"(,"extensions":{"KHR_draco_mesh_compression":{"bufferView":0,"attributes":{)" + ids +
      R"(}}}}]}],"accessors":[)" + accessors + R"(],"bufferViews":[{"buffer":0,"byteLength":)" +
      num(size - 12) + R"(}],"buffers":[{"byteLength":)" + num(size - 12) +
      R"(}],"extensionsUsed":["KHR_draco_mesh_compression"],)" +
      R"("extensionsRequired":["KHR_draco_mesh_compression"]})";
  return glb(json, std::vector<std::uint8_t>(data + 12, data + size));
}
#elif defined(WP_FUZZ_MESHOPT)
std::vector<std::uint8_t> wrap(const std::uint8_t* data, std::size_t size) {
  if (size < 8) return {};
  static const char* const kModes[] = {"ATTRIBUTES", "TRIANGLES", "INDICES"};
  static const char* const kFilters[] = {"NONE", "OCTAHEDRAL", "QUATERNION", "EXPONENTIAL"};
  const char* mode = kModes[data[0] % 3];
  const char* filter = kFilters[data[1] % 4];
  const std::uint32_t stride = std::uint32_t(data[2]) | std::uint32_t(data[3]) << 8;
  const std::uint32_t count = u32(data + 4) % (1u << 24);
  const std::uint64_t length = std::uint64_t(stride) * count;
  // Where the decoded view can be POSITION (12-byte floats or wider elements), a triangle list
  // reads it; the rest only decodes.
  const bool position = data[0] % 3 == 0 && stride >= 12 && stride % 4 == 0 && count >= 3;
  std::string json = std::string("{") + kAsset + R"("scenes":[{"nodes":[)" + (position ? "0" : "") +
                     R"(]}],"nodes":[{"mesh":0}],)";
  json += R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)";
  json += R"("accessors":[{"bufferView":0,"componentType":5126,"count":)" + num(count) +
          R"(,"type":"VEC3"}],)";
  json += R"("bufferViews":[{"buffer":1,"byteLength":)" + num(length) +
          (position ? R"(,"byteStride":)" + num(stride) : "") +
          R"(,"extensions":{"EXT_meshopt_compression":{"buffer":0,"byteLength":)" + num(size - 8) +
          R"(,"byteStride":)" + num(stride) + R"(,"count":)" + num(count) + R"(,"mode":")" + mode +
          R"(","filter":")" + filter + R"("}}}],)";
  json += R"("buffers":[{"byteLength":)" + num(size - 8) + R"(},{"byteLength":)" + num(length) +
          R"(,"extensions":{"EXT_meshopt_compression":{"fallback":true}}}],)";
  json += R"("extensionsUsed":["EXT_meshopt_compression"],)"
          R"("extensionsRequired":["EXT_meshopt_compression"]})";
  return glb(json, std::vector<std::uint8_t>(data + 8, data + size));
}
#elif defined(WP_FUZZ_WEBP)
std::vector<std::uint8_t> wrap(const std::uint8_t* data, std::size_t size) {
  // A quad (positions, then texture coordinates: 80 bytes), then the image.
  const float quad[20] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0, 1, 1, 1, 1, 0, 0, 0};
  std::vector<std::uint8_t> bin(reinterpret_cast<const std::uint8_t*>(quad),
                                reinterpret_cast<const std::uint8_t*>(quad) + sizeof quad);
  bin.insert(bin.end(), data, data + size);
  const std::string json =
      std::string("{") + kAsset + R"("scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)" +
      R"("meshes":[{"primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1},"mode":6,)" +
      R"("material":0}]}],"materials":[{"pbrMetallicRoughness":{"baseColorTexture":)" +
      R"({"index":0}}}],"textures":[{"extensions":{"EXT_texture_webp":{"source":0}}}],)" +
      R"("images":[{"bufferView":2,"mimeType":"image/webp"}],)" +
      R"("accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"},)" +
      R"({"bufferView":1,"componentType":5126,"count":4,"type":"VEC2"}],)" +
      R"("bufferViews":[{"buffer":0,"byteLength":48},{"buffer":0,"byteOffset":48,)" +
      R"("byteLength":32},{"buffer":0,"byteOffset":80,"byteLength":)" + num(size) + "}]," +
      R"("buffers":[{"byteLength":)" + num(bin.size()) + "}]," +
      R"("extensionsUsed":["EXT_texture_webp"],"extensionsRequired":["EXT_texture_webp"]})";
  return glb(json, bin);
}
#else
#error "define WP_FUZZ_DRACO, WP_FUZZ_MESHOPT or WP_FUZZ_WEBP"
#endif

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const bool verbose = std::getenv("WP_FUZZ_VERBOSE") != nullptr;
  const std::vector<std::uint8_t> file = wrap(data, size);
  if (file.empty()) return 0;
  const std::string path = wp::fuzz::write_input(file.data(), file.size(), ".glb");
  try {
    const wp::Scene scene = wp::load_gltf(path, wp::fuzz::load_options());
    if (verbose) std::fprintf(stderr, "loaded: %zu triangles\n", scene.triangle_count());
  } catch (const wp::Error& e) {
    if (verbose) std::fprintf(stderr, "wp::Error: %s\n", e.what());
  }
  return 0;
}
