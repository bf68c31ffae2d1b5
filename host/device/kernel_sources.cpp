#include "host/device/kernel_sources.h"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "host/util/error.h"

namespace wp {

KernelSources::KernelSources() {
  if (const char* dir = std::getenv("WAVEPATH_KERNEL_DIR"); dir && *dir) disk_root_ = dir;
  add(core_kernel_sources());
}

void KernelSources::add(const std::vector<EmbeddedFile>& files) {
  for (const EmbeddedFile& f : files) files_.emplace_back(f.name, f.text);
}

std::string KernelSources::text_of(const std::string& name) const {
  if (!disk_root_.empty()) {
    std::ifstream in(disk_root_ + "/" + name);
    if (in) {
      std::stringstream ss;
      ss << in.rdbuf();
      return ss.str();
    }
  }
  for (const auto& [n, text] : files_)
    if (n == name) return text;
  return {};
}

static std::string folder_of(const std::string& name) {
  const auto slash = name.find_last_of('/');
  return slash == std::string::npos ? std::string() : name.substr(0, slash + 1);
}

static bool exists(const std::vector<std::pair<std::string, std::string>>& files,
                   const std::string& name) {
  return std::any_of(files.begin(), files.end(), [&](const auto& f) { return f.first == name; });
}

void KernelSources::expand_into(const std::string& name, std::vector<std::string>& done,
                                std::string& out, int depth) const {
  if (depth > 32) throw Error("kernel include nesting too deep at " + name);
  // X-macro lists (.def) are meant to be expanded at every include; everything else once.
  const bool once = name.size() < 4 || name.compare(name.size() - 4, 4, ".def") != 0;
  if (once && std::find(done.begin(), done.end(), name) != done.end()) return;
  if (once) done.push_back(name);
  const std::string text = text_of(name);
  if (text.empty()) throw Error("kernel source not found: " + name);

  std::istringstream lines(text);
  std::string line;
  int number = 0;
  out += "#line 1 \"" + name + "\"\n";
  while (std::getline(lines, line)) {
    ++number;
    const auto first = line.find_first_not_of(" \t");
    // `#include "file"` is expanded; `#include <...>` (only in C++ branches of shared headers,
    // which OpenCL C skips) is kept as it is.
    if (first != std::string::npos && line.compare(first, 8, "#include") == 0 &&
        line.find('<', first) == std::string::npos) {
      const auto open = line.find('"', first);
      const auto close = open == std::string::npos ? open : line.find('"', open + 1);
      if (close == std::string::npos)
        throw Error(name + ":" + std::to_string(number) + ": only #include \"file\" is supported");
      const std::string inc = line.substr(open + 1, close - open - 1);
      std::string resolved = folder_of(name) + inc;
      if (!exists(files_, resolved)) resolved = inc;
      if (!exists(files_, resolved))
        throw Error(name + ":" + std::to_string(number) + ": kernel include not found: " + inc);
      expand_into(resolved, done, out, depth + 1);
      out += "#line " + std::to_string(number + 1) + " \"" + name + "\"\n";
      continue;
    }
    out += line;
    out += '\n';
  }
}

std::string KernelSources::expand(const std::vector<std::string>& names) const {
  std::vector<std::string> done;
  std::string out;
  for (const auto& n : names) expand_into(n, done, out, 0);
  return out;
}

}  // namespace wp
