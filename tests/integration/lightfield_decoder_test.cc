// Property tests of the view-dependent decoder (decoder/include/calf/decoder/lightfield_decoder.h)
// on random clips encoded by the real encoder: the state its updates build (applied by CpuTextures)
// must equal the reference full-frame decoder (lightfield_reference.h) on every visible cell and
// tile, whatever path led to the frame — playing 0..N, seeking straight to N, wandering there
// through random frames, one viewer or several, hierarchical or brute-force culling, with or
// without the background thread.
#include <gtest/gtest.h>

#include <unistd.h>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/decoder/cpu_textures.h"
#include "calf/decoder/lightfield_decoder.h"
#include "calf/decoder/lightfield_reference.h"
#include "calf/decoder/lightfield_verify.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/format/container.h"
#include "calf/format/container_io.h"
#include "calf/format/log_depth.h"
#include "synthetic_capture.h"

namespace calf::decoder {
namespace {

namespace fs = std::filesystem;

struct ClipSpec {
  uint32_t face = 16, frames = 12, views = 2, seed = 1;
  bool material = false, hdr = false;
  // A second, 2 x 2 square on face 0 moving down its right edge: with one rectangle per P-frame
  // the rectangle spans both squares and the static texels between them.
  bool second_square = false;
  encoder::LightfieldEncodeOptions options;
};

// Smooth colour with per-seed moving squares (colour and depth), a fading face, sky patches and,
// optionally, material on one face: enough motion for several keyframes per cell and non-empty
// depth P-frames, with static regions in between.
capture::ViewFrame make_frame(const ClipSpec& s, uint32_t view, uint32_t frame) {
  std::mt19937 rng(s.seed * 7919 + view);
  std::uniform_int_distribution<int> pos(0, static_cast<int>(s.face) - 1);
  const int sx = pos(rng), sy = pos(rng), dx = 1 + static_cast<int>(rng() % 3);
  const int size = 3 + static_cast<int>(rng() % 5);
  capture::ViewFrame vf;
  vf.resize(s.face, s.material);
  const float inf = std::numeric_limits<float>::infinity();
  for (uint32_t face = 0; face < 6; ++face) {
    for (uint32_t y = 0; y < s.face; ++y) {
      for (uint32_t x = 0; x < s.face; ++x) {
        const size_t i = vf.texel_index(static_cast<CubeFace>(face), x, y);
        float r = 0.2f + 0.5f * x / s.face, g = 0.3f + 0.4f * y / s.face;
        float b = 0.1f * face + 0.05f * view;
        float z = 2.0f + 0.1f * face + 0.05f * x + 0.03f * y + 0.5f * view;
        const int mx = (sx + dx * static_cast<int>(frame)) % static_cast<int>(s.face);
        if ((face == s.seed % 6 || face == 0) && static_cast<int>(x) >= mx &&
            static_cast<int>(x) < mx + size && static_cast<int>(y) >= sy &&
            static_cast<int>(y) < sy + size) {
          r = 0.9f;
          g = 0.1f + 0.05f * (frame % 3);
          z = 1.0f + 0.02f * frame;
        }
        if (s.second_square && face == 0 && x + 3 >= s.face && x + 1 < s.face &&
            (y + s.face - (2 * frame) % s.face) % s.face < 2) {
          z = 1.5f;
        }
        if (face == 2) {
          r *= 1.0f - 0.04f * static_cast<float>(frame);
          g *= 1.0f - 0.03f * static_cast<float>(frame);
        }
        if (face == 3 && y < s.face / 2) z = inf;
        if (s.hdr && face == 4) r *= 30.0f;
        vf.color[3 * i] = r;
        vf.color[3 * i + 1] = g;
        vf.color[3 * i + 2] = b;
        vf.depth[i] = z;
        if (s.material) {
          const bool mirror = face == 1 && x < s.face / 2 + (frame % 4);
          vf.material[3 * i] = mirror ? 0.8f : 0.0f;
          vf.material[3 * i + 1] = 0.0f;
          vf.material[3 * i + 2] = mirror ? 1.5f : 1.0f;
        }
      }
    }
  }
  return vf;
}

// An encoded clip held in memory, with its reader.
struct Clip {
  std::vector<uint8_t> bytes;
  std::unique_ptr<container::Reader> reader;
};

Clip make_clip(const ClipSpec& s) {
  // Appends, not operator+ chains: GCC 12 -O3 reports a false -Wrestrict on those.
  std::string name = "calf_clipdec_";
  name.append(std::to_string(::getpid())).append("_").append(std::to_string(s.seed));
  const fs::path dir = fs::temp_directory_path() / name;
  fs::remove_all(dir);
  testing_support::SceneSpec scene;
  scene.face = s.face;
  scene.frames = s.frames;
  scene.views = s.views;
  scene.material = s.material;
  scene.first_viewpoint = {-0.25, 0, 0};
  scene.viewpoint_step = {0.5, 0.1, 0};
  Clip clip;
  {
    const Status written = testing_support::write_capture(
        dir, scene, [&](uint32_t v, uint32_t f) { return make_frame(s, v, f); });
    EXPECT_TRUE(written.ok()) << written.to_string();
    auto in = capture::CaptureSetReader::open(dir);
    EXPECT_TRUE(in.ok()) << in.status().to_string();
    auto writer = container::Writer::create(container::memory_sink(&clip.bytes));
    EXPECT_TRUE(writer.ok());
    auto stats = encoder::encode_lightfield(*in, *writer, s.options);
    EXPECT_TRUE(stats.ok()) << stats.status().to_string();
    EXPECT_TRUE(writer->finish().ok());
  }
  fs::remove_all(dir);
  auto r = container::Reader::open(container::memory_source(clip.bytes));
  EXPECT_TRUE(r.ok()) << r.status().to_string();
  clip.reader = std::make_unique<container::Reader>(std::move(*r));
  return clip;
}

ClipSpec random_spec(uint32_t seed) {
  std::mt19937 rng(seed);
  ClipSpec s;
  s.seed = seed;
  s.views = 1 + rng() % 3;
  s.material = rng() % 2 == 0;
  s.hdr = rng() % 4 == 0;
  encoder::LightfieldEncodeOptions& o = s.options;
  o.cell_size = (rng() % 2 == 0) ? 4 : 8;
  o.min_psnr_db = 35 + rng() % 20;
  o.depth = rng() % 2 == 0 ? encoder::DepthCoding::kRaw16 : encoder::DepthCoding::kBc5;
  o.depth_regions_per_side = 1 + rng() % 4;
  o.depth_keyframe_interval = 1 + rng() % 8;
  o.depth_window = 1 + rng() % 3;
  o.max_aabbs = 1 + rng() % 3;
  const encoder::ColourCoding ldr[] = {encoder::ColourCoding::kBc1, encoder::ColourCoding::kRgba8,
                                       encoder::ColourCoding::kBc7};
  o.colour = s.hdr ? (rng() % 2 ? encoder::ColourCoding::kBc6h : encoder::ColourCoding::kRgba16f)
                   : ldr[rng() % 3];
  return s;
}

EyeView random_eye(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  EyeView e;
  e.position = {u(rng), u(rng), u(rng)};
  do {
    e.forward = {u(rng), u(rng), u(rng)};
  } while (std::abs(e.forward.x) + std::abs(e.forward.y) + std::abs(e.forward.z) < 0.1);
  e.up = {u(rng), u(rng), u(rng)};
  if (std::abs(e.up.x) + std::abs(e.up.y) + std::abs(e.up.z) < 0.1) e.up = {0, 1, 0};
  e.fov_y = 0.6 + 0.8 * (u(rng) + 1) / 2;
  e.aspect = 1.0 + (u(rng) + 1) / 2;
  e.near = 0.05;
  e.far = 6 + 10 * (u(rng) + 1);
  return e;
}

// Compares, for every visible cell and tile of `fu`, the applied state with the reference decoder
// at `frame`. Returns the number of texels compared.
size_t expect_matches_reference(const Clip& clip, const CpuTextures& tex,
                                const LightfieldFrameUpdates& fu, uint32_t frame,
                                const std::string& context) {
  auto ref = LightfieldReference::open(*clip.reader, 0);
  EXPECT_TRUE(ref.ok());
  const auto& h = ref->header();
  auto tiles = FaceGrid::with_cell_size(h.face_size, h.depth_region_size);
  std::map<std::pair<uint32_t, int>, LightfieldFace> faces;
  auto face_of = [&](uint32_t v, CubeFace f) -> const LightfieldFace& {
    auto key = std::make_pair(v, cube_face_index(f));
    if (!faces.count(key)) {
      EXPECT_TRUE(ref->decode_face(v, cube_face_index(f), frame, &faces[key]).ok());
    }
    return faces[key];
  };
  size_t compared = 0;
  const uint32_t n = h.face_size;
  for (const CellParams& c : fu.cells) {
    const LightfieldFace& want = face_of(c.view, c.face);
    const std::vector<float> got = tex.colour(c.view, c.face);
    const PixelRect r = *tex.cells().cell_rect(c.cell);
    // The one-cell form (what the player's CPU views refresh from) holds the same texels.
    std::vector<float> cell_rgb;
    tex.colour_cell(c.view, c.face, c.cell, &cell_rgb);
    if (cell_rgb.size() != size_t{r.width} * r.height * 3) {
      ADD_FAILURE() << context << ": colour_cell gave " << cell_rgb.size() << " floats";
      return compared;
    }
    for (uint32_t y = 0; y < r.height; ++y) {
      for (uint32_t x = 0; x < r.width; ++x) {
        for (int k = 0; k < 3; ++k) {
          const size_t i = (size_t{r.y + y} * n + r.x + x) * 3 + k;
          if (cell_rgb[(size_t{y} * r.width + x) * 3 + k] != want.colour[i]) {
            ADD_FAILURE() << context << ": colour_cell view " << c.view << " cell " << c.cell
                          << " texel (" << r.x + x << ", " << r.y + y << ") differs";
            return compared;
          }
        }
      }
    }
    for (uint32_t y = r.y; y < r.y + r.height; ++y) {
      for (uint32_t x = r.x; x < r.x + r.width; ++x) {
        for (int k = 0; k < 3; ++k) {
          const size_t i = (size_t{y} * n + x) * 3 + k;
          if (got[i] != want.colour[i]) {
            ADD_FAILURE() << context << ": colour view " << c.view << " face "
                          << cube_face_index(c.face) << " texel (" << x << ", " << y << ") "
                          << got[i] << " != " << want.colour[i];
            return compared;
          }
        }
        ++compared;
      }
    }
  }
  for (const LightfieldRegionRef& t : fu.tiles) {
    const LightfieldFace& want = face_of(t.view, t.face);
    const auto depth = tex.depth(t.view, t.face);
    const auto material = tex.material(t.view, t.face);
    const PixelRect r = *tiles->cell_rect(t.tile);
    for (uint32_t y = r.y; y < r.y + r.height; ++y) {
      for (uint32_t x = r.x; x < r.x + r.width; ++x) {
        const size_t i = size_t{y} * n + x;
        if (depth[i] != want.depth[i]) {
          ADD_FAILURE() << context << ": depth view " << t.view << " face "
                        << cube_face_index(t.face) << " texel (" << x << ", " << y << ") "
                        << depth[i] << " != " << want.depth[i];
          return compared;
        }
        if (!want.material.empty()) {
          for (int k = 0; k < 3; ++k) {
            if (material[3 * i + k] != want.material[3 * i + k]) {
              ADD_FAILURE() << context << ": material view " << t.view << " texel (" << x << ", "
                            << y << ")";
              return compared;
            }
          }
        }
        ++compared;
      }
    }
  }
  return compared;
}

LightfieldFrameUpdates advance_ok(LightfieldDecoder& d, CpuTextures& tex, uint32_t frame,
                                  const std::vector<EyeView>& eyes,
                                  const std::vector<uint32_t>& active = {}) {
  LightfieldFrameUpdates fu;
  const Status s = d.advance(frame, eyes, active, &fu);
  EXPECT_TRUE(s.ok()) << s.to_string();
  EXPECT_EQ(fu.stats.errors, 0u) << fu.stats.first_error;
  EXPECT_TRUE(tex.apply(fu).ok());
  return fu;
}

LightfieldDecoder open_decoder(const Clip& clip, LightfieldDecoderOptions o = {}) {
  auto d = LightfieldDecoder::open(*clip.reader, 0, o);
  EXPECT_TRUE(d.ok()) << d.status().to_string();
  return std::move(*d);
}

CpuTextures textures_for(const LightfieldDecoder& d) {
  std::vector<LightfieldViewInfo> views;
  for (uint32_t v = 0; v < d.header().view_count; ++v) views.push_back(d.view(v));
  return CpuTextures(d.header(), views);
}

// Playing every frame with everything visible reproduces the reference decoder exactly.
TEST(LightfieldDecoder, PlayingWithoutCullingEqualsReferenceOnEveryFrame) {
  for (uint32_t seed = 1; seed <= 6; ++seed) {
    const ClipSpec spec = random_spec(seed);
    const Clip clip = make_clip(spec);
    LightfieldDecoderOptions o;
    o.view_dependent = false;
    LightfieldDecoder d = open_decoder(clip, o);
    CpuTextures tex = textures_for(d);
    for (uint32_t f = 0; f < spec.frames; ++f) {
      const LightfieldFrameUpdates fu = advance_ok(d, tex, f, {});
      EXPECT_EQ(fu.stats.visible_cells, fu.stats.total_cells);
      const size_t n = expect_matches_reference(clip, tex, fu, f, "seed " + std::to_string(seed));
      EXPECT_EQ(n, size_t{spec.views} * 6 * spec.face * spec.face * 2);
    }
  }
}

// Seeking to N (fresh decoder), playing 0..N and wandering through random frames before N give
// the same state for every cell and tile visible at N, equal to the reference.
TEST(LightfieldDecoder, SeekingEqualsPlayingEqualsReference) {
  size_t visible_somewhere = 0;
  for (uint32_t seed = 11; seed <= 18; ++seed) {
    const ClipSpec spec = random_spec(seed);
    const Clip clip = make_clip(spec);
    std::mt19937 rng(seed);
    for (int trial = 0; trial < 3; ++trial) {
      std::vector<EyeView> eyes = {random_eye(rng)};
      const uint32_t target = rng() % spec.frames;
      LightfieldDecoder play = open_decoder(clip), seek = open_decoder(clip),
                        wander = open_decoder(clip);
      CpuTextures tp = textures_for(play), ts = textures_for(seek), tw = textures_for(wander);
      LightfieldFrameUpdates last;
      for (uint32_t f = 0; f <= target; ++f) last = advance_ok(play, tp, f, eyes);
      const LightfieldFrameUpdates direct = advance_ok(seek, ts, target, eyes);
      for (int hop = 0; hop < 5; ++hop) {
        advance_ok(wander, tw, rng() % spec.frames, {random_eye(rng)});
      }
      const LightfieldFrameUpdates wandered = advance_ok(wander, tw, target, eyes);
      EXPECT_EQ(last.cells.size(), direct.cells.size());
      EXPECT_TRUE(last.tiles == direct.tiles && direct.tiles == wandered.tiles);
      const std::string ctx = "seed " + std::to_string(seed) + " frame " + std::to_string(target);
      visible_somewhere += expect_matches_reference(clip, tp, last, target, ctx + " play");
      expect_matches_reference(clip, ts, direct, target, ctx + " seek");
      expect_matches_reference(clip, tw, wandered, target, ctx + " wander");
      // A fresh seek uploads no more than playing did in total, and usually far less.
      EXPECT_LE(direct.stats.update_bytes(),
                last.stats.update_bytes() + direct.stats.update_bytes());
    }
  }
  EXPECT_GT(visible_somewhere, 0u) << "no trial saw anything: the test would prove nothing";
}

// The visible set for several viewers is the union of each one's, and the state on it is right.
TEST(LightfieldDecoder, SeveralViewersGiveTheUnionOfEachViewer) {
  for (uint32_t seed = 21; seed <= 26; ++seed) {
    const ClipSpec spec = random_spec(seed);
    const Clip clip = make_clip(spec);
    std::mt19937 rng(seed);
    const std::vector<EyeView> eyes = {random_eye(rng), random_eye(rng), random_eye(rng)};
    const uint32_t frame = rng() % spec.frames;
    std::set<std::tuple<uint32_t, int, uint32_t>> cells_union, tiles_union;
    for (const EyeView& e : eyes) {
      LightfieldDecoder d = open_decoder(clip);
      CpuTextures tex = textures_for(d);
      const LightfieldFrameUpdates fu = advance_ok(d, tex, frame, {e});
      for (const CellParams& c : fu.cells)
        cells_union.insert({c.view, cube_face_index(c.face), c.cell});
      for (const LightfieldRegionRef& t : fu.tiles)
        tiles_union.insert({t.view, cube_face_index(t.face), t.tile});
    }
    LightfieldDecoder all = open_decoder(clip);
    CpuTextures tex = textures_for(all);
    const LightfieldFrameUpdates fu = advance_ok(all, tex, frame, eyes);
    std::set<std::tuple<uint32_t, int, uint32_t>> cells, tiles;
    for (const CellParams& c : fu.cells) cells.insert({c.view, cube_face_index(c.face), c.cell});
    for (const LightfieldRegionRef& t : fu.tiles)
      tiles.insert({t.view, cube_face_index(t.face), t.tile});
    EXPECT_EQ(cells, cells_union) << "seed " << seed;
    EXPECT_EQ(tiles, tiles_union) << "seed " << seed;
    expect_matches_reference(clip, tex, fu, frame, "seed " + std::to_string(seed));
  }
}

// Hierarchical culling, brute force, every level count, background thread or not, any prefetch
// and cache size: byte-identical updates.
TEST(LightfieldDecoder, UpdatesDoNotDependOnCullingPathThreadOrCache) {
  const ClipSpec spec = random_spec(31);
  const Clip clip = make_clip(spec);
  std::mt19937 rng(31);
  std::vector<std::vector<EyeView>> eyes;
  std::vector<uint32_t> frames;
  for (int i = 0; i < 10; ++i) {
    eyes.push_back({random_eye(rng), random_eye(rng)});
    frames.push_back(rng() % spec.frames);
  }
  auto run = [&](LightfieldDecoderOptions o) {
    LightfieldDecoder d = open_decoder(clip, o);
    std::vector<uint8_t> log;
    for (size_t i = 0; i < frames.size(); ++i) {
      LightfieldFrameUpdates fu;
      EXPECT_TRUE(d.advance(frames[i], eyes[i], {}, &fu).ok());
      for (const TextureUpdate& u : fu.updates) {
        const uint32_t head[] = {static_cast<uint32_t>(u.target),
                                 u.view,
                                 uint32_t(cube_face_index(u.face)),
                                 u.slot,
                                 u.rect.x,
                                 u.rect.y,
                                 u.rect.width,
                                 u.rect.height};
        log.insert(log.end(), reinterpret_cast<const uint8_t*>(head),
                   reinterpret_cast<const uint8_t*>(head) + sizeof(head));
        log.insert(log.end(), u.bytes.begin(), u.bytes.end());
      }
      for (const CellParams& c : fu.cells) log.insert(log.end(), {c.t, c.a_slot});
    }
    return log;
  };
  const std::vector<uint8_t> base = run({});
  EXPECT_GT(base.size(), 1000u);
  LightfieldDecoderOptions o;
  o.brute_force_culling = true;
  EXPECT_EQ(run(o), base);
  for (uint32_t levels = 1; levels <= 4; ++levels) {
    o = {};
    o.quadtree_levels = levels;
    EXPECT_EQ(run(o), base) << levels;
  }
  o = {};
  o.background_thread = false;
  o.prefetch_frames = 0;
  EXPECT_EQ(run(o), base);
  o = {};
  o.cache_bytes = size_t{1} << 20;
  o.prefetch_frames = 64;
  EXPECT_EQ(run(o), base);
}

// Sec. 7.1: a seek restarts depth from the group keyframe and then steps W frames at a time —
// with predicted depth (r16p) too, whose rectangles decode on their own.
class DepthSeek : public ::testing::TestWithParam<encoder::DepthCoding> {};
INSTANTIATE_TEST_SUITE_P(Codings, DepthSeek,
                         ::testing::Values(encoder::DepthCoding::kRaw16,
                                           encoder::DepthCoding::kRaw16Predicted,
                                           encoder::DepthCoding::kRaw16PredictedMasked),
                         [](const auto& p) {
                           return std::string(p.param == encoder::DepthCoding::kRaw16 ? "raw16"
                                              : p.param == encoder::DepthCoding::kRaw16Predicted
                                                  ? "pred16"
                                                  : "pred16m");
                         });
TEST_P(DepthSeek, StepsThroughTheWindow) {
  ClipSpec spec;
  spec.options.depth = GetParam();
  spec.seed = 41;
  spec.views = 1;
  spec.frames = 12;
  spec.options.cell_size = 8;
  spec.options.depth_keyframe_interval = 12;
  spec.options.depth_window = 3;
  spec.options.max_aabbs = 1;
  const Clip clip = make_clip(spec);
  auto ref = LightfieldReference::open(*clip.reader, 0);
  ASSERT_TRUE(ref.ok());
  for (uint32_t target = 0; target < spec.frames; ++target) {
    LightfieldDecoderOptions o;
    o.view_dependent = false;
    LightfieldDecoder d = open_decoder(clip, o);
    CpuTextures tex = textures_for(d);
    const LightfieldFrameUpdates fu = advance_ok(d, tex, target, {});
    expect_matches_reference(clip, tex, fu, target, "frame " + std::to_string(target));
    // Expected depth updates: per tile the keyframe rect, then the rects of frames W, 2W, ...,
    // target (the last step shorter), counted from the encoder's rectangle table.
    uint64_t expected = 0;
    const uint32_t tiles_per_face =
        spec.options.depth_regions_per_side * spec.options.depth_regions_per_side;
    for (uint32_t face = 0; face < 6; ++face) {
      for (uint32_t tile = 0; tile < tiles_per_face; ++tile) {
        auto counts = ref->depth_rect_counts(0, face, tile);
        ASSERT_TRUE(counts.ok());
        expected += (*counts)[0];
        for (uint32_t at = 0; at < target;) {
          at = std::min(target, at + 3);
          expected += (*counts)[at];
        }
      }
    }
    uint64_t depth_updates = 0;
    for (const TextureUpdate& u : fu.updates) depth_updates += u.target == UpdateTarget::kDepth;
    EXPECT_EQ(depth_updates, expected) << "frame " << target;
    // Random access: the seek reads one depth chunk per tile (the group's) and one t chunk plus
    // one or two keyframe chunks per cell — nothing more for predicted depth than for raw16.
    const uint32_t cells =
        6 * (spec.face / spec.options.cell_size) * (spec.face / spec.options.cell_size);
    EXPECT_GE(fu.stats.chunks_needed, 6 * tiles_per_face + 2 * cells) << "frame " << target;
    EXPECT_LE(fu.stats.chunks_needed, 6 * tiles_per_face + 3 * cells) << "frame " << target;
  }
}

// Depth format r16p is lossless: every decoded depth code of every view, face and frame equals
// raw16's, sky (a half face and a moving square's edges beside finite depth) included; the
// seek reads as many chunks; and on this smooth synthetic depth the depth stream is smaller.
TEST(LightfieldDecoder, PredictedDepthDecodesToRaw16Codes) {
  ClipSpec spec;
  spec.seed = 43;
  spec.frames = 7;
  spec.material = true;
  spec.options.cell_size = 8;
  spec.options.depth_keyframe_interval = 4;
  const Clip raw = make_clip(spec);
  spec.options.depth = encoder::DepthCoding::kRaw16Predicted;
  const Clip pred = make_clip(spec);
  auto a = LightfieldReference::open(*raw.reader, 0);
  auto b = LightfieldReference::open(*pred.reader, 0);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(b->header().depth_format, static_cast<uint16_t>(container::PixelFormat::kR16Predicted));
  size_t sky = 0;
  for (uint32_t v = 0; v < spec.views; ++v) {
    for (uint32_t face = 0; face < 6; ++face) {
      for (uint32_t f = 0; f < spec.frames; ++f) {
        LightfieldFace fa, fb;
        ASSERT_TRUE(a->decode_face(v, face, f, &fa).ok());
        ASSERT_TRUE(b->decode_face(v, face, f, &fb).ok());
        ASSERT_EQ(fa.depth, fb.depth) << "view " << v << " face " << face << " frame " << f;
        EXPECT_EQ(fa.material, fb.material);
        for (uint16_t c : fb.depth) sky += c == kLog16Sky;
      }
    }
  }
  EXPECT_GT(sky, 0u);
  // The view-dependent decoder's seek to frame 6 applies the same codes from as many chunks.
  for (const Clip* c : {&raw, &pred}) {
    LightfieldDecoderOptions o;
    o.view_dependent = false;
    LightfieldDecoder d = open_decoder(*c, o);
    CpuTextures tex = textures_for(d);
    const LightfieldFrameUpdates fu = advance_ok(d, tex, 6, {});
    expect_matches_reference(*c, tex, fu, 6, c == &raw ? "raw16 seek" : "pred16 seek");
  }
  uint64_t depth_raw = 0, depth_pred = 0;
  for (const auto& [clip, sum] : {std::pair{&raw, &depth_raw}, std::pair{&pred, &depth_pred}}) {
    for (const auto& e : clip->reader->chunks()) {
      if (e.keys.stream == static_cast<uint16_t>(container::LightfieldStream::kDepth))
        *sum += e.stored_size;
    }
  }
  EXPECT_LT(depth_pred, depth_raw);
}

// Depth format r16pm (SPEC §11.1.9) is lossless from any frame a decoder may hold: every code of
// the reference decoder equals raw16's at every frame, and the view-dependent decoder that holds
// frame j and is asked for frame n (every j < n of a chunk: skipping up to W - 1 frames inside
// the window, or more through the W steps of a seek) builds exactly raw16's tile state. A mask
// taken against frame n - 1 alone, or unchanged texels read from anything but the tile state,
// would fail the jumps over skipped frames. The P-frames really skip texels.
TEST(LightfieldDecoder, MaskedDepthDecodesToRaw16CodesFromAnyFrameOfTheWindow) {
  ClipSpec spec;
  spec.seed = 53;
  spec.views = 1;
  spec.frames = 9;
  spec.material = true;
  spec.options.cell_size = 8;
  spec.options.depth_keyframe_interval = 6;
  spec.options.depth_window = 3;
  spec.options.max_aabbs = 1;
  spec.options.depth_regions_per_side = 1;
  spec.options.merge_static_groups = false;
  spec.second_square = true;
  const Clip raw = make_clip(spec);
  spec.options.depth = encoder::DepthCoding::kRaw16PredictedMasked;
  const Clip masked = make_clip(spec);
  auto a = LightfieldReference::open(*raw.reader, 0);
  auto b = LightfieldReference::open(*masked.reader, 0);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(b->header().depth_format,
            static_cast<uint16_t>(container::PixelFormat::kR16PredictedMasked));
  for (uint32_t face = 0; face < 6; ++face) {
    for (uint32_t f = 0; f < spec.frames; ++f) {
      LightfieldFace fa, fb;
      ASSERT_TRUE(a->decode_face(0, face, f, &fa).ok());
      ASSERT_TRUE(b->decode_face(0, face, f, &fb).ok());
      ASSERT_EQ(fa.depth, fb.depth) << "face " << face << " frame " << f;
      EXPECT_EQ(fa.material, fb.material);
    }
  }
  for (uint32_t j = 0; j < spec.frames; ++j) {
    for (uint32_t n = j + 1; n < spec.frames; ++n) {
      LightfieldDecoderOptions o;
      o.view_dependent = false;
      LightfieldDecoder d = open_decoder(masked, o);
      CpuTextures tex = textures_for(d);
      advance_ok(d, tex, j, {});
      const LightfieldFrameUpdates fu = advance_ok(d, tex, n, {});
      // Compared with the raw16 clip's reference decode: colour is coded alike, depth must be.
      expect_matches_reference(raw, tex, fu, n,
                               "from frame " + std::to_string(j) + " to " + std::to_string(n));
    }
  }
  // Texels of P-frame rectangles not stored: the area of the rectangles minus the stored texels
  // beyond the keyframe's (the wrapping square makes one rectangle span unchanged texels).
  uint64_t skipped = 0;
  const auto& chunks = masked.reader->chunks();
  for (uint32_t id = 0; id < chunks.size(); ++id) {
    if (chunks[id].keys.stream != static_cast<uint16_t>(container::LightfieldStream::kDepth))
      continue;
    auto bytes = masked.reader->read_chunk(id);
    ASSERT_TRUE(bytes.ok());
    const uint32_t side = spec.face / spec.options.depth_regions_per_side;
    auto c = lf::parse_region_chunk(*bytes, chunks[id].keys.frame_count, side, side,
                                    lf::RegionCoding::kR16PredictedMasked, "depth");
    ASSERT_TRUE(c.ok()) << c.status().to_string();
    uint64_t area = 0;
    for (const lf::RegionRect& r : c->rects) area += uint64_t{r.w} * r.h;
    skipped += area - c->units;
  }
  EXPECT_GT(skipped, 0u);
}

// A tile that does not change over whole groups of K frames keeps one depth (material) chunk
// across them (SPEC §11.1.2): the clip decodes to the same faces as with one chunk per K frames,
// has fewer, smaller depth chunks, never merges across a segment boundary, and a seek still reads
// one depth chunk per tile.
TEST(LightfieldDecoder, StaticTilesKeepOneChunkAcrossGroups) {
  ClipSpec spec;
  spec.seed = 47;
  spec.frames = 9;
  spec.material = true;
  spec.options.cell_size = 8;
  spec.options.depth_keyframe_interval = 2;
  spec.options.depth_window = 2;
  const Clip merged = make_clip(spec);
  spec.options.merge_static_groups = false;
  const Clip fixed = make_clip(spec);
  spec.options.merge_static_groups = true;
  spec.options.segment_frames = 4;
  const Clip segmented = make_clip(spec);

  auto a = LightfieldReference::open(*fixed.reader, 0);
  auto b = LightfieldReference::open(*merged.reader, 0);
  auto c = LightfieldReference::open(*segmented.reader, 0);
  ASSERT_TRUE(a.ok() && b.ok() && c.ok());
  for (uint32_t v = 0; v < spec.views; ++v) {
    for (uint32_t face = 0; face < 6; ++face) {
      for (uint32_t f = 0; f < spec.frames; ++f) {
        LightfieldFace fa, fb, fc;
        ASSERT_TRUE(a->decode_face(v, face, f, &fa).ok());
        ASSERT_TRUE(b->decode_face(v, face, f, &fb).ok());
        ASSERT_TRUE(c->decode_face(v, face, f, &fc).ok());
        const std::string at = "view " + std::to_string(v) + " face " + std::to_string(face) +
                               " frame " + std::to_string(f);
        ASSERT_EQ(fa.depth, fb.depth) << at;
        ASSERT_EQ(fa.material, fb.material) << at;
        ASSERT_EQ(fa.colour, fb.colour) << at;
        ASSERT_EQ(fa.depth, fc.depth) << at;
        ASSERT_EQ(fa.material, fc.material) << at;
      }
    }
  }

  const uint32_t k = spec.options.depth_keyframe_interval;
  struct Shape {
    uint32_t chunks = 0, spanning = 0, crossing_segment = 0;
    uint64_t stored = 0;
  };
  auto shape = [&](const Clip& clip, uint16_t stream) {
    Shape out;
    for (const auto& e : clip.reader->chunks()) {
      if (e.keys.stream != stream) continue;
      out.chunks += 1;
      out.stored += e.stored_size;
      EXPECT_EQ(e.keys.first_frame % k, 0u);
      const uint32_t last = e.keys.first_frame + e.keys.frame_count - 1;
      EXPECT_TRUE(e.keys.frame_count % k == 0 || last == spec.frames - 1);
      out.spanning += e.keys.frame_count > k;
      out.crossing_segment += e.keys.first_frame / 4 != last / 4;
    }
    return out;
  };
  for (const auto stream :
       {container::LightfieldStream::kDepth, container::LightfieldStream::kMaterial}) {
    const uint16_t tag = static_cast<uint16_t>(stream);
    const Shape f = shape(fixed, tag), m = shape(merged, tag), g = shape(segmented, tag);
    EXPECT_EQ(f.spanning, 0u);
    EXPECT_GT(m.spanning, 0u) << "stream " << tag;
    EXPECT_GT(m.crossing_segment, 0u) << "stream " << tag;
    EXPECT_EQ(g.crossing_segment, 0u) << "stream " << tag;
    EXPECT_LT(m.chunks, g.chunks) << "stream " << tag;
    EXPECT_LT(g.chunks, f.chunks) << "stream " << tag;
    EXPECT_LT(m.stored, f.stored) << "stream " << tag;
  }
  // Some tile changes after its first group, so it has more than one chunk: not everything is
  // merged. In a merged chunk, P-frames from the second group on are empty but for the first
  // W - 1 (what changed in the W frames before the group).
  const uint32_t tiles_per_face =
      spec.options.depth_regions_per_side * spec.options.depth_regions_per_side;
  uint32_t tiles_with_several = 0;
  for (uint32_t v = 0; v < spec.views; ++v) {
    for (uint32_t face = 0; face < 6; ++face) {
      for (uint32_t tile = 0; tile < tiles_per_face; ++tile) {
        uint32_t count = 0;
        for (const auto& e : merged.reader->chunks()) {
          if (e.keys.stream != static_cast<uint16_t>(container::LightfieldStream::kDepth) ||
              e.keys.view != v || e.keys.face != face || e.keys.region != tile) {
            continue;
          }
          count += 1;
          auto counts = b->depth_rect_counts(v, face, tile);
          ASSERT_TRUE(counts.ok());
          for (uint32_t i = e.keys.first_frame + k + spec.options.depth_window - 1;
               i < e.keys.first_frame + e.keys.frame_count; ++i) {
            EXPECT_EQ((*counts)[i], 0u)
                << "view " << v << " face " << face << " tile " << tile << " frame " << i;
          }
        }
        tiles_with_several += count > 1;
      }
    }
  }
  EXPECT_GT(tiles_with_several, 0u);
  // Random access: a seek to any frame reads one depth and one material chunk per tile.
  const uint32_t cells =
      6 * (spec.face / spec.options.cell_size) * (spec.face / spec.options.cell_size);
  for (uint32_t target = 0; target < spec.frames; ++target) {
    LightfieldDecoderOptions o;
    o.view_dependent = false;
    LightfieldDecoder d = open_decoder(merged, o);
    CpuTextures tex = textures_for(d);
    const LightfieldFrameUpdates fu = advance_ok(d, tex, target, {});
    expect_matches_reference(merged, tex, fu, target, "merged seek " + std::to_string(target));
    const uint32_t region_chunks = spec.views * 6 * tiles_per_face * 2;
    EXPECT_GE(fu.stats.chunks_needed, region_chunks + spec.views * 2 * cells) << target;
    EXPECT_LE(fu.stats.chunks_needed, region_chunks + spec.views * 3 * cells) << target;
  }
}

// Nothing visible without viewers; a viewer looking away from a view sees fewer cells.
TEST(LightfieldDecoder, VisibilityFollowsTheViewers) {
  ClipSpec spec;
  spec.seed = 51;
  spec.options.cell_size = 4;
  const Clip clip = make_clip(spec);
  LightfieldDecoder d = open_decoder(clip);
  LightfieldFrameUpdates fu;
  ASSERT_TRUE(d.advance(0, {}, {}, &fu).ok());
  EXPECT_EQ(fu.stats.visible_cells, 0u);
  EXPECT_TRUE(fu.updates.empty());
  EyeView narrow;
  narrow.position = {0, 0, 0};
  narrow.forward = {1, 0, 0};
  narrow.fov_y = 0.3;
  narrow.far = 3;
  ASSERT_TRUE(d.advance(0, std::vector<EyeView>{narrow}, {}, &fu).ok());
  EXPECT_GT(fu.stats.visible_cells, 0u);
  EXPECT_LT(fu.stats.visible_cells, fu.stats.total_cells / 2);
  EXPECT_GT(fu.stats.culling_tests, 0u);
  EXPECT_GT(fu.stats.mbps_at_24fps(), 0.0);
  // Only the active view is decoded.
  ASSERT_TRUE(d.advance(1, std::vector<EyeView>{narrow}, std::vector<uint32_t>{1}, &fu).ok());
  for (const TextureUpdate& u : fu.updates) EXPECT_EQ(u.view, 1u);
  EXPECT_EQ(fu.stats.total_cells, 6 * 16u);
  // Switching view-dependent decoding off (a renderer tracing secondary rays) decodes everything
  // from the next frame on, and the state is the reference's.
  d.set_view_dependent(false);
  CpuTextures tex = textures_for(d);
  d.reset();
  fu = advance_ok(d, tex, 2, std::vector<EyeView>{narrow});
  EXPECT_EQ(fu.stats.visible_cells, fu.stats.total_cells);
  expect_matches_reference(clip, tex, fu, 2, "view-dependent off");
}

// The decoder keeps its visible sets from frame to frame while the viewers and the culling options
// stay the same (culling them again gives the same sets): any change of an eye — position,
// direction, near or far plane, count — or of the options recomputes them. Each frame's sets equal
// those of a fresh decoder given the same viewers.
TEST(LightfieldDecoder, VisibleSetsAreKeptOnlyWhileTheViewersStay) {
  ClipSpec spec;
  spec.seed = 57;
  spec.views = 3;
  spec.options.cell_size = 4;
  const Clip clip = make_clip(spec);
  std::mt19937 rng(57);
  const EyeView a = random_eye(rng), b = random_eye(rng);
  EyeView a_near = a, a_far = a, a_moved = a, a_turned = a;
  a_near.near = a.near * 4;
  a_far.far = a.far / 3;
  a_moved.position.x += 0.25;
  a_turned.forward.y += 0.2;
  const std::vector<std::vector<EyeView>> steps = {
      {a}, {a}, {b}, {a}, {a_near}, {a_far}, {a_far}, {a_moved}, {a_turned}, {a, b}, {a, b}, {b}};
  LightfieldDecoder kept = open_decoder(clip);
  using Set = std::set<std::tuple<uint32_t, int, uint32_t>>;
  auto sets = [](const LightfieldFrameUpdates& fu) {
    Set cells, tiles;
    for (const CellParams& c : fu.cells) cells.insert({c.view, cube_face_index(c.face), c.cell});
    for (const LightfieldRegionRef& t : fu.tiles)
      tiles.insert({t.view, cube_face_index(t.face), t.tile});
    return std::make_pair(cells, tiles);
  };
  int changed = 0;
  for (size_t i = 0; i < steps.size(); ++i) {
    const uint32_t frame = static_cast<uint32_t>(i % spec.frames);
    LightfieldFrameUpdates fu, fresh_fu;
    ASSERT_TRUE(kept.advance(frame, steps[i], {}, &fu).ok());
    LightfieldDecoder fresh = open_decoder(clip);
    ASSERT_TRUE(fresh.advance(frame, steps[i], {}, &fresh_fu).ok());
    EXPECT_EQ(sets(fu), sets(fresh_fu)) << "step " << i;
    const bool same =
        i > 0 && steps[i].size() == steps[i - 1].size() &&
        std::memcmp(steps[i].data(), steps[i - 1].data(), steps[i].size() * sizeof(EyeView)) == 0;
    // Kept sets cost no culling; changed viewers are culled again (tests, or decisions kept by
    // the culler's memory where they provably still hold).
    if (same) {
      EXPECT_EQ(fu.stats.culling_tests + fu.stats.culling_reused, 0u) << "step " << i;
    } else {
      EXPECT_GT(fu.stats.culling_tests + fu.stats.culling_reused, 0u) << "step " << i;
      changed += sets(fu) != sets(LightfieldFrameUpdates{}) ? 1 : 0;
    }
  }
  EXPECT_GE(changed, 5);
  // Options: brute force and view dependence switched per frame keep giving the fresh sets.
  kept.set_view_dependent(false);
  LightfieldFrameUpdates fu;
  ASSERT_TRUE(kept.advance(0, steps[0], {}, &fu).ok());
  EXPECT_EQ(fu.stats.visible_cells, fu.stats.total_cells);
  kept.set_view_dependent(true);
  LightfieldFrameUpdates again, fresh_fu;
  ASSERT_TRUE(kept.advance(0, steps[0], {}, &again).ok());
  LightfieldDecoder fresh = open_decoder(clip);
  ASSERT_TRUE(fresh.advance(0, steps[0], {}, &fresh_fu).ok());
  EXPECT_EQ(sets(again), sets(fresh_fu));
  EXPECT_GT(again.stats.culling_tests + again.stats.culling_reused, 0u);
}

// A moving pair of eyes (turning, stepping, zooming, now and then jumping): the decoder culls
// mostly from its culler's memory of earlier frames, and every frame's updates are byte for byte
// those of a decoder that tests every cell afresh (brute force, no memory) on the same sequence.
TEST(LightfieldDecoder, MovingEyesCullFromMemoryWithTheSameUpdates) {
  ClipSpec spec;
  spec.seed = 58;
  spec.views = 3;
  spec.options.cell_size = 4;
  const Clip clip = make_clip(spec);
  LightfieldDecoderOptions brute;
  brute.brute_force_culling = true;
  brute.background_thread = false;
  LightfieldDecoderOptions quadtree;
  quadtree.background_thread = false;
  LightfieldDecoder remembering = open_decoder(clip, quadtree), fresh = open_decoder(clip, brute);
  std::mt19937 rng(58);
  std::uniform_real_distribution<double> u01(0, 1);
  std::vector<EyeView> eyes = {random_eye(rng), random_eye(rng)};
  uint64_t tests = 0, reused = 0;
  for (uint32_t step = 0; step < 40; ++step) {
    for (EyeView& e : eyes) {
      const double a = 0.01 * (1 + step % 3), c = std::cos(a), s = std::sin(a);
      e.forward = {e.forward.x * c - e.forward.z * s, e.forward.y,
                   e.forward.x * s + e.forward.z * c};
      e.position.x += 0.002;
      if (step % 7 == 3) e.fov_y *= 1.01;
      if (step % 13 == 12) e = random_eye(rng);
    }
    const uint32_t frame = step % spec.frames;
    LightfieldFrameUpdates a, b;
    ASSERT_TRUE(remembering.advance(frame, eyes, {}, &a).ok());
    ASSERT_TRUE(fresh.advance(frame, eyes, {}, &b).ok());
    ASSERT_EQ(a.updates.size(), b.updates.size()) << "step " << step;
    for (size_t i = 0; i < a.updates.size(); ++i) {
      EXPECT_EQ(a.updates[i].view, b.updates[i].view);
      EXPECT_EQ(a.updates[i].face, b.updates[i].face);
      EXPECT_EQ(a.updates[i].target, b.updates[i].target);
      EXPECT_EQ(a.updates[i].slot, b.updates[i].slot);
      EXPECT_EQ(a.updates[i].rect, b.updates[i].rect);
      EXPECT_TRUE(std::equal(a.updates[i].bytes.begin(), a.updates[i].bytes.end(),
                             b.updates[i].bytes.begin(), b.updates[i].bytes.end()))
          << "step " << step << " update " << i;
    }
    ASSERT_EQ(a.cells.size(), b.cells.size()) << "step " << step;
    for (size_t i = 0; i < a.cells.size(); ++i) {
      EXPECT_TRUE(a.cells[i].view == b.cells[i].view && a.cells[i].face == b.cells[i].face &&
                  a.cells[i].cell == b.cells[i].cell && a.cells[i].t == b.cells[i].t &&
                  a.cells[i].a_slot == b.cells[i].a_slot)
          << "step " << step << " cell " << i;
    }
    EXPECT_EQ(a.tiles, b.tiles) << "step " << step;
    tests += a.stats.culling_tests;
    reused += a.stats.culling_reused;
  }
  EXPECT_GT(reused, tests);
}

// Sky is at infinity: the renderer reads each view's sky in the eye ray's own direction. A view
// far to the side of a narrow viewer must therefore still decode the cells in the directions the
// viewer looks along, although no point of the viewer's frustum lies in them (seen from the view).
// Before this rule those cells were culled and rendered black sky bands.
TEST(LightfieldDecoder, CellsInTheViewersDirectionsAreDecodedForSky) {
  ClipSpec spec;
  spec.seed = 52;
  spec.options.cell_size = 4;
  const Clip clip = make_clip(spec);
  LightfieldDecoder d = open_decoder(clip);
  EyeView side;
  side.position = {0, 10, 0};  // 10 above view 0 at (-0.25, 0, 0); its frustum stays near y = 10
  side.forward = {1, 0, 0};
  side.fov_y = 0.3;
  side.far = 3;
  LightfieldFrameUpdates fu;
  ASSERT_TRUE(d.advance(0, std::vector<EyeView>{side}, std::vector<uint32_t>{0}, &fu).ok());
  // The +X face's centre texel of view 0 looks along (1, 0, 0); it lies in cell (2, 2) of the
  // 16-texel face's 4-texel grid.
  const Expected<FaceGrid> grid = FaceGrid::with_cell_size(spec.face, 4);
  ASSERT_TRUE(grid.ok());
  const uint32_t centre = grid->cell_index_at_texel(8, 8);
  ASSERT_EQ(centre, 2 * 4 + 2u);
  bool found = false;
  for (const CellParams& c : fu.cells) {
    found |= c.view == 0 && c.face == CubeFace::kPosX && c.cell == centre;
  }
  EXPECT_TRUE(found) << "cell " << centre << " of view 0's +X face was culled";
  // Directions behind the viewer stay culled: the -X face is never visible.
  for (const CellParams& c : fu.cells) EXPECT_NE(c.face, CubeFace::kNegX);
}

TEST(LightfieldDecoder, BadArgumentsAreE300AndChangeNothing) {
  ClipSpec spec;
  spec.seed = 61;
  const Clip clip = make_clip(spec);
  LightfieldDecoderOptions bad;
  bad.cache_bytes = 1000;
  EXPECT_EQ(LightfieldDecoder::open(*clip.reader, 0, bad).status().id(), ErrorId::kDecoderArgument);
  LightfieldDecoder d = open_decoder(clip);
  LightfieldFrameUpdates fu;
  EXPECT_EQ(d.advance(spec.frames, {}, {}, &fu).id(), ErrorId::kDecoderArgument);
  EXPECT_EQ(d.advance(0, {}, std::vector<uint32_t>{0, 0}, &fu).id(), ErrorId::kDecoderArgument);
  EXPECT_EQ(d.advance(0, {}, std::vector<uint32_t>{7}, &fu).id(), ErrorId::kDecoderArgument);
  EyeView e;
  e.far = e.near;
  EXPECT_EQ(d.advance(0, std::vector<EyeView>{e}, {}, &fu).id(), ErrorId::kDecoderArgument);
  e = EyeView{};
  e.position.x = std::nan("");
  EXPECT_EQ(d.advance(0, std::vector<EyeView>{e}, {}, &fu).id(), ErrorId::kDecoderArgument);
  e = EyeView{};
  e.up = e.forward * -2.0;  // parallel axes: the frustum would be NaN
  EXPECT_EQ(d.advance(0, std::vector<EyeView>{e}, {}, &fu).id(), ErrorId::kDecoderArgument);
  EXPECT_EQ(LightfieldDecoder::open(*clip.reader, 5).status().id(), ErrorId::kInvalidArgument);
}

// A damaged chunk is reported in the frame's stats; the cells needing it keep their last good
// state, every other cell decodes, and the decoder goes on.
TEST(LightfieldDecoder, CorruptChunkIsReportedAndLastGoodStateKept) {
  ClipSpec spec;
  spec.seed = 71;
  spec.views = 1;
  spec.options.min_psnr_db = 60;  // many keyframes
  Clip clip = make_clip(spec);
  // Damage the stored bytes of the last colour keyframe chunk of some cell (hash mismatch).
  const auto& chunks = clip.reader->chunks();
  int64_t victim = -1;
  for (uint32_t id = 0; id < chunks.size(); ++id) {
    if (chunks[id].keys.stream == static_cast<uint16_t>(container::LightfieldStream::kColour) &&
        chunks[id].keys.first_frame > 0 && chunks[id].stored_size > 0) {
      victim = id;
    }
  }
  ASSERT_GE(victim, 0);
  const container::ChunkKeys keys = chunks[victim].keys;
  std::vector<uint8_t> damaged = clip.bytes;
  damaged[chunks[victim].offset] ^= 0x5A;
  auto reader = container::Reader::open(container::memory_source(damaged));
  ASSERT_TRUE(reader.ok());
  LightfieldDecoderOptions o;
  o.view_dependent = false;
  auto d = LightfieldDecoder::open(*reader, 0, o);
  ASSERT_TRUE(d.ok());
  CpuTextures tex = textures_for(*d);
  LightfieldFrameUpdates fu;
  std::vector<float> before;
  uint32_t reported = 0;
  for (uint32_t f = 0; f < spec.frames; ++f) {
    ASSERT_TRUE(d->advance(f, {}, {}, &fu).ok());
    ASSERT_TRUE(tex.apply(fu).ok());
    const CubeFace face = static_cast<CubeFace>(keys.face);
    if (fu.stats.errors > 0) {
      ++reported;
      EXPECT_NE(fu.stats.first_error.find("CALF-E"), std::string::npos) << fu.stats.first_error;
      // The damaged cell is absent from the frame's parameters and its texels are unchanged.
      for (const CellParams& c : fu.cells) {
        EXPECT_FALSE(c.face == face && c.cell == keys.region);
      }
      const PixelRect r = *tex.cells().cell_rect(keys.region);
      const std::vector<float> now = tex.colour(0, face);
      for (uint32_t y = r.y; y < r.y + r.height; ++y) {
        for (uint32_t x = r.x; x < r.x + r.width; ++x) {
          const size_t i = (size_t{y} * spec.face + x) * 3;
          ASSERT_EQ(now[i], before[i]);
        }
      }
      EXPECT_EQ(fu.cells.size(), fu.stats.total_cells - 1u);
    } else {
      expect_matches_reference(clip, tex, fu, f, "frame " + std::to_string(f));
    }
    before = tex.colour(0, face);
  }
  EXPECT_GT(reported, 0u) << "the damaged keyframe was never needed";
}

// A view whose index chunk is damaged (hash mismatch, CALF-E058) is dropped at open with its
// reason; the other views decode exactly as before, and naming the dropped view is an error.
// With every index chunk damaged, open fails.
TEST(LightfieldDecoder, DamagedViewIndexDropsThatViewOnly) {
  ClipSpec spec;
  spec.seed = 72;
  spec.views = 3;
  Clip clip = make_clip(spec);
  const auto& chunks = clip.reader->chunks();
  std::vector<uint32_t> index_chunk(spec.views);
  for (uint32_t id = 0; id < chunks.size(); ++id) {
    if (chunks[id].keys.stream == static_cast<uint16_t>(container::LightfieldStream::kIndex)) {
      index_chunk[chunks[id].keys.view] = id;
    }
  }
  std::vector<uint8_t> damaged = clip.bytes;
  damaged[chunks[index_chunk[1]].offset + 3] ^= 0x10;
  auto reader = container::Reader::open(container::memory_source(damaged));
  ASSERT_TRUE(reader.ok()) << reader.status().to_string();
  LightfieldDecoderOptions o;
  o.view_dependent = false;
  auto d = LightfieldDecoder::open(*reader, 0, o);
  ASSERT_TRUE(d.ok()) << d.status().to_string();
  EXPECT_TRUE(d->view_problem(0).ok());
  EXPECT_EQ(d->view_problem(1).id(), ErrorId::kContainerChunkHash)
      << d->view_problem(1).to_string();
  EXPECT_NE(d->view_problem(1).message().find("view 1 index"), std::string::npos);
  EXPECT_TRUE(d->view_problem(2).ok());
  LightfieldDecoder good = open_decoder(clip, o);
  CpuTextures tex = textures_for(*d), want = textures_for(good);
  for (uint32_t f = 0; f < spec.frames; ++f) {
    LightfieldFrameUpdates fu;
    ASSERT_TRUE(d->advance(f, {}, {}, &fu).ok());
    EXPECT_EQ(fu.stats.errors, 0u) << fu.stats.first_error;
    for (const auto& c : fu.cells) EXPECT_NE(c.view, 1u);
    ASSERT_TRUE(tex.apply(fu).ok());
    advance_ok(good, want, f, {});
    for (uint32_t v : {0u, 2u}) {
      for (uint32_t face = 0; face < 6; ++face) {
        const CubeFace cf = static_cast<CubeFace>(face);
        ASSERT_EQ(tex.colour(v, cf), want.colour(v, cf)) << "view " << v << " frame " << f;
        const auto a = tex.depth(v, cf), b = want.depth(v, cf);
        ASSERT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end()));
      }
    }
  }
  LightfieldFrameUpdates fu;
  const Status named = d->advance(0, {}, std::vector<uint32_t>{1}, &fu);
  EXPECT_EQ(named.id(), ErrorId::kDecoderArgument);
  EXPECT_NE(named.message().find("dropped"), std::string::npos) << named.to_string();
  // The reference decoder and the verifier say the same.
  auto ref = LightfieldReference::open(*reader, 0);
  ASSERT_TRUE(ref.ok());
  LightfieldFace face;
  EXPECT_EQ(ref->decode_face(1, 0, 0, &face).id(), ErrorId::kContainerChunkHash);
  EXPECT_TRUE(ref->decode_face(2, 0, 0, &face).ok());
  const LightfieldVerifyResult verified = verify_lightfield_track(*reader, 0, true, 100);
  ASSERT_EQ(verified.problems.size(), 1u);
  EXPECT_EQ(verified.problems[0].id(), ErrorId::kContainerChunkHash);
  EXPECT_TRUE(verified.hashes.empty());
  EXPECT_EQ(verified.faces_decoded, uint64_t{2} * 6 * spec.frames);

  // Flipping all three again: 0 and 2 damaged, 1 whole.
  for (uint32_t v = 0; v < spec.views; ++v) damaged[chunks[index_chunk[v]].offset + 3] ^= 0x10;
  auto one_left = container::Reader::open(container::memory_source(damaged));
  ASSERT_TRUE(one_left.ok());
  EXPECT_TRUE(LightfieldDecoder::open(*one_left, 0, o).ok());
  damaged[chunks[index_chunk[1]].offset + 3] ^= 0x10;  // all three damaged
  auto none_left = container::Reader::open(container::memory_source(damaged));
  ASSERT_TRUE(none_left.ok());
  EXPECT_EQ(LightfieldDecoder::open(*none_left, 0, o).status().id(), ErrorId::kContainerChunkHash);
}

}  // namespace
}  // namespace calf::decoder
