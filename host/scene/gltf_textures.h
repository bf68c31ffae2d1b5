// glTF textures into Scene::images and Scene::textures: the images materials use, decoded to 8-bit
// RGBA (image_decode.h), samplers, textureInfo and KHR_texture_transform. Internal to the glTF
// loader.
#pragma once

#include <string>
#include <vector>

#include <tiny_gltf.h>

#include "host/scene/scene.h"

namespace wp::gltf {

// tinygltf image callback: keeps the encoded bytes of images given by URI (files, data URIs) in
// Image::image and leaves images in bufferViews alone (tinygltf hands those over without checking
// the view against its buffer; TextureTable reads them with that check). Nothing is decoded here:
// TextureTable decodes only the images that materials use.
bool keep_encoded_image(tinygltf::Image* image, int index, std::string* err, std::string* warn,
                        int width, int height, const unsigned char* bytes, int size, void* user);

// A textureInfo as glTF writes it, wherever it sits (a material field or an extension object).
struct TextureInfo {
  int index = -1;                              // into the glTF textures; -1: none
  int texcoord = 0;                            // textureInfo.texCoord
  const tinygltf::Value* transform = nullptr;  // its KHR_texture_transform object, if any
};

TextureInfo texture_info(const tinygltf::TextureInfo& info);
TextureInfo texture_info(const tinygltf::NormalTextureInfo& info);
// `object` is a textureInfo inside an extension (e.g. transmissionTexture); `where` names it.
TextureInfo texture_info(const tinygltf::Value& object, const std::string& where);

// Builds Scene::textures (one entry per distinct use) and Scene::images (the images those use,
// each decoded once) as materials ask for them.
class TextureTable {
 public:
  TextureTable(const tinygltf::Model& model, Scene& scene);

  // The Scene::textures index for `info`, or -1 when info.index < 0 (no texture) or when the
  // texture cannot be used (no image source, a texture coordinate set above 1: a warning says
  // so). `srgb`: colour data (base colour, emissive). Throws wp::Error naming `where` and the
  // element for a missing texture, image or sampler, a malformed transform or an image whose
  // bytes cannot be read. The image's pixels come with decode().
  int add(const TextureInfo& info, bool srgb, const std::string& where);

  // Decodes the images add() has given slots in Scene::images since the last call, on all hardware
  // threads. Throws wp::Error for an image that cannot be decoded (the first such in slot order).
  void decode();

  // The checks of add() for a texture wavepath reads nothing from (e.g. KHR_materials_volume's
  // thicknessTexture): the texture, its sampler and image index and its transform must be valid;
  // nothing is decoded, added or warned about.
  void check(const TextureInfo& info, const std::string& where) const;

 private:
  // add()'s TextureRef for `info` with `image` still the glTF image index, or false when the
  // texture cannot be used (a warning says why when `warn_unusable`).
  bool describe(const TextureInfo& info, bool srgb, const std::string& where, bool warn_unusable,
                TextureRef& ref) const;
  int image(int index);
  void warn(const std::string& message) const;

  // An image with a slot, not yet decoded: its name for errors and its encoded bytes (the
  // model's, which outlives the table).
  struct Pending {
    std::string what;
    const unsigned char* bytes;
    std::size_t size;
  };

  const tinygltf::Model& model_;
  Scene& scene_;
  std::vector<int> image_slot_;  // glTF image -> Scene::images index, -1 until used
  std::vector<Pending> pending_;
};

// The KHR_texture_transform of `transform` (may be null: identity) as the rows of TextureRef,
// the matrix T(offset) R(rotation) S(scale) of the extension's specification; `texcoord` is
// replaced by the extension's texCoord when it has one. Throws wp::Error naming `where`.
void texture_transform(const tinygltf::Value* transform, const std::string& where, TextureRef& ref,
                       int& texcoord);

}  // namespace wp::gltf
