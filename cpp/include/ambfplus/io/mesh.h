#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "ambfplus/export.h"

namespace ambfplus {

/// A triangle mesh in one frame, ready for rendering or collision.
struct AMBFPLUS_API MeshData {
  /// 3 floats per vertex, or 4 (homogeneous, w = 0 for points at infinity) when position_size is 4.
  std::vector<float> positions;
  /// 3 floats per vertex, unit length.
  std::vector<float> normals;
  /// 3 indices per triangle.
  std::vector<std::uint32_t> indices;
  int position_size = 3;
  /// 2 floats per vertex (u, v; v = 0 at the image's bottom row, as OBJ writes them), or empty
  /// when the file has none.
  std::vector<float> texcoords;
  /// The diffuse texture its material names (an MTL's map_Kd), an absolute path; "" for none.
  /// A file whose meshes name several keeps the first.
  std::string texture;

  std::size_t vertex_count() const { return positions.size() / position_size; }
  std::size_t triangle_count() const { return indices.size() / 3; }
};

/// Reads every mesh in a file (OBJ, STL, PLY, glTF, 3DS, ... through assimp) into one MeshData,
/// with node transforms applied and positions multiplied by scale. Throws AssetNotFound when the
/// file does not exist and ConfigError (naming the file and assimp's reason) when it cannot be
/// read.
AMBFPLUS_API MeshData load_mesh(const std::string& path, double scale = 1.0);

/// load_mesh, shared: while any holder keeps the result, loading the same file (unchanged on
/// disk) at the same scale returns it again instead of reading the file. Thread-safe.
AMBFPLUS_API std::shared_ptr<const MeshData> load_mesh_shared(const std::string& path,
                                                              double scale = 1.0);

}  // namespace ambfplus
