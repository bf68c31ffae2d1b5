// The kernel program cache (host/device/program_cache.h, ClRuntime::build with a cache folder): a
// second build comes from the cached binary and runs the same; a corrupted, truncated or refused
// entry is a miss that builds from source and replaces it; the key changes with the source and
// options.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "host/device/cl_runtime.h"
#include "host/device/program_cache.h"

namespace {

namespace fs = std::filesystem;

const std::string kSource =
    "__kernel void affine(__global uint* out) {\n"
    "  const uint i = get_global_id(0);\n"
    "  out[i] = i * SCALE + 1u;\n"
    "}\n";
const std::string kOptions = "-D SCALE=3u";
constexpr std::size_t kCount = 256;

class ProgramCache : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { runtime_ = new wp::ClRuntime(wp::select_device("")); }
  static void TearDownTestSuite() {
    delete runtime_;
    runtime_ = nullptr;
  }
  void SetUp() override {
    dir_ =
        (fs::temp_directory_path() / ("wp_program_cache_" + std::to_string(::getpid()))).string();
    fs::remove_all(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string driver() const { return runtime_->device().device.getInfo<CL_DRIVER_VERSION>(); }
  std::string entry() const {
    return wp::program_cache_path(
        dir_, wp::program_cache_key(runtime_->device(), driver(), kSource, kOptions));
  }
  // Builds kSource through the cache and runs it; the output must be i * 3 + 1.
  bool build_and_check() {
    cl::Program program = runtime_->build(kSource, kOptions, dir_);
    cl::Kernel kernel(program, "affine");
    cl::Buffer out(runtime_->context(), CL_MEM_WRITE_ONLY, kCount * sizeof(cl_uint));
    kernel.setArg(0, out);
    runtime_->queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(kCount),
                                           cl::NullRange);
    std::vector<cl_uint> got(kCount);
    runtime_->queue().enqueueReadBuffer(out, CL_TRUE, 0, kCount * sizeof(cl_uint), got.data());
    for (std::size_t i = 0; i < kCount; ++i) EXPECT_EQ(got[i], cl_uint(i * 3 + 1)) << i;
    return runtime_->cached_build();
  }
  // Overwrites the entry's byte at `offset` (from the end when negative) with its complement.
  void flip_byte(long offset) {
    std::FILE* f = std::fopen(entry().c_str(), "r+b");
    ASSERT_NE(f, nullptr);
    std::fseek(f, offset, offset < 0 ? SEEK_END : SEEK_SET);
    const int c = std::fgetc(f);
    std::fseek(f, -1, SEEK_CUR);
    std::fputc(~c & 0xff, f);
    std::fclose(f);
  }

  static wp::ClRuntime* runtime_;
  std::string dir_;
};
wp::ClRuntime* ProgramCache::runtime_ = nullptr;

TEST_F(ProgramCache, SecondBuildComesFromTheCacheAndRunsTheSame) {
  EXPECT_FALSE(build_and_check());
  ASSERT_TRUE(fs::exists(entry()));
  EXPECT_TRUE(build_and_check());
  EXPECT_TRUE(build_and_check());
}

TEST_F(ProgramCache, NoFolderCachesNothing) {
  cl::Program program = runtime_->build(kSource, kOptions);
  EXPECT_FALSE(runtime_->cached_build());
  EXPECT_FALSE(fs::exists(dir_));
}

TEST_F(ProgramCache, CorruptedOrTruncatedEntryIsAMissAndIsReplaced) {
  EXPECT_FALSE(build_and_check());
  flip_byte(-1);  // the binary's last byte: the checksum no longer matches
  EXPECT_FALSE(wp::program_cache_load(
      dir_, wp::program_cache_key(runtime_->device(), driver(), kSource, kOptions)));
  EXPECT_FALSE(build_and_check());  // from source, and stored again
  EXPECT_TRUE(build_and_check());
  fs::resize_file(entry(), fs::file_size(entry()) / 2);
  EXPECT_FALSE(build_and_check());
  EXPECT_TRUE(build_and_check());
  flip_byte(0);  // the magic
  EXPECT_FALSE(build_and_check());
  EXPECT_TRUE(build_and_check());
  flip_byte(16 + 2);  // the size field: it claims megabytes more or fewer than the file holds
  EXPECT_FALSE(wp::program_cache_load(
      dir_, wp::program_cache_key(runtime_->device(), driver(), kSource, kOptions)));
  EXPECT_FALSE(build_and_check());
  EXPECT_TRUE(build_and_check());
}

TEST_F(ProgramCache, BinaryTheDeviceRefusesIsAMissAndIsReplaced) {
  const std::uint64_t key = wp::program_cache_key(runtime_->device(), driver(), kSource, kOptions);
  // A well-formed entry (its checksum matches) whose bytes are no program at all.
  wp::program_cache_store(dir_, key, std::vector<unsigned char>(4096, 0x5a));
  ASSERT_TRUE(wp::program_cache_load(dir_, key));
  EXPECT_FALSE(build_and_check());
  EXPECT_TRUE(build_and_check());
}

TEST(ProgramCacheKey, ChangesWithSourceOptionsAndDriver) {
  wp::DeviceEntry d;
  d.platform_name = "p";
  d.name = "n";
  d.version = "v";
  const std::uint64_t k = wp::program_cache_key(d, "1", kSource, kOptions);
  EXPECT_EQ(k, wp::program_cache_key(d, "1", kSource, kOptions));
  EXPECT_NE(k, wp::program_cache_key(d, "2", kSource, kOptions));
  EXPECT_NE(k, wp::program_cache_key(d, "1", kSource + " ", kOptions));
  EXPECT_NE(k, wp::program_cache_key(d, "1", kSource, kOptions + " -D X"));
  wp::DeviceEntry other = d;
  other.name = "m";
  EXPECT_NE(k, wp::program_cache_key(other, "1", kSource, kOptions));
}

}  // namespace
