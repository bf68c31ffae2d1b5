// Placeholder until the environment-map work lands: loading is refused.
#include "host/environment.h"

#include "host/error.h"

namespace wp {

EnvironmentMap load_environment(const std::string& path) {
  throw Error(path + ": environment maps are not supported yet");
}

void build_environment_tables(EnvironmentMap&) {}

}  // namespace wp
