// Shared helpers of the numerical-extremes tests (tests/extreme/): hand-built capture
// sets in a temporary directory, encoding them with the real encoder, decoding every cell with the
// view-dependent decoder into CpuTextures (as a GPU would hold them), player views from that
// state, an OSMesa context shared by a test program, and the NaN / Inf checks every case makes.
//
// Expected values never come from here: each test computes them from the scene it builds.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "../gl_test_context.h"
#include "calf/capture/capture_set.h"
#include "calf/decoder/cpu_textures.h"
#include "calf/decoder/lightfield_decoder.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/format/container.h"
#include "calf/format/log_depth.h"
#include "calf/player/gl_context.h"
#include "calf/player/lightfield_cpu_renderer.h"
#include "calf/player/view_set.h"

namespace calf::extreme {

namespace fs = std::filesystem;

inline constexpr float kInfF = std::numeric_limits<float>::infinity();

// Concatenates strings and integers by appending (GCC 12 at -O3 misfires -Wrestrict on chains
// of std::string operator+).
inline void append_text(std::string& s, const std::string& part) {
  s.append(part);
}
inline void append_text(std::string& s, const char* part) {
  s.append(part);
}
template <typename I>
requires std::is_integral_v<I>
inline void append_text(std::string& s, I part) {
  s.append(std::to_string(part));
}
template <typename... T>
std::string cat(const T&... parts) {
  std::string s;
  (append_text(s, parts), ...);
  return s;
}

// A scratch directory, unique per process and name, removed with everything in it at the end.
class TempDir {
 public:
  explicit TempDir(const std::string& name) {
    std::string leaf = "calf_extreme_";  // appends: GCC 12 -O3 misfires -Wrestrict on operator+
    leaf.append(std::to_string(::getpid())).append("_").append(name);
    path_ = fs::temp_directory_path() / leaf;
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const fs::path& path() const { return path_; }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

// A manifest for `positions.size()` viewpoints with faces of `face_size` texels, `frames` frames
// at 24 fps, and a view volume of the viewpoints' bounding box grown by `margin`.
inline capture::CaptureManifest make_manifest(uint32_t face_size, uint32_t frames,
                                              const std::vector<Vec3>& positions,
                                              double margin = 0.5) {
  capture::CaptureManifest m;
  m.frame_count = frames;
  m.face_size = face_size;
  m.fps = 24;
  Box3 box{positions[0], positions[0]};
  for (size_t v = 0; v < positions.size(); ++v) {
    std::string name = "v";
    name.append(std::to_string(v));
    m.viewpoints.push_back({name, positions[v]});
    const Vec3& p = positions[v];
    box.min = {std::min(box.min.x, p.x), std::min(box.min.y, p.y), std::min(box.min.z, p.z)};
    box.max = {std::max(box.max.x, p.x), std::max(box.max.y, p.y), std::max(box.max.z, p.z)};
  }
  m.view_volume = {{box.min.x - margin, box.min.y - margin, box.min.z - margin},
                   {box.max.x + margin, box.max.y + margin, box.max.z + margin}};
  return m;
}

// Fills one view-frame (already sized for the manifest's face size and material flag).
using FrameFill = std::function<void(uint32_t view, uint32_t frame, capture::ViewFrame& out)>;

// Writes a complete capture set into `dir`; returns the writer's first error.
inline Status write_capture(const fs::path& dir, const capture::CaptureManifest& m,
                            const FrameFill& fill) {
  CALF_ASSIGN_OR_RETURN(capture::CaptureSetWriter writer,
                        capture::CaptureSetWriter::create(dir, m));
  capture::ViewFrame vf;
  for (uint32_t v = 0; v < m.viewpoints.size(); ++v) {
    for (uint32_t f = 0; f < m.frame_count; ++f) {
      vf.resize(m.face_size, m.material);
      fill(v, f, vf);
      CALF_RETURN_IF_ERROR(writer.write(v, f, vf));
    }
  }
  return writer.finish();
}

// Sets every texel of a face to one colour and depth.
inline void fill_face(capture::ViewFrame& vf, CubeFace face, const float rgb[3], float depth) {
  for (uint32_t y = 0; y < vf.face_size; ++y) {
    for (uint32_t x = 0; x < vf.face_size; ++x) {
      const size_t i = vf.texel_index(face, x, y);
      for (int c = 0; c < 3; ++c) vf.color[3 * i + c] = rgb[c];
      vf.depth[i] = depth;
    }
  }
}

// A clip file and the decoder state after decoding one frame with every cell and tile of every
// view kept current (view-dependent decoding off): what a GPU holds.
struct DecodedClip {
  std::unique_ptr<container::Reader> reader;
  std::optional<decoder::LightfieldDecoder> decoder;
  std::optional<decoder::CpuTextures> textures;
  decoder::LightfieldFrameUpdates last;  // the updates of the last advance()

  const container::LightfieldTrackHeader& header() const { return decoder->header(); }
  uint32_t view_count() const { return header().view_count; }
  // Brings every view to `frame`; errors as LightfieldDecoder::advance and CpuTextures::apply.
  Status advance(uint32_t frame) {
    CALF_RETURN_IF_ERROR(decoder->advance(frame, {}, {}, &last));
    if (last.stats.errors != 0) {
      return Status(ErrorId::kInternal, "chunk errors: " + last.stats.first_error);
    }
    return textures->apply(last);
  }
};

// Opens `path` (its lightfield track is track 0) and decodes `frame`. Fails the test on error.
inline std::unique_ptr<DecodedClip> decode_clip(const std::string& path, uint32_t frame) {
  auto out = std::make_unique<DecodedClip>();
  auto reader = container::Reader::open(path);
  EXPECT_TRUE(reader.ok()) << reader.status().to_string();
  if (!reader.ok()) return nullptr;
  out->reader = std::make_unique<container::Reader>(std::move(*reader));
  decoder::LightfieldDecoderOptions o;
  o.view_dependent = false;
  o.background_thread = false;
  auto d = decoder::LightfieldDecoder::open(*out->reader, 0, o);
  EXPECT_TRUE(d.ok()) << d.status().to_string();
  if (!d.ok()) return nullptr;
  out->decoder.emplace(std::move(*d));
  std::vector<decoder::LightfieldViewInfo> views;
  for (uint32_t v = 0; v < out->view_count(); ++v) views.push_back(out->decoder->view(v));
  out->textures.emplace(out->header(), views);
  const Status s = out->advance(frame);
  EXPECT_TRUE(s.ok()) << s.to_string();
  return s.ok() ? std::move(out) : nullptr;
}

// Player views of every view of a decoded clip (the CPU renderer's input, as calf-play builds it
// for its CPU path): linear colour, log-16 codes with the view's z_near / z_far.
inline Expected<player::ViewSet> view_set_of(const DecodedClip& clip) {
  player::ViewSet set;
  const uint32_t n = clip.textures->face_size();
  for (uint32_t v = 0; v < clip.view_count(); ++v) {
    const decoder::LightfieldViewInfo& info = clip.decoder->view(v);
    CALF_ASSIGN_OR_RETURN(LogDepthRange range, LogDepthRange::make(info.z_near, info.z_far));
    const Vec3 p = info.position;
    CALF_ASSIGN_OR_RETURN(player::View view, player::View::make(p, range, n, false));
    const PixelRect whole{0, 0, n, n};
    for (int f = 0; f < kCubeFaceCount; ++f) {
      const CubeFace face = cube_face_from_index(f);
      CALF_RETURN_IF_ERROR(view.write_colour_rect(face, whole, clip.textures->colour(v, face)));
      CALF_RETURN_IF_ERROR(view.write_depth_rect(face, whole, clip.textures->depth(v, face)));
    }
    set.views.push_back(std::move(view));
  }
  return set;
}

// Pixels of an image whose colour or depth is NaN, or whose colour is infinite (depth may be
// +inf: sky), for EXPECT_EQ(..., 0u).
inline size_t bad_pixels(const player::RenderedImage& img) {
  size_t bad = 0;
  for (size_t k = 0; k < img.depth.size(); ++k) {
    bool ok = !std::isnan(img.depth[k]) && img.depth[k] > 0;
    for (int c = 0; c < 3; ++c) ok = ok && std::isfinite(img.color[3 * k + c]);
    bad += ok ? 0 : 1;
  }
  return bad;
}

using ::calf::test::gl_context;

// The value a float takes when stored as a half and read back (the capture set's colour
// precision), computed independently of calf's converter: round to nearest even with 10
// mantissa bits, subnormals below 2^-14 on a grid of 2^-24. For 0 <= v <= 65504 only.
inline float as_half(float v) {
  if (v == 0) return 0;
  const double d = v;
  int e;
  std::frexp(d, &e);                          // d = m * 2^e, m in [0.5, 1)
  const int exponent = std::max(e - 1, -14);  // normal: 2^(e-1) <= d; subnormal grid below 2^-14
  const double quantum = std::ldexp(1.0, exponent - 10);
  return static_cast<float>(std::nearbyint(d / quantum) * quantum);  // nearbyint: ties to even
}

}  // namespace calf::extreme
