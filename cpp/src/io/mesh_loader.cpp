#include <assimp/DefaultIOSystem.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Importer.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <system_error>

#include "ambfplus/errors.h"
#include "ambfplus/io/mesh.h"
#include "io/json_check.h"
#include "io/off_check.h"
#include "io/ply_check.h"
#include "io/stl_check.h"
#include "util/files.h"
#include "util/strings.h"

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

// The file's bytes, for the checks assimp cannot be trusted to make itself.
std::string read_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw ConfigError(path, std::string("cannot open the mesh: ") + std::strerror(errno));
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Whether the file's first bytes (after white space) are a JSON object's or binary glTF's.
bool opens_like_gltf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[64] = {};
  in.read(head, sizeof head);
  const std::string start(head, static_cast<std::size_t>(in.gcount()));
  if (start.compare(0, 4, "glTF") == 0) return true;
  const std::size_t first = start.find_first_not_of(" \t\r\n");
  return first != std::string::npos && start[first] == '{';
}

bool has_extension(const std::string& path, const char* wanted) {
  return to_lower(std::filesystem::path(path).extension().string()) == wanted;
}

bool starts_with_ply(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char head[5] = {};
  in.read(head, sizeof(head));
  return io::looks_like_ply(std::string(head, static_cast<std::size_t>(in.gcount())));
}

// Our own checks of what the file holds, made before any post-processing step can mend or drop
// it (assimp's invalid-data step deletes a mesh with a non-finite vertex, which would leave the
// file half-loaded): every mesh has vertices, its faces name them, and every position is finite.
void check_file_meshes(const std::string& path, const aiScene& scene) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* in = scene.mMeshes[m];
    const std::string which =
        "mesh " + std::to_string(m) +
        (in && in->mName.length > 0 ? " ('" + std::string(in->mName.C_Str()) + "')"
                                    : std::string());
    if (in == nullptr || (in->mNumVertices > 0 && in->mVertices == nullptr)) {
      throw ConfigError(path, which + " has no vertex positions");
    }
    for (unsigned v = 0; v < in->mNumVertices; ++v) {
      const aiVector3D& p = in->mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
        std::ostringstream at;
        at << "(" << p.x << ", " << p.y << ", " << p.z << ")";
        throw ConfigError(path, "vertex " + std::to_string(v) + " of " + which + " is " + at.str() +
                                    "; expected finite coordinates");
      }
    }
    for (unsigned f = 0; f < in->mNumFaces; ++f) {
      const aiFace& face = in->mFaces[f];
      for (unsigned i = 0; i < face.mNumIndices; ++i) {
        if (face.mIndices[i] >= in->mNumVertices) {
          throw ConfigError(path, "face " + std::to_string(f) + " of " + which + " names vertex " +
                                      std::to_string(face.mIndices[i]) + " but there are " +
                                      std::to_string(in->mNumVertices) + " vertices");
        }
      }
    }
  }
}

// Our own checks of what assimp's post-processing produced: faces name vertices of their mesh, and
// every position is finite after the node transforms and scale (normals of degenerate triangles
// are replaced, not trusted).
// With textured, texture coordinates too ((0, 0) for a mesh without them).
void append_mesh(const std::string& path, const aiMesh& in, double scale, bool textured,
                 MeshData& mesh) {
  const auto base = static_cast<std::uint32_t>(mesh.vertex_count());
  for (unsigned v = 0; v < in.mNumVertices; ++v) {
    const aiVector3D& p = in.mVertices[v];
    for (float c : {p.x, p.y, p.z}) {
      if (!std::isfinite(c)) {
        throw ConfigError(path, "vertex " + std::to_string(v) + " of mesh '" +
                                    std::string(in.mName.C_Str()) + "' has non-finite coordinates");
      }
      const double scaled = c * scale;
      if (!std::isfinite(static_cast<float>(scaled))) {
        throw ConfigError(path, "vertex " + std::to_string(v) + " scaled by " +
                                    std::to_string(scale) + " is not a finite float");
      }
      mesh.positions.push_back(static_cast<float>(scaled));
    }
    aiVector3D n = in.mNormals ? in.mNormals[v] : aiVector3D(0, 0, 1);
    if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z) || n.Length() == 0) {
      n = aiVector3D(0, 0, 1);
    }
    mesh.normals.insert(mesh.normals.end(), {n.x, n.y, n.z});
    if (textured) {
      const aiVector3D t = in.HasTextureCoords(0) ? in.mTextureCoords[0][v] : aiVector3D();
      mesh.texcoords.insert(mesh.texcoords.end(), {t.x, t.y});
    }
  }
  for (unsigned f = 0; f < in.mNumFaces; ++f) {
    const aiFace& face = in.mFaces[f];
    if (face.mNumIndices != 3) continue;
    for (unsigned i = 0; i < 3; ++i) {
      if (face.mIndices[i] >= in.mNumVertices) {
        throw ConfigError(path, "face " + std::to_string(f) + " names vertex " +
                                    std::to_string(face.mIndices[i]) + " of " +
                                    std::to_string(in.mNumVertices));
      }
      mesh.indices.push_back(base + face.mIndices[i]);
    }
  }
}

// The files assimp opens for a mesh (an OBJ's mtllib, ...) as the default system opens them,
// but regular files only: a FIFO named by a mesh would block its read forever. What is not one
// is as good as missing (assimp goes on without a material library, as AMBF does).
class RegularFilesOnly : public Assimp::DefaultIOSystem {
 public:
  bool Exists(const char* file) const override { return is_regular_file(file); }
  Assimp::IOStream* Open(const char* file, const char* mode = "rb") override {
    if (!is_regular_file(file)) return nullptr;
    return DefaultIOSystem::Open(file, mode);
  }
};

}  // namespace

MeshData load_mesh(const std::string& path, double scale) {
  require_regular_file(path, "mesh");
  if (!std::isfinite(scale) || !(scale > 0)) {
    throw ArgumentError("mesh " + path + ": scale must be a positive finite number, got " +
                        std::to_string(scale));
  }
  // Debian's assimp hangs or corrupts memory on some malformed PLY files before any of its
  // checks run, so PLY structure is checked here first.
  if (starts_with_ply(path)) io::check_ply(path, read_bytes(path));
  // assimp says only that it cannot tell which kind a cut binary STL is.
  if (has_extension(path, ".stl")) io::check_stl(path, read_bytes(path));
  // assimp allocates what an OFF header's counts ask for before reading a row.
  if (has_extension(path, ".off")) io::check_off(path, read_bytes(path));
  // assimp's JSON reader recurses per level of nesting: a deep glTF overflowed the stack.
  // assimp also tells glTF by its content, so any file that opens like JSON or binary glTF.
  if (has_extension(path, ".gltf") || has_extension(path, ".glb") || opens_like_gltf(path)) {
    io::check_gltf_json(path, read_bytes(path));
  }
  Assimp::Importer importer;
  importer.SetIOHandler(new RegularFilesOnly);  // the importer owns and deletes it
  // Points and lines carry no surface; drop them so a file of only those reads as empty.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  // Read and validated first, checked by us, and only then post-processed.
  const aiScene* scene = importer.ReadFile(path, aiProcess_ValidateDataStructure);
  if (scene == nullptr) {
    throw ConfigError(path, std::string("cannot read mesh: ") + importer.GetErrorString());
  }
  check_file_meshes(path, *scene);
  const unsigned steps = aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                         aiProcess_GenSmoothNormals | aiProcess_PreTransformVertices |
                         aiProcess_SortByPType | aiProcess_FindInvalidData;
  scene = importer.ApplyPostProcessing(steps);
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
    append_mesh(path, *in, scale, textured, mesh);
    if (mesh.texture.empty() && in->HasTextureCoords(0) && scene->mMaterials != nullptr &&
        in->mMaterialIndex < scene->mNumMaterials) {
      mesh.texture = diffuse_texture(*scene->mMaterials[in->mMaterialIndex], path);
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
