#pragma once

#include <epoxy/gl.h>

#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace ambfplus::render {

/// The folder of the engine's own GLSL files: AMBFPLUS_SHADER_DIR if set, else `shaders/` next to
/// libambfplus (as installed in the package and mirrored in the build tree).
std::string shader_dir();

/// A GLSL file's text with each `#include "file"` line replaced by that file, found beside the
/// includer or else in shader_dir() (so users' shaders can include the engine's lighting.glsl).
/// Throws AssetNotFound for a missing file.
std::string read_shader(const std::string& path);

/// Attribute names bound to locations before a program links.
using AttributeBindings = std::vector<std::pair<std::string, GLuint>>;

/// A linked GLSL program. Needs a current context to create, use and destroy.
class Program {
 public:
  /// Compiles and links two files, with `defines` (lines of "#define NAME VALUE") inserted after
  /// each file's #version line. RenderError names the file and carries the compiler's log.
  Program(const std::string& vertex_path, const std::string& fragment_path,
          const std::string& defines = "");
  /// Compiles and links two sources (the paths only name them in errors), binding attributes.
  Program(const std::string& vertex_path, const std::string& vertex_source,
          const std::string& fragment_path, const std::string& fragment_source,
          const AttributeBindings& attributes);
  ~Program();
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  void use() const { glUseProgram(id_); }
  GLuint id() const { return id_; }
  /// Location of a uniform, -1 if the program does not use it (cached).
  GLint uniform(const std::string& name);

 private:
  GLuint id_ = 0;
  std::unordered_map<std::string, GLint> uniforms_;
};

}  // namespace ambfplus::render
