// The surfel representation; what it does is in the public header.
#include "calf/player/surfel_representation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <limits>
#include <string>
#include <vector>

#include "calf/decoder/mesh_track.h"
#include "calf/decoder/surfels_track.h"
#include "calf/format/surfels_layout.h"
#include "calf/player/frame_controller.h"
#include "calf/player/rendered_image.h"
#include "calf/player/surfel_renderer.h"
#include "object_transform.h"

namespace calf::player {
namespace {

// The frame controller's passes: the near meshes (triangles) and the surfels. The mesh pass's
// share is 3/4: it costs per triangle and per covered pixel, which the triangles predict only in
// part (frame_controller.h).
constexpr size_t kMeshPass = 0, kSurfelPass = 1;
constexpr double kMeshShare = 0.75;

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// A pass's wall and process CPU time (std::clock: every thread of the process, llvmpipe's
// rasteriser threads included).
struct PassTimer {
  std::chrono::steady_clock::time_point wall = std::chrono::steady_clock::now();
  std::clock_t cpu = std::clock();
  void add_to(double* wall_ms, double* cpu_ms) const {
    *wall_ms += ms_since(wall);
    *cpu_ms += 1000.0 * static_cast<double>(std::clock() - cpu) / CLOCKS_PER_SEC;
  }
};

std::string format(const char* fmt, auto... args) {
  char buf[160];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

Status option_error(const std::string& what) {
  return Status(ErrorId::kPlaybackOption, "surfel option " + what);
}

// How an object is drawn at the prepared frame.
enum class Drawn : uint8_t { kSurfels, kBoth, kMesh };

// e of SurfelFoveation for a point seen by `eye`: its image-plane position in units of the
// half-diagonal; infinity behind the eye.
double eccentricity(const Camera& eye, const CameraFrame& frame, const Vec3& point) {
  const Vec3 v = point - eye.position;
  const double z = dot(v, frame.forward);
  if (!(z > 0)) return std::numeric_limits<double>::infinity();
  const double ty = std::tan(eye.fov_y / 2);
  const double tx = ty * eye.width / eye.height;
  const double x = dot(v, frame.right) / z, y = dot(v, frame.up) / z;
  return std::sqrt((x * x + y * y) / (tx * tx + ty * ty));
}

// The point-size factor of SurfelFoveation at eccentricity e.
double foveation_factor(const SurfelFoveation& f, double e) {
  if (!f.enabled || e <= f.inner) return 1;
  if (e >= f.outer) return f.periphery_scale;
  return 1 + (f.periphery_scale - 1) * (e - f.inner) / (f.outer - f.inner);
}

}  // namespace

Status validate_surfel_options(const SurfelOptions& o) {
  CALF_RETURN_IF_ERROR(validate_surfel_render_options(o.render));
  CALF_RETURN_IF_ERROR(validate_mesh_render_options(o.mesh.render));
  if (!(o.min_point_size > 0 && o.min_point_size <= o.max_point_size && o.max_point_size <= 64)) {
    return option_error(format("point size range [%g, %g] is not within (0, 64]", o.min_point_size,
                               o.max_point_size));
  }
  if (!(o.point_size >= o.min_point_size && o.point_size <= o.max_point_size)) {
    return option_error(format("point size %g is outside [%g, %g]", o.point_size, o.min_point_size,
                               o.max_point_size));
  }
  if (!(std::isfinite(o.target_frame_ms) && o.target_frame_ms >= 0)) {
    return option_error(
        format("target frame time %g ms is not finite and >= 0", o.target_frame_ms));
  }
  if (!(o.controller_deadband >= 0 && o.controller_deadband < 1)) {
    return option_error(format("controller deadband %g is outside [0, 1)", o.controller_deadband));
  }
  if (!(o.blend_share >= 0 && o.blend_share <= 1)) {
    return option_error(format("blend share %g is outside [0, 1]", o.blend_share));
  }
  const SurfelFoveation& f = o.foveation;
  if (!(f.inner >= 0 && f.inner <= f.outer && f.outer <= 4)) {
    return option_error(format(
        "foveation zones inner %g, outer %g are not 0 <= inner <= outer <= 4", f.inner, f.outer));
  }
  if (!(f.periphery_scale >= 1 && f.periphery_scale <= 16)) {
    return option_error(
        format("foveation periphery scale %g is outside [1, 16]", f.periphery_scale));
  }
  return Status::Ok();
}

struct SurfelRepresentation::Impl {
  uint16_t track = 0;
  RenderBackend backend = RenderBackend::kGl;
  SurfelOptions options;
  double point_size = 2;
  std::unique_ptr<MeshRepresentation> mesh;
  std::vector<surfels::PrototypeRecord> records;
  // Per prototype: the centre and radius of its box's bounding sphere, object space.
  std::vector<Vec3> centres;
  std::vector<double> radii;
  SurfelDrawList list;
  std::vector<Drawn> drawn;
  // Per object at the prepared view: the disc radius at point size 1 in object units (the
  // foveation factor included; 0 for a prototype without surfels) and its mesh's triangles.
  std::vector<double> unit_radius;
  std::vector<uint64_t> triangles;
  std::unique_ptr<FrameController> controller;  // with a target frame time
  FrameWork work;                               // the prepared frame's
  // The passes' times since the latest prepare: [0] wall, [1] process CPU, ms.
  double mesh_ms[2] = {0, 0}, surfels_ms[2] = {0, 0}, frame_ms[2] = {0, 0};
  std::unique_ptr<GlSurfelRenderer> gl;
  RenderedImage layer;  // the surfels' image before compositing
  std::vector<Camera> eyes;
  uint64_t surfels = 0;
  uint32_t counts[3] = {0, 0, 0};  // objects per Drawn
  uint32_t peripheral = 0;         // objects drawn with a foveation factor > 1
  double render_ms = 0, prepare_ms = 0;

  // Fills unit_radius for the prepared eyes.
  void measure(const Camera& first);
  // How object o is drawn at point size s, and its prefix (0 unless surfels are drawn).
  Drawn classify(size_t o, double s, uint32_t* count, double* radius) const;
  FrameWork work_at(double s) const;
  // Sets the draw list, the mesh's visible objects and the counts for point size s.
  void apply(double s);
};

SurfelRepresentation::SurfelRepresentation(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
SurfelRepresentation::~SurfelRepresentation() = default;

Expected<std::unique_ptr<SurfelRepresentation>> SurfelRepresentation::open(
    const container::Reader& reader, uint16_t track, const SurfelOptions& options,
    RenderBackend backend, const GlFunctions* gl) {
  if (track >= reader.tracks().size() ||
      !std::holds_alternative<container::SurfelsTrackHeader>(reader.tracks()[track].header)) {
    return Status(ErrorId::kMeshPlayback,
                  "track " + std::to_string(track) + " is not a surfels track");
  }
  CALF_RETURN_IF_ERROR(validate_surfel_options(options));
  auto impl = std::make_unique<Impl>();
  impl->track = track;
  impl->backend = backend;
  impl->options = options;
  impl->point_size = options.point_size;
  CALF_ASSIGN_OR_RETURN(const decoder::SurfelsTrack surfels,
                        decoder::SurfelsTrack::open(reader, track));
  {
    CALF_ASSIGN_OR_RETURN(const decoder::MeshTrack mesh_track,
                          decoder::MeshTrack::open(reader, surfels.mesh_track()));
    CALF_RETURN_IF_ERROR(surfels.check_pairing(mesh_track));
  }
  CALF_ASSIGN_OR_RETURN(impl->mesh, MeshRepresentation::open(reader, surfels.mesh_track(),
                                                             options.mesh, backend, gl));
  for (uint32_t p = 0; p < surfels.prototype_count(); ++p) {
    const surfels::PrototypeRecord& r = surfels.record(p);
    impl->records.push_back(r);
    const Vec3 lo{r.box_min[0], r.box_min[1], r.box_min[2]};
    const Vec3 hi{r.box_max[0], r.box_max[1], r.box_max[2]};
    impl->centres.push_back((lo + hi) * 0.5);
    impl->radii.push_back(length(hi - lo) * 0.5);
    decoder::SurfelBuffer buffer;
    CALF_RETURN_IF_ERROR(surfels.prototype(p, &buffer));
    SurfelDrawPrototype d;
    d.positions = std::move(buffer.positions);
    d.normals = std::move(buffer.normals);
    d.colours = std::move(buffer.colours);
    impl->list.prototypes.push_back(std::move(d));
  }
  // A surfel's colour multiplies its object's material base colour unless its prototype's
  // colours are the base colour itself (SPEC §11.3.2): the object's tint. Emission is not drawn.
  const MeshDrawList& mesh_list = impl->mesh->draw_list();
  for (const MeshDrawObject& o : mesh_list.objects) {
    SurfelDrawObject s;
    s.prototype = o.prototype;
    s.transform = o.transform;
    if (s.prototype < impl->records.size() &&
        (impl->records[s.prototype].flags & surfels::kColourIsBase) == 0) {
      s.tint = mesh_list.materials[o.material].base_colour;
    }
    impl->list.objects.push_back(s);
  }
  impl->drawn.assign(impl->list.objects.size(), Drawn::kMesh);
  for (const MeshDrawObject& o : mesh_list.objects) {
    impl->triangles.push_back(o.drawn_triangles(mesh_list.prototypes[o.prototype]));
  }
  if (options.target_frame_ms > 0) {
    // The knob is the point size: continuous, the work falls as it grows; a symmetric deadband
    // and no limit on growth (the point size has no cautious step).
    FrameControllerOptions c;
    c.target_ms = options.target_frame_ms;
    c.min = options.min_point_size;
    c.max = options.max_point_size;
    c.pass_share[kMeshPass] = kMeshShare;
    c.pass_share[kSurfelPass] = 1;
    c.shrink_above = c.grow_below = options.controller_deadband;
    impl->controller = std::make_unique<FrameController>(c, options.point_size);
  }
  CALF_RETURN_IF_ERROR(validate_surfel_draw_list(impl->list));
  if (backend == RenderBackend::kGl) {
    if (gl == nullptr) {
      return Status(ErrorId::kPlayerGl,
                    "the GL surfel renderer needs a current OpenGL 4.5 context");
    }
    CALF_ASSIGN_OR_RETURN(impl->gl, GlSurfelRenderer::make(*gl));
    CALF_RETURN_IF_ERROR(impl->gl->upload(impl->list));
  }
  return std::unique_ptr<SurfelRepresentation>(new SurfelRepresentation(std::move(impl)));
}

void SurfelRepresentation::Impl::measure(const Camera& first) {
  const MeshDrawList& mesh_list = mesh->draw_list();
  const double pixel =
      2 * std::tan(first.fov_y / 2) / first.height;  // world size per unit distance
  peripheral = 0;
  std::vector<CameraFrame> frames;
  for (const Camera& eye : eyes) frames.push_back(camera_frame(eye));
  unit_radius.assign(list.objects.size(), 0);
  for (size_t o = 0; o < list.objects.size(); ++o) {
    SurfelDrawObject& s = list.objects[o];
    s.transform = mesh_list.objects[o].transform;
    if (records[s.prototype].surfel_count == 0) continue;
    const internal::ObjectTransform t(s.transform);
    const double scale = std::cbrt(std::abs(t.det));
    const Vec3 centre = t.linear(centres[s.prototype]) + t.translation();
    double d = std::numeric_limits<double>::infinity();
    double e = std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < eyes.size(); ++k) {
      d = std::min(d, length(centre - eyes[k].position));
      if (options.foveation.enabled) e = std::min(e, eccentricity(eyes[k], frames[k], centre));
    }
    d = std::max(d - scale * radii[s.prototype], options.render.near);
    const double factor = foveation_factor(options.foveation, e);
    if (factor > 1) ++peripheral;
    unit_radius[o] = factor / 2 * pixel * d / scale;  // object units at point size 1
  }
}

Drawn SurfelRepresentation::Impl::classify(size_t o, double s, uint32_t* count,
                                           double* radius) const {
  *count = 0;
  *radius = 0;
  if (unit_radius[o] <= 0) return Drawn::kMesh;
  const surfels::PrototypeRecord& rec = records[list.objects[o].prototype];
  *radius = unit_radius[o] * s;
  // Eq. 1 unclamped, to tell "needs more than the buffer holds" from "needs all of it".
  const double need = rec.prefix_count * std::pow(rec.prefix_radius / *radius, 2);
  if (need > rec.surfel_count) return Drawn::kMesh;
  *count = surfels::prefix_for_radius(rec, *radius);
  return need > options.blend_share * rec.surfel_count ? Drawn::kBoth : Drawn::kSurfels;
}

FrameWork SurfelRepresentation::Impl::work_at(double s) const {
  FrameWork w;
  for (size_t o = 0; o < list.objects.size(); ++o) {
    uint32_t count;
    double radius;
    if (classify(o, s, &count, &radius) != Drawn::kSurfels) {
      w.pass[kMeshPass] += static_cast<double>(triangles[o]);
    }
    w.pass[kSurfelPass] += count;
  }
  return w;
}

void SurfelRepresentation::Impl::apply(double s) {
  counts[0] = counts[1] = counts[2] = 0;
  for (size_t o = 0; o < list.objects.size(); ++o) {
    SurfelDrawObject& obj = list.objects[o];
    double radius;
    const Drawn how = classify(o, s, &obj.count, &radius);
    obj.radius = static_cast<float>(radius);
    drawn[o] = how;
    ++counts[static_cast<int>(how)];
    mesh->set_object_visible(o, how != Drawn::kSurfels);
  }
  surfels = 0;
  for (const SurfelDrawObject& obj : list.objects) surfels += obj.count;
  work.pass[kMeshPass] = static_cast<double>(mesh->triangles_drawn());
  work.pass[kSurfelPass] = static_cast<double>(surfels);
}

std::string_view SurfelRepresentation::kind() const {
  return "surfels";
}
uint16_t SurfelRepresentation::track() const {
  return impl_->track;
}
RenderBackend SurfelRepresentation::backend() const {
  return impl_->backend;
}
uint32_t SurfelRepresentation::frame_count() const {
  return impl_->mesh->frame_count();
}
double SurfelRepresentation::fps() const {
  return impl_->mesh->fps();
}
const Box3& SurfelRepresentation::view_volume() const {
  return impl_->mesh->view_volume();
}
uint16_t SurfelRepresentation::mesh_track() const {
  return impl_->mesh->track();
}
double SurfelRepresentation::point_size() const {
  return impl_->point_size;
}
double SurfelRepresentation::predicted_frame_ms() const {
  return impl_->controller ? impl_->controller->predicted_ms() : 0;
}
SurfelPassTimes SurfelRepresentation::last_pass_times() const {
  const Impl& d = *impl_;
  SurfelPassTimes t;
  t.mesh_ms = d.mesh_ms[0];
  t.surfels_ms = d.surfels_ms[0];
  t.frame_ms = d.frame_ms[0];
  t.mesh_cpu_ms = d.mesh_ms[1];
  t.surfels_cpu_ms = d.surfels_ms[1];
  t.frame_cpu_ms = d.frame_ms[1];
  return t;
}
uint64_t SurfelRepresentation::surfels_drawn() const {
  return impl_->surfels;
}
uint64_t SurfelRepresentation::triangles_drawn() const {
  return impl_->mesh->triangles_drawn();
}
uint32_t SurfelRepresentation::peripheral_objects() const {
  return impl_->peripheral;
}
const SurfelDrawList& SurfelRepresentation::draw_list() const {
  return impl_->list;
}

Status SurfelRepresentation::prepare(uint32_t frame, std::span<const Camera> eyes) {
  Impl& d = *impl_;
  const auto t0 = std::chrono::steady_clock::now();
  CALF_RETURN_IF_ERROR(d.mesh->prepare(frame, eyes));
  d.eyes.assign(eyes.begin(), eyes.end());
  d.measure(eyes.front());
  if (d.controller) {
    // The feed-forward: the controller sees what this view costs at every point size.
    d.point_size = d.controller->plan([&d](double s) { return d.work_at(s); });
  }
  d.apply(d.point_size);
  for (int c = 0; c < 2; ++c) d.mesh_ms[c] = d.surfels_ms[c] = d.frame_ms[c] = 0;
  d.prepare_ms = ms_since(t0);
  return Status::Ok();
}

Status SurfelRepresentation::render(const Camera& camera, RenderedImage* out) {
  Impl& d = *impl_;
  const auto t0 = std::chrono::steady_clock::now();
  const PassTimer frame;
  // A pass is skipped when it draws nothing: with no mesh object the surfels render straight into
  // `out`; with no surfel the mesh does. Each pass is timed apart: the controller models them
  // apart (both passes read their image back, so a pass's time is its whole cost).
  const bool meshes = d.mesh->triangles_drawn() > 0;
  if (meshes || d.surfels == 0) {
    const PassTimer pass;
    CALF_RETURN_IF_ERROR(d.mesh->render(camera, out));
    pass.add_to(&d.mesh_ms[0], &d.mesh_ms[1]);
  }
  if (d.surfels > 0) {
    RenderedImage* target = meshes ? &d.layer : out;
    const PassTimer pass;
    if (d.gl) {
      CALF_RETURN_IF_ERROR(d.gl->render(d.list, camera, d.options.render, target));
    } else {
      CALF_RETURN_IF_ERROR(render_surfels_cpu(d.list, camera, d.options.render, target));
    }
    pass.add_to(&d.surfels_ms[0], &d.surfels_ms[1]);
    if (meshes) CALF_RETURN_IF_ERROR(composite_nearest(d.layer, out));
  }
  frame.add_to(&d.frame_ms[0], &d.frame_ms[1]);
  d.render_ms = ms_since(t0);
  return Status::Ok();
}

Status SurfelRepresentation::report_frame_time(double frame_ms) {
  Impl& d = *impl_;
  if (!(std::isfinite(frame_ms) && frame_ms >= 0)) {
    return Status(ErrorId::kViewSelectFrameTime,
                  "frame time " + std::to_string(frame_ms) + " ms is negative or not finite");
  }
  if (d.controller && frame_ms > 0) {
    // Wall clock: the caller's frame time, the passes inside it; CPU clock: the process CPU
    // time of the renders since the prepare and of their passes.
    const int c = d.options.controller_clock == SurfelClock::kCpu ? 1 : 0;
    FrameTimes times;
    times.pass_ms[kMeshPass] = d.mesh_ms[c];
    times.pass_ms[kSurfelPass] = d.surfels_ms[c];
    times.frame_ms = c == 1 ? d.frame_ms[1] : frame_ms;
    d.controller->report(d.work, times);
  }
  return Status::Ok();
}

FrameFigures SurfelRepresentation::figures() const {
  FrameFigures f;
  f.triangles_drawn = triangles_drawn();
  f.points = FrameFigures::Points{.drawn = surfels_drawn(),
                                  .point_size = point_size(),
                                  .peripheral_objects = peripheral_objects(),
                                  .passes = last_pass_times(),
                                  .predicted_frame_ms = predicted_frame_ms()};
  return f;
}

RepresentationStats SurfelRepresentation::stats() const {
  const Impl& d = *impl_;
  RepresentationStats out;
  out.title =
      format("surfels track %u (%s)", d.track, d.backend == RenderBackend::kGl ? "gl" : "cpu");
  out.entries.push_back({"objects surfels / both / mesh",
                         format("%u / %u / %u", d.counts[0], d.counts[1], d.counts[2])});
  out.entries.push_back(
      {"surfels drawn", format("%llu", static_cast<unsigned long long>(d.surfels))});
  out.entries.push_back({"triangles drawn", format("%llu", static_cast<unsigned long long>(
                                                               d.mesh->triangles_drawn()))});
  out.entries.push_back(
      {"point size", format("%.2f px%s", d.point_size,
                            d.options.target_frame_ms > 0
                                ? format(" (target %.1f ms)", d.options.target_frame_ms).c_str()
                                : "")});
  if (d.options.foveation.enabled) {
    const SurfelFoveation& f = d.options.foveation;
    out.entries.push_back(
        {"foveation", format("x%.2g beyond %.2g, from %.2g; %u objects peripheral",
                             f.periphery_scale, f.outer, f.inner, d.peripheral)});
  }
  out.entries.push_back({"prepare", format("%.2f ms", d.prepare_ms)});
  out.entries.push_back({"draw", format("%.1f ms", d.render_ms)});
  return out;
}

}  // namespace calf::player
