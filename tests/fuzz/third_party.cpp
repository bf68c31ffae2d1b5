// tinygltf compiled from Debian's header (libtinygltf-dev, nlohmann-json3-dev) in this build, so
// the fuzzer sees its coverage and the sanitizers check it, instead of linking the uninstrumented
// libtinygltf.so. Nothing is copied. TINYGLTF_NO_STB_IMAGE and TINYGLTF_NO_STB_IMAGE_WRITE
// (CMakeLists.txt) leave stb_image and stb_image_write out: the loader decodes images itself.
#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf.h>
