#include "calf/player/playback.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "calf/decoder/cpu_textures.h"
#include "calf/format/lightfield_layout.h"
#include "calf/player/gl_renderer.h"
#include "calf/player/gl_views.h"

namespace calf::player {
namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The view volume from the clip's metadata ("x0 y0 z0 x1 y1 z1"), if present and well formed.
std::optional<Box3> parse_volume(const std::string* text) {
  if (text == nullptr) return std::nullopt;
  std::istringstream in(*text);
  double v[6];
  for (double& x : v) {
    if (!(in >> x) || !std::isfinite(x)) return std::nullopt;
  }
  if (v[0] > v[3] || v[1] > v[4] || v[2] > v[5]) return std::nullopt;
  return Box3{{v[0], v[1], v[2]}, {v[3], v[4], v[5]}};
}

}  // namespace

struct Playback::Impl {
  std::unique_ptr<container::Reader> reader;
  std::optional<decoder::ClipDecoder> decoder;
  PlaybackOptions options;
  std::optional<ViewSelector> selector;
  std::vector<Vec3> viewpoints;
  Box3 volume;
  bool has_material = false;

  // GL path.
  const GlFunctions* gl = nullptr;
  std::unique_ptr<GlViews> gl_views;
  std::unique_ptr<GlRenderer> gl_renderer;
  // CPU path.
  std::optional<decoder::CpuTextures> cpu_textures;
  ViewSet view_set;                   // the active views, in selection order
  std::vector<uint32_t> view_set_of;  // clip view -> index in view_set (or -1)

  decoder::FrameUpdates updates;
  ViewSelection selection;
  double render_ms = 0;

  Status load_view_set();
  RenderOptions frame_options(const Vec3& eye) const;
};

Playback::Playback(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Playback::~Playback() = default;

Expected<std::unique_ptr<Playback>> Playback::open(const std::string& clip_path,
                                                   const PlaybackOptions& options,
                                                   const GlFunctions* gl) {
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  CALF_ASSIGN_OR_RETURN(container::Reader reader, container::Reader::open(clip_path));
  impl->reader = std::make_unique<container::Reader>(std::move(reader));
  int64_t track = -1;
  for (size_t t = 0; t < impl->reader->tracks().size(); ++t) {
    if (std::holds_alternative<container::LightfieldTrackHeader>(impl->reader->tracks()[t].header)) {
      track = static_cast<int64_t>(t);
      break;
    }
  }
  if (track < 0) {
    return Status(ErrorId::kPlaybackClip, clip_path + ": no lightfield track to play");
  }
  CALF_ASSIGN_OR_RETURN(decoder::ClipDecoder d,
                        decoder::ClipDecoder::open(*impl->reader, static_cast<uint16_t>(track),
                                                   options.decoder));
  impl->decoder.emplace(std::move(d));
  const auto& h = impl->decoder->header();
  std::vector<decoder::LightfieldViewInfo> views;
  Box3 bounds{{INFINITY, INFINITY, INFINITY}, {-INFINITY, -INFINITY, -INFINITY}};
  for (uint32_t v = 0; v < h.view_count; ++v) {
    const auto& info = impl->decoder->view(v);
    views.push_back(info);
    const Vec3 p{info.position[0], info.position[1], info.position[2]};
    impl->viewpoints.push_back(p);
    bounds = box_union(bounds, p);
    impl->has_material = impl->has_material || info.has_material;
  }
  impl->volume = parse_volume(impl->reader->find_metadata("view_volume")).value_or(bounds);
  CALF_ASSIGN_OR_RETURN(ViewSelector sel, ViewSelector::make(impl->viewpoints, options.selection));
  impl->selector.emplace(std::move(sel));

  if (options.use_gl) {
    if (gl == nullptr) {
      return Status(ErrorId::kPlayerGl, "the GL renderer needs a current OpenGL 4.5 context");
    }
    impl->gl = gl;
    CALF_ASSIGN_OR_RETURN(GlTextureLayout layout,
                          layout_for_clip(h, views, options.keep_bc5_depth));
    CALF_ASSIGN_OR_RETURN(impl->gl_views, GlViews::make(*gl, std::move(layout)));
    // A view set with no active view is refused by the option check: validate with all views.
    RenderOptions probe = options.render;
    probe.active_views.clear();
    CALF_ASSIGN_OR_RETURN(impl->gl_renderer, GlRenderer::make(*impl->gl_views, probe));
  } else {
    impl->cpu_textures.emplace(h, views);
  }
  return std::unique_ptr<Playback>(new Playback(std::move(impl)));
}

uint32_t Playback::frame_count() const { return impl_->decoder->header().frame_count; }

double Playback::fps() const {
  const auto& h = impl_->decoder->header();
  return static_cast<double>(h.fps_numerator) / h.fps_denominator;
}

uint32_t Playback::frame_at_time(double seconds) const {
  if (!(seconds > 0)) return 0;  // negative or NaN
  const double f = std::floor(seconds * fps() + 1e-9);
  return static_cast<uint32_t>(std::min<double>(f, frame_count() - 1));
}

bool Playback::has_material() const { return impl_->has_material; }
const Box3& Playback::view_volume() const { return impl_->volume; }
const std::vector<Vec3>& Playback::viewpoints() const { return impl_->viewpoints; }

bool Playback::inside_view_volume(const Vec3& p) const {
  const auto& [lo, hi] = impl_->volume;
  constexpr double kSlack = 1e-9;
  return p.x >= lo.x - kSlack && p.y >= lo.y - kSlack && p.z >= lo.z - kSlack &&
         p.x <= hi.x + kSlack && p.y <= hi.y + kSlack && p.z <= hi.z + kSlack;
}

const PlaybackOptions& Playback::options() const { return impl_->options; }
ViewSelector& Playback::selector() { return *impl_->selector; }
const decoder::FrameStats& Playback::last_stats() const { return impl_->updates.stats; }
const ViewSelection& Playback::last_selection() const { return impl_->selection; }
double Playback::last_render_ms() const { return impl_->render_ms; }

Status Playback::set_render_options(const RenderOptions& options) {
  RenderOptions probe = options;
  probe.active_views.clear();
  if (impl_->gl_renderer) CALF_RETURN_IF_ERROR(impl_->gl_renderer->set_options(probe));
  impl_->options.render = options;
  return Status::Ok();
}

Status Playback::prepare(uint32_t frame, std::span<const EyeCamera> eyes) {
  Impl& d = *impl_;
  if (eyes.empty()) return Status(ErrorId::kPlayerOptions, "prepare() needs at least one eye");
  Vec3 mid, forward;
  for (const EyeCamera& e : eyes) {
    mid += e.position / static_cast<double>(eyes.size());
    forward += e.forward;
  }
  CALF_ASSIGN_OR_RETURN(d.selection, d.selector->select(mid, forward));
  // The viewers' frusta, out to the march range's far end: nothing farther is ever sampled.
  std::vector<EyeView> frusta;
  for (const EyeCamera& e : eyes) {
    const RenderOptions r = d.frame_options(e.position);
    frusta.push_back(eye_view(e, r.near, r.far));
  }
  // Reflection / refraction rays leave the eyes' frusta and read any texel of the active views:
  // with RR on, every cell is kept current (with culling, stale cells cost ~0.8 dB on mirror-box).
  d.decoder->set_view_dependent(d.options.decoder.view_dependent &&
                                !(d.options.render.rr && d.has_material));
  CALF_RETURN_IF_ERROR(d.decoder->advance(frame, frusta, d.selection.active, &d.updates));
  if (d.gl_views) return d.gl_views->apply(d.updates);
  CALF_RETURN_IF_ERROR(d.cpu_textures->apply(d.updates));
  return d.load_view_set();
}

// The CPU renderer reads linear float views: rebuilt from the texture state for the active views.
Status Playback::Impl::load_view_set() {
  view_set.views.clear();
  const uint32_t n = cpu_textures->face_size();
  for (uint32_t v : selection.active) {
    const auto& info = decoder->view(v);
    CALF_ASSIGN_OR_RETURN(LogDepthRange range, LogDepthRange::make(info.z_near, info.z_far));
    CALF_ASSIGN_OR_RETURN(View view, View::make(viewpoints[v], range, n, info.has_material));
    const PixelRect whole{0, 0, n, n};
    for (int f = 0; f < kCubeFaceCount; ++f) {
      const CubeFace face = static_cast<CubeFace>(f);
      CALF_RETURN_IF_ERROR(view.write_color_rect(face, whole, cpu_textures->colour(v, face)));
      CALF_RETURN_IF_ERROR(view.write_depth_rect(face, whole, cpu_textures->depth(v, face)));
      if (info.has_material) {
        const auto codes = cpu_textures->material(v, face);
        std::vector<float> m(codes.size());
        for (size_t i = 0; i < codes.size(); i += 3) {
          m[i] = lf::material_weight_from_code(codes[i]);
          m[i + 1] = lf::material_weight_from_code(codes[i + 1]);
          m[i + 2] = lf::material_ior_from_code(codes[i + 2]);
        }
        CALF_RETURN_IF_ERROR(view.write_material_rect(face, whole, m));
      }
    }
    view_set.views.push_back(std::move(view));
  }
  return Status::Ok();
}

RenderOptions Playback::Impl::frame_options(const Vec3& eye) const {
  if (options.fixed_march_range) return options.render;
  // march_range_for's rule over every view of the clip, so the range does not jump when the
  // active set changes.
  std::vector<MarchView> m;
  for (uint32_t v = 0; v < viewpoints.size(); ++v) {
    m.push_back({viewpoints[v], decoder->view(v).z_near, decoder->view(v).z_far});
  }
  return *march_range_for(m, eye, options.render);  // never empty: a clip has >= 1 view
}

Status Playback::render(const EyeCamera& camera, RenderedImage* out) {
  Impl& d = *impl_;
  const auto t0 = std::chrono::steady_clock::now();
  RenderOptions r = d.frame_options(camera.position);
  if (d.gl_renderer) {
    r.active_views = d.selection.active;
    CALF_RETURN_IF_ERROR(d.gl_renderer->set_options(r));
    CALF_RETURN_IF_ERROR(d.gl_renderer->render(camera, out));
  } else {
    r.active_views.clear();  // the view set holds exactly the active views
    CALF_ASSIGN_OR_RETURN(CpuRenderer cpu, CpuRenderer::make(d.view_set, r));
    CALF_RETURN_IF_ERROR(cpu.render(camera, out));
  }
  d.render_ms = ms_since(t0);
  return Status::Ok();
}

}  // namespace calf::player
