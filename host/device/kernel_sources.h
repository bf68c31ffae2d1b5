// OpenCL C sources, embedded into the binary at build time (host/device/embed_sources.cmake), and
// the include expansion that turns a kernel file into one self-contained program source.
#pragma once

#include <string>
#include <vector>

namespace wp {

struct EmbeddedFile {
  const char* name;  // path relative to its root, e.g. "shared/compat.h"
  const char* text;
};

// The project's kernels/ tree.
const std::vector<EmbeddedFile>& core_kernel_sources();

// A set of named sources that `#include "name"` lines resolve against: first relative to the
// including file's folder, then from the root, as a compiler given `-I kernels` reads them. The
// expansion is what the preprocessor would see: every header is include-guarded (the kernel tree
// test checks), so a header already pasted where it was certain to be read (outside any #if but
// its own guard, in a file so read) is left out of later includes; one included inside an #if,
// or in a file itself included inside one, is pasted at each such include and its guard decides,
// as does everything an X-macro list (.def) includes: a .def is pasted at every include.
class KernelSources {
 public:
  // The core kernels; with WAVEPATH_KERNEL_DIR set, read from that folder on disk instead.
  KernelSources();
  void add(const std::vector<EmbeddedFile>& files);

  // The program text of `names`, in order, with includes expanded. Throws wp::Error when a file
  // or an include is missing.
  std::string expand(const std::vector<std::string>& names) const;

 private:
  std::string text_of(const std::string& name) const;
  void expand_into(const std::string& name, bool conditional, std::vector<std::string>& done,
                   std::string& out, int depth) const;
  std::vector<std::pair<std::string, std::string>> files_;
  std::string disk_root_;
};

}  // namespace wp
