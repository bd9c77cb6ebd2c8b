// The ADF reader's shared checks (adf/adf_yaml.h): keys written twice, lists naming a block
// twice, vectors missing a component and names holding a NUL.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "adf/adf_yaml.h"
#include "ambfplus/errors.h"

namespace ambfplus::adf {
namespace {

namespace fs = std::filesystem;

std::string write(const std::string& name, const std::string& text) {
  const fs::path path = fs::temp_directory_path() / ("ambfplus_test_adf_yaml_" + name);
  std::ofstream(path, std::ios::binary) << text;
  return path.string();
}

std::string config_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no ConfigError";
  return "";
}

TEST(AdfYaml, KeyTwiceWithOneValueWarnsNamingBothLines) {
  const std::string path = write("same.yaml", "a: 1\nb: {x: 1}\na: 1\n");
  Diagnostics diag;
  const Doc doc = load(path, "model file", &diag);
  EXPECT_EQ(doc.root["a"].as<int>(), 1);
  ASSERT_EQ(diag.warnings().size(), 1u);
  EXPECT_EQ(diag.warnings()[0].file, path);
  const std::string& m = diag.warnings()[0].message;
  EXPECT_NE(m.find("line 3: key 'a' is given twice"), std::string::npos) << m;
  EXPECT_NE(m.find("first on line 1"), std::string::npos) << m;
}

TEST(AdfYaml, KeyTwiceWithTwoValuesIsAConfigError) {
  const std::string path = write("differ.yaml", "b: {x: 1, y: [1, 2]}\nb: {x: 1, y: [1, 3]}\n");
  Diagnostics diag;
  const std::string m = config_error([&] { load(path, "model file", &diag); });
  EXPECT_NE(m.find(path + ": line 2: key 'b' is given twice"), std::string::npos) << m;
  EXPECT_NE(m.find("first on line 1"), std::string::npos) << m;
  EXPECT_NE(m.find("different values"), std::string::npos) << m;
}

TEST(AdfYaml, NestedKeyTwiceIsFoundAndAliasesAreVisitedOnce) {
  const std::string path =
      write("nested.yaml", "base: &b {x: 1, x: 1}\nc: *b\nd: *b\nlist: [{y: 2, y: 3}]\n");
  Diagnostics diag;
  const std::string m = config_error([&] { load(path, "model file", &diag); });
  EXPECT_NE(m.find("line 4: key 'y' is given twice"), std::string::npos) << m;
  EXPECT_EQ(diag.warnings().size(), 1u);  // x of the anchored mapping, once
}

TEST(AdfYaml, ListNamingABlockTwiceGivesItOnceAndOneWarning) {
  const std::string path = write(
      "list.yaml", "bodies:\n- BODY a\n- BODY b\n- BODY a\nBODY a: {name: a}\nBODY b: {name: b}\n");
  Diagnostics diag;
  const Doc doc = load(path, "model file", &diag);
  const auto blocks = listed(doc, "bodies");
  ASSERT_EQ(blocks.size(), 2u);
  EXPECT_EQ(blocks[0].first, "BODY a");
  EXPECT_EQ(blocks[1].first, "BODY b");
  EXPECT_TRUE(diag.warnings().empty());
  diag.repeated_entries(doc, {"bodies"});
  ASSERT_EQ(diag.warnings().size(), 1u);
  const std::string& m = diag.warnings()[0].message;
  EXPECT_NE(m.find("line 4: 'bodies' names 'BODY a' again (first on line 2)"), std::string::npos)
      << m;
}

TEST(AdfYaml, VectorMissingAComponentIsAConfigError) {
  const std::string path = write("xyz.yaml", "p: {x: 1, z: 2}\nq: {orientation: {r: 0, p: 0}}\n");
  const Doc doc = load(path, "model file");
  std::string m = config_error(
      [&] { xyz(doc, doc.root["p"], "BODY a", "location.position", Eigen::Vector3d::Zero()); });
  EXPECT_NE(m.find("line 1: BODY a: 'location.position' needs x, y and z; 'y' is missing"),
            std::string::npos)
      << m;
  m = config_error([&] { frame(doc, doc.root["q"], "BODY a", "location"); });
  EXPECT_NE(m.find("'location.orientation' needs r, p and y; 'y' is missing"), std::string::npos)
      << m;
}

TEST(AdfYaml, TextHoldingANulIsAConfigError) {
  const std::string path = write("nul.yaml", "mesh: \"Ball_A.STL\\0.png\"\n");
  const Doc doc = load(path, "model file");
  const std::string m = config_error([&] { text(doc, doc.root["mesh"], "BODY a", "mesh"); });
  EXPECT_NE(m.find("'mesh' holds a NUL character"), std::string::npos) << m;
  EXPECT_NE(m.find("after 'Ball_A.STL'"), std::string::npos) << m;
}

}  // namespace
}  // namespace ambfplus::adf
