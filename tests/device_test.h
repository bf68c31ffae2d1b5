// A test suite that shares one OpenCL runtime on the default device (PoCL on a machine without a
// GPU): made before the suite's first test, destroyed after its last, so that its programs are
// built once per suite.
#pragma once

#include <gtest/gtest.h>

#include "host/device/cl_runtime.h"

namespace wp::test {

class DeviceTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { runtime_ = new ClRuntime(select_device("")); }
  static void TearDownTestSuite() {
    delete runtime_;
    runtime_ = nullptr;
  }
  inline static ClRuntime* runtime_ = nullptr;
};

}  // namespace wp::test
