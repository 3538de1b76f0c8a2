// The whole playback path on a real clip: an animated synthetic room (a sphere moving over a
// mirror floor) captured from three viewpoints, encoded by calf's encoder (BC7 / BC1 colour
// keyframes with per-cell t, raw16 or BC5 depth, material), decoded view-dependently by the
// LightfieldDecoder for the eye's frustum, its updates applied to the GL textures (GlViews) and to
// the decoder's CPU image of them (CpuTextures). Each frame the GL renderer's image must match the
// CPU renderer's on the CPU image (>= 45 dB, same depths); both are also compared with the exact
// ground truth, as a sanity bound.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "../gl_test_context.h"
#include "../player/synthetic_scene.h"
#include "calf/capture/capture_set.h"
#include "calf/decoder/cpu_textures.h"
#include "calf/decoder/lightfield_decoder.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/format/container.h"
#include "calf/format/container_io.h"
#include "calf/player/gl_context.h"
#include "calf/player/gl_views.h"
#include "calf/player/lightfield_cpu_renderer.h"
#include "calf/player/lightfield_gl_renderer.h"

namespace calf::player {
namespace {

namespace fs = std::filesystem;

using ::calf::test::gl_context;

constexpr uint32_t kFace = 24, kFrames = 4;
const Vec3 kViews[] = {{-0.5, 0.1, 0.3}, {0.5, -0.1, 0.3}, {0.0, 0.4, -0.4}};

testing::Scene scene_at(uint32_t frame) {
  testing::Scene s;
  s.room_half = 3;
  s.mirror_floor = true;
  s.spheres = {{{-0.6 + 0.3 * frame, -0.4, -1.6}, 0.6}, {{1.2, 0.5, -1.0}, 0.4}};
  return s;
}

capture::ViewFrame capture_frame(const testing::Scene& s, const Vec3& position) {
  capture::ViewFrame vf;
  vf.resize(kFace, true);
  for (int f = 0; f < 6; ++f) {
    for (uint32_t y = 0; y < kFace; ++y) {
      for (uint32_t x = 0; x < kFace; ++x) {
        const CubeFace face = cube_face_from_index(f);
        const Vec3 d = direction_from_texel(face, x, y, kFace);
        double rgb[3], z;
        Material m;
        testing::shade(s, position, {d.x, d.y, d.z}, rgb, &z, &m);
        const size_t i = vf.texel_index(face, x, y);
        for (int ch = 0; ch < 3; ++ch) vf.color[3 * i + ch] = static_cast<float>(rgb[ch]);
        vf.depth[i] = static_cast<float>(z);
        vf.material[3 * i] = m.reflect;
        vf.material[3 * i + 1] = m.refract;
        vf.material[3 * i + 2] = m.ior;
      }
    }
  }
  return vf;
}

struct Clip {
  std::vector<uint8_t> bytes;
  std::unique_ptr<container::Reader> reader;
};

Clip encode_clip(const encoder::LightfieldEncodeOptions& options) {
  std::string name = "calf_gl_clip_";
  name.append(std::to_string(::getpid()));
  const fs::path dir = fs::temp_directory_path() / name;
  fs::remove_all(dir);
  capture::CaptureManifest m;
  m.frame_count = kFrames;
  m.face_size = kFace;
  m.fps = 24;
  m.material = true;
  m.view_volume = {{-1, -1, -1}, {1, 1, 1}};
  for (size_t v = 0; v < std::size(kViews); ++v) {
    std::string view_name = "v";  // append, not operator+: GCC 12 -O3 misreports -Wrestrict
    view_name.append(std::to_string(v));
    m.viewpoints.push_back({view_name, {kViews[v].x, kViews[v].y, kViews[v].z}});
  }
  Clip clip;
  {
    auto w = capture::CaptureSetWriter::create(dir, m);
    EXPECT_TRUE(w.ok()) << w.status().to_string();
    for (uint32_t f = 0; f < kFrames; ++f) {
      const testing::Scene s = scene_at(f);
      for (uint32_t v = 0; v < std::size(kViews); ++v) {
        EXPECT_TRUE(w->write(v, f, capture_frame(s, kViews[v])).ok());
      }
    }
    EXPECT_TRUE(w->finish().ok());
    auto in = capture::CaptureSetReader::open(dir);
    EXPECT_TRUE(in.ok()) << in.status().to_string();
    auto writer = container::Writer::create(container::memory_sink(&clip.bytes));
    EXPECT_TRUE(writer.ok());
    auto stats = encoder::encode_lightfield(*in, *writer, options);
    EXPECT_TRUE(stats.ok()) << stats.status().to_string();
    EXPECT_TRUE(writer->finish().ok());
  }
  fs::remove_all(dir);
  auto r = container::Reader::open(container::memory_source(clip.bytes));
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  clip.reader = std::make_unique<container::Reader>(std::move(*r));
  return clip;
}

// The CPU renderer's views: the decoder's CPU image of the textures.
ViewSet view_set_from(const decoder::LightfieldDecoder& d, const decoder::CpuTextures& tex) {
  ViewSet set;
  for (uint32_t v = 0; v < d.header().view_count; ++v) {
    const decoder::LightfieldViewInfo& info = d.view(v);
    const bool material = info.has_material && d.header().material_format != 0;
    View view = *View::make(info.position, *LogDepthRange::make(info.z_near, info.z_far),
                            tex.face_size(), material);
    const uint32_t n = tex.face_size();
    for (int f = 0; f < kCubeFaceCount; ++f) {
      const CubeFace face = cube_face_from_index(f);
      EXPECT_TRUE(view.write_colour_rect(face, {0, 0, n, n}, tex.colour(v, face)).ok());
      EXPECT_TRUE(view.write_depth_rect(face, {0, 0, n, n}, tex.depth(v, face)).ok());
      if (material) {
        const std::span<const uint8_t> codes = tex.material(v, face);
        std::vector<float> m;
        for (size_t i = 0; i < codes.size(); i += 3) {
          m.insert(m.end(),
                   {codes[i] / 255.0f, codes[i + 1] / 255.0f, 1 + 2 * (codes[i + 2] / 255.0f)});
        }
        EXPECT_TRUE(view.write_material_rect(face, {0, 0, n, n}, m).ok());
      }
    }
    set.views.push_back(std::move(view));
  }
  return set;
}

double psnr(const std::vector<float>& ref, const std::vector<float>& test) {
  double se = 0;
  for (size_t i = 0; i < ref.size(); ++i)
    se += (double{ref[i]} - test[i]) * (double{ref[i]} - test[i]);
  const double mse = se / static_cast<double>(ref.size());
  return mse == 0 ? 200.0 : 10 * std::log10(1.0 / mse);
}

// `min_db`: besides the 45 dB acceptance bound, what float rounding alone gives (llvmpipe
// decodes BC7 exactly, BC1 with its own rounding of the interpolants).
void play(const char* name, const encoder::LightfieldEncodeOptions& options, bool keep_bc5,
          double min_db) {
  const Clip clip = encode_clip(options);
  ASSERT_TRUE(clip.reader);
  auto d = decoder::LightfieldDecoder::open(*clip.reader, 0);
  ASSERT_TRUE(d.ok()) << d.status().to_string();
  std::vector<decoder::LightfieldViewInfo> infos;
  for (uint32_t v = 0; v < d->header().view_count; ++v) infos.push_back(d->view(v));
  decoder::CpuTextures tex(d->header(), infos);
  Expected<GlTextureLayout> layout = layout_for_clip(d->header(), infos, keep_bc5);
  ASSERT_TRUE(layout.ok()) << layout.status().to_string();
  Expected<std::unique_ptr<GlViews>> gv = GlViews::make(gl_context()->gl(), *layout);
  ASSERT_TRUE(gv.ok()) << gv.status().to_string();

  Camera cam;
  cam.position = {0.05, 0.05, 0.2};
  cam.forward = {0.05, -0.45, -1};
  cam.width = cam.height = 64;
  cam.fov_y = 1.2;
  EyeView eye;
  eye.position = cam.position;
  eye.forward = cam.forward;
  eye.up = cam.up;
  eye.fov_y = cam.fov_y;
  eye.aspect = 1;
  eye.near = 0.01;
  eye.far = 20;
  LightfieldRenderOptions o;
  o.rr = true;
  o.threads = 2;
  for (uint32_t frame = 0; frame < kFrames; ++frame) {
    decoder::LightfieldFrameUpdates fu;
    const Status advanced = d->advance(frame, {&eye, 1}, {}, &fu);
    ASSERT_TRUE(advanced.ok()) << advanced.to_string();
    ASSERT_EQ(fu.stats.errors, 0u) << fu.stats.first_error;
    ASSERT_TRUE(tex.apply(fu).ok());
    const Status applied = (*gv)->apply(fu);
    ASSERT_TRUE(applied.ok()) << applied.to_string();
    EXPECT_GT(fu.cells.size(), 0u);
    EXPECT_LT(fu.stats.visible_cells, fu.stats.total_cells);  // the decoder culled something

    const ViewSet views = view_set_from(*d, tex);
    const LightfieldRenderOptions ro = *march_range_for(views, cam.position, o);
    RenderedImage want, got;
    ASSERT_TRUE(LightfieldCpuRenderer::make(views, ro)->render(cam, &want).ok());
    std::unique_ptr<LightfieldGlRenderer> r = *LightfieldGlRenderer::make(**gv, ro);
    ASSERT_TRUE(r->render(cam, &got).ok());
    const RenderedImage truth = testing::ground_truth(scene_at(frame), cam);
    size_t same_depth = 0;
    for (size_t k = 0; k < want.depth.size(); ++k) {
      same_depth += std::isinf(want.depth[k]) ? std::isinf(got.depth[k])
                                              : std::fabs(got.depth[k] / want.depth[k] - 1) < 1e-3;
    }
    const double gl_cpu = psnr(want.color, got.color);
    std::printf(
        "%s frame %u: %zu updates, %u of %u cells; GL vs CPU %.2f dB (depth agrees %.1f %%), "
        "GL vs truth %.2f dB, CPU vs truth %.2f dB\n",
        name, frame, fu.updates.size(), fu.stats.visible_cells, fu.stats.total_cells, gl_cpu,
        100.0 * same_depth / want.depth.size(), psnr(truth.color, got.color),
        psnr(truth.color, want.color));
    if (keep_bc5) continue;  // GPU-decoded BC5 depth: reported only (see gl_updates_test)
    EXPECT_GE(gl_cpu, 45.0) << name << " frame " << frame;
    EXPECT_GE(gl_cpu, min_db) << name << " frame " << frame;
    EXPECT_GE(same_depth, want.depth.size() * 99 / 100);
    EXPECT_GE(psnr(truth.color, got.color), 18.0);  // a sanity bound, not a quality goal
  }
}

TEST(GlClip, DecodedBc7ClipWithRawDepthMatchesTheCpuRenderer) {
  CALF_REQUIRE_GL();
  encoder::LightfieldEncodeOptions o;
  o.cell_size = 8;
  o.min_psnr_db = 40;
  o.colour = encoder::ColourCoding::kBc7;
  o.depth = encoder::DepthCoding::kRaw16;
  play("BC7 + raw16", o, false, 70);
}

TEST(GlClip, DecodedBc1ClipWithBc5DepthMatchesTheCpuRenderer) {
  CALF_REQUIRE_GL();
  encoder::LightfieldEncodeOptions o;
  o.cell_size = 8;
  o.min_psnr_db = 40;
  o.colour = encoder::ColourCoding::kBc1;
  o.depth = encoder::DepthCoding::kBc5;
  play("BC1 + BC5 (CPU-decoded)", o, false, 55);
  play("BC1 + BC5 (GPU-decoded)", o, true, 0);
}

}  // namespace
}  // namespace calf::player
