#include "host/device/kernel_sources.h"

#include <algorithm>
#include <cctype>
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

// Whether `line` opens (#if, #ifdef, #ifndef) or closes (#endif) a conditional block: +1, -1, or 0.
static int conditional_step(const std::string& line) {
  std::size_t i = line.find_first_not_of(" \t");
  if (i == std::string::npos || line[i] != '#') return 0;
  i = line.find_first_not_of(" \t", i + 1);
  if (i == std::string::npos) return 0;
  const auto word = [&](const char* w) {
    const std::size_t n = std::char_traits<char>::length(w);
    return line.compare(i, n, w) == 0 &&
           (i + n == line.size() || !std::isalnum(static_cast<unsigned char>(line[i + n])));
  };
  if (word("if") || word("ifdef") || word("ifndef")) return 1;
  if (word("endif")) return -1;
  return 0;
}

void KernelSources::expand_into(const std::string& name, bool conditional,
                                std::vector<std::string>& done, std::string& out, int depth) const {
  if (depth > 32) throw Error("kernel include nesting too deep at " + name);
  const bool def = name.size() >= 4 && name.compare(name.size() - 4, 4, ".def") == 0;
  const bool header = name.size() >= 2 && name.compare(name.size() - 2, 2, ".h") == 0;
  if (!def && std::find(done.begin(), done.end(), name) != done.end()) return;
  // Pasted where the preprocessor certainly reads it: its guard is defined from here on.
  if (!def && !conditional) done.push_back(name);
  const std::string text = text_of(name);
  if (text.empty()) throw Error("kernel source not found: " + name);

  std::istringstream lines(text);
  std::string line;
  int number = 0;
  int open = 0;        // conditional blocks open at this line
  int guard_open = 0;  // a header's own include guard: the first block it opens
  out += "#line 1 \"" + name + "\"\n";
  while (std::getline(lines, line)) {
    ++number;
    const int step = conditional_step(line);
    if (step > 0 && header && guard_open == 0 && open == 0) guard_open = 1;
    open += step;
    const auto first = line.find_first_not_of(" \t");
    // `#include "file"` is expanded; `#include <...>` (only in C++ branches of shared headers,
    // which OpenCL C skips) is kept as it is.
    if (first != std::string::npos && line.compare(first, 8, "#include") == 0 &&
        line.find('<', first) == std::string::npos) {
      const auto quote = line.find('"', first);
      const auto close = quote == std::string::npos ? quote : line.find('"', quote + 1);
      if (close == std::string::npos)
        throw Error(name + ":" + std::to_string(number) + ": only #include \"file\" is supported");
      const std::string inc = line.substr(quote + 1, close - quote - 1);
      std::string resolved = folder_of(name) + inc;
      if (!exists(files_, resolved)) resolved = inc;
      if (!exists(files_, resolved))
        throw Error(name + ":" + std::to_string(number) + ": kernel include not found: " + inc);
      expand_into(resolved, conditional || def || open > guard_open, done, out, depth + 1);
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
  for (const auto& n : names) expand_into(n, false, done, out, 0);
  return out;
}

}  // namespace wp
