// The kernels/ tree as a newcomer meets it: every stage's entry point (kernels/<stage>.cl) builds
// on its own, with nothing but what it includes, and defines exactly its stage's kernel; and no
// kernel file reaches a path-state lane except through the accessors path_state.h generates from
// shared/path_state.def.
#include <cstdlib>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "host/device/cl_runtime.h"
#include "host/device/kernel_sources.h"
#include "host/render/pipeline.h"
#include "tests/device_test.h"

namespace {

class KernelSourcesOnDevice : public wp::test::DeviceTest {};

// Each stage's .cl alone, every feature on (features.h's defaults) and AOVs, so that every
// #if branch a stage has is compiled: it builds, and its program holds one kernel, the stage's.
TEST_F(KernelSourcesOnDevice, EachStageBuildsAlone) {
  for (const char* name : wp::kStageNames) {
    SCOPED_TRACE(name);
    const std::string source = wp::KernelSources().expand({std::string(name) + ".cl"});
    cl::Program program;
    ASSERT_NO_THROW(program = runtime_->build(source, "-cl-std=CL1.2 -D WP_AOV=1"));
    EXPECT_EQ(program.getInfo<CL_PROGRAM_KERNEL_NAMES>(), name);
  }
}

// The path-state fields, in the order path_state.def declares them.
std::vector<std::string> path_fields() {
  std::vector<std::string> fields;
  for (const wp::EmbeddedFile& f : wp::core_kernel_sources()) {
    if (std::string(f.name) != "shared/path_state.def") continue;
    const std::regex field(
        R"(^WP_PATH_(?:AOV_|OPT_|SURF_|ALIAS_)?FIELD\((?:"[^"]*",\s*)?\w+,\s*(\w+),)");
    std::istringstream lines(f.text);
    for (std::string line; std::getline(lines, line);) {
      std::smatch m;
      if (std::regex_search(line, m, field)) fields.push_back(m[1]);
    }
  }
  return fields;
}

// A field indexed by slot (`paths.hit[slot]`, `p.hit [i]`): the raw access the accessors replace.
std::regex raw_access(const std::vector<std::string>& fields) {
  std::string alternatives;
  for (const auto& f : fields) alternatives += (alternatives.empty() ? "" : "|") + f;
  return std::regex(R"(\.\s*()" + alternatives + R"()\s*\[)");
}

TEST(KernelSources, PathStateIsReachedOnlyThroughItsAccessors) {
  const std::vector<std::string> fields = path_fields();
  ASSERT_GE(fields.size(), 20u) << "path_state.def not found or not parsed";
  const std::regex raw = raw_access(fields);
  // The pattern catches what it is meant to (else the test below could pass by matching nothing).
  EXPECT_TRUE(std::regex_search(std::string("paths.hit[slot].w = 0u;"), raw));
  EXPECT_TRUE(std::regex_search(std::string("p . throughput [i].xyz"), raw));
  EXPECT_FALSE(
      std::regex_search(std::string("path_info(paths, slot); wp_prefetch(paths.hit + s)"), raw));
  int files = 0;
  for (const wp::EmbeddedFile& f : wp::core_kernel_sources()) {
    const std::string name = f.name;
    if (name == "integrator/path_state.h") continue;  // the accessors themselves
    ++files;
    std::istringstream lines(f.text);
    int number = 0;
    for (std::string line; std::getline(lines, line);) {
      ++number;
      EXPECT_FALSE(std::regex_search(line, raw)) << name << ":" << number << ": " << line;
    }
  }
  EXPECT_GT(files, 20);
}

// The kernels' source with its comments blanked (newlines kept, so line numbers stay).
std::string without_comments(const std::string& text) {
  std::string out = text;
  for (std::size_t i = 0; i + 1 < out.size(); ++i) {
    if (out[i] == '/' && out[i + 1] == '*') {
      const std::size_t end = out.find("*/", i + 2);
      const std::size_t stop = end == std::string::npos ? out.size() : end + 2;
      for (std::size_t k = i; k < stop; ++k)
        if (out[k] != '\n') out[k] = ' ';
      i = stop - 1;
    } else if (out[i] == '/' && out[i + 1] == '/') {
      for (; i < out.size() && out[i] != '\n'; ++i) out[i] = ' ';
    }
  }
  return out;
}

// No kernel calls OpenCL's transcendental builtins: PoCL compiles them into out-of-line library
// routines, which took 12-20% of renders where they were on the hot path (docs/performance.md,
// "Environment lookups without library calls", "Sheen without library calls");
// kernels/util/elementary.h has inlined versions with stated bounds. sqrt, fma, floor and the like,
// single instructions, are not in the list.
TEST(KernelSources, NoTranscendentalLibraryCalls) {
  const std::regex call(
      R"((^|[^\w.])(exp|exp2|exp10|expm1|log|log2|log10|log1p|logb|pow|powr|pown|rootn|cbrt|sin|)"
      R"(cos|tan|sincos|sinpi|cospi|tanpi|asin|acos|atan|atan2|atanpi|atan2pi|sinh|cosh|tanh|)"
      R"(asinh|acosh|atanh|hypot|erf|erfc|tgamma|lgamma)\s*\()");
  // The pattern catches what it is meant to (else the test below could pass by matching nothing).
  EXPECT_TRUE(std::regex_search(std::string("x = pow(a, 2.4f);"), call));
  EXPECT_TRUE(std::regex_search(std::string("  return exp (y) * 2;"), call));
  EXPECT_FALSE(std::regex_search(std::string("exp_poly(x) + s.log(x) + sqrt(y) + x.cos"), call));
  EXPECT_FALSE(std::regex_search(without_comments("/* pow(x) */ a; // cos(y)\n"), call));
  int files = 0;
  for (const wp::EmbeddedFile& f : wp::core_kernel_sources()) {
    ++files;
    std::istringstream lines(without_comments(f.text));
    int number = 0;
    for (std::string line; std::getline(lines, line);) {
      ++number;
      EXPECT_FALSE(std::regex_search(line, call)) << f.name << ":" << number << ": " << line;
    }
  }
  EXPECT_GT(files, 20);
}

// Every stage has its entry point, and every stage but the fused one its logic header; the fused
// shade includes the four headers of the stages it fuses.
TEST(KernelSources, EveryStageHasItsFiles) {
  std::set<std::string> names;
  for (const wp::EmbeddedFile& f : wp::core_kernel_sources()) names.insert(f.name);
  for (const char* stage : wp::kStageNames) {
    const std::string s = stage;
    EXPECT_TRUE(names.count(s + ".cl")) << s;
    if (s != "shade") {
      EXPECT_TRUE(names.count("integrator/" + s + ".h")) << s;
    }
  }
  const std::string fused = wp::KernelSources().expand({"shade.cl"});
  for (const char* header : {"shade_surface", "sample_lights", "sample_bsdf", "roulette_compact"})
    EXPECT_NE(fused.find(std::string("#line 1 \"integrator/") + header + ".h\""), std::string::npos)
        << header;
}

// No function is written twice, one copy for a feature switch and one for its absence: a switch
// sits inside the one definition, where the lobes or paths are composed (the X-macro walks of
// traversal/*.def, instantiated per level under names of their own, are not functions here).
// Forward declarations (a `;` after the parameters) are not definitions.
TEST(KernelSources, NoFunctionIsDefinedTwice) {
  const std::regex definition(
      R"((?:^|\n)(?:static\s+inline|WP_LANES_FN|WP_BSDF_EVAL_INLINE|WP_STAGE_FN))"
      R"((?:\s+__attribute__\s*\(\([^)]*\)\))?\s[^;{}()]*?)"
      R"(\b(\w+)\s*\([^;{}]*\)\s*\{)");
  // The pattern catches what it is meant to (else the test below could pass by matching nothing).
  const std::string probe =
      "static inline float f(float x) {\n}\n#if A\nWP_LANES_FN float8 g(float8 x,\n    int y) {}\n"
      "static inline float h(float x);\nstatic inline __attribute__((always_inline)) int k() {}\n";
  std::vector<std::string> found;
  for (std::sregex_iterator it(probe.begin(), probe.end(), definition), end; it != end; ++it)
    found.push_back((*it)[1]);
  EXPECT_EQ(found, (std::vector<std::string>{"f", "g", "k"}));
  std::map<std::string, std::string> where;
  int definitions = 0;
  for (const wp::EmbeddedFile& f : wp::core_kernel_sources()) {
    const std::string name = f.name;
    if (name.size() > 4 && name.compare(name.size() - 4, 4, ".def") == 0) continue;
    const std::string text = without_comments(f.text);
    for (std::sregex_iterator it(text.begin(), text.end(), definition), end; it != end; ++it) {
      ++definitions;
      const std::string fn = (*it)[1];
      const auto [at, fresh] = where.emplace(fn, name);
      EXPECT_TRUE(fresh) << fn << " is defined in " << at->second << " and again in " << name;
    }
  }
  EXPECT_GT(definitions, 200);
}

// Every header is include-guarded: its first directive opens `#ifndef X` `#define X` and its last
// closes it. The expander leaves out a header already read (kernel_sources.h), which is what the
// preprocessor would do only because of the guard.
TEST(KernelSources, EveryHeaderIsIncludeGuarded) {
  const std::regex guard(R"(^\s*#\s*ifndef\s+(\w+)\s*\n\s*#\s*define\s+(\w+))");
  int headers = 0;
  for (const wp::EmbeddedFile& f : wp::core_kernel_sources()) {
    const std::string name = f.name;
    if (name.size() < 2 || name.compare(name.size() - 2, 2, ".h") != 0) continue;
    ++headers;
    const std::string text = without_comments(f.text);
    const std::size_t first = text.find('#');
    std::smatch m;
    const std::string head = first == std::string::npos ? "" : text.substr(first);
    ASSERT_TRUE(std::regex_search(head, m, guard, std::regex_constants::match_continuous))
        << name << ": no #ifndef/#define guard as its first directive";
    EXPECT_EQ(m[1], m[2]) << name;
    const std::size_t last = text.find_last_of('#');
    EXPECT_EQ(text.compare(last, 6, "#endif"), 0) << name << ": the guard's #endif is not last";
  }
  EXPECT_GT(headers, 20);
}

// The expander reads includes as the preprocessor does: a header included first inside an #if
// (here one that is false) is pasted again where it is next included, and its guard decides; one
// already read outside any #if is not pasted twice; an X-macro list (.def) at every include.
TEST(KernelSources, IncludesBehaveAsThePreprocessorSays) {
  wp::KernelSources sources;
  static const std::vector<wp::EmbeddedFile> files = {
      {"probe/guarded.h",
       "#ifndef PROBE_GUARDED_H\n#define PROBE_GUARDED_H\nint guarded;\n#endif\n"},
      {"probe/list.def", "ITEM(one)\n"},
      {"probe/after_false_if.cl",
       "#if 0\n#include \"guarded.h\"\n#endif\n#include \"guarded.h\"\n"},
      {"probe/twice.cl", "#include \"guarded.h\"\n#include \"probe/guarded.h\"\n"},
      {"probe/lists.cl", "#include \"list.def\"\n#include \"list.def\"\n"},
  };
  sources.add(files);
  const auto count = [](const std::string& text, const std::string& what) {
    int n = 0;
    for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
      ++n;
    return n;
  };
  EXPECT_EQ(count(sources.expand({"probe/after_false_if.cl"}), "int guarded;"), 2);
  EXPECT_EQ(count(sources.expand({"probe/twice.cl"}), "int guarded;"), 1);
  EXPECT_EQ(count(sources.expand({"probe/lists.cl"}), "ITEM(one)"), 2);
  // A header that the first program pasted conditionally only: the second still gets it.
  EXPECT_EQ(count(sources.expand({"probe/after_false_if.cl", "probe/twice.cl"}), "int guarded;"),
            2);
}

// A stock OpenCL C compiler builds each stage file from the source tree, with `-I kernels` and
// its own #include (clang, as tools/gpu_compile.py uses it; PoCL's own compiler is clang too,
// but is given the expanded source): the tree reads as ordinary C. Syntax and semantics only,
// every feature on and AOVs, for the SPIR target (no device's code generator needed).
TEST(KernelSources, EachStageBuildsWithClangFromTheSourceTree) {
  if (std::system("clang --version > /dev/null 2>&1") != 0)
    GTEST_SKIP() << "clang not found (tools/setup.sh installs it)";
  for (const char* name : wp::kStageNames) {
    SCOPED_TRACE(name);
    const std::string kernels = std::string(WP_SOURCE_DIR) + "/kernels";
    const std::string cmd =
        "clang -x cl -cl-std=CL1.2 -Xclang -finclude-default-header "
        "-D__OPENCL_VERSION__=120 -D WP_AOV=1 -target spir64 -fsyntax-only "
        "-Werror -Wall -I '" +
        kernels + "' '" + kernels + "/" + name + ".cl' 2>&1";
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  }
}

}  // namespace
