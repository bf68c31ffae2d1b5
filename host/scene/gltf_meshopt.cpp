#include "host/scene/gltf_meshopt.h"

#include <algorithm>
#include <limits>
#include <vector>

#include <meshoptimizer.h>

#include "host/scene/gltf_json.h"
#include "host/util/error.h"

namespace wp::gltf {
namespace {

constexpr const char* kName = "EXT_meshopt_compression";

MeshoptMode parse_mode(const std::string& mode, const std::string& where) {
  if (mode == "ATTRIBUTES") return MeshoptMode::kAttributes;
  if (mode == "TRIANGLES") return MeshoptMode::kTriangles;
  if (mode == "INDICES") return MeshoptMode::kIndices;
  throw Error(where + ": mode '" + mode.substr(0, 32) +
              "' is not ATTRIBUTES, TRIANGLES or INDICES");
}

MeshoptFilter parse_filter(const std::string& filter, const std::string& where) {
  if (filter == "NONE") return MeshoptFilter::kNone;
  if (filter == "OCTAHEDRAL") return MeshoptFilter::kOctahedral;
  if (filter == "QUATERNION") return MeshoptFilter::kQuaternion;
  if (filter == "EXPONENTIAL") return MeshoptFilter::kExponential;
  throw Error(where + ": filter '" + filter.substr(0, 32) +
              "' is not NONE, OCTAHEDRAL, QUATERNION or EXPONENTIAL");
}

// One compressed view: where its bytes are and where they decode to.
struct Job {
  int view = -1;
  MeshoptStream stream;
  const unsigned char* data = nullptr;
  std::size_t size = 0;
  std::size_t offset = 0;  // in the decoded buffer
};

// The extension of bufferView `index`, checked against the spec's rules and the buffers.
Job plan(const tinygltf::Model& model, int index, const tinygltf::Value& ext,
         const PlaceholderBuffers& placeholders) {
  const tinygltf::BufferView& view = model.bufferViews[static_cast<std::size_t>(index)];
  const std::string where = "bufferView " + std::to_string(index) + " " + kName;
  Job job;
  job.view = index;
  const std::uint64_t buffer = count_member(ext, "buffer", where, true);
  const std::uint64_t offset = count_member(ext, "byteOffset", where, false, 0);
  const std::uint64_t length = count_member(ext, "byteLength", where, true, 0, 1);
  const std::uint64_t stride = count_member(ext, "byteStride", where, true, 0, 1);
  const std::uint64_t count = count_member(ext, "count", where, true, 0, 1);
  job.stream.mode = parse_mode(string_member(ext, "mode", where, true), where);
  job.stream.filter = parse_filter(string_member(ext, "filter", where, false, "NONE"), where);
  // The stride is checked before it multiplies anything (at most 256).
  job.stream.stride = static_cast<std::size_t>(std::min<std::uint64_t>(stride, 1u << 20));
  job.stream.count = static_cast<std::size_t>(std::min<std::uint64_t>(count, 1ull << 52));
  check_meshopt_stream(job.stream, length, where);

  if (buffer >= model.buffers.size())
    throw Error(where + ": buffer " + std::to_string(buffer) + " does not exist");
  if (placeholders.count(static_cast<int>(buffer)))
    throw Error(where + ": buffer " + std::to_string(buffer) +
                " is a fallback buffer without data (the compressed bytes cannot be there)");
  const std::vector<unsigned char>& data = model.buffers[buffer].data;
  if (offset > data.size() || length > data.size() - offset)
    throw Error(where + ": bytes " + std::to_string(offset) + " + " + std::to_string(length) +
                " exceed buffer " + std::to_string(buffer) + " (" + std::to_string(data.size()) +
                " bytes)");
  job.data = data.data() + offset;
  job.size = static_cast<std::size_t>(length);

  // The parent view holds the decoded data: its stride and length must agree, and it must lie in
  // its buffer (a placeholder's declared byteLength "MUST be sufficiently large").
  const std::string parent = "bufferView " + std::to_string(index);
  if (view.byteStride != 0 && view.byteStride != job.stream.stride)
    throw Error(parent + ": byteStride " + std::to_string(view.byteStride) + " differs from " +
                kName + "'s " + std::to_string(job.stream.stride));
  if (view.byteLength != job.stream.count * job.stream.stride)
    throw Error(parent + ": byteLength " + std::to_string(view.byteLength) + " is not " + kName +
                "'s count x byteStride = " + std::to_string(job.stream.count * job.stream.stride));
  if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model.buffers.size())
    throw Error(parent + ": buffer " + std::to_string(view.buffer) + " does not exist");
  const auto placeholder = placeholders.find(view.buffer);
  const std::uint64_t room = placeholder != placeholders.end()
                                 ? placeholder->second
                                 : model.buffers[static_cast<std::size_t>(view.buffer)].data.size();
  if (view.byteOffset > room || view.byteLength > room - view.byteOffset)
    throw Error(parent + ": offset " + std::to_string(view.byteOffset) + " + length " +
                std::to_string(view.byteLength) + " exceed buffer " + std::to_string(view.buffer) +
                " (" + std::to_string(room) + " bytes)");
  return job;
}

}  // namespace

// How far the codecs can expand (the extension's bitstream, Appendix A), so that a stream whose
// count x byteStride its compressed bytes cannot hold is refused before anything is allocated:
// ATTRIBUTES stores, for every byte of an element and every group of 16 elements, at least a 2-bit
// header (deltas all 0): 16 bytes in 1/4 byte, 64-fold; TRIANGLES at least one code byte per
// triangle (12 bytes of 32-bit indices, 12-fold); INDICES at least one byte per index (4-fold).
// 64-fold therefore bounds them all.
void check_meshopt_stream(const MeshoptStream& s, std::uint64_t compressed_bytes,
                          const std::string& where) {
  const bool attributes = s.mode == MeshoptMode::kAttributes;
  if (s.count == 0) throw Error(where + ": count must be >= 1");
  if (attributes && (s.stride % 4 != 0 || s.stride > 256))
    throw Error(where + ": ATTRIBUTES need a byteStride divisible by 4 and at most 256 (got " +
                std::to_string(s.stride) + ")");
  if (!attributes && s.stride != 2 && s.stride != 4)
    throw Error(where + ": TRIANGLES and INDICES need a byteStride of 2 or 4 (got " +
                std::to_string(s.stride) + ")");
  if (s.mode == MeshoptMode::kTriangles && s.count % 3 != 0)
    throw Error(where + ": TRIANGLES need a count divisible by 3 (got " + std::to_string(s.count) +
                ")");
  if (!attributes && s.filter != MeshoptFilter::kNone)
    throw Error(where + ": TRIANGLES and INDICES take no filter");
  if (s.filter == MeshoptFilter::kOctahedral && s.stride != 4 && s.stride != 8)
    throw Error(where + ": OCTAHEDRAL needs a byteStride of 4 or 8 (got " +
                std::to_string(s.stride) + ")");
  if (s.filter == MeshoptFilter::kQuaternion && s.stride != 8)
    throw Error(where + ": QUATERNION needs a byteStride of 8 (got " + std::to_string(s.stride) +
                ")");
  // (EXPONENTIAL's stride divisible by 4 holds: it is an ATTRIBUTES filter.)
  const double decoded = double(s.count) * double(s.stride);
  if (decoded > 64.0 * double(compressed_bytes))
    throw Error(where + ": " + std::to_string(s.count) + " x " + std::to_string(s.stride) +
                " bytes cannot decode from " + std::to_string(compressed_bytes) +
                " compressed bytes (at most 64 times as many)");
}

void decode_meshopt_stream(const MeshoptStream& s, const unsigned char* data, std::size_t size,
                           unsigned char* out, const std::string& where) {
  int status = 0;
  const char* mode = "ATTRIBUTES";
  switch (s.mode) {
    case MeshoptMode::kAttributes:
      status = meshopt_decodeVertexBuffer(out, s.count, s.stride, data, size);
      break;
    case MeshoptMode::kTriangles:
      mode = "TRIANGLES";
      status = meshopt_decodeIndexBuffer(out, s.count, s.stride, data, size);
      break;
    case MeshoptMode::kIndices:
      mode = "INDICES";
      status = meshopt_decodeIndexSequence(out, s.count, s.stride, data, size);
      break;
  }
  if (status != 0)
    throw Error(where + ": corrupt " + mode + " data (meshoptimizer's decoder returned " +
                std::to_string(status) + ")");
  switch (s.filter) {
    case MeshoptFilter::kNone:
      break;
    case MeshoptFilter::kOctahedral:
      meshopt_decodeFilterOct(out, s.count, s.stride);
      break;
    case MeshoptFilter::kQuaternion:
      meshopt_decodeFilterQuat(out, s.count, s.stride);
      break;
    case MeshoptFilter::kExponential:
      meshopt_decodeFilterExp(out, s.count, s.stride);
      break;
  }
}

void decode_meshopt(tinygltf::Model& model, const PlaceholderBuffers& placeholders) {
  for (const auto& placeholder : placeholders) {
    model.buffers[static_cast<std::size_t>(placeholder.first)].data.clear();
    model.buffers[static_cast<std::size_t>(placeholder.first)].uri.clear();
  }
  std::vector<Job> jobs;
  std::size_t total = 0;
  for (std::size_t i = 0; i < model.bufferViews.size(); ++i) {
    const std::string where = "bufferView " + std::to_string(i);
    const tinygltf::Value* ext = extension_object(model.bufferViews[i].extensions, kName, where);
    if (!ext) continue;
    jobs.push_back(plan(model, static_cast<int>(i), *ext, placeholders));
    total = (total + 3) / 4 * 4;  // each view 4-byte aligned, as accessors expect
    jobs.back().offset = total;
    total += jobs.back().stream.count * jobs.back().stream.stride;
  }
  if (jobs.empty()) return;
  // Views may share compressed bytes, so the bound of each is not one of all: together they decode
  // to at most 64 times the file's data.
  double input = 0.0;
  for (const tinygltf::Buffer& b : model.buffers) input += double(b.data.size());
  if (double(total) > 64.0 * input)
    throw Error(std::string(kName) + ": " + std::to_string(jobs.size()) + " views decode to " +
                std::to_string(total) + " bytes, more than 64 times the file's " +
                std::to_string(std::uint64_t(input)) + " bytes of data");
  tinygltf::Buffer decoded;
  decoded.name = std::string(kName) + " (decoded)";
  decoded.data.resize(total);
  for (const Job& job : jobs)
    decode_meshopt_stream(job.stream, job.data, job.size, decoded.data.data() + job.offset,
                          "bufferView " + std::to_string(job.view) + " " + kName);
  const int buffer = static_cast<int>(model.buffers.size());
  model.buffers.push_back(std::move(decoded));
  for (const Job& job : jobs) {
    tinygltf::BufferView& view = model.bufferViews[static_cast<std::size_t>(job.view)];
    view.buffer = buffer;
    view.byteOffset = job.offset;
  }
}

}  // namespace wp::gltf
