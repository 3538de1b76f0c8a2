// The light-field representation; what it does is in the public header.
#include "calf/player/lightfield_representation.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>

#include "calf/decoder/cpu_textures.h"
#include "calf/format/clip_metadata.h"
#include "calf/format/lightfield_layout.h"
#include "calf/player/gl_views.h"
#include "calf/player/lightfield_gl_renderer.h"

namespace calf::player {
namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

std::string format(const char* fmt, auto... args) {
  char buf[160];
  std::snprintf(buf, sizeof buf, fmt, args...);
  return buf;
}

}  // namespace

struct LightfieldRepresentation::Impl {
  const container::Reader* reader = nullptr;
  uint16_t track = 0;
  RenderBackend backend = RenderBackend::kGl;
  std::optional<decoder::LightfieldDecoder> decoder;
  LightfieldOptions options;
  std::optional<ViewSelector> selector;
  std::vector<Vec3> viewpoints;
  Box3 volume;
  bool has_material = false;
  bool coverage_decoded = false;  // the track has a coverage stream and it is decoded

  // GL path.
  std::unique_ptr<GlViews> gl_views;
  std::unique_ptr<LightfieldGlRenderer> lightfield_gl_renderer;
  // CPU path. The CPU renderer reads linear float views: one View per clip view, indexed like the
  // clip, so that a view which stays active is never rebuilt; after each frame only what the
  // updates changed is converted again from the texture state: the rects of depth and material
  // updates, and the colour cells whose slots an update wrote or whose interpolation parameters
  // changed. A view never active yet is a one-texel placeholder (the renderer reads only the
  // active views), built in full when it first becomes active.
  std::optional<decoder::CpuTextures> cpu_textures;
  ViewSet view_set;
  std::vector<uint8_t> view_built;  // per clip view: full size and current
  struct CellRef {
    uint32_t view, face, cell;
  };
  std::vector<CellRef> stale_cells;  // colour cells of built views to mix again, no duplicates
  std::vector<uint8_t> cell_stale;   // per (view, face, cell): listed in stale_cells
  std::vector<float> scratch;
  decoder::LightfieldFrameUpdates updates;
  ViewSelection selection;
  double render_ms = 0, upload_ms = 0;

  // Whether the decoder culls by the eyes' frusta for these options: not with RR on a clip with
  // material, whose reflection / refraction rays leave the frusta and read any texel of the
  // active views (with culling, stale cells cost ~0.8 dB on mirror-box).
  bool view_dependent_for(const LightfieldRenderOptions& r) const {
    return options.decoder.view_dependent && !(r.rr && has_material);
  }
  void mark_stale_cell(uint32_t view, CubeFace face, uint32_t cell);
  void collect_changed_cells();
  Status refresh_cpu_views();
  Status build_view(uint32_t v);
  Status convert_material(uint32_t v, CubeFace face, const PixelRect& rect);
  Status convert_coverage(uint32_t v, CubeFace face, const PixelRect& rect);
  LightfieldRenderOptions frame_options(const Vec3& eye) const;
};

LightfieldRepresentation::LightfieldRepresentation(std::unique_ptr<Impl> impl)
    : impl_(std::move(impl)) {}
LightfieldRepresentation::~LightfieldRepresentation() = default;

Expected<std::unique_ptr<LightfieldRepresentation>> LightfieldRepresentation::open(
    const container::Reader& reader, uint16_t track, const LightfieldOptions& options,
    RenderBackend backend, const GlFunctions* gl) {
  if (track >= reader.tracks().size() ||
      !std::holds_alternative<container::LightfieldTrackHeader>(reader.tracks()[track].header)) {
    return Status(ErrorId::kPlaybackClip,
                  "track " + std::to_string(track) + " is not a lightfield track");
  }
  auto impl = std::make_unique<Impl>();
  impl->reader = &reader;
  impl->track = track;
  impl->backend = backend;
  impl->options = options;
  // Both renderers read a clip's coverage (SPEC §11.1.11), the CPU reference into its views as it
  // reads a capture set's, the GL renderer into its coverage textures; it is decoded whatever
  // LightfieldRenderOptions::coverage says, so that coverage can be turned on while playing,
  // unless keep_coverage is off and the options read none of it.
  decoder::LightfieldDecoderOptions decoder_options = options.decoder;
  decoder_options.coverage = options.keep_coverage || options.render.coverage != 0 ||
                             options.render.surface_hint_coverage != 0;
  CALF_ASSIGN_OR_RETURN(decoder::LightfieldDecoder d,
                        decoder::LightfieldDecoder::open(reader, track, decoder_options));
  impl->decoder.emplace(std::move(d));
  impl->coverage_decoded = impl->decoder->has_coverage() && decoder_options.coverage;
  const auto& h = impl->decoder->header();
  std::vector<decoder::LightfieldViewInfo> views;
  Box3 bounds{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
  for (uint32_t v = 0; v < h.view_count; ++v) {
    const auto& info = impl->decoder->view(v);
    views.push_back(info);
    const Vec3 p = info.position;
    impl->viewpoints.push_back(p);
    if (!impl->decoder->view_problem(v).ok()) continue;  // dropped: its position is unknown
    bounds = box_union(bounds, p);
    impl->has_material = impl->has_material || info.has_material;
  }
  impl->volume = container::parse_view_volume(reader.find_metadata(container::kViewVolumeKey))
                     .value_or(bounds);
  CALF_ASSIGN_OR_RETURN(ViewSelector sel, ViewSelector::make(impl->viewpoints, options.selection));
  impl->selector.emplace(std::move(sel));
  for (uint32_t v = 0; v < h.view_count; ++v) {
    if (!impl->decoder->view_problem(v).ok()) CALF_RETURN_IF_ERROR(impl->selector->exclude(v));
  }
  impl->decoder->set_view_dependent(impl->view_dependent_for(options.render));

  if (backend == RenderBackend::kGl) {
    if (gl == nullptr) {
      return Status(ErrorId::kPlayerGl, "the GL renderer needs a current OpenGL 4.5 context");
    }
    CALF_ASSIGN_OR_RETURN(GlTextureLayout layout, layout_for_clip(h, views, options.keep_bc5_depth,
                                                                  impl->coverage_decoded));
    CALF_ASSIGN_OR_RETURN(impl->gl_views, GlViews::make(*gl, std::move(layout)));
    CALF_ASSIGN_OR_RETURN(impl->lightfield_gl_renderer,
                          LightfieldGlRenderer::make(*impl->gl_views, options.render));
  } else {
    impl->cpu_textures.emplace(h, views);
    const LogDepthRange placeholder_range = *LogDepthRange::make(1, 2);
    for (uint32_t v = 0; v < h.view_count; ++v) {
      CALF_ASSIGN_OR_RETURN(View placeholder,
                            View::make(impl->viewpoints[v], placeholder_range, 1, false));
      impl->view_set.views.push_back(std::move(placeholder));
    }
    impl->view_built.assign(h.view_count, 0);
    impl->cell_stale.assign(
        size_t{h.view_count} * kCubeFaceCount * impl->cpu_textures->cells().cell_count(), 0);
  }
  return std::unique_ptr<LightfieldRepresentation>(new LightfieldRepresentation(std::move(impl)));
}

std::string_view LightfieldRepresentation::kind() const {
  return "lightfield";
}
uint16_t LightfieldRepresentation::track() const {
  return impl_->track;
}
RenderBackend LightfieldRepresentation::backend() const {
  return impl_->backend;
}
uint32_t LightfieldRepresentation::frame_count() const {
  return impl_->decoder->header().frame_count;
}

double LightfieldRepresentation::fps() const {
  const auto& h = impl_->decoder->header();
  return static_cast<double>(h.fps_numerator) / h.fps_denominator;
}

const Box3& LightfieldRepresentation::view_volume() const {
  return impl_->volume;
}
bool LightfieldRepresentation::has_material() const {
  return impl_->has_material;
}
bool LightfieldRepresentation::has_coverage() const {
  return impl_->decoder->has_coverage();
}
const ViewSet* LightfieldRepresentation::cpu_views() const {
  return impl_->cpu_textures ? &impl_->view_set : nullptr;
}
const std::vector<Vec3>& LightfieldRepresentation::viewpoints() const {
  return impl_->viewpoints;
}
const LightfieldOptions& LightfieldRepresentation::options() const {
  return impl_->options;
}
ViewSelector& LightfieldRepresentation::selector() {
  return *impl_->selector;
}
std::vector<std::pair<uint32_t, Status>> LightfieldRepresentation::dropped_views() const {
  std::vector<std::pair<uint32_t, Status>> out;
  for (uint32_t v = 0; v < impl_->viewpoints.size(); ++v) {
    const Status& problem = impl_->decoder->view_problem(v);
    if (!problem.ok()) out.emplace_back(v, problem);
  }
  return out;
}

const decoder::FrameStats& LightfieldRepresentation::last_stats() const {
  return impl_->updates.stats;
}
const ViewSelection& LightfieldRepresentation::last_selection() const {
  return impl_->selection;
}
double LightfieldRepresentation::last_render_ms() const {
  return impl_->render_ms;
}
double LightfieldRepresentation::last_upload_ms() const {
  return impl_->upload_ms;
}

Status LightfieldRepresentation::report_frame_time(double frame_ms) {
  return impl_->selector->report_frame_time(frame_ms);
}

Status LightfieldRepresentation::set_render_options(const LightfieldRenderOptions& options) {
  if (impl_->lightfield_gl_renderer)
    CALF_RETURN_IF_ERROR(impl_->lightfield_gl_renderer->set_options(options));
  impl_->options.render = options;
  impl_->decoder->set_view_dependent(impl_->view_dependent_for(options));
  return Status::Ok();
}

Status LightfieldRepresentation::prepare(uint32_t frame, std::span<const Camera> eyes) {
  Impl& d = *impl_;
  if (eyes.empty()) return Status(ErrorId::kPlayerOptions, "prepare() needs at least one eye");
  Vec3 mid, forward;
  for (const Camera& e : eyes) {
    mid += e.position / static_cast<double>(eyes.size());
    forward += e.forward;
  }
  CALF_ASSIGN_OR_RETURN(d.selection, d.selector->select(mid, forward));
  // The viewers' frusta, out to the march range's far end: nothing farther is ever sampled.
  std::vector<EyeView> frusta;
  for (const Camera& e : eyes) {
    const LightfieldRenderOptions r = d.frame_options(e.position);
    frusta.push_back(eye_view(e, r.near, r.far));
  }
  CALF_RETURN_IF_ERROR(d.decoder->advance(frame, frusta, d.selection.active, &d.updates));
  const auto t0 = std::chrono::steady_clock::now();
  Status s = Status::Ok();
  if (d.gl_views) {
    s = d.gl_views->apply(d.updates);
  } else {
    d.collect_changed_cells();
    s = d.cpu_textures->apply(d.updates);
    if (s.ok()) {
      s = d.refresh_cpu_views();
    } else {
      // Part of the frame may be in the texture state: rebuild every view when next active.
      std::fill(d.view_built.begin(), d.view_built.end(), 0);
      d.stale_cells.clear();
      std::fill(d.cell_stale.begin(), d.cell_stale.end(), 0);
    }
  }
  d.upload_ms = ms_since(t0);
  return s;
}

void LightfieldRepresentation::Impl::mark_stale_cell(uint32_t view, CubeFace face, uint32_t cell) {
  const uint32_t f = static_cast<uint32_t>(cube_face_index(face));
  const size_t i = (size_t{view} * kCubeFaceCount + f) * cpu_textures->cells().cell_count() + cell;
  if (cell_stale[i]) return;
  cell_stale[i] = 1;
  stale_cells.push_back({view, f, cell});
}

// Before the updates are applied: the cells of built views whose interpolation parameters change
// (the decoder sends every visible cell every frame, most of them unchanged).
void LightfieldRepresentation::Impl::collect_changed_cells() {
  const uint32_t cell_count = cpu_textures->cells().cell_count();
  for (const decoder::CellParams& c : updates.cells) {
    if (c.view >= view_built.size() || !view_built[c.view] || c.cell >= cell_count) continue;
    const decoder::CellParams now = cpu_textures->cell(c.view, c.face, c.cell);
    if (now.t != c.t || now.a_slot != c.a_slot) mark_stale_cell(c.view, c.face, c.cell);
  }
}

// Material codes of `rect` of a face, as the renderer's floats, into the CPU view.
Status LightfieldRepresentation::Impl::convert_material(uint32_t v, CubeFace face,
                                                        const PixelRect& rect) {
  const uint32_t n = cpu_textures->face_size();
  const auto codes = cpu_textures->material(v, face);
  scratch.resize(size_t{rect.width} * rect.height * 3);
  for (uint32_t y = 0; y < rect.height; ++y) {
    const uint8_t* from = &codes[(size_t{rect.y + y} * n + rect.x) * 3];
    float* to = &scratch[size_t{y} * rect.width * 3];
    for (size_t i = 0; i < size_t{rect.width} * 3; i += 3) {
      to[i] = lf::material_weight_from_code(from[i]);
      to[i + 1] = lf::material_weight_from_code(from[i + 1]);
      to[i + 2] = lf::material_ior_from_code(from[i + 2]);
    }
  }
  return view_set.views[v].write_material_rect(face, rect, scratch);
}

// Coverage texels of `rect` of a face as the renderer's (near share, far share, mask) floats, the
// values a capture set's coverage channels hold, into the CPU view. Nothing before the view's
// first coverage update (its texels are plain, as the view's default).
Status LightfieldRepresentation::Impl::convert_coverage(uint32_t v, CubeFace face,
                                                        const PixelRect& rect) {
  const uint32_t n = cpu_textures->face_size();
  const auto texels = cpu_textures->coverage(v, face);
  if (texels.empty()) return Status::Ok();
  scratch.resize(size_t{rect.width} * rect.height * 3);
  for (uint32_t y = 0; y < rect.height; ++y) {
    for (uint32_t x = 0; x < rect.width; ++x) {
      const lf::CoverageTexel& t = texels[size_t{rect.y + y} * n + rect.x + x];
      float* to = &scratch[(size_t{y} * rect.width + x) * 3];
      to[0] = t.near / 16.0f;
      to[1] = t.far() / 16.0f;
      to[2] = static_cast<float>(t.mask);
    }
  }
  return view_set.views[v].write_coverage_rect(face, rect, scratch);
}

// A view that becomes active for the first time: full size, every face converted.
Status LightfieldRepresentation::Impl::build_view(uint32_t v) {
  const auto& info = decoder->view(v);
  CALF_ASSIGN_OR_RETURN(LogDepthRange range, LogDepthRange::make(info.z_near, info.z_far));
  const uint32_t n = cpu_textures->face_size();
  CALF_ASSIGN_OR_RETURN(View view, View::make(viewpoints[v], range, n, info.has_material));
  view_set.views[v] = std::move(view);
  const PixelRect whole{0, 0, n, n};
  for (int f = 0; f < kCubeFaceCount; ++f) {
    const CubeFace face = static_cast<CubeFace>(f);
    View& out = view_set.views[v];
    CALF_RETURN_IF_ERROR(out.write_colour_rect(face, whole, cpu_textures->colour(v, face)));
    CALF_RETURN_IF_ERROR(out.write_depth_rect(face, whole, cpu_textures->depth(v, face)));
    if (out.has_material()) CALF_RETURN_IF_ERROR(convert_material(v, face, whole));
    CALF_RETURN_IF_ERROR(convert_coverage(v, face, whole));
  }
  view_built[v] = 1;
  return Status::Ok();
}

// After the updates are applied: what they changed in built views is converted again from the
// texture state (which holds the frame's final texels, so overlapping updates need no order);
// views active for the first time are built in full.
Status LightfieldRepresentation::Impl::refresh_cpu_views() {
  const FaceGrid& grid = cpu_textures->cells();
  const uint32_t n = cpu_textures->face_size();
  for (const decoder::TextureUpdate& u : updates.updates) {
    if (!view_built[u.view]) continue;
    View& view = view_set.views[u.view];
    const PixelRect& r = u.rect;
    switch (u.target) {
      case decoder::UpdateTarget::kColour: {
        // Every cell the rect touches shows the slot it wrote.
        const uint32_t per_side = grid.cells_per_side();
        const uint32_t c0 = grid.cell_index_at_texel(r.x, r.y);
        const uint32_t c1 = grid.cell_index_at_texel(r.x + r.width - 1, r.y + r.height - 1);
        for (uint32_t cy = c0 / per_side; cy <= c1 / per_side; ++cy) {
          for (uint32_t cx = c0 % per_side; cx <= c1 % per_side; ++cx) {
            mark_stale_cell(u.view, u.face, grid.cell_index(cx, cy));
          }
        }
        break;
      }
      case decoder::UpdateTarget::kDepth:
        CALF_RETURN_IF_ERROR(view.write_depth_rect(
            u.face, r, cpu_textures->depth(u.view, u.face).subspan(size_t{r.y} * n + r.x), n));
        break;
      case decoder::UpdateTarget::kMaterial:
        if (view.has_material()) CALF_RETURN_IF_ERROR(convert_material(u.view, u.face, r));
        break;
      case decoder::UpdateTarget::kCoverage:
        CALF_RETURN_IF_ERROR(convert_coverage(u.view, u.face, r));
        break;
    }
  }
  const uint32_t per_side = grid.cells_per_side();
  for (const CellRef& c : stale_cells) {
    const CubeFace face = static_cast<CubeFace>(c.face);
    cpu_textures->colour_cell(c.view, face, c.cell, &scratch);
    CALF_RETURN_IF_ERROR(view_set.views[c.view].write_colour_rect(
        face, grid.cell_rect(c.cell % per_side, c.cell / per_side), scratch));
    cell_stale[(size_t{c.view} * kCubeFaceCount + c.face) * grid.cell_count() + c.cell] = 0;
  }
  stale_cells.clear();
  for (uint32_t v : selection.active) {
    if (!view_built[v]) CALF_RETURN_IF_ERROR(build_view(v));
  }
  return Status::Ok();
}

LightfieldRenderOptions LightfieldRepresentation::Impl::frame_options(const Vec3& eye) const {
  if (options.fixed_march_range) return options.render;
  // march_range_for's rule over every view of the clip, so the range does not jump when the
  // active set changes.
  std::vector<MarchView> m;
  for (uint32_t v = 0; v < viewpoints.size(); ++v) {
    if (!decoder->view_problem(v).ok()) continue;
    m.push_back({viewpoints[v], decoder->view(v).z_near, decoder->view(v).z_far});
  }
  return *march_range_for(m, eye, options.render);  // never empty: the decoder keeps >= 1 view
}

Status LightfieldRepresentation::render(const Camera& camera, RenderedImage* out) {
  Impl& d = *impl_;
  const auto t0 = std::chrono::steady_clock::now();
  const LightfieldRenderOptions r = d.frame_options(camera.position);
  const std::span<const uint32_t> active = d.selection.active;
  if (d.lightfield_gl_renderer) {
    CALF_RETURN_IF_ERROR(d.lightfield_gl_renderer->set_options(r));
    CALF_RETURN_IF_ERROR(d.lightfield_gl_renderer->render(camera, active, out));
  } else {
    // The view set is indexed like the clip; the active views in selection order, as the GL path.
    CALF_ASSIGN_OR_RETURN(LightfieldCpuRenderer cpu, LightfieldCpuRenderer::make(d.view_set, r));
    CALF_RETURN_IF_ERROR(cpu.render(camera, active, out));
  }
  d.render_ms = ms_since(t0);
  return Status::Ok();
}

RepresentationStats LightfieldRepresentation::stats() const {
  const Impl& d = *impl_;
  const decoder::FrameStats& st = d.updates.stats;
  const ViewSelection& sel = d.selection;
  const ViewSelectionOptions& so = d.selector->options();
  RepresentationStats out;
  out.title =
      format("lightfield track %u (%s)", d.track, d.backend == RenderBackend::kGl ? "gl" : "cpu");
  out.entries.push_back(
      {"active views", format("%zu (max %u, %s priority)", sel.active.size(), so.max_active,
                              so.priority == ViewPriority::kDistance ? "distance" : "angle")});
  out.entries.push_back({"culled views", format("angle %u, performance %u", sel.culled_by_angle,
                                                sel.culled_by_performance)});
  out.entries.push_back(
      {"cells visible", format("%u / %u, tiles %u / %u", st.visible_cells, st.total_cells,
                               st.visible_regions, st.total_regions)});
  out.entries.push_back({"updates", format("%.2f Mbps @24 fps", st.mbps_at_24fps())});
  out.entries.push_back({"decode", format("%.2f ms", st.decode_ms)});
  out.entries.push_back({"upload", format("%.2f ms", d.upload_ms)});
  out.entries.push_back({"render", format("%.1f ms", d.render_ms)});
  out.entries.push_back(
      {"RR", d.options.render.rr ? (d.has_material ? "on" : "on (no material)") : "off"});
  // The coverage rule in use (the window's C key turns it on and off).
  std::string coverage = "off";
  if (d.options.render.coverage != 0) coverage = format("mode %u", d.options.render.coverage);
  if (!d.decoder->has_coverage()) {
    coverage += " (none in the clip)";
  } else if (!d.coverage_decoded) {
    coverage += " (not decoded)";
  }
  out.entries.push_back({"coverage", coverage});
  // Sharpened colour taps (the window's K key turns them on and off).
  out.entries.push_back({"colour sharpen", d.options.render.colour_sharpen > 0
                                               ? format("k %.2f", d.options.render.colour_sharpen)
                                               : std::string("off")});
  if (st.errors) out.entries.push_back({"damaged chunks", st.first_error, true});
  return out;
}

}  // namespace calf::player
