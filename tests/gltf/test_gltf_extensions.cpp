// The extension table, gltf_extensions.cpp: the statuses it gives, the loader refusing and warning
// exactly as it says, and README.md's glTF extension table listing the same names and statuses.
#include <fstream>
#include <set>
#include <utility>

#include "host/scene/gltf_extensions.h"
#include "tests/gltf/gltf_files.h"

namespace {

using namespace wp::test::gltf_files;
using wp::ExtensionSupport;

// The (name, status) rows of README.md's table under "## glTF support": lines "| `NAME` | status
// |".
std::set<std::pair<std::string, std::string>> readme_rows() {
  std::ifstream in(wp::test::source_path("README.md"));
  std::set<std::pair<std::string, std::string>> rows;
  bool in_section = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("## ", 0) == 0) in_section = line == "## glTF support";
    if (!in_section || line.rfind("| `", 0) != 0) continue;
    const std::size_t name_end = line.find('`', 3);
    const std::size_t status_start = line.find("| ", name_end) + 2;
    const std::size_t status_end = line.find(" |", status_start);
    rows.insert(
        {line.substr(3, name_end - 3), line.substr(status_start, status_end - status_start)});
  }
  return rows;
}

TEST(GltfExtensions, ReadmeTableIsTheTable) {
  std::set<std::pair<std::string, std::string>> table;
  for (const wp::KnownExtension& e : wp::known_extensions())
    table.insert({e.name, e.supported ? "supported" : "ignored"});
  const auto readme = readme_rows();
  ASSERT_FALSE(readme.empty()) << "no table under '## glTF support' in README.md";
  for (const auto& row : readme)
    EXPECT_TRUE(table.count(row)) << "README.md has " << row.first << " " << row.second;
  for (const auto& row : table)
    EXPECT_TRUE(readme.count(row)) << "README.md lacks " << row.first << " " << row.second;
}

TEST(GltfExtensions, Statuses) {
  const std::vector<wp::ExtensionUse> uses =
      wp::extension_uses({"KHR_materials_clearcoat", "EXT_lights_image_based", "EXT_texture_avif",
                          "VENDOR_unknown", "KHR_materials_clearcoat"},
                         {"KHR_materials_clearcoat", "EXT_texture_avif", "VENDOR_required_only"});
  ASSERT_EQ(uses.size(), 5u);  // each once, used first, then the rest of required
  const std::vector<std::pair<std::string, ExtensionSupport>> expected = {
      {"KHR_materials_clearcoat", ExtensionSupport::kSupported},
      {"EXT_lights_image_based", ExtensionSupport::kIgnored},
      {"EXT_texture_avif", ExtensionSupport::kRefused},
      {"VENDOR_unknown", ExtensionSupport::kIgnored},
      {"VENDOR_required_only", ExtensionSupport::kRefused}};
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_EQ(uses[i].name, expected[i].first);
    EXPECT_EQ(uses[i].support, expected[i].second) << uses[i].name;
    EXPECT_FALSE(uses[i].note.empty()) << uses[i].name;
  }
  EXPECT_TRUE(uses[0].required);
  EXPECT_FALSE(uses[1].required);
  EXPECT_EQ(uses[3].note, "unknown to wavepath");
  EXPECT_STREQ(wp::extension_support_name(ExtensionSupport::kRefused), "refused");
}

// For every extension of the table, used and required: the loader does what the status says.
TEST(GltfExtensions, LoaderFollowsTheTable) {
  for (const wp::KnownExtension& e : wp::known_extensions()) {
    SCOPED_TRACE(e.name);
    const std::string name = e.name;
    Gltf g = one_triangle("");
    g.top = "\"extensionsUsed\":[\"" + name + "\"]";
    const wp::Scene used = wp::load_gltf(g.write("used.gltf"));
    if (e.supported) {
      EXPECT_TRUE(used.warnings.empty()) << used.warnings.front();
    } else {
      ASSERT_EQ(used.warnings.size(), 1u);
      EXPECT_NE(used.warnings[0].find("ignoring unsupported extension " + name + " (" + e.note),
                std::string::npos)
          << used.warnings[0];
    }
    EXPECT_EQ(used.gltf.extensions_used, std::vector<std::string>{name});

    g.top += ",\"extensionsRequired\":[\"" + name + "\"]";
    const std::string required = g.write("required.gltf");
    if (e.supported) {
      EXPECT_TRUE(wp::load_gltf(required).warnings.empty());
      continue;
    }
    try {
      wp::load_gltf(required);
      ADD_FAILURE() << "loaded";
    } catch (const wp::RefusedExtensions& refused) {
      EXPECT_NE(std::string(refused.what()).find("requires unsupported extension " + name),
                std::string::npos)
          << refused.what();
      ASSERT_EQ(refused.uses().size(), 1u);
      EXPECT_EQ(refused.uses()[0].support, ExtensionSupport::kRefused);
    }
  }
}

}  // namespace
