// Playback (player/include/calf/player/playback.h) of a clip encoded from a small capture of the
// built-in interior scene: the GL renderer (OSMesa) and the CPU reference, fed by the same
// view-dependent decoder, agree on the same frames; time maps to frames as documented; the view
// volume comes from the clip's metadata.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <utility>

#include "../scratch_dir.h"
#include "calf/capture/capture_set.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/format/container.h"
#include "calf/format/container_io.h"
#include "calf/player/image_compare.h"
#include "calf/player/playback.h"

namespace calf::player {
namespace {

namespace fs = std::filesystem;

// A clip made once for the whole file: calf-capture's interior scene, 16-texel faces, 3 frames.
const std::string& clip_path() {
  static const std::string path = [] {
    const fs::path& dir = test::scratch_dir("calf_playback");
    const std::string capture = (dir / "cap").string(), clip = (dir / "clip.calf").string();
    std::string cmd = CALF_CAPTURE_EXE;
    cmd.append(" --scene interior --face-size 16 --frames 3 --quiet --out ").append(capture);
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    encoder::LightfieldEncodeOptions o;
    o.cell_size = 8;
    auto stats = encoder::encode_lightfield_file(capture, clip, o);
    EXPECT_TRUE(stats.ok()) << stats.status().to_string();
    return clip;
  }();
  return path;
}

// Each kind's options by their type: the defaults until set, then the value set, copied by value.
TEST(PlaybackOptions, KindOptionsByTypeAreValues) {
  PlaybackOptions o;
  const PlaybackOptions& unset = o;
  EXPECT_EQ(unset.of<LightfieldOptions>().render.steps, LightfieldOptions{}.render.steps);
  EXPECT_EQ(unset.of<SurfelOptions>().point_size, SurfelOptions{}.point_size);
  o.of<LightfieldOptions>().render.steps = 7;
  o.of<SurfelOptions>().point_size = 3;
  PlaybackOptions copy = o;
  o.of<LightfieldOptions>().render.steps = 9;
  const PlaybackOptions& set = copy;
  EXPECT_EQ(set.of<LightfieldOptions>().render.steps, 7);
  EXPECT_EQ(set.of<SurfelOptions>().point_size, 3.0);
  EXPECT_EQ(set.of<TilesOptions>().render.occlusion_alpha, TilesOptions{}.render.occlusion_alpha);
  EXPECT_EQ(std::as_const(o).of<LightfieldOptions>().render.steps, 9);
}

TEST(Playback, TimeMapsToFramesAndClamps) {
  PlaybackOptions o;
  o.use_gl = false;
  auto play = Playback::open(clip_path(), o, nullptr);
  ASSERT_TRUE(play.ok()) << play.status().to_string();
  const double fps = (*play)->fps();
  EXPECT_EQ((*play)->frame_count(), 3u);
  EXPECT_EQ((*play)->frame_at_time(-1), 0u);
  EXPECT_EQ((*play)->frame_at_time(std::nan("")), 0u);
  EXPECT_EQ((*play)->frame_at_time(0.999 / fps), 0u);
  EXPECT_EQ((*play)->frame_at_time(1.0 / fps), 1u);
  EXPECT_EQ((*play)->frame_at_time(2.5 / fps), 2u);
  EXPECT_EQ((*play)->frame_at_time(1e9), 2u);
}

TEST(Playback, ViewVolumeComesFromTheClip) {
  PlaybackOptions o;
  o.use_gl = false;
  auto play = Playback::open(clip_path(), o, nullptr);
  ASSERT_TRUE(play.ok());
  const auto& [lo, hi] = (*play)->view_volume();
  EXPECT_LT(lo.x, hi.x);
  for (const Vec3& p : (*play)->lightfield()->viewpoints()) {
    EXPECT_TRUE((*play)->inside_view_volume(p));
  }
  EXPECT_FALSE((*play)->inside_view_volume({hi.x + 1, hi.y, hi.z}));
}

TEST(Playback, GlAndCpuRenderTheSameFrames) {
  auto context = OsMesaContext::make();
  if (!context.ok()) GTEST_SKIP() << context.status().to_string();
  PlaybackOptions o;
  o.of<LightfieldOptions>().render.steps = 48;
  o.of<LightfieldOptions>().selection.budget.target_frame_ms = 0;
  auto gl = Playback::open(clip_path(), o, &(*context)->gl());
  ASSERT_TRUE(gl.ok()) << gl.status().to_string();
  o.use_gl = false;
  auto cpu = Playback::open(clip_path(), o, nullptr);
  ASSERT_TRUE(cpu.ok());
  const auto& [lo, hi] = (*gl)->view_volume();
  for (uint32_t frame = 0; frame < 3; ++frame) {
    Camera cam;
    cam.position = {lo.x + 0.3 * (hi.x - lo.x), lo.y + 0.5 * (hi.y - lo.y),
                    lo.z + 0.6 * (hi.z - lo.z)};
    cam.forward = {std::cos(frame * 2.0), -0.1, std::sin(frame * 2.0)};
    cam.width = 40;
    cam.height = 32;
    ASSERT_TRUE((*gl)->prepare(frame, std::span<const Camera>(&cam, 1)).ok());
    ASSERT_TRUE((*cpu)->prepare(frame, std::span<const Camera>(&cam, 1)).ok());
    EXPECT_EQ((*gl)->lightfield()->last_selection().active,
              (*cpu)->lightfield()->last_selection().active);
    EXPECT_GT((*gl)->lightfield()->last_stats().visible_cells, 0u);
    RenderedImage a, b;
    ASSERT_TRUE((*gl)->render(cam, &a).ok());
    ASSERT_TRUE((*cpu)->render(cam, &b).ok());
    auto p = psnr(rgb_ref(a), rgb_ref(b));
    ASSERT_TRUE(p.ok());
    EXPECT_GE(*p, 45.0) << "frame " << frame;
    std::printf("frame %u: GL vs CPU PSNR %.2f dB\n", frame, *p);
  }
}

// The representation interface on its own: the light field's GL and CPU backends, opened on the
// same track and driven only through Representation, agree; the figures are there for a HUD.
TEST(LightfieldRepresentation, GlAndCpuBackendsAgreeThroughTheInterface) {
  auto context = OsMesaContext::make();
  if (!context.ok()) GTEST_SKIP() << context.status().to_string();
  auto reader = container::Reader::open(clip_path());
  ASSERT_TRUE(reader.ok()) << reader.status().to_string();
  LightfieldOptions o;
  o.render.steps = 48;
  o.selection.budget.target_frame_ms = 0;
  auto gl_lf = LightfieldRepresentation::open(*reader, 0, o, RenderBackend::kGl, &(*context)->gl());
  ASSERT_TRUE(gl_lf.ok()) << gl_lf.status().to_string();
  auto cpu_lf = LightfieldRepresentation::open(*reader, 0, o, RenderBackend::kCpu, nullptr);
  ASSERT_TRUE(cpu_lf.ok()) << cpu_lf.status().to_string();
  Representation& gl = **gl_lf;
  Representation& cpu = **cpu_lf;
  EXPECT_EQ(gl.kind(), "lightfield");
  EXPECT_EQ(cpu.backend(), RenderBackend::kCpu);
  EXPECT_EQ(gl.frame_count(), 3u);
  const auto& [lo, hi] = gl.view_volume();
  for (uint32_t frame = 0; frame < 3; ++frame) {
    Camera cam;
    cam.position = {lo.x + 0.7 * (hi.x - lo.x), lo.y + 0.4 * (hi.y - lo.y),
                    lo.z + 0.2 * (hi.z - lo.z)};
    cam.forward = {std::sin(frame * 1.5), 0.05, -std::cos(frame * 1.5)};
    cam.width = 36;
    cam.height = 30;
    ASSERT_TRUE(gl.prepare(frame, std::span<const Camera>(&cam, 1)).ok());
    ASSERT_TRUE(cpu.prepare(frame, std::span<const Camera>(&cam, 1)).ok());
    RenderedImage a, b;
    ASSERT_TRUE(gl.render(cam, &a).ok());
    ASSERT_TRUE(cpu.render(cam, &b).ok());
    ASSERT_EQ(a.depth.size(), size_t{36} * 30);
    ASSERT_EQ(b.depth.size(), a.depth.size());
    auto p = psnr(rgb_ref(a), rgb_ref(b));
    ASSERT_TRUE(p.ok());
    EXPECT_GE(*p, 45.0) << "frame " << frame;
    // Radial depth, the compositing key: the backends agree where both see a surface.
    size_t both = 0, close = 0;
    for (size_t i = 0; i < a.depth.size(); ++i) {
      if (!std::isfinite(a.depth[i]) || !std::isfinite(b.depth[i])) continue;
      ++both;
      if (std::abs(a.depth[i] - b.depth[i]) <= 0.01f * b.depth[i]) ++close;
    }
    EXPECT_GT(both, a.depth.size() / 2);
    EXPECT_GE(close, both * 95 / 100) << "frame " << frame;
    std::printf("frame %u: representation GL vs CPU PSNR %.2f dB, depth within 1 %%: %zu / %zu\n",
                frame, *p, close, both);
  }
  const RepresentationStats st = gl.stats();
  EXPECT_EQ(st.title, "lightfield track 0 (gl)");
  ASSERT_FALSE(st.entries.empty());
  EXPECT_EQ(st.entries[0].name, "active views");
  EXPECT_TRUE(gl.report_frame_time(12.5).ok());
  EXPECT_EQ(gl.report_frame_time(-1).id(), ErrorId::kViewSelectFrameTime);
}

// With one playable track, Playback's composite is that track's render, bit for bit.
TEST(Playback, OneTrackRendersExactlyItsRepresentation) {
  PlaybackOptions o;
  o.use_gl = false;
  auto play = Playback::open(clip_path(), o, nullptr);
  ASSERT_TRUE(play.ok()) << play.status().to_string();
  ASSERT_EQ((*play)->representations().size(), 1u);
  ASSERT_NE((*play)->lightfield(), nullptr);
  auto reader = container::Reader::open(clip_path());
  ASSERT_TRUE(reader.ok());
  auto lf = LightfieldRepresentation::open(*reader, 0, o.of<LightfieldOptions>(),
                                           RenderBackend::kCpu, nullptr);
  ASSERT_TRUE(lf.ok());
  const auto& [lo, hi] = (*play)->view_volume();
  Camera cam;
  cam.position = {0.5 * (lo.x + hi.x), 0.5 * (lo.y + hi.y), 0.5 * (lo.z + hi.z)};
  cam.width = 24;
  cam.height = 20;
  for (uint32_t frame = 0; frame < 3; ++frame) {
    ASSERT_TRUE((*play)->prepare(frame, std::span<const Camera>(&cam, 1)).ok());
    ASSERT_TRUE((*lf)->prepare(frame, std::span<const Camera>(&cam, 1)).ok());
    RenderedImage a, b;
    ASSERT_TRUE((*play)->render(cam, &a).ok());
    ASSERT_TRUE((*lf)->render(cam, &b).ok());
    EXPECT_EQ(a.color, b.color) << "frame " << frame;
    ASSERT_EQ(a.depth.size(), b.depth.size());
    for (size_t i = 0; i < a.depth.size(); ++i) {
      ASSERT_TRUE(a.depth[i] == b.depth[i] || (std::isinf(a.depth[i]) && std::isinf(b.depth[i])));
    }
  }
  const auto stats = (*play)->stats();
  ASSERT_EQ(stats.size(), 1u);
  EXPECT_EQ(stats[0].title, "lightfield track 0 (cpu)");
  // A light field draws no triangles, quads or points.
  const FrameFigures fig = (*play)->figures();
  EXPECT_EQ(fig.triangles_drawn, 0u);
  EXPECT_FALSE(fig.quads.has_value());
  EXPECT_FALSE(fig.points.has_value());
}

TEST(Playback, FileWithoutLightfieldIsRefused) {
  PlaybackOptions o;
  o.use_gl = false;
  const char* source = std::getenv("CALF_SOURCE_DIR");
  std::string empty = source ? source : ".";
  empty.append("/tests/conformance/container/valid/empty.calf");
  auto play = Playback::open(empty, o, nullptr);
  EXPECT_EQ(play.status().id(), ErrorId::kPlaybackClip);
}

// A clip whose view 0 index chunk is damaged plays with the other views: the representation
// reports the dropped view with its reason and never selects it.
TEST(LightfieldRepresentation, DamagedViewIndexPlaysTheOtherViews) {
  auto whole = container::Reader::open(clip_path());
  ASSERT_TRUE(whole.ok()) << whole.status().to_string();
  ASSERT_GE(std::get<container::LightfieldTrackHeader>(whole->tracks()[0].header).view_count, 2u);
  std::vector<uint8_t> bytes;
  {
    std::FILE* f = std::fopen(clip_path().c_str(), "rb");
    ASSERT_NE(f, nullptr);
    uint8_t buf[65536];
    size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) bytes.insert(bytes.end(), buf, buf + n);
    std::fclose(f);
  }
  for (const auto& c : whole->chunks()) {
    if (c.keys.stream == static_cast<uint16_t>(container::LightfieldStream::kIndex) &&
        c.keys.view == 0) {
      bytes[c.offset + 1] ^= 0x40;
    }
  }
  auto reader = container::Reader::open(container::memory_source(bytes));
  ASSERT_TRUE(reader.ok()) << reader.status().to_string();
  LightfieldOptions o;
  o.selection.budget.target_frame_ms = 0;
  auto lf = LightfieldRepresentation::open(*reader, 0, o, RenderBackend::kCpu, nullptr);
  ASSERT_TRUE(lf.ok()) << lf.status().to_string();
  const auto dropped = (*lf)->dropped_views();
  ASSERT_EQ(dropped.size(), 1u);
  EXPECT_EQ(dropped[0].first, 0u);
  EXPECT_EQ(dropped[0].second.id(), ErrorId::kContainerChunkHash);
  Camera cam;
  // At the dropped view's placeholder position (the origin): were it selectable it would rank
  // first.
  cam.position = (*lf)->viewpoints()[0];
  cam.width = 24;
  cam.height = 16;
  for (uint32_t frame = 0; frame < 2; ++frame) {
    ASSERT_TRUE((*lf)->prepare(frame, std::span<const Camera>(&cam, 1)).ok());
    const auto& active = (*lf)->last_selection().active;
    EXPECT_FALSE(active.empty());
    EXPECT_EQ(std::count(active.begin(), active.end(), 0u), 0);
    RenderedImage image;
    ASSERT_TRUE((*lf)->render(cam, &image).ok());
  }
}

}  // namespace
}  // namespace calf::player
