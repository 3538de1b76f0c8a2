// The OpenGL 4.5 rasteriser of a mesh draw list (mesh_renderer.h). Eye-relative coordinates
// throughout: the CPU folds the eye into each object's translation in double, so the GPU's floats
// keep their precision however far the scene lies from the origin.
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "calf/player/mesh_renderer.h"
#include "gl_errors.h"
#include "gl_program.h"
#include "gl_raster_target.h"
#include "object_transform.h"

namespace calf::player {

namespace {

constexpr const char* kVertexShader = R"(
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 colour;
layout(location = 3) in vec2 uv;
// Object -> eye-relative world: columns of the 3 x 3 part and the translation minus the eye.
uniform vec3 model_x, model_y, model_z, model_t;
// The normal matrix (inverse transpose of the 3 x 3 part), by columns.
uniform vec3 normal_x, normal_y, normal_z;
uniform CalfRasterCamera calf_camera;  // glsl_conventions.h
out vec3 v_rel;
out vec3 v_normal;
out vec3 v_colour;
out vec2 v_uv;
void main() {
  v_rel = model_x * position.x + model_y * position.y + model_z * position.z + model_t;
  v_normal = normal_x * normal.x + normal_y * normal.y + normal_z * normal.z;
  v_colour = colour;
  v_uv = uv;
  gl_Position = calf_raster_position(v_rel, calf_camera);
}
)";

constexpr const char* kGeometryShader = R"(
layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;
in vec3 v_rel[];
in vec3 v_normal[];
in vec3 v_colour[];
in vec2 v_uv[];
out vec3 g_rel;
out vec3 g_normal;
out vec3 g_colour;
out vec2 g_uv;
flat out vec3 g_base;
flat out vec3 g_emission;
flat out int g_textured;
// texture_index.x: the base-colour texture, 0xffffffff for none.
struct Material { vec4 base; vec4 emission; uvec4 texture_index; };
layout(std430, binding = 0) readonly buffer Materials { Material materials[]; };
layout(std430, binding = 1) readonly buffer TriangleMaterials { uint triangle_materials[]; };
layout(std430, binding = 2) readonly buffer Subset { uint subset[]; };
uniform bool has_normals, has_triangle_materials, has_subset, has_uvs;
uniform uint object_material;
// The texture bound for this pass (0xffffffff: the untextured pass): a triangle is drawn in the
// pass of its own texture only.
uniform uint pass_texture;
void main() {
  vec3 face = cross(v_rel[1] - v_rel[0], v_rel[2] - v_rel[0]);
  // The side the eye sees: flip the normals when the front faces away.
  float side = dot(face, v_rel[0]) > 0.0 ? -1.0 : 1.0;
  vec3 face_normal = normalize(face) * side;
  uint triangle = has_subset ? subset[gl_PrimitiveIDIn] : uint(gl_PrimitiveIDIn);
  uint m = has_triangle_materials ? triangle_materials[triangle] : object_material;
  if (m == 0xffffffffu) m = object_material;  // kMeshObjectMaterial
  uint tex = has_uvs ? materials[m].texture_index.x : 0xffffffffu;
  if (tex != pass_texture) return;
  for (int i = 0; i < 3; ++i) {
    gl_Position = gl_in[i].gl_Position;
    g_rel = v_rel[i];
    g_normal = has_normals ? v_normal[i] * side : face_normal;
    g_colour = v_colour[i];
    g_uv = v_uv[i];
    g_textured = tex != 0xffffffffu ? 1 : 0;
    g_base = materials[m].base.rgb;
    g_emission = materials[m].emission.rgb;
    EmitVertex();
  }
  EndPrimitive();
}
)";

constexpr const char* kFragmentShader = R"(
in vec3 g_rel;
in vec3 g_normal;
in vec3 g_colour;
in vec2 g_uv;
flat in vec3 g_base;
flat in vec3 g_emission;
flat in int g_textured;
// Layer 0 of an sRGB8_ALPHA8 array texture with its mip chain: LINEAR_MIPMAP_LINEAR, REPEAT.
uniform sampler2DArray base_texture;
uniform vec3 light;
uniform float ambient;
layout(location = 0) out vec4 out_colour;
void main() {
  vec3 n = normalize(g_normal);
  float lit = ambient + (1.0 - ambient) * max(0.0, dot(n, light));
  // Sampled in uniform control flow (the derivatives are the quad's), then ignored if untextured.
  vec3 t = texture(base_texture, vec3(g_uv, 0.0)).rgb;
  if (g_textured == 0) t = vec3(1.0);
  out_colour = vec4(g_base * t * g_colour * lit + g_emission, length(g_rel));
}
)";

Status structure_error(const std::string& what) {
  return Status(ErrorId::kMeshGlStructure, what + " (upload the draw list again)");
}

template <class T>
GLuint make_buffer(const GlFunctions& gl, GLenum target, const std::vector<T>& data) {
  GLuint b = 0;
  gl.GenBuffers(1, &b);
  gl.BindBuffer(target, b);
  // A zero-sized store is legal but cannot be bound as a storage range: keep one element.
  const std::vector<T> one(1);
  const std::vector<T>& d = data.empty() ? one : data;
  gl.BufferData(target, static_cast<GLsizeiptr>(d.size() * sizeof(T)), d.data(), GL_STATIC_DRAW);
  return b;
}

}  // namespace

Expected<std::unique_ptr<GlMeshRenderer>> GlMeshRenderer::make(const GlFunctions& gl) {
  std::unique_ptr<GlMeshRenderer> r(new GlMeshRenderer(gl));
  r->target_ = std::make_unique<internal::GlRasterTarget>(gl, /*with_depth=*/true);
  CALF_RETURN_IF_ERROR(r->build_program());
  return r;
}

GlMeshRenderer::GlMeshRenderer(const GlFunctions& gl) : gl_(&gl) {}

GlMeshRenderer::~GlMeshRenderer() {
  release_buffers();
  const GlFunctions& gl = *gl_;
  if (program_ != 0) gl.DeleteProgram(program_);
}

Status GlMeshRenderer::build_program() {
  const GlFunctions& gl = *gl_;
  const Expected<GLuint> program = internal::build_gl_program(
      gl,
      {{GL_VERTEX_SHADER, std::string(kGlslConventions) + kVertexShader, "vertex"},
       {GL_GEOMETRY_SHADER, kGeometryShader, "geometry"},
       {GL_FRAGMENT_SHADER, kFragmentShader, "fragment"}},
      "the mesh program");
  if (!program.ok()) return program.status();
  program_ = *program;
  const auto loc = [&](const char* name) { return gl.GetUniformLocation(program_, name); };
  uniforms_ = {loc("model_x"),     loc("model_y"),         loc("model_z"),
               loc("model_t"),     loc("normal_x"),        loc("normal_y"),
               loc("normal_z"),    loc("has_normals"),     loc("has_triangle_materials"),
               loc("has_subset"),  loc("object_material"), loc("has_uvs"),
               loc("pass_texture")};
  return check_gl_error(gl, "building the mesh program");
}

void GlMeshRenderer::release_buffers() {
  const GlFunctions& gl = *gl_;
  for (PrototypeBuffers& p : prototypes_) {
    const GLuint buffers[] = {p.positions,          p.normals, p.colours, p.indices,
                              p.triangle_materials, p.uvs};
    for (GLuint b : buffers) {
      if (b != 0) gl.DeleteBuffers(1, &b);
    }
    if (p.vao != 0) gl.DeleteVertexArrays(1, &p.vao);
  }
  for (ObjectBuffers& o : objects_) {
    if (o.indices != 0) gl.DeleteBuffers(1, &o.indices);
    if (o.triangles != 0) gl.DeleteBuffers(1, &o.triangles);
  }
  if (materials_ != 0) gl.DeleteBuffers(1, &materials_);
  materials_ = 0;
  for (GLuint t : textures_) gl.DeleteTextures(1, &t);
  textures_.clear();
  prototypes_.clear();
  objects_.clear();
}

Status GlMeshRenderer::upload(const MeshDrawList& list) {
  CALF_RETURN_IF_ERROR(validate_mesh_draw_list(list));
  const GlFunctions& gl = *gl_;
  release_buffers();
  for (const MeshDrawPrototype& p : list.prototypes) {
    PrototypeBuffers b;
    b.vertex_count = static_cast<uint32_t>(p.vertex_count());
    b.triangle_count = static_cast<uint32_t>(p.triangle_count());
    b.has_normals = !p.normals.empty();
    b.has_colours = !p.colours.empty();
    b.has_triangle_materials = !p.triangle_materials.empty();
    b.has_uvs = !p.uvs.empty();
    // The materials its triangles name (kMeshObjectMaterial: the object's): render() draws one
    // pass per texture they use.
    b.used_materials.assign(p.triangle_materials.begin(), p.triangle_materials.end());
    std::sort(b.used_materials.begin(), b.used_materials.end());
    b.used_materials.erase(std::unique(b.used_materials.begin(), b.used_materials.end()),
                           b.used_materials.end());
    if (b.used_materials.empty()) b.used_materials.push_back(kMeshObjectMaterial);
    gl.GenVertexArrays(1, &b.vao);
    gl.BindVertexArray(b.vao);
    b.positions = make_buffer(gl, GL_ARRAY_BUFFER, p.positions);
    gl.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    gl.EnableVertexAttribArray(0);
    // Absent normals / colours: the attribute reads the constant set at draw time.
    if (b.has_normals) {
      b.normals = make_buffer(gl, GL_ARRAY_BUFFER, p.normals);
      gl.VertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
      gl.EnableVertexAttribArray(1);
    }
    if (b.has_colours) {
      b.colours = make_buffer(gl, GL_ARRAY_BUFFER, p.colours);
      gl.VertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
      gl.EnableVertexAttribArray(2);
    }
    if (b.has_uvs) {
      b.uvs = make_buffer(gl, GL_ARRAY_BUFFER, p.uvs);
      gl.VertexAttribPointer(3, 2, GL_FLOAT, GL_FALSE, 0, nullptr);
      gl.EnableVertexAttribArray(3);
    }
    b.indices = make_buffer(gl, GL_ELEMENT_ARRAY_BUFFER, p.indices);
    gl.BindVertexArray(0);
    if (b.has_triangle_materials) {
      b.triangle_materials = make_buffer(gl, GL_SHADER_STORAGE_BUFFER, p.triangle_materials);
    }
    prototypes_.push_back(b);
  }
  for (const MeshDrawObject& o : list.objects) {
    ObjectBuffers b;
    b.prototype = o.prototype;
    b.all_triangles = o.all_triangles;
    b.drawn = static_cast<uint32_t>(o.drawn_triangles(list.prototypes[o.prototype]));
    if (!o.all_triangles) {
      // The subset's own index buffer (subsets do not change between frames) and its triangle
      // numbers, which the geometry shader maps primitives through.
      const std::vector<uint32_t>& all = list.prototypes[o.prototype].indices;
      std::vector<uint32_t> indices;
      indices.reserve(3 * o.triangles.size());
      for (uint32_t t : o.triangles) {
        for (int c = 0; c < 3; ++c) indices.push_back(all[3 * size_t{t} + c]);
      }
      // Created through GL_ARRAY_BUFFER (buffers are typeless): no vertex array is bound here.
      b.indices = make_buffer(gl, GL_ARRAY_BUFFER, indices);
      b.triangles = make_buffer(gl, GL_SHADER_STORAGE_BUFFER, o.triangles);
    }
    objects_.push_back(b);
  }
  gl.BindBuffer(GL_ARRAY_BUFFER, 0);
  // Each texture: an array texture of one layer (the loader has TexSubImage3D), every level of
  // the chain uploaded as it is (mesh_texture.h), sRGB decoded by the sampler before filtering.
  gl.PixelStorei(GL_UNPACK_ALIGNMENT, 4);
  for (const std::vector<mesh::TextureTexels>& chain : list.textures) {
    GLuint t = 0;
    gl.GenTextures(1, &t);
    textures_.push_back(t);
    gl.BindTexture(GL_TEXTURE_2D_ARRAY, t);
    gl.TexStorage3D(GL_TEXTURE_2D_ARRAY, static_cast<GLsizei>(chain.size()), GL_SRGB8_ALPHA8,
                    static_cast<GLsizei>(chain[0].width), static_cast<GLsizei>(chain[0].height), 1);
    for (size_t k = 0; k < chain.size(); ++k) {
      gl.TexSubImage3D(GL_TEXTURE_2D_ARRAY, static_cast<GLint>(k), 0, 0, 0,
                       static_cast<GLsizei>(chain[k].width), static_cast<GLsizei>(chain[k].height),
                       1, GL_RGBA, GL_UNSIGNED_BYTE, chain[k].rgba.data());
    }
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_REPEAT);
    gl.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_REPEAT);
  }
  gl.BindTexture(GL_TEXTURE_2D_ARRAY, 0);
  CALF_RETURN_IF_ERROR(update_materials(list));
  return check_gl_error(gl, "uploading the mesh buffers");
}

Status GlMeshRenderer::update_materials(const MeshDrawList& list) {
  const GlFunctions& gl = *gl_;
  for (size_t m = 0; m < list.materials.size(); ++m) {
    const uint32_t t = list.materials[m].base_colour_texture;
    if (t != kMeshNoTexture && t >= textures_.size()) {
      return structure_error("material " + std::to_string(m) + " names texture " +
                             std::to_string(t) + " of " + std::to_string(textures_.size()));
    }
  }
  std::vector<float> packed;  // std430: vec4 base, vec4 emission, uvec4 texture
  for (const MeshDrawMaterial& m : list.materials) {
    for (float v : m.base_colour) packed.push_back(v);
    packed.push_back(0);
    for (float v : m.emission) packed.push_back(v);
    packed.push_back(0);
    packed.push_back(std::bit_cast<float>(m.base_colour_texture));
    for (int i = 0; i < 3; ++i) packed.push_back(0);
  }
  material_textures_.clear();
  for (const MeshDrawMaterial& m : list.materials)
    material_textures_.push_back(m.base_colour_texture);
  if (materials_ != 0) gl.DeleteBuffers(1, &materials_);
  materials_ = make_buffer(gl, GL_SHADER_STORAGE_BUFFER, packed);
  material_count_ = list.materials.size();
  return check_gl_error(gl, "uploading the mesh materials");
}

Status GlMeshRenderer::check_structure(const MeshDrawList& list) const {
  if (list.textures.size() != textures_.size()) {
    return structure_error("the draw list has " + std::to_string(list.textures.size()) +
                           " textures, the upload " + std::to_string(textures_.size()));
  }
  if (list.prototypes.size() != prototypes_.size() || list.objects.size() != objects_.size() ||
      list.materials.size() != material_count_) {
    return structure_error("the draw list has " + std::to_string(list.prototypes.size()) +
                           " prototypes, " + std::to_string(list.objects.size()) + " objects and " +
                           std::to_string(list.materials.size()) + " materials, the upload " +
                           std::to_string(prototypes_.size()) + ", " +
                           std::to_string(objects_.size()) + " and " +
                           std::to_string(material_count_));
  }
  for (size_t p = 0; p < prototypes_.size(); ++p) {
    const MeshDrawPrototype& lp = list.prototypes[p];
    if (lp.vertex_count() != prototypes_[p].vertex_count ||
        lp.triangle_count() != prototypes_[p].triangle_count ||
        lp.uvs.empty() == prototypes_[p].has_uvs) {
      return structure_error("prototype " + std::to_string(p) +
                             " changed its vertex or triangle count");
    }
  }
  for (size_t o = 0; o < objects_.size(); ++o) {
    const MeshDrawObject& lo = list.objects[o];
    if (lo.prototype != objects_[o].prototype || lo.all_triangles != objects_[o].all_triangles ||
        lo.drawn_triangles(list.prototypes[lo.prototype]) != objects_[o].drawn) {
      return structure_error("object " + std::to_string(o) + " changed its prototype or subset");
    }
  }
  return Status::Ok();
}

Status GlMeshRenderer::update_positions(const MeshDrawList& list, uint32_t prototype) {
  CALF_RETURN_IF_ERROR(check_structure(list));
  if (prototype >= prototypes_.size()) {
    return structure_error("prototype " + std::to_string(prototype) + " was not uploaded");
  }
  const std::vector<float>& p = list.prototypes[prototype].positions;
  for (float x : p) {
    if (!std::isfinite(x)) {
      return Status(ErrorId::kMeshDrawList,
                    "prototype " + std::to_string(prototype) + ": a position is not finite");
    }
  }
  if (p.empty()) return Status::Ok();
  const GlFunctions& gl = *gl_;
  gl.BindBuffer(GL_ARRAY_BUFFER, prototypes_[prototype].positions);
  gl.BufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(p.size() * sizeof(float)), p.data());
  gl.BindBuffer(GL_ARRAY_BUFFER, 0);
  return check_gl_error(gl, "updating mesh positions");
}

Status GlMeshRenderer::render(const MeshDrawList& list, const Camera& camera,
                              const MeshRenderOptions& options, RenderedImage* out) {
  CALF_RETURN_IF_ERROR(validate_camera(camera));
  CALF_RETURN_IF_ERROR(validate_mesh_render_options(options));
  CALF_RETURN_IF_ERROR(check_structure(list));
  const GlFunctions& gl = *gl_;
  CALF_RETURN_IF_ERROR(
      target_->bind_and_clear(camera.width, camera.height, "the mesh render target"));
  for (GLenum cap : {GL_BLEND, GL_SCISSOR_TEST, GL_CULL_FACE, GL_STENCIL_TEST}) gl.Disable(cap);
  gl.Enable(GL_DEPTH_TEST);
  gl.DepthFunc(GL_GREATER);
  gl.ClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  gl.UseProgram(program_);
  const auto loc = [&](const char* name) { return gl.GetUniformLocation(program_, name); };
  const auto f = [](double x) { return static_cast<float>(x); };
  internal::upload_raster_camera(gl, program_, camera, options.near);
  gl.Uniform3f(loc("light"), kMeshKeyLight[0], kMeshKeyLight[1], kMeshKeyLight[2]);
  gl.Uniform1f(loc("ambient"), kMeshAmbient);
  gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, materials_);
  gl.Uniform1i(loc("base_texture"), 0);
  gl.ActiveTexture(GL_TEXTURE0);
  const ObjectUniforms& u = uniforms_;
  const auto at = [&](GLint location, const Vec3& v) {
    gl.Uniform3f(location, f(v.x), f(v.y), f(v.z));
  };

  for (size_t o = 0; o < objects_.size(); ++o) {
    const ObjectBuffers& ob = objects_[o];
    if (ob.drawn == 0 || !list.objects[o].visible) continue;
    const PrototypeBuffers& pb = prototypes_[ob.prototype];
    const MeshDrawObject& lo = list.objects[o];
    const internal::ObjectTransform t(lo.transform);
    const auto& r = t.r;
    at(u.model_x, {r[0][0], r[1][0], r[2][0]});
    at(u.model_y, {r[0][1], r[1][1], r[2][1]});
    at(u.model_z, {r[0][2], r[1][2], r[2][2]});
    at(u.model_t, t.translation() - camera.position);
    // Inverse transpose up to a positive factor: the cofactor matrix (normals are normalised).
    const auto& cof = t.cof;
    at(u.normal_x, {cof[0][0], cof[1][0], cof[2][0]});
    at(u.normal_y, {cof[0][1], cof[1][1], cof[2][1]});
    at(u.normal_z, {cof[0][2], cof[1][2], cof[2][2]});
    gl.Uniform1i(u.has_normals, pb.has_normals ? 1 : 0);
    gl.Uniform1i(u.has_triangle_materials, pb.has_triangle_materials ? 1 : 0);
    gl.Uniform1i(u.has_subset, ob.all_triangles ? 0 : 1);
    gl.Uniform1ui(u.object_material, lo.material);
    gl.Uniform1i(u.has_uvs, pb.has_uvs ? 1 : 0);
    gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 1,
                      pb.has_triangle_materials ? pb.triangle_materials : materials_);
    gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, ob.all_triangles ? materials_ : ob.triangles);
    gl.BindVertexArray(pb.vao);
    if (!pb.has_normals) gl.VertexAttrib3f(1, 0, 0, 1);
    if (!pb.has_colours) gl.VertexAttrib3f(2, 1, 1, 1);
    if (!pb.has_uvs) gl.VertexAttrib3f(3, 0, 0, 0);
    if (!ob.all_triangles) gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, ob.indices);
    // One pass per texture the object's triangles use (kMeshNoTexture, the untextured pass, last):
    // the geometry shader drops the triangles of other passes.
    std::vector<uint32_t> passes;
    for (uint32_t m : pb.used_materials) {
      const uint32_t mat = m == kMeshObjectMaterial ? lo.material : m;
      passes.push_back(pb.has_uvs ? material_textures_[mat] : kMeshNoTexture);
    }
    std::sort(passes.begin(), passes.end());
    passes.erase(std::unique(passes.begin(), passes.end()), passes.end());
    for (uint32_t pass : passes) {
      gl.Uniform1ui(u.pass_texture, pass);
      gl.BindTexture(GL_TEXTURE_2D_ARRAY, pass == kMeshNoTexture ? 0 : textures_[pass]);
      gl.DrawElements(GL_TRIANGLES, static_cast<GLsizei>(3 * ob.drawn), GL_UNSIGNED_INT, nullptr);
    }
    // Give the vertex array its own index buffer back for the next object of this prototype.
    if (!ob.all_triangles) gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, pb.indices);
    gl.BindVertexArray(0);
  }

  // Leave the state other renderers (the light field's full-screen pass, the HUD) expect.
  gl.BindTexture(GL_TEXTURE_2D_ARRAY, 0);
  gl.Disable(GL_DEPTH_TEST);
  gl.ClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
  CALF_RETURN_IF_ERROR(check_gl_error(gl, "drawing the mesh"));

  return target_->read_back("reading back the mesh frame", out);
}

}  // namespace calf::player
