#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <mutex>
#include <system_error>

#include "ambfplus/errors.h"
#include "ambfplus/io/mesh.h"

namespace ambfplus {
namespace {

// The diffuse texture a material names, relative to the mesh file; "" for none or an embedded
// one ("*0"), which is not read.
std::string diffuse_texture(const aiMaterial& material, const std::string& mesh_path) {
  aiString name;
  if (material.GetTextureCount(aiTextureType_DIFFUSE) == 0 ||
      material.GetTexture(aiTextureType_DIFFUSE, 0, &name) != AI_SUCCESS || name.length == 0 ||
      name.C_Str()[0] == '*') {
    return "";
  }
  std::string file = name.C_Str();
  std::replace(file.begin(), file.end(), '\\', '/');
  const std::filesystem::path p(file);
  return (p.is_absolute() ? p : std::filesystem::path(mesh_path).parent_path() / p)
      .lexically_normal()
      .string();
}

}  // namespace

MeshData load_mesh(const std::string& path, double scale) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    if (std::filesystem::is_directory(path, ec)) {
      throw ConfigError(path, "is a directory, expected a mesh file");
    }
    throw AssetNotFound(path, "mesh");
  }
  Assimp::Importer importer;
  // Points and lines carry no surface; drop them so a file of only those reads as empty.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const unsigned flags = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                         aiProcess_GenSmoothNormals | aiProcess_PreTransformVertices |
                         aiProcess_SortByPType | aiProcess_FindInvalidData;
  const aiScene* scene = importer.ReadFile(path, flags);
  if (scene == nullptr) {
    throw ConfigError(path, std::string("cannot read mesh: ") + importer.GetErrorString());
  }
  MeshData mesh;
  // Texture coordinates when any mesh has them (0, 0 for those that do not, to stay aligned).
  bool textured = false;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    textured = textured || scene->mMeshes[m]->HasTextureCoords(0);
  }
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* in = scene->mMeshes[m];
    if (!(in->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
    const auto base = static_cast<std::uint32_t>(mesh.vertex_count());
    for (unsigned v = 0; v < in->mNumVertices; ++v) {
      const aiVector3D& p = in->mVertices[v];
      const aiVector3D n = in->mNormals ? in->mNormals[v] : aiVector3D(0, 0, 1);
      for (float c : {p.x, p.y, p.z}) {
        if (!std::isfinite(c)) throw ConfigError(path, "mesh has non-finite vertex coordinates");
        mesh.positions.push_back(static_cast<float>(c * scale));
      }
      mesh.normals.insert(mesh.normals.end(), {n.x, n.y, n.z});
      if (textured) {
        const aiVector3D t = in->HasTextureCoords(0) ? in->mTextureCoords[0][v] : aiVector3D();
        mesh.texcoords.insert(mesh.texcoords.end(), {t.x, t.y});
      }
    }
    if (mesh.texture.empty() && in->HasTextureCoords(0) && scene->mMaterials != nullptr &&
        in->mMaterialIndex < scene->mNumMaterials) {
      mesh.texture = diffuse_texture(*scene->mMaterials[in->mMaterialIndex], path);
    }
    for (unsigned f = 0; f < in->mNumFaces; ++f) {
      const aiFace& face = in->mFaces[f];
      if (face.mNumIndices != 3) continue;
      for (unsigned i = 0; i < 3; ++i) mesh.indices.push_back(base + face.mIndices[i]);
    }
  }
  if (mesh.indices.empty()) {
    throw ConfigError(path, "mesh file holds no triangles");
  }
  return mesh;
}

std::shared_ptr<const MeshData> load_mesh_shared(const std::string& path, double scale) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path canonical = fs::weakly_canonical(path, ec);
  const auto stamp = fs::last_write_time(path, ec);
  const auto bytes = fs::file_size(path, ec);
  if (ec) return std::make_shared<const MeshData>(load_mesh(path, scale));  // it says why
  struct Entry {
    fs::file_time_type stamp;
    std::uintmax_t bytes;
    std::weak_ptr<const MeshData> mesh;
  };
  static std::mutex mutex;
  static std::map<std::pair<std::string, double>, Entry> cache;
  const auto key = std::make_pair(canonical.string(), scale);
  {
    std::lock_guard<std::mutex> lock(mutex);
    const auto it = cache.find(key);
    if (it != cache.end() && it->second.stamp == stamp && it->second.bytes == bytes) {
      if (auto mesh = it->second.mesh.lock()) return mesh;
    }
  }
  auto mesh = std::make_shared<const MeshData>(load_mesh(path, scale));
  std::lock_guard<std::mutex> lock(mutex);
  for (auto it = cache.begin(); it != cache.end();) {
    it = it->second.mesh.expired() ? cache.erase(it) : std::next(it);
  }
  cache[key] = Entry{stamp, bytes, mesh};
  return mesh;
}

}  // namespace ambfplus
