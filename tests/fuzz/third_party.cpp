// tinygltf and stb_image compiled from Debian's headers (libtinygltf-dev, libstb-dev,
// nlohmann-json3-dev) in this build, so the fuzzer sees their coverage and the sanitizers check
// them, instead of linking the uninstrumented libtinygltf.so and libstb.so. Nothing is copied.
#define TINYGLTF_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <tiny_gltf.h>  // includes stb_image.h and stb_image_write.h, once each
