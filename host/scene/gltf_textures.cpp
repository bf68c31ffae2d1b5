#include "host/scene/gltf_textures.h"

#include <climits>
#include <cmath>
#include <exception>
#include <string>

#include "host/scene/gltf_json.h"
#include "host/scene/image_decode.h"
#include "host/util/error.h"
#include "host/util/parallel.h"

namespace wp::gltf {
namespace {

constexpr std::uint64_t kNoSource = ~std::uint64_t{0};
constexpr int kRepeat = 10497, kClampToEdge = 33071, kMirroredRepeat = 33648, kNearest = 9728,
              kLinear = 9729;  // magnification filters, and minification without mip-maps

std::string image_name(const tinygltf::Model& model, int index) {
  const tinygltf::Image& image = model.images[static_cast<std::size_t>(index)];
  std::string s = "image " + std::to_string(index);
  if (!image.name.empty()) s += " '" + image.name + "'";
  if (!image.uri.empty() && image.uri.compare(0, 5, "data:") != 0) s += " (" + image.uri + ")";
  return s;
}

Wrap wrap_mode(int mode, const std::string& where, const char* field) {
  if (mode == kRepeat) return Wrap::kRepeat;
  if (mode == kClampToEdge) return Wrap::kClampToEdge;
  if (mode == kMirroredRepeat) return Wrap::kMirroredRepeat;
  throw Error(where + ": unknown " + field + " " + std::to_string(mode));
}

double finite_number(const tinygltf::Value& v, const std::string& where, const char* field) {
  if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()))
    throw Error(where + "." + field + " is not a finite number");
  return v.GetNumberAsDouble();
}

// A two-number array member of `object`, or `fallback` when absent.
glm::dvec2 vec2_member(const tinygltf::Value& object, const char* field, glm::dvec2 fallback,
                       const std::string& where) {
  if (!object.Has(field)) return fallback;
  const tinygltf::Value& v = object.Get(field);
  if (!v.IsArray() || v.ArrayLen() != 2) throw Error(where + "." + field + " needs 2 numbers");
  return {finite_number(v.Get(0), where, field), finite_number(v.Get(1), where, field)};
}

int int_member(const tinygltf::Value& object, const char* field, int fallback,
               const std::string& where) {
  if (!object.Has(field)) return fallback;
  const tinygltf::Value& v = object.Get(field);
  if (!v.IsInt()) throw Error(where + "." + field + " is not an integer");
  return v.GetNumberAsInt();
}

const tinygltf::Value* transform_of(const tinygltf::ExtensionMap& extensions) {
  const auto it = extensions.find("KHR_texture_transform");
  return it == extensions.end() ? nullptr : &it->second;
}

bool same_use(const TextureRef& a, const TextureRef& b) {
  return a.image == b.image && a.wrap_s == b.wrap_s && a.wrap_t == b.wrap_t &&
         a.nearest == b.nearest && a.mipmaps == b.mipmaps && a.srgb == b.srgb &&
         a.texcoord == b.texcoord && a.row_u == b.row_u && a.row_v == b.row_v;
}

}  // namespace

bool keep_encoded_image(tinygltf::Image* image, int, std::string*, std::string*, int, int,
                        const unsigned char* bytes, int size, void*) {
  if (image->bufferView < 0 && bytes && size > 0) image->image.assign(bytes, bytes + size);
  return true;
}

TextureInfo texture_info(const tinygltf::TextureInfo& info) {
  return {info.index, info.texCoord, transform_of(info.extensions)};
}

TextureInfo texture_info(const tinygltf::NormalTextureInfo& info) {
  return {info.index, info.texCoord, transform_of(info.extensions)};
}

TextureInfo texture_info(const tinygltf::Value& object, const std::string& where) {
  if (!object.IsObject()) throw Error(where + " is not an object");
  TextureInfo info;
  info.index = int_member(object, "index", -1, where);
  if (info.index < 0) throw Error(where + " has no valid index");
  info.texcoord = int_member(object, "texCoord", 0, where);
  if (object.Has("extensions")) {
    const tinygltf::Value& ext = object.Get("extensions");
    if (ext.IsObject() && ext.Has("KHR_texture_transform"))
      info.transform = &ext.Get("KHR_texture_transform");
  }
  return info;
}

// The extension's matrix T(offset) R(rotation) S(scale) has rows (c sx, s sy, ox) and
// (-s sx, c sy, oy), c = cos(rotation), s = sin(rotation): UVs turn counter-clockwise, the image
// clockwise, as the extension's example (offset [0, 1], rotation pi/2, scale 0.5 selects the
// lower left quadrant) and the Khronos sample viewer have it. (The extension's GLSL listing, read
// as GLSL's column-major constructor, has the opposite sign of rotation and contradicts that
// example.)
void texture_transform(const tinygltf::Value* transform, const std::string& where, TextureRef& ref,
                       int& texcoord) {
  if (!transform) return;
  const std::string at = where + ".KHR_texture_transform";
  if (!transform->IsObject()) throw Error(at + " is not an object");
  const glm::dvec2 offset = vec2_member(*transform, "offset", glm::dvec2(0.0), at);
  const glm::dvec2 scale = vec2_member(*transform, "scale", glm::dvec2(1.0), at);
  const double rotation =
      transform->Has("rotation") ? finite_number(transform->Get("rotation"), at, "rotation") : 0.0;
  texcoord = int_member(*transform, "texCoord", texcoord, at);
  const double c = std::cos(rotation), s = std::sin(rotation);
  ref.row_u = glm::vec3(glm::dvec3(c * scale.x, s * scale.y, offset.x));
  ref.row_v = glm::vec3(glm::dvec3(-s * scale.x, c * scale.y, offset.y));
}

TextureTable::TextureTable(const tinygltf::Model& model, Scene& scene)
    : model_(model), scene_(scene), image_slot_(model.images.size(), -1) {}

void TextureTable::warn(const std::string& message) const {
  scene_.warnings.push_back(scene_.source + ": " + message);
}

bool TextureTable::describe(const TextureInfo& info, bool srgb, const std::string& where,
                            bool warn_unusable, TextureRef& ref) const {
  if (static_cast<std::size_t>(info.index) >= model_.textures.size())
    throw Error(where + ": texture " + std::to_string(info.index) + " does not exist");
  const tinygltf::Texture& texture = model_.textures[static_cast<std::size_t>(info.index)];
  const std::string tex_where = where + ": texture " + std::to_string(info.index);
  int texcoord = info.texcoord;
  texture_transform(info.transform, where, ref, texcoord);
  if (texcoord < 0) throw Error(where + ": texCoord " + std::to_string(texcoord) + " is negative");
  if (texcoord > 1) {
    if (warn_unusable)
      warn(where + ": TEXCOORD_" + std::to_string(texcoord) +
           " is not supported (only 0 and 1); texture ignored");
    return false;
  }
  // EXT_texture_webp's source is the image to use; `source` is a fallback for viewers without it.
  // KHR_texture_basisu's KTX2 images have no decoder here (none in Debian): its fallback `source`
  // is used, and a texture in use without one is an error naming the extension.
  std::uint64_t source = texture.source < 0 ? kNoSource : std::uint64_t(texture.source);
  if (const tinygltf::Value* webp =
          extension_object(texture.extensions, "EXT_texture_webp", tex_where))
    source = count_member(*webp, "source", tex_where + ": EXT_texture_webp", true);
  if (source == kNoSource) {  // e.g. only an extension's source (KTX2, AVIF)
    if (!warn_unusable) return false;
    if (texture.extensions.count("KHR_texture_basisu"))
      throw Error(tex_where +
                  ": KHR_texture_basisu (KTX2) images cannot be decoded and the "
                  "texture has no fallback source");
    warn(tex_where + " has no PNG, JPEG or WebP source; ignored");
    return false;
  }
  if (source >= model_.images.size())
    throw Error(tex_where + ": image " + std::to_string(source) + " does not exist");
  if (texture.sampler >= 0) {
    if (static_cast<std::size_t>(texture.sampler) >= model_.samplers.size())
      throw Error(tex_where + ": sampler " + std::to_string(texture.sampler) + " does not exist");
    const tinygltf::Sampler& s = model_.samplers[static_cast<std::size_t>(texture.sampler)];
    const std::string sampler_where = "sampler " + std::to_string(texture.sampler);
    ref.wrap_s = wrap_mode(s.wrapS, sampler_where, "wrapS");
    ref.wrap_t = wrap_mode(s.wrapT, sampler_where, "wrapT");
    if (s.magFilter != -1 && s.magFilter != kNearest && s.magFilter != kLinear)
      throw Error(sampler_where + ": unknown magFilter " + std::to_string(s.magFilter));
    // minFilter: NEAREST, LINEAR, or one of the four *_MIPMAP_* modes 9984-9987 (trilinear
    // here, whichever of them).
    if (s.minFilter != -1 && s.minFilter != kNearest && s.minFilter != kLinear &&
        !(s.minFilter >= 9984 && s.minFilter <= 9987))
      throw Error(sampler_where + ": unknown minFilter " + std::to_string(s.minFilter));
    ref.nearest = s.magFilter == kNearest;
    ref.mipmaps = s.minFilter != kNearest && s.minFilter != kLinear;
  }
  ref.srgb = srgb;
  ref.texcoord = texcoord;
  ref.image = static_cast<int>(source);
  return true;
}

void TextureTable::check(const TextureInfo& info, const std::string& where) const {
  TextureRef ref;
  if (info.index >= 0) describe(info, false, where, false, ref);
}

int TextureTable::add(const TextureInfo& info, bool srgb, const std::string& where) {
  if (info.index < 0) return -1;
  TextureRef ref;
  if (!describe(info, srgb, where, true, ref)) return -1;
  ref.image = image(ref.image);
  for (std::size_t i = 0; i < scene_.textures.size(); ++i)
    if (same_use(scene_.textures[i], ref)) return static_cast<int>(i);
  scene_.textures.push_back(ref);
  return static_cast<int>(scene_.textures.size() - 1);
}

// Image `index`'s slot in Scene::images, given on first use: its bytes (from its bufferView,
// checked against the buffer, or those keep_encoded_image kept for a URI) are checked and kept
// for decode(), which fills the slot.
int TextureTable::image(int index) {
  int& slot = image_slot_[static_cast<std::size_t>(index)];
  if (slot >= 0) return slot;
  const tinygltf::Image& in = model_.images[static_cast<std::size_t>(index)];
  const std::string what = image_name(model_, index);
  const unsigned char* bytes = in.image.data();
  std::size_t size = in.image.size();
  if (in.bufferView >= 0) {
    if (static_cast<std::size_t>(in.bufferView) >= model_.bufferViews.size())
      throw Error(what + ": bufferView " + std::to_string(in.bufferView) + " does not exist");
    const tinygltf::BufferView& view = model_.bufferViews[static_cast<std::size_t>(in.bufferView)];
    if (view.buffer < 0 || static_cast<std::size_t>(view.buffer) >= model_.buffers.size())
      throw Error(what + ": buffer " + std::to_string(view.buffer) + " does not exist");
    const std::vector<unsigned char>& data =
        model_.buffers[static_cast<std::size_t>(view.buffer)].data;
    if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset)
      throw Error(what + ": bufferView " + std::to_string(in.bufferView) + " exceeds buffer " +
                  std::to_string(view.buffer));
    bytes = data.data() + view.byteOffset;
    size = view.byteLength;
  }
  if (size == 0) throw Error(what + ": no image data (file missing or unreadable?)");
  if (size > static_cast<std::size_t>(INT_MAX)) throw Error(what + ": larger than 2 GiB");
  Image out;
  out.name = in.name.empty() ? in.uri.substr(0, 64) : in.name;
  slot = static_cast<int>(scene_.images.size());
  scene_.images.push_back(std::move(out));
  pending_.push_back({what, bytes, size});
  return slot;
}

void TextureTable::decode() {
  const std::size_t first = scene_.images.size() - pending_.size();
  std::vector<std::exception_ptr> errors(pending_.size());
  parallel_for(pending_.size(), [&](std::size_t i) {
    const Pending& p = pending_[i];
    try {
      decode_image(p.bytes, p.size, p.what, scene_.images[first + i]);
    } catch (...) {
      errors[i] = std::current_exception();
    }
  });
  pending_.clear();
  for (const std::exception_ptr& e : errors)  // the first image's error, whichever thread was first
    if (e) std::rethrow_exception(e);
}

}  // namespace wp::gltf
