// The one error type of the project. Everything that can go wrong for a user (bad input, no
// device, a kernel that fails to build) throws wp::Error with a one-line message naming the cause;
// main() catches it in one place, prints it and exits non-zero.
#pragma once

#include <stdexcept>
#include <string>

namespace wp {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message, std::string details = {})
      : std::runtime_error(message), details_(std::move(details)) {}
  // Multi-line supplement printed after the message (e.g. an OpenCL build log); may be empty.
  const std::string& details() const { return details_; }

 private:
  std::string details_;
};

}  // namespace wp
