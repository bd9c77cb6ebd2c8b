#include "render/gl_program.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "ambfplus/errors.h"

namespace ambfplus::render {
namespace {

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw AssetNotFound(path, "shader");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The source with defines spliced in after its #version line (which must come first in GLSL).
std::string with_defines(const std::string& source, const std::string& defines) {
  if (defines.empty()) return source;
  const std::size_t version = source.find("#version");
  if (version == std::string::npos) return defines + source;
  const std::size_t eol = source.find('\n', version);
  if (eol == std::string::npos) return source + "\n" + defines;
  return source.substr(0, eol + 1) + defines + source.substr(eol + 1);
}

// The compiler's or linker's log of a shader or program object.
template <typename GetIv, typename GetLog>
std::string info_log(GLuint object, GetIv get_iv, GetLog get_log) {
  GLint length = 0;
  get_iv(object, GL_INFO_LOG_LENGTH, &length);
  std::vector<char> log(static_cast<std::size_t>(length) + 1, '\0');
  get_log(object, length, nullptr, log.data());
  return log.data();
}

std::string with_includes(const std::string& source, const std::string& path, int depth = 0) {
  if (depth > 8) throw RenderError(path + ": #include nested too deep");
  std::istringstream in(source);
  std::ostringstream out;
  std::string line;
  while (std::getline(in, line)) {
    const std::size_t at = line.find("#include");
    const std::size_t open = line.find('"');
    const std::size_t close = line.rfind('"');
    if (at != std::string::npos && line.find_first_not_of(" \t") == at &&
        open != std::string::npos && close > open) {
      const std::string name = line.substr(open + 1, close - open - 1);
      std::string included = (std::filesystem::path(path).parent_path() / name).string();
      if (!std::filesystem::exists(included)) included = shader_dir() + "/" + name;
      out << with_includes(read_text(included), included, depth + 1) << "\n";
    } else {
      out << line << "\n";
    }
  }
  return out.str();
}

GLuint compile(GLenum stage, const std::string& path, const std::string& source) {
  const GLuint shader = glCreateShader(stage);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok != GL_TRUE) {
    const std::string log = info_log(shader, glGetShaderiv, glGetShaderInfoLog);
    glDeleteShader(shader);
    throw RenderError(path + ": shader does not compile:\n" + log);
  }
  return shader;
}

}  // namespace

std::string read_shader(const std::string& path) { return with_includes(read_text(path), path); }

std::string shader_dir() {
  if (const char* env = std::getenv("AMBFPLUS_SHADER_DIR"); env != nullptr && *env != '\0') {
    return env;
  }
  Dl_info info{};
  if (dladdr(reinterpret_cast<void*>(&shader_dir), &info) == 0 || info.dli_fname == nullptr) {
    throw RenderError("cannot locate libambfplus to find its shaders; set AMBFPLUS_SHADER_DIR");
  }
  const std::filesystem::path dir = std::filesystem::path(info.dli_fname).parent_path() / "shaders";
  if (!std::filesystem::is_directory(dir)) {
    throw RenderError("the engine's shaders are missing: expected the folder " + dir.string() +
                      " (set AMBFPLUS_SHADER_DIR to use another)");
  }
  return dir.string();
}

Program::Program(const std::string& vertex_path, const std::string& fragment_path,
                 const std::string& defines)
    : Program(vertex_path, with_defines(read_shader(vertex_path), defines), fragment_path,
              with_defines(read_shader(fragment_path), defines), {}) {}

Program::Program(const std::string& vertex_path, const std::string& vertex_source,
                 const std::string& fragment_path, const std::string& fragment_source,
                 const AttributeBindings& attributes) {
  const GLuint vs = compile(GL_VERTEX_SHADER, vertex_path, vertex_source);
  GLuint fs = 0;
  try {
    fs = compile(GL_FRAGMENT_SHADER, fragment_path, fragment_source);
  } catch (...) {
    glDeleteShader(vs);
    throw;
  }
  id_ = glCreateProgram();
  glAttachShader(id_, vs);
  glAttachShader(id_, fs);
  for (const auto& [name, location] : attributes) {
    glBindAttribLocation(id_, location, name.c_str());
  }
  glLinkProgram(id_);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(id_, GL_LINK_STATUS, &ok);
  if (ok != GL_TRUE) {
    const std::string log = info_log(id_, glGetProgramiv, glGetProgramInfoLog);
    glDeleteProgram(id_);
    throw RenderError(vertex_path + " + " + fragment_path + ": program does not link:\n" + log);
  }
}

Program::~Program() { glDeleteProgram(id_); }

GLint Program::uniform(const std::string& name) {
  auto it = uniforms_.find(name);
  if (it != uniforms_.end()) return it->second;
  const GLint location = glGetUniformLocation(id_, name.c_str());
  uniforms_.emplace(name, location);
  return location;
}

}  // namespace ambfplus::render
