// The mesh representation; what it does is in the public header.
#include "calf/player/mesh_representation.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "calf/decoder/mesh_track.h"
#include "calf/format/mesh_layout.h"

namespace calf::player {

// The track's "the object's material" passes into the draw list unchanged.
static_assert(mesh::kObjectMaterial == kMeshObjectMaterial);

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::string format(const char* fmt, auto... args) {
  char buf[160];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

Status play_error(const std::string& what) {
  return Status(ErrorId::kMeshPlayback, what);
}

}  // namespace

struct MeshRepresentation::Impl {
  uint16_t track = 0;
  RenderBackend backend = RenderBackend::kGl;
  MeshOptions options;
  uint32_t frames = 1;
  double fps = 24;
  Box3 volume;
  // The decoded track: prototypes (for their vertex states) and objects (their transforms).
  std::optional<decoder::MeshTrack> mesh;
  std::vector<decoder::MeshPrototype> prototypes;
  std::vector<decoder::MeshObject> objects;
  std::vector<uint32_t> dynamic;  // prototypes with vertex states
  MeshDrawList list;
  std::unique_ptr<GlMeshRenderer> gl;
  uint64_t drawn = 0, total = 0;
  uint32_t frame = 0;
  bool prepared = false;
  double render_ms = 0, prepare_ms = 0;

  Status start(const GlFunctions* functions);
};

Status MeshRepresentation::Impl::start(const GlFunctions* functions) {
  CALF_RETURN_IF_ERROR(validate_mesh_render_options(options.render));
  CALF_RETURN_IF_ERROR(validate_mesh_draw_list(list));
  drawn = mesh_draw_triangle_count(list);
  total = 0;
  for (const MeshDrawObject& o : list.objects) {
    total += list.prototypes[o.prototype].triangle_count();
  }
  if (backend == RenderBackend::kGl) {
    if (functions == nullptr) {
      return Status(ErrorId::kPlayerGl, "the GL mesh renderer needs a current OpenGL 4.5 context");
    }
    CALF_ASSIGN_OR_RETURN(gl, GlMeshRenderer::make(*functions));
    CALF_RETURN_IF_ERROR(gl->upload(list));
  }
  return Status::Ok();
}

MeshRepresentation::MeshRepresentation(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
MeshRepresentation::~MeshRepresentation() = default;

Expected<std::unique_ptr<MeshRepresentation>> MeshRepresentation::open(
    const container::Reader& reader, uint16_t track, const MeshOptions& options,
    RenderBackend backend, const GlFunctions* gl) {
  if (track >= reader.tracks().size() ||
      !std::holds_alternative<container::MeshTrackHeader>(reader.tracks()[track].header)) {
    return play_error("track " + std::to_string(track) + " is not a mesh track");
  }
  auto impl = std::make_unique<Impl>();
  impl->track = track;
  impl->backend = backend;
  impl->options = options;
  CALF_ASSIGN_OR_RETURN(decoder::MeshTrack mesh, decoder::MeshTrack::open(reader, track));
  impl->mesh.emplace(std::move(mesh));
  const decoder::MeshTrack& m = *impl->mesh;
  impl->frames = std::max<uint32_t>(1, m.frame_count());
  impl->fps = m.fps();
  impl->volume = m.view_volume();
  const std::string where = "mesh track " + std::to_string(track);
  if (!(std::isfinite(impl->fps) && impl->fps > 0)) {
    return play_error(where + ": frame rate " + std::to_string(impl->fps) + " is not > 0");
  }
  MeshDrawList& list = impl->list;
  for (const decoder::MeshMaterial& mat : m.materials()) {
    list.materials.push_back({mat.base_colour, mat.emission, mat.base_colour_texture});
  }
  // Textures: decoded once, each with its mip chain (calf/format/mesh_texture.h).
  for (uint32_t t = 0; t < m.texture_count(); ++t) {
    mesh::TextureTexels texels;
    CALF_RETURN_IF_ERROR(m.texture(t, &texels));
    list.textures.push_back(mesh::mip_chain(texels));
  }
  impl->prototypes.resize(m.prototype_count());
  for (uint32_t p = 0; p < m.prototype_count(); ++p) {
    decoder::MeshPrototype& proto = impl->prototypes[p];
    CALF_RETURN_IF_ERROR(m.prototype(p, &proto));
    MeshDrawPrototype d;
    decoder::positions_at(proto, 0.0, &d.positions);
    // The decoded prototype is kept only when it has states (prepare() reads them); the draw
    // list takes the rest, so a static scene is held once.
    d.normals = std::move(proto.normals);
    d.colours = std::move(proto.colours);
    d.uvs = std::move(proto.uvs);
    d.indices = std::move(proto.indices);
    d.triangle_materials = std::move(proto.triangle_materials);
    if (!proto.state_times.empty()) {
      impl->dynamic.push_back(p);
    } else {
      proto = decoder::MeshPrototype{};
    }
    list.prototypes.push_back(std::move(d));
  }
  impl->objects.resize(m.object_count());
  for (uint32_t o = 0; o < m.object_count(); ++o) {
    decoder::MeshObject& object = impl->objects[o];
    CALF_RETURN_IF_ERROR(m.object(o, &object));
    if (object.prototype >= list.prototypes.size() || object.material >= list.materials.size() ||
        object.transforms.empty()) {
      return play_error(where + ", object " + std::to_string(o) + ": prototype " +
                        std::to_string(object.prototype) + " or material " +
                        std::to_string(object.material) +
                        " is out of range, or it has no transform");
    }
    MeshDrawObject d;
    d.prototype = object.prototype;
    d.material = object.material;
    d.transform = decoder::transform_at(object, 0);
    d.all_triangles = object.all_triangles;
    d.triangles = object.triangles;
    list.objects.push_back(std::move(d));
  }
  CALF_RETURN_IF_ERROR(impl->start(gl));
  return std::unique_ptr<MeshRepresentation>(new MeshRepresentation(std::move(impl)));
}

Expected<std::unique_ptr<MeshRepresentation>> MeshRepresentation::from_draw_list(
    MeshDrawList list, const Box3& view_volume, const MeshOptions& options, RenderBackend backend,
    const GlFunctions* gl) {
  auto impl = std::make_unique<Impl>();
  impl->backend = backend;
  impl->options = options;
  impl->volume = view_volume;
  impl->list = std::move(list);
  CALF_RETURN_IF_ERROR(impl->start(gl));
  return std::unique_ptr<MeshRepresentation>(new MeshRepresentation(std::move(impl)));
}

std::string_view MeshRepresentation::kind() const {
  return "mesh";
}
uint16_t MeshRepresentation::track() const {
  return impl_->track;
}
RenderBackend MeshRepresentation::backend() const {
  return impl_->backend;
}
uint32_t MeshRepresentation::frame_count() const {
  return impl_->frames;
}
double MeshRepresentation::fps() const {
  return impl_->fps;
}
const Box3& MeshRepresentation::view_volume() const {
  return impl_->volume;
}
const MeshDrawList& MeshRepresentation::draw_list() const {
  return impl_->list;
}
void MeshRepresentation::set_object_visible(size_t o, bool visible) {
  MeshDrawObject& object = impl_->list.objects[o];
  if (object.visible == visible) return;
  const uint64_t n = object.drawn_triangles(impl_->list.prototypes[object.prototype]);
  object.visible = visible;
  impl_->drawn = visible ? impl_->drawn + n : impl_->drawn - n;
}
uint64_t MeshRepresentation::triangles_drawn() const {
  return impl_->drawn;
}
uint64_t MeshRepresentation::triangles_total() const {
  return impl_->total;
}
double MeshRepresentation::last_render_ms() const {
  return impl_->render_ms;
}
double MeshRepresentation::last_prepare_ms() const {
  return impl_->prepare_ms;
}

Status MeshRepresentation::prepare(uint32_t frame, std::span<const Camera> eyes) {
  Impl& d = *impl_;
  if (eyes.empty()) return Status(ErrorId::kPlayerOptions, "prepare() needs at least one eye");
  if (frame >= d.frames) {
    return play_error("frame " + std::to_string(frame) + " is past the mesh track's " +
                      std::to_string(d.frames) + " frames");
  }
  const auto t0 = std::chrono::steady_clock::now();
  if (!d.prepared || frame != d.frame) {
    // Objects of a draw list given directly keep their transforms (there is no track).
    for (size_t o = 0; o < d.objects.size(); ++o) {
      d.list.objects[o].transform = decoder::transform_at(d.objects[o], frame);
    }
    const double time = frame / d.fps;
    for (uint32_t p : d.dynamic) {
      decoder::positions_at(d.prototypes[p], time, &d.list.prototypes[p].positions);
      if (d.gl) CALF_RETURN_IF_ERROR(d.gl->update_positions(d.list, p));
    }
    d.frame = frame;
    d.prepared = true;
  }
  d.prepare_ms = ms_since(t0);
  return Status::Ok();
}

Status MeshRepresentation::render(const Camera& camera, RenderedImage* out) {
  Impl& d = *impl_;
  const auto t0 = std::chrono::steady_clock::now();
  if (d.gl) {
    CALF_RETURN_IF_ERROR(d.gl->render(d.list, camera, d.options.render, out));
  } else {
    CALF_RETURN_IF_ERROR(render_mesh_cpu(d.list, camera, d.options.render, out));
  }
  d.render_ms = ms_since(t0);
  return Status::Ok();
}

Status MeshRepresentation::report_frame_time(double frame_ms) {
  if (!(std::isfinite(frame_ms) && frame_ms >= 0)) {
    return Status(ErrorId::kViewSelectFrameTime,
                  "frame time " + std::to_string(frame_ms) + " ms is negative or not finite");
  }
  return Status::Ok();
}

FrameFigures MeshRepresentation::figures() const {
  FrameFigures f;
  f.triangles_drawn = triangles_drawn();
  return f;
}

RepresentationStats MeshRepresentation::stats() const {
  const Impl& d = *impl_;
  RepresentationStats out;
  out.title = format("mesh track %u (%s)", d.track, d.backend == RenderBackend::kGl ? "gl" : "cpu");
  out.entries.push_back({"objects", format("%zu", d.list.objects.size())});
  const double share = d.total > 0 ? 100.0 * static_cast<double>(d.drawn) / d.total : 100.0;
  out.entries.push_back(
      {"triangles drawn", format("%llu of %llu (%.1f %%)", static_cast<unsigned long long>(d.drawn),
                                 static_cast<unsigned long long>(d.total), share)});
  out.entries.push_back(
      {"animated prototypes", format("%zu of %zu", d.dynamic.size(), d.list.prototypes.size())});
  out.entries.push_back({"prepare", format("%.2f ms", d.prepare_ms)});
  out.entries.push_back({"draw", format("%.1f ms", d.render_ms)});
  return out;
}

}  // namespace calf::player
