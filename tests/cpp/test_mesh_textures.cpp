#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "ambfplus/io/mesh.h"

namespace ambfplus {
namespace {

namespace fs = std::filesystem;

// A quad whose (u, v) is its position mapped from [-1, 1] to [0, 1], with an MTL naming a
// texture in a subfolder.
fs::path write_quad(const fs::path& dir) {
  fs::create_directories(dir / "maps");
  std::ofstream(dir / "quad.mtl") << "newmtl skin\nKd 1 1 1\nmap_Kd maps/skin.png\n";
  std::ofstream(dir / "quad.obj") << "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
                                     "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\nusemtl skin\n"
                                     "f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n";
  return dir / "quad.obj";
}

TEST(MeshTextures, KeepsTextureCoordinatesAndTheMaterialsDiffuseMap) {
  const fs::path dir = fs::temp_directory_path() / "ambfplus_mesh_textures";
  fs::remove_all(dir);
  const MeshData mesh = load_mesh(write_quad(dir).string(), 2.0);
  ASSERT_EQ(mesh.texcoords.size(), 2 * mesh.vertex_count());
  for (std::size_t i = 0; i < mesh.vertex_count(); ++i) {
    // Positions are scaled by 2; texture coordinates are not.
    EXPECT_NEAR(mesh.texcoords[2 * i], (mesh.positions[3 * i] / 2 + 1) / 2, 1e-6);
    EXPECT_NEAR(mesh.texcoords[2 * i + 1], (mesh.positions[3 * i + 1] / 2 + 1) / 2, 1e-6);
  }
  EXPECT_EQ(fs::path(mesh.texture), dir / "maps" / "skin.png");
  fs::remove_all(dir);
}

TEST(MeshTextures, AMeshWithoutCoordinatesHasNone) {
  const fs::path dir = fs::temp_directory_path() / "ambfplus_mesh_no_textures";
  fs::create_directories(dir);
  std::ofstream(dir / "tri.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  const MeshData mesh = load_mesh((dir / "tri.obj").string());
  EXPECT_TRUE(mesh.texcoords.empty());
  EXPECT_TRUE(mesh.texture.empty());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ambfplus
