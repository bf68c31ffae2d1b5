// The CLI's progress on stderr (host/cli/progress.h), written to a temporary file instead: on a
// terminal the set-up steps and then the bar share one line, each drawing cleared first ("\r" and
// erase-line), the bar ends with a newline and a step line is cleared, also when the Progress goes
// out of scope early (an error follows on a clean line); a log gets no step lines, only the pass
// lines; nothing at all when disabled (-q).
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "host/cli/progress.h"

namespace {

using wp::cli::Progress;

constexpr const char* kClear = "\r\033[K";

// What `draw` wrote through a Progress(enabled, terminal) on a temporary file.
template <class Draw>
std::string written(bool enabled, bool terminal, Draw draw) {
  FILE* f = std::tmpfile();
  EXPECT_NE(f, nullptr);
  {
    Progress p(enabled, terminal, /*every=*/0.0, /*pixels=*/100.0, std::nullopt, f);
    draw(p);
  }
  std::string text(static_cast<std::size_t>(std::ftell(f)), '\0');
  std::rewind(f);
  EXPECT_EQ(std::fread(text.data(), 1, text.size(), f), text.size());
  std::fclose(f);
  return text;
}

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (auto at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(Progress, TerminalStepsThenBarOnOneLine) {
  const std::string t = written(true, true, [](Progress& p) {
    p.step("loading scene.glb");
    p.step("building the BVH of 12 triangles");
    p.update(1, 2, 0.5, 1);
    p.update(2, 2, 1.0, 2);
    p.finish();
  });
  // Four drawings (two steps, two bars), each from the start of a cleared line.
  EXPECT_EQ(count(t, kClear), 4u) << t;
  EXPECT_EQ(t.rfind(kClear, 0), 0u) << t;
  EXPECT_NE(t.find("0.0 s  loading scene.glb ..."), std::string::npos) << t;
  EXPECT_NE(t.find("building the BVH of 12 triangles ..."), std::string::npos) << t;
  EXPECT_NE(t.find("[####################] 2/2 spp"), std::string::npos) << t;
  // The bar stays, its line ended; nothing after it.
  EXPECT_EQ(count(t, "\n"), 1u) << t;
  EXPECT_EQ(t.back(), '\n') << t;
}

TEST(Progress, AStepLeftOpenIsCleared) {
  // An error during the set-up: the Progress goes out of scope with a step drawn.
  const std::string t = written(true, true, [](Progress& p) { p.step("packing the scene"); });
  EXPECT_EQ(t.size() - t.rfind(kClear), std::string(kClear).size()) << t;  // ends cleared
  EXPECT_EQ(count(t, "\n"), 0u) << t;
  // Cleared before warnings, then drawn again; finish() without a pass clears it, no newline.
  const std::string w = written(true, true, [](Progress& p) {
    p.step("loading");
    p.clear();
    p.step("packing");
    p.finish();
  });
  EXPECT_EQ(count(w, kClear), 4u) << w;
  EXPECT_EQ(count(w, "\n"), 0u) << w;
  EXPECT_EQ(w.size() - w.rfind(kClear), std::string(kClear).size()) << w;
}

TEST(Progress, LogsAndQuietRunsGetNoStepLines) {
  const std::string log = written(true, false, [](Progress& p) {
    p.step("loading scene.glb");
    p.update(1, 2, 0.5, 1);
    p.finish();
  });
  EXPECT_EQ(log, "wavepath: 1/2 spp (50.0%), 0.5 s, ETA 0.5 s, 200 samples/s\n");
  const std::string quiet = written(false, true, [](Progress& p) {
    p.step("loading scene.glb");
    p.update(1, 2, 0.5, 1);
    p.finish();
  });
  EXPECT_EQ(quiet, "");
}

}  // namespace
