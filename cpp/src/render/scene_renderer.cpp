#include "render/scene_renderer.h"

#include <cmath>
#include <string>
#include <vector>

#include "ambfplus/errors.h"
#include "ambfplus/scene/world.h"
#include "render/egl_context.h"

namespace ambfplus::render {
namespace {

constexpr float kAmbient = 0.15f;

Eigen::Matrix4f to_float(const Eigen::Matrix4d& m) { return m.cast<float>(); }

// The world's lights in the camera frame, grouped by type as mesh.frag wants them. A world
// without lights gets a headlight shining along the camera's view.
struct LightSet {
  std::vector<float> dir_direction, dir_color;
  std::vector<float> point_position, point_color, point_attenuation;
  std::vector<float> spot_position, spot_direction, spot_color, spot_attenuation, spot_cos_cutoff,
      spot_exponent;
  int directional = 0, point = 0, spot = 0;

  static void push3(std::vector<float>& v, const Eigen::Vector3f& x) {
    v.insert(v.end(), {x.x(), x.y(), x.z()});
  }

  LightSet(const World& world, const Eigen::Isometry3d& camera_from_world) {
    for (const Light* light : world.objects_of_kind<Light>()) {
      const Eigen::Vector3f p = (camera_from_world * light->pose().translation()).cast<float>();
      const Eigen::Vector3f d = (camera_from_world.linear() * light->direction()).cast<float>();
      const Eigen::Vector3f c =
          Eigen::Vector3f(light->color()[0], light->color()[1], light->color()[2]) *
          light->intensity();
      const Eigen::Vector3f k(light->attenuation()[0], light->attenuation()[1],
                              light->attenuation()[2]);
      switch (light->type()) {
        case LightSpec::Type::kDirectional:
          ++directional;
          push3(dir_direction, d);
          push3(dir_color, c);
          break;
        case LightSpec::Type::kPoint:
          ++point;
          push3(point_position, p);
          push3(point_color, c);
          push3(point_attenuation, k);
          break;
        case LightSpec::Type::kSpot:
          ++spot;
          push3(spot_position, p);
          push3(spot_direction, d);
          push3(spot_color, c);
          push3(spot_attenuation, k);
          spot_cos_cutoff.push_back(std::cos(light->spot_cutoff()));
          spot_exponent.push_back(light->spot_exponent());
          break;
      }
    }
    if (directional + point + spot == 0) {
      directional = 1;
      push3(dir_direction, Eigen::Vector3f(0, 0, 1));
      push3(dir_color, Eigen::Vector3f::Constant(0.85f));
    }
  }

  // The shader variant for these counts.
  std::string defines() const {
    return "#define DIRECTIONAL_LIGHTS " + std::to_string(directional) + "\n#define POINT_LIGHTS " +
           std::to_string(point) + "\n#define SPOT_LIGHTS " + std::to_string(spot) + "\n";
  }

  void upload(Program& program) const {
    auto vec3s = [&](const char* name, const std::vector<float>& v) {
      if (!v.empty())
        glUniform3fv(program.uniform(name), static_cast<GLsizei>(v.size() / 3), v.data());
    };
    auto floats = [&](const char* name, const std::vector<float>& v) {
      if (!v.empty()) glUniform1fv(program.uniform(name), static_cast<GLsizei>(v.size()), v.data());
    };
    vec3s("u_directional_direction", dir_direction);
    vec3s("u_directional_color", dir_color);
    vec3s("u_point_position", point_position);
    vec3s("u_point_color", point_color);
    vec3s("u_point_attenuation", point_attenuation);
    vec3s("u_spot_position", spot_position);
    vec3s("u_spot_direction", spot_direction);
    vec3s("u_spot_color", spot_color);
    vec3s("u_spot_attenuation", spot_attenuation);
    floats("u_spot_cos_cutoff", spot_cos_cutoff);
    floats("u_spot_exponent", spot_exponent);
  }
};

}  // namespace

SceneRenderer::SceneRenderer(World& world) : world_(world) {}

SceneRenderer::~SceneRenderer() {
  if ((meshes_.empty() && targets_.empty()) || !Context::exists()) return;
  try {
    Context::Scope scope;
    for (auto& [key, m] : meshes_) {
      glDeleteVertexArrays(1, &m.vao);
      glDeleteBuffers(3, m.buffers);
    }
    for (auto& [key, t] : targets_) {
      glDeleteFramebuffers(1, &t.framebuffer);
      glDeleteRenderbuffers(3, t.renderbuffers);
    }
  } catch (const Error&) {
    // The context is gone (e.g. after a fork); its objects went with it.
  }
}

GpuMesh& SceneRenderer::mesh_for(const MeshData* mesh) {
  auto it = meshes_.find(mesh);
  if (it != meshes_.end()) return it->second;
  GpuMesh g;
  glGenVertexArrays(1, &g.vao);
  glGenBuffers(3, g.buffers);
  glBindVertexArray(g.vao);
  glBindBuffer(GL_ARRAY_BUFFER, g.buffers[0]);
  glBufferData(GL_ARRAY_BUFFER, mesh->positions.size() * sizeof(float), mesh->positions.data(),
               GL_STATIC_DRAW);
  glVertexAttribPointer(0, mesh->position_size, GL_FLOAT, GL_FALSE, 0, nullptr);
  glEnableVertexAttribArray(0);
  glBindBuffer(GL_ARRAY_BUFFER, g.buffers[1]);
  glBufferData(GL_ARRAY_BUFFER, mesh->normals.size() * sizeof(float), mesh->normals.data(),
               GL_STATIC_DRAW);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  glEnableVertexAttribArray(1);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.buffers[2]);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, mesh->indices.size() * sizeof(std::uint32_t),
               mesh->indices.data(), GL_STATIC_DRAW);
  glBindVertexArray(0);
  g.index_count = static_cast<GLsizei>(mesh->indices.size());
  check_gl("uploading a mesh");
  return meshes_.emplace(mesh, g).first->second;
}

RenderTarget& SceneRenderer::target_for(const Camera& camera) {
  auto it = targets_.find(camera.id());
  if (it != targets_.end()) return it->second;
  RenderTarget t;
  t.width = camera.width();
  t.height = camera.height();
  glGenFramebuffers(1, &t.framebuffer);
  glGenRenderbuffers(3, t.renderbuffers);
  const GLenum formats[3] = {GL_RGBA8, GL_R32F, GL_DEPTH_COMPONENT32F};
  for (int i = 0; i < 3; ++i) {
    glBindRenderbuffer(GL_RENDERBUFFER, t.renderbuffers[i]);
    glRenderbufferStorage(GL_RENDERBUFFER, formats[i], t.width, t.height);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, t.framebuffer);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                            t.renderbuffers[0]);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT1, GL_RENDERBUFFER,
                            t.renderbuffers[1]);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                            t.renderbuffers[2]);
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    glDeleteFramebuffers(1, &t.framebuffer);
    glDeleteRenderbuffers(3, t.renderbuffers);
    throw RenderError("camera '" + camera.name() + "': off-screen framebuffer of " +
                      std::to_string(t.width) + "x" + std::to_string(t.height) +
                      " is incomplete (status 0x" + std::to_string(status) + ")");
  }
  check_gl("creating a render target");
  return targets_.emplace(camera.id(), t).first->second;
}

void SceneRenderer::draw(const Camera& camera) {
  Context::Scope scope;
  const Eigen::Isometry3d camera_from_world = camera.pose().inverse();
  const LightSet lights(world_, camera_from_world);
  Program& program = Context::get().program("mesh.vert", "mesh.frag", lights.defines());
  RenderTarget& target = target_for(camera);

  glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer);
  const GLenum draw_buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glDrawBuffers(2, draw_buffers);
  glViewport(0, 0, target.width, target.height);
  // Reversed z: clear to 0 (far), keep the greater depth.
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  // Our projection flips image y relative to GL's window y, so visible fronts wind clockwise.
  glFrontFace(GL_CW);
  const auto& bg = camera.background();
  const GLfloat clear_color[4] = {bg[0], bg[1], bg[2], 1.0f};
  const GLfloat clear_depth_image[4] = {0, 0, 0, 0};
  const GLfloat clear_depth = 0.0f;
  glClearBufferfv(GL_COLOR, 0, clear_color);
  glClearBufferfv(GL_COLOR, 1, clear_depth_image);
  glClearBufferfv(GL_DEPTH, 0, &clear_depth);

  program.use();
  const Eigen::Matrix4f projection = to_float(camera.projection());
  glUniformMatrix4fv(program.uniform("u_projection"), 1, GL_FALSE, projection.data());
  glUniform1f(program.uniform("u_ambient"), kAmbient);
  lights.upload(program);
  const GLint u_model_view = program.uniform("u_model_view");
  const GLint u_normal_matrix = program.uniform("u_normal_matrix");
  const GLint u_color = program.uniform("u_color");
  const GLint u_specular = program.uniform("u_specular");
  const GLint u_shininess = program.uniform("u_shininess");

  for (const RigidBody* body : world_.objects_of_kind<RigidBody>()) {
    const GpuMesh& mesh = mesh_for(body->visual_mesh().get());
    // Composed in double, then rounded once, to keep depth exact far from the origin.
    const Eigen::Isometry3d model_view = camera_from_world * body->pose();
    const Eigen::Matrix4f mv = to_float(model_view.matrix());
    const Eigen::Matrix3f normal = model_view.linear().cast<float>();
    glUniformMatrix4fv(u_model_view, 1, GL_FALSE, mv.data());
    glUniformMatrix3fv(u_normal_matrix, 1, GL_FALSE, normal.data());
    const Material& m = body->material();
    glUniform4fv(u_color, 1, m.color.data());
    glUniform1f(u_specular, m.specular);
    glUniform1f(u_shininess, m.shininess);
    glBindVertexArray(mesh.vao);
    glDrawElements(GL_TRIANGLES, mesh.index_count, GL_UNSIGNED_INT, nullptr);
  }
  glBindVertexArray(0);
  check_gl("drawing the scene");
}

void SceneRenderer::read(const Camera& camera, const CaptureBuffers& buffers) {
  Context::Scope scope;
  RenderTarget& target = target_for(camera);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, target.framebuffer);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  if (buffers.rgb != nullptr) {
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, target.width, target.height, GL_RGB, GL_UNSIGNED_BYTE, buffers.rgb);
  }
  if (buffers.depth != nullptr) {
    glReadBuffer(GL_COLOR_ATTACHMENT1);
    glReadPixels(0, 0, target.width, target.height, GL_RED, GL_FLOAT, buffers.depth);
  }
  check_gl("reading back a capture");
}

void SceneRenderer::render(const Camera& camera, const CaptureBuffers& buffers) {
  Context::Scope scope;
  draw(camera);
  read(camera, buffers);
}

}  // namespace ambfplus::render
