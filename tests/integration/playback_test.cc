// Playback (player/include/calf/player/playback.h) of a clip encoded from a small capture of the
// built-in interior scene: the GL renderer (OSMesa) and the CPU reference, fed by the same
// view-dependent decoder, agree on the same frames; time maps to frames as documented; the view
// volume comes from the clip's metadata.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "calf/capture/capture_set.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/player/image_compare.h"
#include "calf/player/playback.h"

namespace calf::player {
namespace {

namespace fs = std::filesystem;

// A clip made once for the whole file: calf-capture's interior scene, 16-texel faces, 3 frames.
const std::string& clip_path() {
  static const std::string path = [] {
    std::string name = "calf_playback_";  // append: GCC 12 -O3 misfires -Wrestrict on operator+
    name.append(std::to_string(::getpid()));
    const fs::path dir = fs::temp_directory_path() / name;
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string capture = (dir / "cap").string(), clip = (dir / "clip.calf").string();
    std::string cmd = CALF_CAPTURE_EXE;
    cmd.append(" --scene interior --face-size 16 --frames 3 --quiet --out ").append(capture);
    EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
    LightfieldEncodeOptions o;
    o.cell_size = 8;
    auto stats = encode_lightfield_file(capture, clip, o);
    EXPECT_TRUE(stats.ok()) << stats.status().to_string();
    return clip;
  }();
  return path;
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
  for (const Vec3& p : (*play)->lightfield()->viewpoints()) EXPECT_TRUE((*play)->inside_view_volume(p));
  EXPECT_FALSE((*play)->inside_view_volume({hi.x + 1, hi.y, hi.z}));
}

TEST(Playback, GlAndCpuRenderTheSameFrames) {
  auto context = OsMesaContext::make();
  if (!context.ok()) GTEST_SKIP() << context.status().to_string();
  PlaybackOptions o;
  o.lightfield.render.steps = 48;
  o.lightfield.selection.target_frame_ms = 0;
  auto gl = Playback::open(clip_path(), o, &(*context)->gl());
  ASSERT_TRUE(gl.ok()) << gl.status().to_string();
  o.use_gl = false;
  auto cpu = Playback::open(clip_path(), o, nullptr);
  ASSERT_TRUE(cpu.ok());
  const auto& [lo, hi] = (*gl)->view_volume();
  for (uint32_t frame = 0; frame < 3; ++frame) {
    Camera cam;
    cam.position = {lo.x + 0.3 * (hi.x - lo.x), lo.y + 0.5 * (hi.y - lo.y), lo.z + 0.6 * (hi.z - lo.z)};
    cam.forward = {std::cos(frame * 2.0), -0.1, std::sin(frame * 2.0)};
    cam.width = 40;
    cam.height = 32;
    ASSERT_TRUE((*gl)->prepare(frame, std::span<const Camera>(&cam, 1)).ok());
    ASSERT_TRUE((*cpu)->prepare(frame, std::span<const Camera>(&cam, 1)).ok());
    EXPECT_EQ((*gl)->lightfield()->last_selection().active, (*cpu)->lightfield()->last_selection().active);
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

TEST(Playback, FileWithoutLightfieldIsRefused) {
  PlaybackOptions o;
  o.use_gl = false;
  const char* source = std::getenv("CALF_SOURCE_DIR");
  std::string empty = source ? source : ".";
  empty.append("/tests/conformance/container/valid/empty.calf");
  auto play = Playback::open(empty, o, nullptr);
  EXPECT_EQ(play.status().id(), ErrorId::kPlaybackClip);
}

}  // namespace
}  // namespace calf::player
