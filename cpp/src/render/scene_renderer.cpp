#include "render/scene_renderer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ambfplus/errors.h"
#include "ambfplus/io/image.h"
#include "ambfplus/io/mesh.h"
#include "ambfplus/log.h"
#include "ambfplus/scene/names.h"
#include "ambfplus/scene/world.h"
#include "render/custom_shader.h"
#include "render/egl_context.h"
#include "render/light_set.h"
#include "render/volume_renderer.h"

namespace ambfplus::render {
namespace {

constexpr float kAmbient = 0.15f;

Eigen::Matrix4f to_float(const Eigen::Matrix4d& m) { return m.cast<float>(); }

std::optional<ShaderSpec> copy_of(const ShaderSpec* spec) {
  return spec != nullptr ? std::optional<ShaderSpec>(*spec) : std::nullopt;
}

}  // namespace

std::unique_ptr<Renderer> make_renderer(World& world) {
  return std::make_unique<SceneRenderer>(world);
}

Renderer& renderer_of(const World& world) {
  if (auto* renderer = world.find_system<Renderer>()) return *renderer;
  throw StateError("world '" + world.name() + "' has no renderer (make it with the engine)");
}

SceneRenderer::SceneRenderer(World& world) : world_(world) {}

SceneRenderer::~SceneRenderer() { release_all(); }

void SceneRenderer::detach_all() { release_all(); }

namespace {

void release_mesh(GpuMesh& m) {
  glDeleteVertexArrays(1, &m.vao);
  if (m.legacy_vao != 0) glDeleteVertexArrays(1, &m.legacy_vao);
  glDeleteBuffers(3, m.buffers);
  if (m.texcoords != 0) glDeleteBuffers(1, &m.texcoords);
}

// The GL state every surface pass draws with. Reversed z: depth clears to 0 (far) and the
// greater depth is kept. Our projections flip image y relative to GL's window y, so visible
// fronts wind clockwise.
void surface_state() {
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glFrontFace(GL_CW);
}

void release_supersampling(RenderTarget& t) {
  if (t.factor == 0) return;
  glDeleteFramebuffers(1, &t.samples_framebuffer);
  glDeleteTextures(2, t.samples);
  glDeleteTextures(1, &t.mask);
  glDeleteTextures(1, &t.lattice_index);
  glDeleteFramebuffers(1, &t.packed_framebuffer);
  glDeleteTextures(3, t.packed);
  t.packed_framebuffer = 0;
  t.packed[0] = t.packed[1] = t.packed[2] = 0;
  t.packed_width = t.packed_height = 0;
  glDeleteVertexArrays(1, &t.points_vao);
  glDeleteBuffers(1, &t.points_buffer);
  t.factor = 0;
  t.stencil = 0;
}

void release_target(RenderTarget& t) {
  glDeleteFramebuffers(1, &t.framebuffer);
  glDeleteTextures(RenderTarget::kBuffers, t.textures);
  release_supersampling(t);
}

void release_shadow_map(ShadowMap& m) {
  glDeleteFramebuffers(1, &m.framebuffer);
  glDeleteTextures(1, &m.texture);
}

}  // namespace

void SceneRenderer::release_all() {
  if ((meshes_.empty() && soft_meshes_.empty() && targets_.empty() && volumes_.empty() &&
       shadow_maps_.empty()) ||
      !Context::exists()) {
    return;
  }
  try {
    Context::Scope scope;
    volumes_.clear();
    for (auto& entry : meshes_) release_mesh(entry.second);
    for (auto& entry : soft_meshes_) release_mesh(entry.second);
    for (auto& entry : targets_) release_target(entry.second);
    for (auto& entry : shadow_maps_) release_shadow_map(entry.second);
    for (auto& entry : textures_) {
      if (entry.second != 0) glDeleteTextures(1, &entry.second);
    }
  } catch (const Error&) {
    // The context is gone (e.g. after a fork); its objects went with it.
    for (auto& v : volumes_) v.second.release();
  }
  volumes_.clear();
  meshes_.clear();
  soft_meshes_.clear();
  targets_.clear();
  textures_.clear();
  shadow_maps_.clear();
}

void SceneRenderer::object_removed(Object& object) {
  std::lock_guard<std::mutex> lock(volumes_mutex_);
  released_ids_.push_back(object.id());
  meshes_to_check_ = meshes_to_check_ || object.kind() == ObjectKind::kRigidBody;
}

void SceneRenderer::release_unused() {
  std::vector<int> ids;
  bool check_meshes = false;
  {
    std::lock_guard<std::mutex> lock(volumes_mutex_);
    ids.swap(released_ids_);
    check_meshes = meshes_to_check_;
    meshes_to_check_ = false;
    for (int id : ids) volumes_.erase(id);
  }
  for (int id : ids) {
    if (auto t = targets_.find(id); t != targets_.end()) {
      release_target(t->second);
      targets_.erase(t);
    }
    if (auto m = soft_meshes_.find(id); m != soft_meshes_.end()) {
      release_mesh(m->second);
      soft_meshes_.erase(m);
    }
    if (auto m = shadow_maps_.find(id); m != shadow_maps_.end()) {
      release_shadow_map(m->second);
      shadow_maps_.erase(m);
    }
  }
  // A mesh only this renderer still holds is drawn by no body any more.
  if (!check_meshes) return;
  for (auto it = meshes_.begin(); it != meshes_.end();) {
    if (it->second.source.use_count() == 1) {
      release_mesh(it->second);
      it = meshes_.erase(it);
    } else {
      ++it;
    }
  }
}

std::array<std::size_t, 4> SceneRenderer::resource_counts() const {
  std::lock_guard<std::mutex> lock(volumes_mutex_);
  return {meshes_.size(), soft_meshes_.size(), targets_.size(), volumes_.size()};
}

std::optional<VolumeUpload> SceneRenderer::last_upload(const Volume& volume) const {
  std::lock_guard<std::mutex> lock(volumes_mutex_);
  auto it = volumes_.find(volume.id());
  if (it == volumes_.end()) return std::nullopt;
  return it->second->last_upload();
}

void SceneRenderer::snapshot(const Camera& camera, unsigned passes, const PoseRequest& poses,
                             Snapshot& snapshot, Frame& frame) {
  auto lock = world_.lock_state_for_copy();
  // Names are checked first, so a bad request leaves the frame as it was.
  std::vector<const Object*> posed;
  if (poses.all) {
    for (const Object* o : world_.objects()) posed.push_back(o);
  } else {
    for (const std::string& name : poses.names) {
      const std::vector<Object*> found = name_candidates(world_, name);
      if (found.size() != 1) {
        throw ArgumentError("poses: " +
                            std::string(found.empty()
                                            ? "no object named '" + name + "'"
                                            : "'" + name + "' is ambiguous (" + found[0]->key() +
                                                  ", " + found[1]->key() + ")") +
                            " in world '" + world_.name() + "'");
      }
      posed.push_back(found.front());
    }
  }
  world_.graphics_update();
  take(camera, passes, snapshot);
  frame.width = camera.width();
  frame.height = camera.height();
  frame.time = world_.time();
  frame.step = world_.step_index();
  frame.camera = camera.name();
  frame.intrinsics = camera.intrinsics();
  frame.pose = camera.pose().matrix();
  // Every capture replaces the poses: a frame refilled without asking keeps none.
  frame.has_poses = !poses.empty();
  frame.poses.clear();
  for (const Object* o : posed) frame.poses.push_back({o->key(), o->id(), o->pose().matrix()});
}

void SceneRenderer::render(const Camera& camera, const CaptureBuffers& buffers,
                           const PoseRequest& poses, Frame& frame) {
  stage_volumes();
  Snapshot s;
  snapshot(camera, buffers.passes() & kRenderedPasses, poses, s, frame);
  Context::Scope scope;
  release_unused();
  draw(s);
  read(s, buffers);
}

const RenderTarget& SceneRenderer::render_to_target(const Camera& camera, unsigned passes,
                                                    Frame& frame) {
  stage_volumes();
  Snapshot s;
  snapshot(camera, passes, PoseRequest{}, s, frame);
  Context::Scope scope;
  release_unused();
  draw(s);
  return target_for(s);
}

const RenderTarget* SceneRenderer::last_target(const Camera& camera) {
  Context::Scope scope;
  auto it = targets_.find(camera.id());
  return it == targets_.end() ? nullptr : &it->second;
}

void SceneRenderer::take(const Camera& camera, unsigned passes, Snapshot& s) {
  s.camera_id = camera.id();
  s.camera_name = camera.name();
  s.width = camera.width();
  s.height = camera.height();
  s.camera_pose = camera.pose();
  s.projection = camera.projection();
  s.background = camera.background();
  s.preprocessing = camera.preprocessing_shader();
  s.passes = passes;
  s.shadows = camera.shadows() && (passes & kPassRgb);
  s.antialiasing = camera.antialiasing();
  s.time = world_.time();
  s.lights.emplace(world_, camera.pose().inverse(), s.shadows);
  for (const RigidBody* body : world_.objects_of_kind<RigidBody>()) {
    if (body->visual_mesh()->indices.empty() || !body->material().visible) continue;
    s.bodies.push_back({body->visual_mesh(), body->pose(), body->material(),
                        copy_of(effective_shader(body->material(), body->model(), world_)),
                        body->id(), body->visual_mesh()->texture});
  }
  for (const SoftBody* body : world_.objects_of_kind<SoftBody>()) {
    if (!body->material().visible) continue;
    const std::vector<double>& x = body->node_positions();
    Snapshot::Soft soft{body->id(), std::vector<float>(x.begin(), x.end()), &body->triangles(),
                        body->material(),
                        copy_of(effective_shader(body->material(), body->model(), world_))};
    s.softs.push_back(std::move(soft));
  }
  for (const Volume* volume : world_.objects_of_kind<Volume>()) {
    GpuVolume& gpu = gpu_volume(*volume);
    gpu.stage(volume->iso());
    s.volumes.push_back({&gpu, volume->pose(), volume->iso(), volume->specular(),
                         volume->shininess(), volume->id(), volume->empty_space_skipping(),
                         camera.looks()});
  }
}

GpuVolume& SceneRenderer::gpu_volume(const Volume& volume) {
  std::lock_guard<std::mutex> lock(volumes_mutex_);
  auto& slot = volumes_[volume.id()];
  // A volume given other data is uploaded afresh.
  if (!slot || slot->data() != volume.data()) slot = std::make_unique<GpuVolume>(volume.data());
  return *slot;
}

void SceneRenderer::stage_volumes() {
  auto lock = world_.lock_state_for_copy();
  for (const Volume* volume : world_.objects_of_kind<Volume>()) {
    gpu_volume(*volume).stage(volume->iso());
  }
}

GpuMesh& SceneRenderer::mesh_for(const std::shared_ptr<const MeshData>& source) {
  const MeshData* mesh = source.get();
  auto it = meshes_.find(mesh);
  if (it != meshes_.end()) return it->second;
  GpuMesh g;
  g.position_size = mesh->position_size;
  g.source = source;
  if (mesh->position_size == 3) {
    for (std::size_t i = 0; i + 2 < mesh->positions.size(); i += 3) {
      g.bounds.extend(Eigen::Vector3f(mesh->positions.data() + i).cast<double>());
    }
  }
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
  if (!mesh->texcoords.empty()) {
    glGenBuffers(1, &g.texcoords);
    glBindBuffer(GL_ARRAY_BUFFER, g.texcoords);
    glBufferData(GL_ARRAY_BUFFER, mesh->texcoords.size() * sizeof(float), mesh->texcoords.data(),
                 GL_STATIC_DRAW);
    glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
    glEnableVertexAttribArray(2);
  }
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.buffers[2]);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, mesh->indices.size() * sizeof(std::uint32_t),
               mesh->indices.data(), GL_STATIC_DRAW);
  glBindVertexArray(0);
  g.index_count = static_cast<GLsizei>(mesh->indices.size());
  check_gl("uploading a mesh");
  return meshes_.emplace(mesh, g).first->second;
}

GLuint SceneRenderer::texture_for(const std::string& path) {
  if (path.empty()) return 0;
  auto it = textures_.find(path);
  if (it != textures_.end()) return it->second;
  GLuint texture = 0;
  try {
    const Image image = read_image(path);
    // 8-bit RGBA, rows bottom first: texture coordinate v = 0 is the image's bottom row (OBJ's,
    // AMBF's).
    std::vector<std::uint8_t> rows(std::size_t(image.width) * image.height * 4);
    for (int r = 0; r < image.height; ++r) {
      const std::uint8_t* in = image.row(image.height - 1 - r);
      std::uint8_t* out = rows.data() + std::size_t(r) * image.width * 4;
      for (int c = 0; c < image.width; ++c, out += 4) {
        // The most significant byte of a 16-bit sample (machine order).
        auto sample = [&](int k) -> std::uint8_t {
          const std::size_t i = (std::size_t(c) * image.channels + k) * image.sample_bytes();
          if (image.sample_bytes() == 1) return in[i];
          std::uint16_t v = 0;
          std::memcpy(&v, in + i, 2);
          return static_cast<std::uint8_t>(v >> 8);
        };
        const bool colour = image.channels >= 3;
        const bool alpha = image.channels == 2 || image.channels == 4;
        out[0] = sample(0);
        out[1] = colour ? sample(1) : out[0];
        out[2] = colour ? sample(2) : out[0];
        out[3] = alpha ? sample(image.channels - 1) : 255;
      }
    }
    glGenTextures(1, &texture);
    glBindTexture(GL_TEXTURE_2D, texture);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, image.width, image.height, 0, GL_RGBA,
                 GL_UNSIGNED_BYTE, rows.data());
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    glBindTexture(GL_TEXTURE_2D, 0);
    check_gl("uploading a texture");
  } catch (const Error& e) {
    log(LogLevel::kWarning, std::string("texture not applied: ") + e.what());
    texture = 0;
  }
  textures_.emplace(path, texture);
  return texture;
}

GpuMesh& SceneRenderer::soft_mesh_for(const Snapshot::Soft& soft) {
  const std::vector<float>& x = soft.positions;
  const std::vector<std::uint32_t>& tri = *soft.triangles;
  const std::size_t n = x.size() / 3;
  // Smooth normals: each node's triangles' normals weighted by their area.
  soft_scratch_.assign(3 * n, 0.0f);
  float* normals = soft_scratch_.data();
  for (std::size_t t = 0; t < tri.size(); t += 3) {
    const Eigen::Vector3f a(x.data() + 3 * tri[t]), b(x.data() + 3 * tri[t + 1]),
        c(x.data() + 3 * tri[t + 2]);
    const Eigen::Vector3f area_normal = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k) {
      Eigen::Map<Eigen::Vector3f>(normals + 3 * tri[t + k]) += area_normal;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Map<Eigen::Vector3f> v(normals + 3 * i);
    const float length = v.norm();
    if (length > 0) v /= length;
  }

  auto it = soft_meshes_.find(soft.id);
  if (it == soft_meshes_.end()) {
    GpuMesh g;
    glGenVertexArrays(1, &g.vao);
    glGenBuffers(3, g.buffers);
    glBindVertexArray(g.vao);
    glBindBuffer(GL_ARRAY_BUFFER, g.buffers[0]);
    glBufferData(GL_ARRAY_BUFFER, 3 * n * sizeof(float), nullptr, GL_DYNAMIC_DRAW);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    glEnableVertexAttribArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, g.buffers[1]);
    glBufferData(GL_ARRAY_BUFFER, 3 * n * sizeof(float), nullptr, GL_DYNAMIC_DRAW);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    glEnableVertexAttribArray(1);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.buffers[2]);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, tri.size() * sizeof(std::uint32_t), tri.data(),
                 GL_STATIC_DRAW);
    glBindVertexArray(0);
    g.index_count = static_cast<GLsizei>(tri.size());
    it = soft_meshes_.emplace(soft.id, g).first;
  }
  const GpuMesh& g = it->second;
  glBindBuffer(GL_ARRAY_BUFFER, g.buffers[0]);
  glBufferSubData(GL_ARRAY_BUFFER, 0, 3 * n * sizeof(float), x.data());
  glBindBuffer(GL_ARRAY_BUFFER, g.buffers[1]);
  glBufferSubData(GL_ARRAY_BUFFER, 0, 3 * n * sizeof(float), normals);
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  check_gl("uploading a soft body's nodes");
  return it->second;
}

namespace {

/// A 2D texture of one level, filtered nearest.
GLuint nearest_texture(GLenum format, int width, int height) {
  GLuint texture = 0;
  glGenTextures(1, &texture);
  glBindTexture(GL_TEXTURE_2D, texture);
  glTexStorage2D(GL_TEXTURE_2D, 1, format, width, height);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glBindTexture(GL_TEXTURE_2D, 0);
  return texture;
}

/// Binds a 2D texture to a unit and names the unit in a sampler uniform.
void bind_unit(Program& program, const char* name, int unit, GLuint texture) {
  glActiveTexture(GL_TEXTURE0 + unit);
  glBindTexture(GL_TEXTURE_2D, texture);
  glUniform1i(program.uniform(name), unit);
}

}  // namespace

RenderTarget& SceneRenderer::target_for(const Snapshot& snapshot) {
  auto it = targets_.find(snapshot.camera_id);
  if (it != targets_.end()) return it->second;
  RenderTarget t;
  t.width = snapshot.width;
  t.height = snapshot.height;
  glGenFramebuffers(1, &t.framebuffer);
  const GLenum formats[RenderTarget::kBuffers] = {
      GL_RGBA8, GL_R32F, GL_R16UI, GL_R32I, GL_R32I, GL_RGBA8, GL_DEPTH_COMPONENT32F};
  glBindFramebuffer(GL_FRAMEBUFFER, t.framebuffer);
  // Textures, so that supersampling can read the passes that find edges.
  for (int i = 0; i < RenderTarget::kBuffers; ++i) {
    t.textures[i] = nearest_texture(formats[i], t.width, t.height);
    const GLenum attachment = i + 1 < RenderTarget::kBuffers
                                  ? static_cast<GLenum>(GL_COLOR_ATTACHMENT0 + i)
                                  : static_cast<GLenum>(GL_DEPTH_ATTACHMENT);
    glFramebufferTexture2D(GL_FRAMEBUFFER, attachment, GL_TEXTURE_2D, t.textures[i], 0);
  }
  glBindTexture(GL_TEXTURE_2D, 0);
  const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE) {
    glDeleteFramebuffers(1, &t.framebuffer);
    glDeleteTextures(RenderTarget::kBuffers, t.textures);
    throw RenderError("camera '" + snapshot.camera_name + "': off-screen framebuffer of " +
                      std::to_string(t.width) + "x" + std::to_string(t.height) +
                      " is incomplete (status 0x" + std::to_string(status) + ")");
  }
  check_gl("creating a render target");
  return targets_.emplace(snapshot.camera_id, t).first->second;
}

void SceneRenderer::draw(const Snapshot& s) {
  const unsigned passes = s.passes;
  const LightSet& lights = *s.lights;
  for (const Snapshot::Volume& v : s.volumes) v.gpu->upload();
  const bool supersampled = (passes & kPassRgb) && s.antialiasing > 1;
  // Supersampling finds edges in the object ids, labels and depth: they are drawn for it.
  const unsigned drawn = supersampled ? passes | kPassDepth | kPassLabel | kPassInstance : passes;
  // Shadow maps first: they leave their own framebuffer bound.
  const ShadowUniforms shadows = shadow_maps(s);
  SurfacePass shading;
  shading.setup = [&shadows](Program& program) { shadows.upload(program); };
  // Shading is the costly part: without an rgb pass the shaders skip it.
  const std::string defines =
      lights.defines() + ((passes & kPassRgb) ? "#define SHADE 1\n" : "#define SHADE 0\n");
  Program& program = Context::get().program("mesh.vert", "mesh.frag", defines);
  RenderTarget& target = target_for(s);

  glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer);
  // Only the passes asked for are written (pass i on attachment i).
  GLenum draw_buffers[kRenderedPassCount];
  for (int i = 0; i < kRenderedPassCount; ++i) {
    draw_buffers[i] = (drawn & (1u << i)) ? static_cast<GLenum>(GL_COLOR_ATTACHMENT0 + i) : GL_NONE;
  }
  glDrawBuffers(kRenderedPassCount, draw_buffers);
  glViewport(0, 0, target.width, target.height);
  surface_state();
  const GLfloat clear_color[4] = {s.background[0], s.background[1], s.background[2], 1.0f};
  const GLfloat clear_depth_image[4] = {0, 0, 0, 0};
  const GLfloat clear_depth = 0.0f;
  glClearBufferfv(GL_COLOR, 0, clear_color);
  glClearBufferfv(GL_COLOR, 1, clear_depth_image);
  const GLuint clear_label[4] = {0, 0, 0, 0};
  glClearBufferuiv(GL_COLOR, 2, clear_label);
  const GLint clear_instance[4] = {0, 0, 0, 0};
  const GLint clear_voxel[4] = {-1, -1, -1, -1};
  glClearBufferiv(GL_COLOR, 3, clear_instance);
  glClearBufferiv(GL_COLOR, 4, clear_voxel);
  glClearBufferfv(GL_COLOR, 5, clear_color);
  glClearBufferfv(GL_DEPTH, 0, &clear_depth);

  program.use();
  draw_surfaces(s, program, s.camera_pose, s.projection, passes, shading);
  if (supersampled) supersample(s, target, shading);
  // Users' shaders colour their meshes; the camera's preprocessing shader its segmentation.
  if (passes & kPassRgb) {
    overlay(s, GL_COLOR_ATTACHMENT0, [](const Material&, const std::optional<ShaderSpec>& own) {
      return own ? &*own : nullptr;
    });
  }
  if ((passes & kPassSegmentation) && s.preprocessing && !s.preprocessing->builtin()) {
    overlay(s, GL_COLOR_ATTACHMENT5,
            [&](const Material&, const std::optional<ShaderSpec>&) { return &*s.preprocessing; });
  }
  check_gl("drawing the scene");
}

void SceneRenderer::draw_surfaces(const Snapshot& s, Program& program,
                                  const Eigen::Isometry3d& view, const Eigen::Matrix4d& projection,
                                  unsigned passes, const SurfacePass& pass) {
  const Eigen::Isometry3d view_from_world = view.inverse();
  const LightSet& lights = *s.lights;
  if (!pass.meshes) {
    if (pass.volumes) {
      for (const Snapshot::Volume& v : s.volumes) {
        v.gpu->draw(v, view, projection, passes, lights, pass);
      }
    }
    return;
  }
  const Eigen::Matrix4f projection_f = to_float(projection);
  glUniformMatrix4fv(program.uniform("u_projection"), 1, GL_FALSE, projection_f.data());
  glUniform1f(program.uniform("u_ambient"), kAmbient);
  lights.upload(program);
  if (pass.setup) pass.setup(program);
  const GLint u_model_view = program.uniform("u_model_view");
  const GLint u_normal_matrix = program.uniform("u_normal_matrix");
  const GLint u_color = program.uniform("u_color");
  const GLint u_specular = program.uniform("u_specular");
  const GLint u_shininess = program.uniform("u_shininess");
  const GLint u_instance = program.uniform("u_instance");
  const GLint u_segmentation_color = program.uniform("u_segmentation_color");
  const GLint u_textured = program.uniform("u_textured");
  auto draw = [&](const GpuMesh& mesh, const Eigen::Isometry3d& model_view, const Material& m,
                  int id, GLuint texture) {
    if (mesh.index_count == 0) return;  // an anchor without geometry
    glUniform1i(u_instance, id);
    // The texture colours the shaded pass only; ground truth is the geometry's.
    const bool textured = texture != 0 && mesh.texcoords != 0;
    if (u_textured >= 0) glUniform1i(u_textured, textured ? 1 : 0);
    if (textured) {
      glActiveTexture(GL_TEXTURE0);
      glBindTexture(GL_TEXTURE_2D, texture);
    }
    const Eigen::Matrix4f mv = to_float(model_view.matrix());
    const Eigen::Matrix3f normal = model_view.linear().cast<float>();
    glUniformMatrix4fv(u_model_view, 1, GL_FALSE, mv.data());
    glUniformMatrix3fv(u_normal_matrix, 1, GL_FALSE, normal.data());
    glUniform4fv(u_color, 1, m.color.data());
    glUniform1f(u_specular, m.specular);
    glUniform1f(u_shininess, m.shininess);
    // What AMBF's preprocessing shader draws: material ambient x light ambient.
    const std::array<float, 3> a = m.ambient_color();
    glUniform3f(u_segmentation_color, kAmbfLightAmbient * a[0], kAmbfLightAmbient * a[1],
                kAmbfLightAmbient * a[2]);
    glBindVertexArray(mesh.vao);
    glDrawElements(GL_TRIANGLES, mesh.index_count, GL_UNSIGNED_INT, nullptr);
  };
  for (const Snapshot::Body& body : s.bodies) {
    // Composed in double, then rounded once, to keep depth exact far from the origin.
    draw(mesh_for(body.mesh), view_from_world * body.pose, body.material, body.id,
         (passes & kPassRgb) ? texture_for(body.texture) : 0);
  }
  // Soft bodies: their nodes are in the world frame.
  for (const Snapshot::Soft& soft : s.softs) {
    draw(soft_mesh_for(soft), view_from_world, soft.material, soft.id, 0);
  }
  glBindTexture(GL_TEXTURE_2D, 0);
  glBindVertexArray(0);
  // Volumes after the meshes: their rays write depth, so each pixel keeps the nearer surface.
  if (!pass.volumes) return;
  for (const Snapshot::Volume& v : s.volumes) {
    v.gpu->draw(v, view, projection, passes, lights, pass);
  }
}

namespace {

// The light's frame (z along the light, origin at a spot light's position) from the world.
Eigen::Isometry3d light_from_world(const ShadowCaster& c) {
  const Eigen::Vector3d z = c.direction.normalized();
  const Eigen::Vector3d helper =
      std::abs(z.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d x = helper.cross(z).normalized();
  Eigen::Isometry3d world_from_light = Eigen::Isometry3d::Identity();
  world_from_light.linear().col(0) = x;
  world_from_light.linear().col(1) = z.cross(x);
  world_from_light.linear().col(2) = z;
  world_from_light.translation() = c.directional ? Eigen::Vector3d::Zero() : c.position;
  return world_from_light.inverse();
}

void hash_into(std::size_t& key, const void* data, std::size_t bytes) {
  const std::size_t h =
      std::hash<std::string_view>()(std::string_view(static_cast<const char*>(data), bytes));
  key ^= h + 0x9e3779b97f4a7c15ull + (key << 6) + (key >> 2);
}

template <typename T>
void hash_value(std::size_t& key, const T& value) {
  hash_into(key, &value, sizeof(T));
}

}  // namespace

ShadowUniforms SceneRenderer::shadow_maps(const Snapshot& s) {
  ShadowUniforms out;
  const LightSet& lights = *s.lights;
  if (lights.casters.empty()) return out;
  // What casts shadows, in the world frame: its bounds and a key of everything drawn.
  Eigen::AlignedBox3d bounds;
  std::size_t scene_key = 0;
  auto extend = [&](const Eigen::AlignedBox3d& box, const Eigen::Isometry3d& pose) {
    if (box.isEmpty()) return;
    for (int corner = 0; corner < 8; ++corner) {
      bounds.extend(pose * box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner)));
    }
  };
  for (const Snapshot::Body& body : s.bodies) {
    const GpuMesh& mesh = mesh_for(body.mesh);
    extend(mesh.bounds, body.pose);
    hash_value(scene_key, body.mesh.get());
    hash_into(scene_key, body.pose.matrix().data(), 16 * sizeof(double));
  }
  for (const Snapshot::Soft& soft : s.softs) {
    for (std::size_t i = 0; i + 2 < soft.positions.size(); i += 3) {
      bounds.extend(Eigen::Vector3f(soft.positions.data() + i).cast<double>());
    }
    hash_value(scene_key, soft.id);
    hash_into(scene_key, soft.positions.data(), soft.positions.size() * sizeof(float));
  }
  for (const Snapshot::Volume& v : s.volumes) {
    const Eigen::Vector3d half = v.gpu->data()->dimensions() / 2;
    extend(Eigen::AlignedBox3d(-half, half), v.pose);
    hash_value(scene_key, v.gpu);
    hash_value(scene_key, v.gpu->generation());
    hash_value(scene_key, v.iso);
    hash_into(scene_key, v.pose.matrix().data(), 16 * sizeof(double));
  }
  const Eigen::Isometry3d world_from_camera = s.camera_pose;
  for (const ShadowCaster& c : lights.casters) {
    std::size_t key = scene_key;
    hash_value(key, c.directional);
    hash_into(key, c.position.data(), 3 * sizeof(double));
    hash_into(key, c.direction.data(), 3 * sizeof(double));
    hash_value(key, c.cutoff);
    hash_value(key, c.size);
    ShadowMap& map = shadow_maps_[c.light_id];
    if (map.size != c.size) {
      release_shadow_map(map);
      map = ShadowMap{};
      map.size = c.size;
      glGenTextures(1, &map.texture);
      glBindTexture(GL_TEXTURE_2D, map.texture);
      glTexStorage2D(GL_TEXTURE_2D, 1, GL_DEPTH_COMPONENT32F, c.size, c.size);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
      // Reversed depth: a point is lit when it is at least as near the light as the map says.
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_GEQUAL);
      glBindTexture(GL_TEXTURE_2D, 0);
      glGenFramebuffers(1, &map.framebuffer);
      glBindFramebuffer(GL_FRAMEBUFFER, map.framebuffer);
      glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, map.texture, 0);
      glDrawBuffer(GL_NONE);
      glReadBuffer(GL_NONE);
      if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        throw RenderError("shadow map of " + std::to_string(c.size) + "x" + std::to_string(c.size) +
                          " texels is incomplete");
      }
      map.key = key + 1;  // drawn below
    }
    const Eigen::Isometry3d light = light_from_world(c);
    if (map.key != key) {
      map.key = key;
      // The light's view fitted around what casts shadows (reversed depth, as the cameras').
      Eigen::AlignedBox3d box;
      if (!bounds.isEmpty()) {
        for (int corner = 0; corner < 8; ++corner) {
          box.extend(light * bounds.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner)));
        }
      }
      Eigen::Matrix4d p = Eigen::Matrix4d::Zero();
      bool visible = !box.isEmpty();
      if (visible && c.directional) {
        const Eigen::Vector3d pad = 0.01 * box.sizes() + Eigen::Vector3d::Constant(1e-4);
        const Eigen::Vector3d lo = box.min() - pad, hi = box.max() + pad;
        p(0, 0) = 2 / (hi.x() - lo.x());
        p(0, 3) = -(hi.x() + lo.x()) / (hi.x() - lo.x());
        p(1, 1) = 2 / (hi.y() - lo.y());
        p(1, 3) = -(hi.y() + lo.y()) / (hi.y() - lo.y());
        p(2, 2) = -1 / (hi.z() - lo.z());
        p(2, 3) = hi.z() / (hi.z() - lo.z());
        p(3, 3) = 1;
        map.texel = {std::max(hi.x() - lo.x(), hi.y() - lo.y()) / c.size, 0.0};
      } else if (visible) {
        const double far = box.max().z() * 1.01;
        const double near = std::max(box.min().z(), far * 1e-4);
        visible = far > 0;
        // The cone, up to 85 degrees off the axis.
        const double t = std::tan(std::min(c.cutoff, 85.0 * M_PI / 180.0));
        p(0, 0) = 1 / t;
        p(1, 1) = 1 / t;
        p(2, 2) = -near / (far - near);
        p(2, 3) = near * far / (far - near);
        p(3, 2) = 1;
        map.texel = {0.0, 2 * t / c.size};
      }
      map.clip_from_world = p * light.matrix();
      glBindFramebuffer(GL_FRAMEBUFFER, map.framebuffer);
      glViewport(0, 0, c.size, c.size);
      surface_state();
      const GLfloat far_depth = 0.0f;
      glClearBufferfv(GL_DEPTH, 0, &far_depth);
      if (visible) {
        // Casters drawn a little farther from the light than they are, against self-shadowing.
        glEnable(GL_POLYGON_OFFSET_FILL);
        glPolygonOffset(-1.0f, -1.0f);
        Program& depth = Context::get().program("mesh.vert", "shadow.frag", "");
        depth.use();
        const Eigen::Matrix4f projection = to_float(p);
        glUniformMatrix4fv(depth.uniform("u_projection"), 1, GL_FALSE, projection.data());
        const GLint u_model_view = depth.uniform("u_model_view");
        auto cast = [&](const GpuMesh& mesh, const Eigen::Isometry3d& model_view) {
          if (mesh.index_count == 0 || mesh.position_size != 3) return;
          const Eigen::Matrix4f mv = to_float(model_view.matrix());
          glUniformMatrix4fv(u_model_view, 1, GL_FALSE, mv.data());
          glBindVertexArray(mesh.vao);
          glDrawElements(GL_TRIANGLES, mesh.index_count, GL_UNSIGNED_INT, nullptr);
        };
        for (const Snapshot::Body& body : s.bodies) cast(mesh_for(body.mesh), light * body.pose);
        for (const Snapshot::Soft& soft : s.softs) cast(soft_mesh_for(soft), light);
        glBindVertexArray(0);
        glDisable(GL_POLYGON_OFFSET_FILL);
        SurfacePass depth_only;
        depth_only.defines = "#define DEPTH_ONLY 1\n";
        depth_only.orthographic = c.directional;
        for (const Snapshot::Volume& v : s.volumes) {
          v.gpu->draw(v, light.inverse(), p, 0, lights, depth_only);
        }
      }
      check_gl("drawing a shadow map");
    }
    const Eigen::Matrix4f from_camera =
        (map.clip_from_world * world_from_camera.matrix()).cast<float>();
    out.textures.push_back(map.texture);
    out.from_camera.insert(out.from_camera.end(), from_camera.data(), from_camera.data() + 16);
    out.texel.push_back(static_cast<float>(map.texel.x()));
    out.texel.push_back(static_cast<float>(map.texel.y()));
  }
  return out;
}

namespace {

/// Whether each of n pixel pairs (p + i, q + i) differs (supersample_edges' rule), into out.
/// Restrict-qualified and without branches, so that the compiler vectorises it.
void differ_run(const std::uint8_t* __restrict rgba, const float* __restrict depth,
                const std::uint16_t* __restrict label, const std::int32_t* __restrict instance,
                std::size_t p, std::size_t q, int n, std::uint8_t* __restrict out) {
  for (int i = 0; i < n; ++i) {
    const std::size_t a = p + i, b = q + i;
    const float za = depth[a], zb = depth[b];
    const float m = std::max(std::fabs(za), std::fabs(zb));
    const int r = int(rgba[4 * a]) - int(rgba[4 * b]);
    const int g = int(rgba[4 * a + 1]) - int(rgba[4 * b + 1]);
    const int bl = int(rgba[4 * a + 2]) - int(rgba[4 * b + 2]);
    out[i] = std::uint8_t((instance[a] != instance[b]) | (label[a] != label[b]) |
                          (std::fabs(za - zb) > 0.01f * m) | (std::abs(r) > 25) |
                          (std::abs(g) > 25) | (std::abs(bl) > 25));
  }
}

}  // namespace

void supersample_edges(const EdgeInputs& in, int width, int height, std::uint8_t* mask) {
  std::fill(mask, mask + std::size_t(width) * height, std::uint8_t(0));
  std::vector<std::uint8_t> row(std::size_t(std::max(width, 0)));
  // Each pair of neighbours once: right, and the three above, a row at a time.
  constexpr int kOffsets[4][2] = {{1, 0}, {-1, 1}, {0, 1}, {1, 1}};
  for (const auto& [dx, dy] : kOffsets) {
    const int x0 = std::max(0, -dx), n = width - std::abs(dx);
    for (int y = 0; y + dy < height; ++y) {
      const std::size_t p = std::size_t(y) * width + x0, q = std::size_t(y + dy) * width + x0 + dx;
      differ_run(in.rgba.data(), in.depth.data(), in.label.data(), in.instance.data(), p, q, n,
                 row.data());
      for (int i = 0; i < n; ++i) {
        mask[p + i] |= row[i];
        mask[q + i] |= row[i];
      }
    }
  }
}

void SceneRenderer::supersample(const Snapshot& s, RenderTarget& target,
                                const SurfacePass& shading) {
  const int k = s.antialiasing;
  const int width = target.width, height = target.height;
  // The samples' lattice, in pixel units with pixel x spanning [x, x + 1]: for k = 2 the pixels'
  // corners (point (i, j) at (i, j)); each pixel sampled becomes the mean of its centre (its
  // own sample from the main pass) and of its four corners, weighted 1/2 and 1/8 each, corners
  // shared with its neighbours. For k = 3 and 4, k x k points per pixel (point (i, j) at
  // ((i + 0.5) / k, (j + 0.5) / k)) and their plain mean.
  const bool corners = k == 2;
  const int lw = corners ? width + 1 : width * k, lh = corners ? height + 1 : height * k;
  const float step = corners ? 1.0f : 1.0f / float(k), origin = corners ? 0.0f : 0.5f / float(k);
  if (target.factor != k) {
    release_supersampling(target);
    target.factor = k;
    target.samples[0] = nearest_texture(GL_RGBA8, lw, lh);
    target.samples[1] = nearest_texture(GL_DEPTH32F_STENCIL8, lw, lh);
    target.mask = nearest_texture(GL_R8UI, width, height);
    target.lattice_index = nearest_texture(GL_RG16I, lw, lh);
    glGenFramebuffers(1, &target.samples_framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, target.samples_framebuffer);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, target.samples[0],
                           0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_TEXTURE_2D,
                           target.samples[1], 0);
    const GLenum samples_status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glGenVertexArrays(1, &target.points_vao);
    glGenBuffers(1, &target.points_buffer);
    glBindVertexArray(target.points_vao);
    glBindBuffer(GL_ARRAY_BUFFER, target.points_buffer);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
    glEnableVertexAttribArray(0);
    glBindVertexArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    if (samples_status != GL_FRAMEBUFFER_COMPLETE) {
      release_supersampling(target);
      throw RenderError("camera '" + s.camera_name + "': the supersampling lattice of " +
                        std::to_string(lw) + "x" + std::to_string(lh) + " cannot be made");
    }
    check_gl("creating a supersampling lattice");
  }
  // Which pixels to sample, from the exact passes and the shaded colour of the pixel centres.
  const std::size_t pixels = std::size_t(width) * height;
  edge_inputs_.rgba.resize(pixels * 4);
  edge_inputs_.depth.resize(pixels);
  edge_inputs_.label.resize(pixels);
  edge_inputs_.instance.resize(pixels);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, target.framebuffer);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  const struct {
    void* data;
    GLenum format, type;
  } inputs[4] = {{edge_inputs_.rgba.data(), GL_RGBA, GL_UNSIGNED_BYTE},
                 {edge_inputs_.depth.data(), GL_RED, GL_FLOAT},
                 {edge_inputs_.label.data(), GL_RED_INTEGER, GL_UNSIGNED_SHORT},
                 {edge_inputs_.instance.data(), GL_RED_INTEGER, GL_INT}};
  for (int i = 0; i < 4; ++i) {
    glReadBuffer(static_cast<GLenum>(GL_COLOR_ATTACHMENT0 + i));
    glReadPixels(0, 0, width, height, inputs[i].format, inputs[i].type, inputs[i].data);
  }
  supersample_mask_.resize(pixels);
  supersample_edges(edge_inputs_, width, height, supersample_mask_.data());

  // The lattice points of the pixels to sample.
  lattice_needed_.assign(std::size_t(lw) * lh, 0);
  std::size_t needed = 0;
  const auto need = [&](int i, int j) {
    std::uint8_t& n = lattice_needed_[std::size_t(j) * lw + i];
    needed += n == 0;
    n = 1;
  };
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      if (supersample_mask_[std::size_t(y) * width + x] == 0) continue;
      const int n = corners ? 2 : k, x0 = corners ? x : k * x, y0 = corners ? y : k * y;
      for (int b = 0; b < n; ++b) {
        for (int a = 0; a < n; ++a) need(x0 + a, y0 + b);
      }
    }
  }
  const auto is_volume = [&](std::int32_t id) {
    for (const Snapshot::Volume& v : s.volumes) {
      if (v.id == id) return true;
    }
    return false;
  };
  // Where a volume's ray at a lattice point searches: between the nearest and farthest depths
  // at which the pixel centres within one pixel of it (along each axis) see a volume, and how
  // far past them (volume.frag): 0 within the range, 1 at a silhouette against the background
  // (a grazing ray meets the surface farther on), 2 with no far end (a mesh seen there may hide
  // any of a volume behind it). False where none of them sees a volume: no ray.
  struct Range {
    float lo, hi, reach;
  };
  const auto depth_range = [&](int i, int j, Range& r) {
    const float sx = origin + float(i) * step, sy = origin + float(j) * step;
    const int x0 = std::max(0, int(std::ceil(sx - 1.5f)));
    const int x1 = std::min(width - 1, int(std::floor(sx + 0.5f)));
    const int y0 = std::max(0, int(std::ceil(sy - 1.5f)));
    const int y1 = std::min(height - 1, int(std::floor(sy + 0.5f)));
    r = {std::numeric_limits<float>::infinity(), -1.0f, 0.0f};
    for (int qy = y0; qy <= y1; ++qy) {
      for (int qx = x0; qx <= x1; ++qx) {
        const std::size_t q = std::size_t(qy) * width + qx;
        const std::int32_t id = edge_inputs_.instance[q];
        if (!is_volume(id)) {
          r.reach = std::max(r.reach, id == 0 ? 1.0f : 2.0f);
          continue;
        }
        r.lo = std::min(r.lo, edge_inputs_.depth[q]);
        r.hi = std::max(r.hi, edge_inputs_.depth[q]);
      }
    }
    return r.hi >= 0.0f;
  };
  // The volumes' rays are packed densely into a target about square, 16 neighbouring lattice
  // points to each 4 x 4 block of it (a software rasteriser shades such blocks together, so its
  // lanes all work, on rays much alike). Per texel: x the lattice column plus reach / 4, y the
  // row, z and w the depth range (w < 0: no ray). lattice_index gives each point its texel.
  const auto round4 = [](int v) { return (v + 3) / 4 * 4; };
  const int side = std::max(4, round4(int(std::ceil(std::sqrt(double(needed))))));
  packed_where_.assign(std::size_t(side) * side * 4, -1.0f);
  lattice_index_.assign(std::size_t(lw) * lh * 2, std::int16_t(-1));
  supersample_points_.clear();
  int packed = 0;
  for (int ty = 0; ty < lh; ty += 4) {
    for (int tx = 0; tx < lw; tx += 4) {
      bool any = false;
      for (int j = ty; j < std::min(ty + 4, lh); ++j) {
        for (int i = tx; i < std::min(tx + 4, lw); ++i) {
          if (lattice_needed_[std::size_t(j) * lw + i] == 0) continue;
          any = true;
          Range r;
          if (!depth_range(i, j, r)) continue;
          const int tile = packed / 16, in_tile = packed % 16;
          const int u = tile % (side / 4) * 4 + in_tile % 4,
                    v = tile / (side / 4) * 4 + in_tile / 4;
          ++packed;
          float* where = &packed_where_[4 * (std::size_t(v) * side + u)];
          where[0] = float(i) + 0.25f * r.reach;
          where[1] = float(j);
          where[2] = r.lo;
          where[3] = r.hi;
          std::int16_t* index = &lattice_index_[2 * (std::size_t(j) * lw + i)];
          index[0] = std::int16_t(u);
          index[1] = std::int16_t(v);
        }
      }
      // One point per 4 x 4 tile of the lattice with a point to sample: the marker.
      if (any)
        supersample_points_.insert(supersample_points_.end(), {float(tx + 2), float(ty + 2)});
    }
  }
  const auto tiles = static_cast<GLsizei>(supersample_points_.size() / 2);
  // One point per 2 x 2 block of pixels with one to sample: the resolve.
  for (int y = 0; y < height; y += 2) {
    for (int x = 0; x < width; x += 2) {
      bool any = false;
      for (int py = y; py < std::min(y + 2, height); ++py) {
        for (int px = x; px < std::min(x + 2, width); ++px) {
          any = any || supersample_mask_[std::size_t(py) * width + px] != 0;
        }
      }
      if (any) supersample_points_.insert(supersample_points_.end(), {float(x + 1), float(y + 1)});
    }
  }
  const auto blocks = static_cast<GLsizei>(supersample_points_.size() / 2) - tiles;
  glEnable(GL_DEPTH_TEST);
  if (blocks == 0) {
    glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer);
    return;
  }
  const int tiles_packed = (packed + 15) / 16, tiles_per_row = side / 4;
  const int rows = 4 * ((tiles_packed + tiles_per_row - 1) / tiles_per_row);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glBindTexture(GL_TEXTURE_2D, target.mask);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width, height, GL_RED_INTEGER, GL_UNSIGNED_BYTE,
                  supersample_mask_.data());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glBindTexture(GL_TEXTURE_2D, target.lattice_index);
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, lw, lh, GL_RG_INTEGER, GL_SHORT, lattice_index_.data());
  if (packed > 0 && (side > target.packed_width || rows > target.packed_height)) {
    glDeleteFramebuffers(1, &target.packed_framebuffer);
    glDeleteTextures(3, target.packed);
    target.packed_width = std::max(side, target.packed_width);
    target.packed_height = std::max(rows, target.packed_height);
    const GLenum formats[3] = {GL_RGBA8, GL_DEPTH_COMPONENT32F, GL_RGBA32F};
    for (int i = 0; i < 3; ++i) {
      target.packed[i] = nearest_texture(formats[i], target.packed_width, target.packed_height);
    }
    glGenFramebuffers(1, &target.packed_framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, target.packed_framebuffer);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, target.packed[0],
                           0);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, target.packed[1], 0);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      release_supersampling(target);
      throw RenderError("camera '" + s.camera_name + "': the supersampling target of " +
                        std::to_string(side) + "x" + std::to_string(rows) + " cannot be made");
    }
  }
  if (packed > 0) {
    glBindTexture(GL_TEXTURE_2D, target.packed[2]);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, side, rows, GL_RGBA, GL_FLOAT, packed_where_.data());
  }
  glBindTexture(GL_TEXTURE_2D, 0);
  glBindBuffer(GL_ARRAY_BUFFER, target.points_buffer);
  glBufferData(GL_ARRAY_BUFFER, supersample_points_.size() * sizeof(float),
               supersample_points_.data(), GL_STREAM_DRAW);
  glBindBuffer(GL_ARRAY_BUFFER, 0);

  // The meshes' samples: the marker points set the lattice's tiles to the background at the far
  // plane and mark them in the stencil with this capture's value (other points keep older
  // values): nothing is cleared, and meshes are shaded at the marked points only. For k = 2 the
  // projection is narrowed so that the lattice's pixel centres fall on the pixels' corners.
  glBindFramebuffer(GL_FRAMEBUFFER, target.samples_framebuffer);
  glViewport(0, 0, lw, lh);
  glEnable(GL_PROGRAM_POINT_SIZE);
  glBindVertexArray(target.points_vao);
  target.stencil = target.stencil % 255 + 1;
  if (target.stencil == 1) glClearBufferfi(GL_DEPTH_STENCIL, 0, 0.0f, 0);
  glEnable(GL_STENCIL_TEST);
  glStencilFunc(GL_ALWAYS, target.stencil, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_REPLACE);
  glDepthFunc(GL_ALWAYS);
  Program& marker =
      Context::get().program("supersample_points.vert", "supersample_marker.frag", "");
  marker.use();
  glUniform2f(marker.uniform("u_size"), float(lw), float(lh));
  glUniform1f(marker.uniform("u_point_size"), 4.0f);
  glUniform4f(marker.uniform("u_background"), s.background[0], s.background[1], s.background[2],
              1.0f);
  glDrawArrays(GL_POINTS, 0, tiles);
  glDepthFunc(GL_GREATER);
  glStencilFunc(GL_EQUAL, target.stencil, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_KEEP);
  Eigen::Matrix4d lattice_projection = s.projection;
  if (corners) {
    lattice_projection.row(0) *= double(width) / double(lw);
    lattice_projection.row(1) *= double(height) / double(lh);
  }
  SurfacePass meshes = shading;
  meshes.volumes = false;
  Program& program =
      Context::get().program("mesh.vert", "mesh.frag", s.lights->defines() + "#define SHADE 1\n");
  program.use();
  draw_surfaces(s, program, s.camera_pose, lattice_projection, kPassRgb, meshes);
  glDisable(GL_STENCIL_TEST);

  // The volumes' samples: each packed texel starts as the meshes' sample at its lattice point,
  // at its depth; the volumes' rays are depth-tested against it.
  constexpr int kWhereUnit = 6;  // between the volume's own units and the shadow maps'
  static_assert(kShadowMapUnit > kWhereUnit);
  if (packed > 0) {
    glBindFramebuffer(GL_FRAMEBUFFER, target.packed_framebuffer);
    glViewport(0, 0, side, rows);
    glDepthFunc(GL_ALWAYS);
    Program& gather =
        Context::get().program("supersample_packed.vert", "supersample_gather.frag", "");
    gather.use();
    bind_unit(gather, "u_packed_where", 0, target.packed[2]);
    bind_unit(gather, "u_lattice_color", 1, target.samples[0]);
    bind_unit(gather, "u_lattice_depth", 2, target.samples[1]);
    glBindVertexArray(target.points_vao);  // (the triangle's corners come from gl_VertexID)
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDepthFunc(GL_GREATER);
    SurfacePass volumes = shading;
    volumes.meshes = false;
    volumes.packed = true;
    volumes.setup = [&](Program& p) {
      if (shading.setup) shading.setup(p);
      bind_unit(p, "u_packed_where", kWhereUnit, target.packed[2]);
      glActiveTexture(GL_TEXTURE0);
      glUniform2f(p.uniform("u_lattice_origin"), origin, origin);
      glUniform1f(p.uniform("u_lattice_step"), step);
      glUniform2f(p.uniform("u_image_size"), float(width), float(height));
    };
    draw_surfaces(s, program, s.camera_pose, s.projection, kPassRgb, volumes);
    for (int unit : {0, 1, 2, kWhereUnit}) {
      glActiveTexture(GL_TEXTURE0 + unit);
      glBindTexture(GL_TEXTURE_2D, 0);
    }
  }

  // The resolve: each pixel sampled becomes the weighted mean of its samples, blended over its
  // centre's colour by the constant alpha (the centre's weight is one minus it).
  glBindFramebuffer(GL_FRAMEBUFFER, target.framebuffer);
  const GLenum colour_only[1] = {GL_COLOR_ATTACHMENT0};
  glDrawBuffers(1, colour_only);
  glViewport(0, 0, width, height);
  glDisable(GL_DEPTH_TEST);
  glEnable(GL_BLEND);
  glBlendColor(0.0f, 0.0f, 0.0f, corners ? 0.5f : 1.0f);
  glBlendFunc(GL_CONSTANT_ALPHA, GL_ONE_MINUS_CONSTANT_ALPHA);
  Program& resolve =
      Context::get().program("supersample_points.vert", "supersample_resolve.frag", "");
  resolve.use();
  constexpr int kResolveUnits = 4;
  bind_unit(resolve, "u_samples", 0, target.samples[0]);
  bind_unit(resolve, "u_packed_color", 1, target.packed[0]);
  bind_unit(resolve, "u_lattice_index", 2, target.lattice_index);
  bind_unit(resolve, "u_supersample_mask", 3, target.mask);
  glUniform1i(resolve.uniform("u_supersample_factor"), k);
  glUniform2f(resolve.uniform("u_size"), float(width), float(height));
  glUniform1f(resolve.uniform("u_point_size"), 2.0f);
  glBindVertexArray(target.points_vao);
  glDrawArrays(GL_POINTS, tiles, blocks);
  glBindVertexArray(0);
  glDisable(GL_BLEND);
  glDisable(GL_PROGRAM_POINT_SIZE);
  for (int unit = 0; unit < kResolveUnits; ++unit) {
    glActiveTexture(GL_TEXTURE0 + unit);
    glBindTexture(GL_TEXTURE_2D, 0);
  }
  glActiveTexture(GL_TEXTURE0);
  glEnable(GL_DEPTH_TEST);
  check_gl("supersampling the rgb pass");
}

template <typename ShaderOf>
void SceneRenderer::overlay(const Snapshot& s, GLenum attachment, ShaderOf shader_of) {
  const Eigen::Isometry3d camera_from_world = s.camera_pose.inverse();
  std::optional<ShaderOverlay> pass;  // begun at the first mesh whose shader runs
  auto draw = [&](const Material& m, const std::optional<ShaderSpec>& own, GpuMesh& mesh,
                  const Eigen::Isometry3d& mv, int id, GLuint texture) {
    const ShaderSpec* spec = shader_of(m, own);
    const UserShader* shader = spec != nullptr ? user_shader(*spec, *s.lights) : nullptr;
    if (shader == nullptr) return;
    if (!pass) pass.emplace(s.projection, s.width, s.height, *s.lights, s.time, attachment);
    pass->draw(*shader, mesh, mv, m, id, texture);
  };
  for (const Snapshot::Body& body : s.bodies) {
    // Textures colour the RGB image only, not the segmentation.
    draw(body.material, body.shader, mesh_for(body.mesh), camera_from_world * body.pose, body.id,
         attachment == GL_COLOR_ATTACHMENT0 ? texture_for(body.texture) : 0);
  }
  for (const Snapshot::Soft& soft : s.softs) {
    // Its nodes were uploaded by the main pass of this draw.
    draw(soft.material, soft.shader, soft_meshes_.at(soft.id), camera_from_world, soft.id, 0);
  }
}

void SceneRenderer::read(const Snapshot& s, const CaptureBuffers& buffers) {
  RenderTarget& target = target_for(s);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, target.framebuffer);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  // Attachment i holds pass i (see draw).
  const struct {
    void* data;
    GLenum format, type;
  } images[kRenderedPassCount] = {{buffers.rgb, GL_RGB, GL_UNSIGNED_BYTE},
                                  {buffers.depth, GL_RED, GL_FLOAT},
                                  {buffers.label, GL_RED_INTEGER, GL_UNSIGNED_SHORT},
                                  {buffers.instance, GL_RED_INTEGER, GL_INT},
                                  {buffers.voxel, GL_RED_INTEGER, GL_INT},
                                  {buffers.segmentation, GL_RGB, GL_UNSIGNED_BYTE}};
  for (int i = 0; i < kRenderedPassCount; ++i) {
    if (images[i].data == nullptr) continue;
    glReadBuffer(static_cast<GLenum>(GL_COLOR_ATTACHMENT0 + i));
    glReadPixels(0, 0, target.width, target.height, images[i].format, images[i].type,
                 images[i].data);
  }
  check_gl("reading back a capture");
}

}  // namespace ambfplus::render
