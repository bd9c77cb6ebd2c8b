#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "ambfplus/errors.h"
#include "ambfplus/io/mesh.h"

namespace ambfplus {
namespace {

namespace fs = std::filesystem;

// One triangle, its three positions in a base64 data URI (float32 (0,0,0), (1,0,0), (0,1,0)).
const char* kTriangle =
    R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
 "nodes": [{"mesh": 0}], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
 "buffers": [{"uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA",
              "byteLength": 36}],
 "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
 "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                "min": [0, 0, 0], "max": [1, 1, 0]}],
 "extras": {"note": "brackets in a string do not nest: [[[[{{{{"}})";

fs::path folder() {
  const fs::path dir = fs::temp_directory_path() / "ambfplus_gltf_depth";
  fs::create_directories(dir);
  return dir;
}

// 200,000 nested arrays inside an otherwise plausible glTF object (a fuzzer's stack overflow).
std::string deep_json() {
  return R"({"asset": {"version": "2.0"}, "extras": )" + std::string(200000, '[') +
         std::string(200000, ']') + "}";
}

void put_u32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}

// Binary glTF: the header, then the JSON chunk (padded with spaces to 4 bytes).
std::string glb(std::string json) {
  while (json.size() % 4 != 0) json.push_back(' ');
  std::string out = "glTF";
  put_u32(out, 2);
  put_u32(out, static_cast<std::uint32_t>(12 + 8 + json.size()));
  put_u32(out, static_cast<std::uint32_t>(json.size()));
  put_u32(out, 0x4E4F534Au);
  return out + json;
}

void write(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

TEST(GltfDepth, AGoodTriangleLoads) {
  const fs::path path = folder() / "triangle.gltf";
  write(path, kTriangle);
  const MeshData mesh = load_mesh(path.string(), 1.0);
  EXPECT_EQ(mesh.vertex_count(), 3u);
  EXPECT_EQ(mesh.indices.size(), 3u);
}

TEST(GltfDepth, DeepNestingIsAnErrorNotAStackOverflow) {
  const fs::path dir = folder();
  // A text glTF, the same JSON under a name that does not say glTF, and a binary glTF.
  write(dir / "deep.gltf", deep_json());
  write(dir / "deep.mesh", "\n  " + deep_json());
  write(dir / "deep.glb", glb(deep_json()));
  for (const char* name : {"deep.gltf", "deep.mesh", "deep.glb"}) {
    try {
      load_mesh((dir / name).string(), 1.0);
      FAIL() << name << " loaded";
    } catch (const ConfigError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(name), std::string::npos) << what;
      EXPECT_NE(what.find("nests deeper than 256 levels"), std::string::npos) << what;
    }
  }
}

}  // namespace
}  // namespace ambfplus
