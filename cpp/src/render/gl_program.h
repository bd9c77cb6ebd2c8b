#pragma once

#include <epoxy/gl.h>

#include <string>
#include <unordered_map>

namespace ambfplus::render {

/// The folder of the engine's own GLSL files: AMBFPLUS_SHADER_DIR if set, else `shaders/` next to
/// libambfplus (as installed in the package and mirrored in the build tree).
std::string shader_dir();

/// A linked GLSL program. Needs a current context to create, use and destroy.
class Program {
 public:
  /// Compiles and links two files, with `defines` (lines of "#define NAME VALUE") inserted after
  /// each file's #version line. RenderError names the file and carries the compiler's log.
  Program(const std::string& vertex_path, const std::string& fragment_path,
          const std::string& defines = "");
  ~Program();
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  void use() const { glUseProgram(id_); }
  /// Location of a uniform, -1 if the program does not use it (cached).
  GLint uniform(const std::string& name);

 private:
  GLuint id_ = 0;
  std::unordered_map<std::string, GLint> uniforms_;
};

}  // namespace ambfplus::render
