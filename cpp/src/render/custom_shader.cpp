#include "render/custom_shader.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include "ambfplus/errors.h"
#include "ambfplus/log.h"
#include "ambfplus/scene/model.h"
#include "ambfplus/scene/world.h"
#include "render/egl_context.h"
#include "render/light_set.h"
#include "render/scene_renderer.h"

namespace ambfplus::render {
namespace {

// AMBF's (CHAI3D's) attribute locations; gl_Vertex comes from the conventional vertex array.
enum LegacyAttribute : GLuint {
  kPosition = 1,
  kNormal = 2,
  kTexCoord = 3,
  kColor = 4,
  kTangent = 5,
  kBitangent = 6,
};

// AMBF's texture units: diffuse 0, shadow map 1, normal map 2; the drilling plugin's matcaps on
// 3 (drill) and 5 (anatomy). Both matcap names get the engine's matcap here.
constexpr GLint kDiffuseUnit = 0, kShadowUnit = 1, kNormalUnit = 2, kMatcapUnit = 5;

// OpenGL's eye frame (x right, y up, looking down -z) from the OpenCV camera frame.
const Eigen::Matrix4f kGlFromCv = Eigen::Vector4f(1, -1, -1, 1).asDiagonal();

// Any of these makes a shader legacy: it needs the compatibility built-ins.
const std::regex kLegacyMarkers(
    R"(\b(ftransform|attribute|varying|texture2D|texture3D|shadow2DProj|shadow2D|gl_(ModelView)"
    R"(\w*|ProjectionMatrix\w*|NormalMatrix|Vertex|Normal|Color|MultiTexCoord\d|FrontMaterial|)"
    R"(BackMaterial|FrontLightProduct|BackLightProduct|LightSource|LightModel|TexCoord|)"
    R"(TextureMatrix\w*|EyePlane[STRQ]|FragColor|FragData|FrontColor))\b)");
const std::regex kVersion(R"(#version[ \t]+(\d+)([ \t]+\w+)?)");

// A legacy source that declares #version 150 or later (core unless told) asks for the
// compatibility profile, which has the built-ins it uses.
std::string with_compatibility(const std::string& source) {
  std::smatch m;
  if (!std::regex_search(source, m, kVersion) || std::stoi(m[1]) < 150 || m[2].matched) {
    return source;
  }
  return source.substr(0, m.position(0)) + m.str(0) + " compatibility" +
         source.substr(m.position(0) + m.length(0));
}

// Lines of "#define" spliced after a modern source's #version line.
std::string with_defines_after_version(const std::string& source, const std::string& defines) {
  std::smatch m;
  if (!std::regex_search(source, m, kVersion)) return defines + source;
  const std::size_t eol = source.find('\n', m.position(0));
  if (eol == std::string::npos) return source + "\n" + defines;
  return source.substr(0, eol + 1) + defines + source.substr(eol + 1);
}

// The first lines of a compiler log, enough to say what is wrong.
std::string first_lines(const std::string& text, int lines) {
  std::size_t end = 0;
  for (int i = 0; i < lines && end != std::string::npos; ++i) {
    end = text.find('\n', end == 0 ? 0 : end + 1);
  }
  return end == std::string::npos ? text : text.substr(0, end) + " ...";
}

// Textures legacy shaders sample: AMBF binds a diffuse texture, a shadow map and a normal map,
// and the drilling plugin a matcap. Made once per process, in the process's one context.
struct LegacyTextures {
  GLuint white = 0, shadow = 0, flat_normal = 0, matcap = 0;

  LegacyTextures() {
    auto texture_2d = [](GLenum internal, GLsizei size, GLenum format, GLenum type,
                         const void* pixels) {
      GLuint t = 0;
      glGenTextures(1, &t);
      glBindTexture(GL_TEXTURE_2D, t);
      glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
      glTexImage2D(GL_TEXTURE_2D, 0, internal, size, size, 0, format, type, pixels);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
      return t;
    };
    const std::uint8_t white_pixel[3] = {255, 255, 255};
    white = texture_2d(GL_RGB8, 1, GL_RGB, GL_UNSIGNED_BYTE, white_pixel);
    const std::uint8_t up[3] = {128, 128, 255};
    flat_normal = texture_2d(GL_RGB8, 1, GL_RGB, GL_UNSIGNED_BYTE, up);
    // No shadows are cast: every lookup compares as lit (1), in every channel, as CHAI3D's
    // shadow map reads where nothing occludes.
    const float far_depth = 1.0f;
    shadow = texture_2d(GL_DEPTH_COMPONENT32F, 1, GL_DEPTH_COMPONENT, GL_FLOAT, &far_depth);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_ALWAYS);
    glTexParameteri(GL_TEXTURE_2D, GL_DEPTH_TEXTURE_MODE, GL_INTENSITY);
    const std::vector<std::uint8_t> sphere = matcap_image(kMatcapSize);
    matcap = texture_2d(GL_RGB8, kMatcapSize, GL_RGB, GL_UNSIGNED_BYTE, sphere.data());
    glBindTexture(GL_TEXTURE_2D, 0);
    check_gl("making the textures of legacy shaders");
  }

  static constexpr int kMatcapSize = 128;

  // A matcap: a grey sphere in the eye frame, lit from the upper left with a highlight, so
  // matcap shaders shade like the drilling plugin's brushed-metal and shiny-white images.
  static std::vector<std::uint8_t> matcap_image(int size) {
    std::vector<std::uint8_t> rgb(static_cast<std::size_t>(size) * size * 3);
    const Eigen::Vector3f light = Eigen::Vector3f(-0.45f, 0.55f, 0.7f).normalized();
    const Eigen::Vector3f half = (light + Eigen::Vector3f::UnitZ()).normalized();
    for (int row = 0; row < size; ++row) {
      for (int col = 0; col < size; ++col) {
        // Texture row 0 is v = 0, the bottom of the sphere.
        float x = 2.0f * (col + 0.5f) / size - 1.0f, y = 2.0f * (row + 0.5f) / size - 1.0f;
        const float r2 = x * x + y * y;
        if (r2 > 1.0f) {
          x /= std::sqrt(r2);
          y /= std::sqrt(r2);
        }
        const Eigen::Vector3f n(x, y, std::sqrt(std::max(0.0f, 1.0f - x * x - y * y)));
        const float diffuse = std::max(0.0f, n.dot(light));
        const float specular = std::pow(std::max(0.0f, n.dot(half)), 40.0f);
        const float v = std::min(1.0f, 0.22f + 0.68f * diffuse + 0.45f * specular);
        for (int c = 0; c < 3; ++c) {
          rgb[(static_cast<std::size_t>(row) * size + col) * 3 + c] =
              static_cast<std::uint8_t>(std::lround(255.0f * v));
        }
      }
    }
    return rgb;
  }
};

LegacyTextures& legacy_textures() {
  static LegacyTextures* textures = new LegacyTextures();  // lives with the context
  return *textures;
}

// The attribute layout legacy shaders read, on the mesh's own buffers (made on first use).
void bind_legacy_vao(GpuMesh& mesh) {
  if (mesh.legacy_vao == 0) {
    glGenVertexArrays(1, &mesh.legacy_vao);
    glBindVertexArray(mesh.legacy_vao);
    glBindBuffer(GL_ARRAY_BUFFER, mesh.buffers[0]);
    glVertexPointer(mesh.position_size, GL_FLOAT, 0, nullptr);
    glEnableClientState(GL_VERTEX_ARRAY);
    glVertexAttribPointer(kPosition, mesh.position_size, GL_FLOAT, GL_FALSE, 0, nullptr);
    glEnableVertexAttribArray(kPosition);
    glBindBuffer(GL_ARRAY_BUFFER, mesh.buffers[1]);
    glNormalPointer(GL_FLOAT, 0, nullptr);
    glEnableClientState(GL_NORMAL_ARRAY);
    glVertexAttribPointer(kNormal, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    glEnableVertexAttribArray(kNormal);
    if (mesh.texcoords != 0) {
      glBindBuffer(GL_ARRAY_BUFFER, mesh.texcoords);
      glClientActiveTexture(GL_TEXTURE0);
      glTexCoordPointer(2, GL_FLOAT, 0, nullptr);
      glEnableClientState(GL_TEXTURE_COORD_ARRAY);
      glVertexAttribPointer(kTexCoord, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
      glEnableVertexAttribArray(kTexCoord);
    }
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, mesh.buffers[2]);
  }
  glBindVertexArray(mesh.legacy_vao);
}

void set_sampler(Program& program, const char* name, GLint unit) {
  const GLint location = program.uniform(name);
  if (location >= 0) glUniform1i(location, unit);
}

// gl_LightSource[i]: the world's lights (directional, point, then spot; at most 8) in the eye
// frame, with CHAI3D's ambient; the rest dark.
void set_legacy_lights(const LightSet& lights) {
  GLint max_lights = 8;
  glGetIntegerv(GL_MAX_LIGHTS, &max_lights);
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();  // positions and directions below are already in the eye frame
  auto eye = [](const std::vector<float>& v, int i) {
    return Eigen::Vector3f(v[3 * i], -v[3 * i + 1], -v[3 * i + 2]);
  };
  int n = 0;
  auto light = [&](const Eigen::Vector4f& position, const Eigen::Vector3f& color) -> GLenum {
    const GLenum id = GL_LIGHT0 + n++;
    const GLfloat ambient[4] = {kAmbfLightAmbient, kAmbfLightAmbient, kAmbfLightAmbient, 1};
    const GLfloat c[4] = {color.x(), color.y(), color.z(), 1};
    glLightfv(id, GL_AMBIENT, ambient);
    glLightfv(id, GL_DIFFUSE, c);
    glLightfv(id, GL_SPECULAR, c);
    glLightfv(id, GL_POSITION, position.data());
    const GLfloat no_spot = 180.0f;
    glLightfv(id, GL_SPOT_CUTOFF, &no_spot);
    glLightf(id, GL_CONSTANT_ATTENUATION, 1.0f);
    glLightf(id, GL_LINEAR_ATTENUATION, 0.0f);
    glLightf(id, GL_QUADRATIC_ATTENUATION, 0.0f);
    return id;
  };
  for (int i = 0; i < lights.directional && n < max_lights; ++i) {
    const Eigen::Vector3f d = eye(lights.dir_direction, i);
    light(Eigen::Vector4f(-d.x(), -d.y(), -d.z(), 0),
          Eigen::Vector3f(lights.dir_color.data() + 3 * i));
  }
  auto attenuate = [](GLenum id, const std::vector<float>& k, int i) {
    glLightf(id, GL_CONSTANT_ATTENUATION, k[3 * i]);
    glLightf(id, GL_LINEAR_ATTENUATION, k[3 * i + 1]);
    glLightf(id, GL_QUADRATIC_ATTENUATION, k[3 * i + 2]);
  };
  for (int i = 0; i < lights.point && n < max_lights; ++i) {
    const Eigen::Vector3f p = eye(lights.point_position, i);
    const GLenum id = light(Eigen::Vector4f(p.x(), p.y(), p.z(), 1),
                            Eigen::Vector3f(lights.point_color.data() + 3 * i));
    attenuate(id, lights.point_attenuation, i);
  }
  for (int i = 0; i < lights.spot && n < max_lights; ++i) {
    const Eigen::Vector3f p = eye(lights.spot_position, i);
    const GLenum id = light(Eigen::Vector4f(p.x(), p.y(), p.z(), 1),
                            Eigen::Vector3f(lights.spot_color.data() + 3 * i));
    attenuate(id, lights.spot_attenuation, i);
    const Eigen::Vector3f d = eye(lights.spot_direction, i);
    glLightfv(id, GL_SPOT_DIRECTION, d.data());
    const float cutoff = std::acos(std::clamp(lights.spot_cos_cutoff[i], -1.0f, 1.0f));
    const GLfloat degrees = std::min(90.0f, cutoff * 180.0f / static_cast<float>(M_PI));
    glLightf(id, GL_SPOT_CUTOFF, degrees);
    glLightf(id, GL_SPOT_EXPONENT, std::clamp(lights.spot_exponent[i], 0.0f, 128.0f));
  }
  const GLfloat dark[4] = {0, 0, 0, 1};
  for (; n < max_lights; ++n) {
    const GLenum id = GL_LIGHT0 + n;
    glLightfv(id, GL_AMBIENT, dark);
    glLightfv(id, GL_DIFFUSE, dark);
    glLightfv(id, GL_SPECULAR, dark);
  }
}

}  // namespace

const ShaderSpec* effective_shader(const Material& material, const Model& model,
                                   const World& world) {
  const ShaderSpec* spec = material.shader  ? &*material.shader
                           : model.shader() ? &*model.shader()
                           : world.shader() ? &*world.shader()
                                            : nullptr;
  return spec != nullptr && !spec->builtin() ? spec : nullptr;
}

const UserShader* user_shader(const ShaderSpec& spec, const LightSet& lights) {
  // Keyed by files and light counts (modern shaders may include lighting.glsl); failures too,
  // so each is reported once.
  static std::map<std::string, std::unique_ptr<UserShader>> shaders;
  const std::string key = "user:" + spec.vertex + "|" + spec.fragment + "|" + lights.defines();
  auto found = shaders.find(key);
  if (found != shaders.end()) return found->second.get();
  std::unique_ptr<UserShader> shader;
  try {
    std::string vertex = read_shader(spec.vertex);
    std::string fragment = read_shader(spec.fragment);
    auto made = std::make_unique<UserShader>();
    if (std::regex_search(vertex, kLegacyMarkers) || std::regex_search(fragment, kLegacyMarkers)) {
      made->dialect = ShaderDialect::kLegacy;
      vertex = with_compatibility(vertex);
      fragment = with_compatibility(fragment);
    } else {
      vertex = with_defines_after_version(vertex, lights.defines());
      fragment = with_defines_after_version(fragment, lights.defines());
    }
    const AttributeBindings attributes =
        made->dialect == ShaderDialect::kLegacy
            ? AttributeBindings{{"aPosition", kPosition}, {"aNormal", kNormal},
                                {"aTexCoord", kTexCoord}, {"aColor", kColor},
                                {"aTangent", kTangent},   {"aBitangent", kBitangent}}
            : AttributeBindings{{"a_position", 0}, {"a_normal", 1}};
    made->program = &Context::get().program(key, [&] {
      return std::make_unique<Program>(spec.vertex, vertex, spec.fragment, fragment, attributes);
    });
    shader = std::move(made);
  } catch (const Error& e) {
    log(LogLevel::kWarning,
        "shader " + spec.vertex + " + " + spec.fragment +
            " cannot run; the engine's own shader draws instead: " + first_lines(e.what(), 6));
  }
  return shaders.emplace(key, std::move(shader)).first->second.get();
}

ShaderOverlay::ShaderOverlay(const Eigen::Matrix4d& projection, int width, int height,
                             const LightSet& lights, double time, GLenum attachment)
    : projection_(projection.cast<float>()),
      width_(width),
      height_(height),
      lights_(lights),
      time_(time) {
  const GLenum buffers[1] = {attachment};
  glDrawBuffers(1, buffers);
  glDepthFunc(GL_GEQUAL);
  glDepthMask(GL_FALSE);
  // Reversed z: a positive offset moves fragments towards the camera, past the rounding
  // between this pass's transform and the main pass's.
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(1.0f, 16.0f);
}

ShaderOverlay::~ShaderOverlay() {
  glBindVertexArray(0);
  glUseProgram(0);
  glDisable(GL_POLYGON_OFFSET_FILL);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_GREATER);
  glActiveTexture(GL_TEXTURE0);
}

void ShaderOverlay::begin(const UserShader& shader) {
  current_ = &shader;
  Program& program = *shader.program;
  program.use();
  const Eigen::Matrix4f& projection = projection_;
  if (shader.dialect == ShaderDialect::kModern) {
    glUniformMatrix4fv(program.uniform("u_projection"), 1, GL_FALSE, projection.data());
    glUniform1f(program.uniform("u_ambient"), 0.15f);
    glUniform1f(program.uniform("u_time"), static_cast<float>(time_));
    glUniform2f(program.uniform("u_resolution"), static_cast<float>(width_),
                static_cast<float>(height_));
    lights_.upload(program);
    return;
  }
  // AMBF's fixed-function state: matrices for the eye frame, lights, texture units.
  glMatrixMode(GL_PROJECTION);
  const Eigen::Matrix4f gl_projection = projection * kGlFromCv;
  glLoadMatrixf(gl_projection.data());
  set_legacy_lights(lights_);
  LegacyTextures& t = legacy_textures();
  const struct {
    GLint unit;
    GLuint texture;
  } units[4] = {{kDiffuseUnit, t.white},
                {kShadowUnit, t.shadow},
                {kNormalUnit, t.flat_normal},
                {kMatcapUnit, t.matcap}};
  for (const auto& u : units) {
    glActiveTexture(GL_TEXTURE0 + u.unit);
    glBindTexture(GL_TEXTURE_2D, u.texture);
    glMatrixMode(GL_TEXTURE);
    glLoadIdentity();
  }
  // Texture unit 1's eye planes give shadow-map coordinates; without shadows, any point.
  glActiveTexture(GL_TEXTURE0 + kShadowUnit);
  glMatrixMode(GL_MODELVIEW);
  glLoadIdentity();
  const GLfloat s[4] = {0, 0, 0, 0.5f}, r[4] = {0, 0, 0, 0}, q[4] = {0, 0, 0, 1};
  glTexGenfv(GL_S, GL_EYE_PLANE, s);
  glTexGenfv(GL_T, GL_EYE_PLANE, s);
  glTexGenfv(GL_R, GL_EYE_PLANE, r);
  glTexGenfv(GL_Q, GL_EYE_PLANE, q);
  glActiveTexture(GL_TEXTURE0);
  set_sampler(program, "diffuseMap", kDiffuseUnit);
  set_sampler(program, "shadowMap", kShadowUnit);
  set_sampler(program, "normalMap", kNormalUnit);
  for (const char* name : {"uMatcapMap", "matcapMap", "aoMap"}) {
    set_sampler(program, name, kMatcapUnit);
  }
  for (const char* name : {"vEnableNormalMapping", "uTextureEnabled", "uEnableShadow"}) {
    set_sampler(program, name, 0);
  }
}

void ShaderOverlay::draw(const UserShader& shader, GpuMesh& mesh,
                         const Eigen::Isometry3d& model_view, const Material& material, int id,
                         GLuint texture) {
  if (mesh.index_count == 0) return;
  if (current_ != &shader) begin(shader);
  Program& program = *shader.program;
  const Eigen::Matrix4f mv = model_view.matrix().cast<float>();
  const auto& c = material.color;
  const std::array<float, 3> a = material.ambient_color();
  if (shader.dialect == ShaderDialect::kModern) {
    const Eigen::Matrix3f normal = model_view.linear().cast<float>();
    glUniformMatrix4fv(program.uniform("u_model_view"), 1, GL_FALSE, mv.data());
    glUniformMatrix3fv(program.uniform("u_normal_matrix"), 1, GL_FALSE, normal.data());
    glUniform4fv(program.uniform("u_color"), 1, c.data());
    glUniform3fv(program.uniform("u_ambient_color"), 1, a.data());
    glUniform1f(program.uniform("u_specular"), material.specular);
    glUniform1f(program.uniform("u_shininess"), material.shininess);
    glUniform1i(program.uniform("u_instance"), id);
    const GLint textured = program.uniform("u_textured");
    if (textured >= 0) glUniform1i(textured, texture != 0 && mesh.texcoords != 0 ? 1 : 0);
    glActiveTexture(GL_TEXTURE0 + kDiffuseUnit);
    glBindTexture(GL_TEXTURE_2D, texture != 0 ? texture : legacy_textures().white);
    set_sampler(program, "u_diffuse_map", kDiffuseUnit);
    glBindVertexArray(mesh.vao);
  } else {
    glMatrixMode(GL_MODELVIEW);
    const Eigen::Matrix4f gl_model_view = kGlFromCv * mv;
    glLoadMatrixf(gl_model_view.data());
    const GLfloat ambient[4] = {a[0], a[1], a[2], c[3]};
    const GLfloat specular[4] = {material.specular, material.specular, material.specular, 1};
    const GLfloat black[4] = {0, 0, 0, 1};
    glMaterialfv(GL_FRONT_AND_BACK, GL_AMBIENT, ambient);
    glMaterialfv(GL_FRONT_AND_BACK, GL_DIFFUSE, c.data());
    glMaterialfv(GL_FRONT_AND_BACK, GL_SPECULAR, specular);
    glMaterialfv(GL_FRONT_AND_BACK, GL_EMISSION, black);
    glMaterialf(GL_FRONT_AND_BACK, GL_SHININESS, std::clamp(material.shininess, 0.0f, 128.0f));
    bind_legacy_vao(mesh);
    // The body's texture on the diffuse unit (white without one, which leaves colours as they
    // are), and whether the shader should sample it.
    const bool textured = texture != 0 && mesh.texcoords != 0;
    glActiveTexture(GL_TEXTURE0 + kDiffuseUnit);
    glBindTexture(GL_TEXTURE_2D, textured ? texture : legacy_textures().white);
    const GLint enabled = program.uniform("uTextureEnabled");
    if (enabled >= 0) glUniform1i(enabled, textured ? 1 : 0);
    // Attributes without arrays read these constants.
    glVertexAttrib4f(kTexCoord, 0, 0, 0, 1);
    glVertexAttrib4f(kColor, c[0], c[1], c[2], c[3]);
    glVertexAttrib4f(kTangent, 1, 0, 0, 0);
    glVertexAttrib4f(kBitangent, 0, 1, 0, 0);
    glColor4f(c[0], c[1], c[2], c[3]);
  }
  glDrawElements(GL_TRIANGLES, mesh.index_count, GL_UNSIGNED_INT, nullptr);
}

}  // namespace ambfplus::render
