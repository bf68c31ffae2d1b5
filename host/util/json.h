// JSON output helpers, shared by the render report (--json) and the .wpfilm header.
#pragma once

#include <string>

namespace wp {

// A JSON string literal with the necessary escapes.
std::string json_string(const std::string& s);

}  // namespace wp
