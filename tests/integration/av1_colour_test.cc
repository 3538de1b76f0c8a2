// AV1 colour end to end (format/SPEC.md §11.1.12): a synthetic capture set encoded by calf-encode's
// library with encoder::ColourCoding::kAv1, its layout (GOP chunks, no t chunks, version 1.3),
// encodes independent of the thread count, the reference decoder and the view-dependent decoder (in
// order and seeking) giving the same colour, that colour close to the input, and damaged chunks
// refused with their ids; the same for a HDR capture set (format av1hdr: 10-bit codes of half
// floats, a curve per cell), and for both with 4:4:4 pictures (formats av1-444 and av1hdr-444,
// libaom, the High profile, container 1.5), whose texel-frequency chroma 4:2:0 cannot keep. With
// CALF_CONFORMANCE_OUT set it writes the conformance clips av1_pred16m, av1_hdr_pred16m,
// av1_444_pred16m and av1_hdr_444_pred16m there.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/decoder/cpu_textures.h"
#include "calf/decoder/lightfield_decoder.h"
#include "calf/decoder/lightfield_reference.h"
#include "calf/decoder/lightfield_verify.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/format/av1_hdr_colour.h"
#include "calf/format/colour.h"
#include "calf/format/container.h"
#include "calf/format/lightfield_layout.h"
#include "clip_edit.h"
#include "synthetic_capture.h"

// SVT-AV1 logs to stderr unless SVT_LOG says otherwise (calf-encode sets it in main).
[[maybe_unused]] static const int kQuietSvt = setenv("SVT_LOG", "0", 0);

namespace calf {
namespace {

namespace fs = std::filesystem;
using container::LightfieldStream;
using testing_support::SceneSpec;

class Av1Colour : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() /
            ("calf_av1_" + std::to_string(::getpid()) + "_" +
             ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
    ASSERT_TRUE(testing_support::write_synthetic_capture(root_ / "set", spec_).ok());
  }
  void TearDown() override { fs::remove_all(root_); }

  // The conformance clip's options: one stream per 16-texel face, a key frame every 2 frames.
  // With `chroma444` the 4:4:4 clips' (libaom, cpu-used 6: its preset 10 is out of range).
  static encoder::LightfieldEncodeOptions options(uint32_t threads = 1, bool chroma444 = false) {
    encoder::LightfieldEncodeOptions o;
    o.colour = encoder::ColourCoding::kAv1;
    o.cell_size = 16;
    o.av1.keyframe_interval = 2;
    o.av1.preset = chroma444 ? 6 : 10;
    o.av1.chroma444 = chroma444;
    o.threads = threads;
    return o;
  }

  std::vector<uint8_t> encode(const encoder::LightfieldEncodeOptions& o, bool hdr = false) {
    std::vector<uint8_t> bytes;
    if (hdr && !fs::exists(root_ / "hdr")) {
      SceneSpec spec = spec_;
      spec.hdr = true;
      EXPECT_TRUE(testing_support::write_synthetic_capture(root_ / "hdr", spec).ok());
    }
    auto in = capture::CaptureSetReader::open(root_ / (hdr ? "hdr" : "set"));
    EXPECT_TRUE(in.ok()) << in.status().to_string();
    auto writer = container::Writer::create(container::memory_sink(&bytes));
    EXPECT_TRUE(writer.ok());
    auto s = encoder::encode_lightfield(*in, *writer, o);
    EXPECT_TRUE(s.ok()) << s.status().to_string();
    EXPECT_TRUE(writer->finish().ok());
    return bytes;
  }

  static container::Reader open(const std::vector<uint8_t>& bytes) {
    auto r = container::Reader::open(container::memory_source(bytes));
    EXPECT_TRUE(r.ok()) << r.status().to_string();
    return std::move(*r);
  }

  void decoders_agree(bool hdr, bool chroma444);

  fs::path root_;
  SceneSpec spec_{.face = 16, .frames = 5, .views = 2};
};

// PSNR over sRGB bytes of two linear RGB images.
double psnr_srgb8(const std::vector<float>& a, const std::vector<float>& b) {
  double se = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double d = static_cast<double>(srgb8_from_linear(a[i])) - srgb8_from_linear(b[i]);
    se += d * d;
  }
  const double mse = se / static_cast<double>(a.size());
  return mse == 0 ? 99 : 10 * std::log10(255.0 * 255.0 / mse);
}

// log2-PSNR (SPEC §11.1.4, HDR): over log2(max(v, 2^-14)) of every channel, peak 8.
double psnr_log2(const std::vector<float>& a, const std::vector<float>& b) {
  double se = 0;
  for (size_t i = 0; i < a.size(); ++i) {
    const double d = std::log2(std::max(a[i], 0x1p-14f)) - std::log2(std::max(b[i], 0x1p-14f));
    se += d * d;
  }
  const double mse = se / static_cast<double>(a.size());
  return mse == 0 ? 99 : 10 * std::log10(64.0 / mse);
}

// seq_profile of the sequence header in a GOP's first unit (AV1 §5.5.1: the header's first 3
// bits): 0 Main (4:2:0), 1 High (4:4:4). The unit is a temporal delimiter (0x12 0x00) and then the
// sequence header OBU, its size a LEB128 value.
int seq_profile(std::span<const uint8_t> unit) {
  size_t at = 2;
  if (unit.size() < 4 || ((unit[at] >> 3) & 15) != 1) return -1;
  ++at;
  while (at < unit.size() && (unit[at] & 0x80)) ++at;
  ++at;
  return at < unit.size() ? unit[at] >> 5 : -1;
}

// What every AV1 colour layout shares: no t-parameter chunk, and each colour chunk of track 0 an
// AV1 chunk of its format (parse_av1_chunk) holding one unit per frame. `check` sees each colour
// chunk's keys, GOP and curve; `count` the number of colour chunks.
void for_each_colour_gop(const container::Reader& r, uint32_t* count,
                         const std::function<void(const container::ChunkKeys&, const lf::Av1Gop&,
                                                  const lf::Av1HdrCurve&)>& check) {
  const auto& h = std::get<container::LightfieldTrackHeader>(r.tracks()[0].header);
  *count = 0;
  for (uint32_t id = 0; id < r.chunks().size(); ++id) {
    const container::ChunkKeys& k = r.chunks()[id].keys;
    EXPECT_NE(k.stream, static_cast<uint16_t>(LightfieldStream::kTParams));
    if (k.stream != static_cast<uint16_t>(LightfieldStream::kColour)) continue;
    ++*count;
    auto raw = r.read_chunk(id);
    ASSERT_TRUE(raw.ok());
    lf::Av1HdrCurve curve;
    auto gop = lf::parse_av1_chunk(*raw, k.frame_count, h.colour_format, &curve, "chunk");
    ASSERT_TRUE(gop.ok()) << gop.status().to_string();
    ASSERT_EQ(gop->units.size(), k.frame_count);
    check(k, *gop, curve);
  }
}

TEST_F(Av1Colour, LayoutIsGopChunksWithoutTChunksInA13File) {
  const std::vector<uint8_t> bytes = encode(options());
  const container::Reader r = open(bytes);
  EXPECT_EQ(r.header().version_minor, container::kVersionMinorAv1);
  const auto& h = std::get<container::LightfieldTrackHeader>(r.tracks()[0].header);
  EXPECT_EQ(h.colour_format, static_cast<uint16_t>(container::PixelFormat::kAv1));
  EXPECT_EQ(h.flags, 0);
  uint32_t colour = 0;
  for_each_colour_gop(
      r, &colour, [](const container::ChunkKeys& k, const lf::Av1Gop& gop, const lf::Av1HdrCurve&) {
        // GOPs of 2 frames over 5: 0+2, 2+2, 4+1.
        EXPECT_EQ(k.first_frame % 2, 0u);
        EXPECT_EQ(k.frame_count, k.first_frame == 4 ? 1u : 2u);
        // Every unit starts with a temporal delimiter OBU (type 2, with a size field: 0x12 0x00);
        // the first then holds the sequence header (type 1).
        for (const auto& unit : gop.units) {
          ASSERT_GE(unit.size(), 3u);
          EXPECT_EQ(unit[0], 0x12);
          EXPECT_EQ(unit[1], 0x00);
        }
        EXPECT_EQ((gop.units[0][2] >> 3) & 15, 1);
        EXPECT_EQ(seq_profile(gop.units[0]), 0);  // Main
      });
  EXPECT_EQ(colour, spec_.views * 6 * 3);
}

// 4:4:4 pictures: formats av1-444 (LDR) and av1hdr-444 (HDR), a 1.5 file, the same GOP chunks
// (HDR: headed by the curve), every stream's sequence header the High profile.
TEST_F(Av1Colour, Chroma444IsTheHighProfileInA15File) {
  for (const bool hdr : {false, true}) {
    SCOPED_TRACE(hdr ? "HDR" : "LDR");
    const std::vector<uint8_t> bytes = encode(options(1, true), hdr);
    const container::Reader r = open(bytes);
    EXPECT_EQ(r.header().version_minor, container::kVersionMinorAv1Chroma444);
    const auto& h = std::get<container::LightfieldTrackHeader>(r.tracks()[0].header);
    EXPECT_EQ(h.colour_format, static_cast<uint16_t>(hdr ? container::PixelFormat::kAv1HdrChroma444
                                                         : container::PixelFormat::kAv1Chroma444));
    EXPECT_EQ(h.flags, hdr ? 1 : 0);
    uint32_t colour = 0;
    for_each_colour_gop(
        r, &colour,
        [](const container::ChunkKeys& k, const lf::Av1Gop& gop, const lf::Av1HdrCurve&) {
          EXPECT_EQ(k.frame_count, k.first_frame == 4 ? 1u : 2u);
          for (const auto& unit : gop.units) {
            ASSERT_GE(unit.size(), 3u);
            EXPECT_EQ(unit[0], 0x12);
            EXPECT_EQ(unit[1], 0x00);
          }
          EXPECT_EQ(seq_profile(gop.units[0]), 1);  // High
        });
    EXPECT_EQ(colour, spec_.views * 6 * 3);
  }
}

TEST_F(Av1Colour, HdrLayoutIsCurveHeadedGopChunksInA14File) {
  const std::vector<uint8_t> bytes = encode(options(), true);
  const container::Reader r = open(bytes);
  EXPECT_EQ(r.header().version_minor, container::kVersionMinorAv1Hdr);
  const auto& h = std::get<container::LightfieldTrackHeader>(r.tracks()[0].header);
  EXPECT_EQ(h.colour_format, static_cast<uint16_t>(container::PixelFormat::kAv1Hdr));
  EXPECT_EQ(h.flags, 1);
  uint32_t colour = 0, wide = 0;
  for_each_colour_gop(
      r, &colour,
      [&wide](const container::ChunkKeys& k, const lf::Av1Gop& gop, const lf::Av1HdrCurve& curve) {
        // The synthetic scene's LDR faces lie within [2^-14, 1] (a span of 0x3800 bits, which shift
        // 4 covers); its face 4 goes up to 40 (SceneSpec), which its top code must reach.
        EXPECT_GE(curve.base, 0x0400);
        EXPECT_LE(curve.shift, k.face == 4 ? 5 : 4);
        if (k.face == 4) wide += lf::av1_hdr_half_bits(curve, 1023) > 0x4900;  // above 10
        // Unit 0: a temporal delimiter, then the sequence header.
        EXPECT_EQ(gop.units[0][0], 0x12);
        EXPECT_EQ((gop.units[0][2] >> 3) & 15, 1);
      });
  EXPECT_EQ(colour, spec_.views * 6 * 3);
  EXPECT_EQ(wide, spec_.views * 3);
}

TEST_F(Av1Colour, EncodeDoesNotDependOnTheThreadCount) {
  for (const bool chroma444 : {false, true}) {
    EXPECT_EQ(encode(options(1, chroma444)), encode(options(2, chroma444)));
    EXPECT_EQ(encode(options(1, chroma444), true), encode(options(2, chroma444), true));
  }
}

TEST_F(Av1Colour, DecodersAgreeInOrderAndSeekingAndFollowTheInput) {
  for (const bool chroma444 : {false, true}) {
    for (const bool hdr : {false, true}) {
      SCOPED_TRACE(std::string(hdr ? "HDR (av1hdr" : "LDR (av1") + (chroma444 ? "-444)" : ")"));
      decoders_agree(hdr, chroma444);
    }
  }
}

void Av1Colour::decoders_agree(bool hdr, bool chroma444) {
  SceneSpec spec = spec_;
  spec.hdr = hdr;
  const std::vector<uint8_t> bytes = encode(options(1, chroma444), hdr);
  const container::Reader r = open(bytes);
  auto ref = decoder::LightfieldReference::open(r, 0);
  ASSERT_TRUE(ref.ok()) << ref.status().to_string();
  decoder::LightfieldDecoderOptions dopt;
  dopt.view_dependent = false;
  dopt.background_thread = false;
  auto dec = decoder::LightfieldDecoder::open(r, 0, dopt);
  ASSERT_TRUE(dec.ok()) << dec.status().to_string();
  std::vector<decoder::LightfieldViewInfo> infos = {dec->view(0), dec->view(1)};
  decoder::CpuTextures tex(dec->header(), infos);
  decoder::LightfieldFrameUpdates updates;
  decoder::LightfieldFace face;
  double worst = 1e9, sum = 0;
  int faces = 0;
  // In order, then seeks backwards, into the middle of a GOP and across GOPs.
  for (const uint32_t frame : {0u, 1u, 2u, 3u, 4u, 1u, 3u, 0u, 4u, 2u, 2u}) {
    ASSERT_TRUE(dec->advance(frame, {}, {}, &updates).ok());
    EXPECT_EQ(updates.stats.errors, 0u) << updates.stats.first_error;
    for (const decoder::TextureUpdate& u : updates.updates) {
      if (u.target != decoder::UpdateTarget::kColour) continue;
      EXPECT_EQ(u.format, hdr ? container::PixelFormat::kRgba16f : container::PixelFormat::kRgba8);
      EXPECT_EQ(u.slot, 0u);
    }
    for (const decoder::CellParams& c : updates.cells) EXPECT_EQ(c.t, 0);
    ASSERT_TRUE(tex.apply(updates).ok());
    for (uint32_t v = 0; v < spec_.views; ++v) {
      const capture::ViewFrame input = testing_support::make_frame(spec, v, frame);
      for (uint32_t f = 0; f < 6; ++f) {
        ASSERT_TRUE(ref->decode_face(v, f, frame, &face).ok());
        ASSERT_EQ(tex.colour(v, static_cast<CubeFace>(f)), face.colour)
            << "view " << v << " face " << f << " frame " << frame;
        std::vector<float> want;
        for (uint32_t y = 0; y < spec_.face; ++y) {
          for (uint32_t x = 0; x < spec_.face; ++x) {
            const size_t i = input.texel_index(static_cast<CubeFace>(f), x, y);
            for (int c = 0; c < 3; ++c) want.push_back(input.color[3 * i + c]);
          }
        }
        const double psnr = hdr ? psnr_log2(want, face.colour) : psnr_srgb8(want, face.colour);
        worst = std::min(worst, psnr);
        sum += psnr;
        ++faces;
      }
    }
  }
  // The synthetic scene is smooth gradients and a square with hard edges moving across a 16-texel
  // face: 4:2:0 chroma blurs those edges. Measured with SVT-AV1 1.4.1 (preset 10, CRF 32): LDR
  // (PSNR of sRGB bytes) mean 36.44 dB, worst face-frame 25.39 dB; HDR (log2-PSNR) mean 40.73 dB,
  // worst 25.33 dB; with 4:4:4 pictures (libaom 3.6.0, cpu-used 6, CQ level 32) LDR mean
  // 45.34 dB, worst 35.49 dB, HDR mean 52.47 dB, worst 32.91 dB. The upper bounds say when the
  // coding got lossless by accident (or the test compares the decoder with itself).
  const double mean = sum / faces;
  std::printf("AV1 colour (%s, %s) vs input: mean %.2f dB, worst %.2f dB over %d face-frames\n",
              hdr ? "HDR, log2-PSNR" : "LDR, sRGB PSNR", chroma444 ? "4:4:4" : "4:2:0", mean, worst,
              faces);
  EXPECT_GT(mean, 30.0);
  EXPECT_LT(mean, 60.0);
  EXPECT_GT(worst, 20.0);
  EXPECT_LT(worst, 60.0);
  const decoder::LightfieldVerifyResult verified = decoder::verify_lightfield_track(r, 0, true, 4);
  EXPECT_TRUE(verified.problems.empty())
      << (verified.problems.empty() ? "" : verified.problems[0].to_string());
  if (const char* out_dir = std::getenv("CALF_CONFORMANCE_OUT")) {
    const std::string name = std::string(hdr ? "av1_hdr" : "av1") + (chroma444 ? "_444" : "");
    std::ofstream(fs::path(out_dir) / (name + "_pred16m.calf"), std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()),
               static_cast<std::streamsize>(bytes.size()));
  }
}

// The file with the first colour chunk of (view, face, cell 0) edited; other chunks as they are.
std::vector<uint8_t> with_colour_chunk(const container::Reader& r, uint32_t view, uint32_t face,
                                       const std::function<void(std::vector<uint8_t>&)>& edit) {
  return testing_support::with_chunk_edited(
      r,
      [&](const container::ChunkKeys& k) {
        return k.stream == static_cast<uint16_t>(LightfieldStream::kColour) && k.view == view &&
               k.face == face;
      },
      edit);
}

// A seek decodes at most the keyframe interval of pictures per cell: it restarts at the key frame
// of the GOP holding the frame. GOPs of 3 over 5 frames are frames 0-2 and 3-4; the pictures each
// jump needs follow from that layout alone.
TEST_F(Av1Colour, SeekDecodesWithinTheKeyframeInterval) {
  encoder::LightfieldEncodeOptions o = options();
  o.av1.keyframe_interval = 3;
  const std::vector<uint8_t> bytes = encode(o);
  const container::Reader r = open(bytes);
  decoder::LightfieldDecoderOptions dopt;
  dopt.view_dependent = false;
  dopt.background_thread = false;
  auto dec = decoder::LightfieldDecoder::open(r, 0, dopt);
  ASSERT_TRUE(dec.ok()) << dec.status().to_string();
  const uint32_t cells = 6 * spec_.views;  // one cell per 16-texel face
  struct Step {
    uint32_t frame, pictures;
  };
  // 4: key 3, then 4; 2: key 0, 1, 2; 0: back to the key; 1: on from 0; 3: the other GOP's key;
  // 2: key 0 again, 1, 2; 4: key 3, then 4; 4 again: nothing to decode.
  for (const Step s : {Step{4, 2}, Step{2, 3}, Step{0, 1}, Step{1, 1}, Step{3, 1}, Step{2, 3},
                       Step{4, 2}, Step{4, 0}}) {
    decoder::LightfieldFrameUpdates updates;
    ASSERT_TRUE(dec->advance(s.frame, {}, {}, &updates).ok());
    EXPECT_EQ(updates.stats.errors, 0u) << updates.stats.first_error;
    EXPECT_EQ(updates.stats.av1_max_pictures_per_cell, s.pictures) << "frame " << s.frame;
    EXPECT_EQ(updates.stats.av1_pictures, s.pictures * cells) << "frame " << s.frame;
    EXPECT_LE(updates.stats.av1_max_pictures_per_cell, o.av1.keyframe_interval);
  }
}

TEST_F(Av1Colour, DamagedChunksAreRefusedWithTheirIds) {
  const std::vector<uint8_t> bytes = encode(options());
  const container::Reader r = open(bytes);
  // A head whose frame count is not the chunk's: E067.
  const auto bad_head = with_colour_chunk(r, 1, 2, [](std::vector<uint8_t>& raw) { raw[0] = 7; });
  // A unit that is not AV1: the first unit's bytes after its temporal delimiter, all 0xff (OBU
  // type 15 with reserved bits): E301.
  const auto bad_unit = with_colour_chunk(r, 1, 2, [](std::vector<uint8_t>& raw) {
    const size_t first = 4 + 4 * size_t{raw[0]};
    for (size_t i = first + 2; i < first + 12 && i < raw.size(); ++i) raw[i] = 0xff;
  });
  struct Case {
    const std::vector<uint8_t>* file;
    ErrorId id;
  };
  for (const Case& c :
       {Case{&bad_head, ErrorId::kAv1Chunk}, Case{&bad_unit, ErrorId::kAv1Decode}}) {
    const container::Reader damaged = open(*c.file);
    const decoder::LightfieldVerifyResult v = decoder::verify_lightfield_track(damaged, 0, true, 4);
    ASSERT_FALSE(v.problems.empty());
    EXPECT_EQ(v.problems[0].id(), c.id) << v.problems[0].to_string();
    EXPECT_NE(v.problems[0].message().find("view 1 face 2"), std::string::npos)
        << v.problems[0].message();
    decoder::LightfieldDecoderOptions dopt;
    dopt.view_dependent = false;
    dopt.background_thread = false;
    auto dec = decoder::LightfieldDecoder::open(damaged, 0, dopt);
    ASSERT_TRUE(dec.ok());
    decoder::LightfieldFrameUpdates updates;
    ASSERT_TRUE(dec->advance(0, {}, {}, &updates).ok());
    EXPECT_EQ(updates.stats.errors, 1u);
    EXPECT_EQ(updates.stats.first_error.rfind(
                  std::string("CALF-E") + (c.id == ErrorId::kAv1Chunk ? "067" : "301"), 0),
              0u)
        << updates.stats.first_error;
  }
}

TEST_F(Av1Colour, HdrCurveOutOfRangeIsRefused) {
  const std::vector<uint8_t> bytes = encode(options(), true);
  const container::Reader r = open(bytes);
  // A shift of 6 (at most 5), a base of 0x7C00 (infinity; at most 0x7BFF), a chunk shorter than
  // its curve: E067.
  const auto bad_shift = with_colour_chunk(r, 1, 2, [](std::vector<uint8_t>& raw) { raw[2] = 6; });
  const auto bad_base = with_colour_chunk(r, 1, 2, [](std::vector<uint8_t>& raw) {
    raw[0] = 0x00;
    raw[1] = 0x7C;
  });
  const auto short_chunk =
      with_colour_chunk(r, 1, 2, [](std::vector<uint8_t>& raw) { raw.resize(3); });
  struct Case {
    const std::vector<uint8_t>* file;
    ErrorId id;
  };
  for (const Case& c : {Case{&bad_shift, ErrorId::kAv1Chunk}, Case{&bad_base, ErrorId::kAv1Chunk},
                        Case{&short_chunk, ErrorId::kAv1Chunk}}) {
    const container::Reader damaged = open(*c.file);
    const decoder::LightfieldVerifyResult v = decoder::verify_lightfield_track(damaged, 0, true, 4);
    ASSERT_FALSE(v.problems.empty());
    EXPECT_EQ(v.problems[0].id(), c.id) << v.problems[0].to_string();
    EXPECT_NE(v.problems[0].message().find("view 1 face 2"), std::string::npos)
        << v.problems[0].message();
  }
}

// A red / green checkerboard at texel frequency: 4:2:0 keeps one chroma sample per 2 x 2 texels,
// the mean of two reds and two greens, so no bit rate brings it back; 4:4:4 keeps every texel's.
TEST_F(Av1Colour, Chroma444KeepsTexelFrequencyColourThat420Loses) {
  SceneSpec spec = spec_;
  spec.animated = false;
  auto checker = [&](uint32_t v, uint32_t f) {
    capture::ViewFrame vf = testing_support::make_frame(spec, v, f);
    for (uint32_t face = 0; face < 6; ++face) {
      for (uint32_t y = 0; y < spec.face; ++y) {
        for (uint32_t x = 0; x < spec.face; ++x) {
          const size_t i = vf.texel_index(static_cast<CubeFace>(face), x, y);
          const bool red = (x + y) % 2 == 0;
          vf.color[3 * i] = red ? 0.8f : 0.05f;
          vf.color[3 * i + 1] = red ? 0.05f : 0.8f;
          vf.color[3 * i + 2] = 0.05f;
        }
      }
    }
    return vf;
  };
  ASSERT_TRUE(testing_support::write_capture(root_ / "checker", spec, checker).ok());
  auto in = capture::CaptureSetReader::open(root_ / "checker");
  ASSERT_TRUE(in.ok());
  double psnr[2] = {0, 0};
  for (const bool chroma444 : {false, true}) {
    encoder::LightfieldEncodeOptions o = options(1, chroma444);
    o.av1.crf = 20;
    std::vector<uint8_t> bytes;
    auto writer = container::Writer::create(container::memory_sink(&bytes));
    ASSERT_TRUE(writer.ok());
    ASSERT_TRUE(encoder::encode_lightfield(*in, *writer, o).ok());
    ASSERT_TRUE(writer->finish().ok());
    const container::Reader r = open(bytes);
    auto ref = decoder::LightfieldReference::open(r, 0);
    ASSERT_TRUE(ref.ok()) << ref.status().to_string();
    decoder::LightfieldFace face;
    std::vector<float> want, got;
    for (uint32_t v = 0; v < spec.views; ++v) {
      const capture::ViewFrame input = checker(v, 1);
      for (uint32_t f = 0; f < 6; ++f) {
        ASSERT_TRUE(ref->decode_face(v, f, 1, &face).ok());
        got.insert(got.end(), face.colour.begin(), face.colour.end());
        for (uint32_t y = 0; y < spec.face; ++y) {
          for (uint32_t x = 0; x < spec.face; ++x) {
            const size_t i = input.texel_index(static_cast<CubeFace>(f), x, y);
            for (int c = 0; c < 3; ++c) want.push_back(input.color[3 * i + c]);
          }
        }
      }
    }
    psnr[chroma444] = psnr_srgb8(want, got);
  }
  std::printf("red / green texel checkerboard at CRF 20: 4:2:0 %.2f dB, 4:4:4 %.2f dB\n", psnr[0],
              psnr[1]);
  EXPECT_LT(psnr[0], 15.0);
  EXPECT_GT(psnr[1], 30.0);
}

// A 4:4:4 stream where the track says 4:2:0, and the reverse: the colour chunk of one cell taken
// from the other clip decodes, and its picture is refused as not the track's (E302), in one line
// that names the cell and both layouts.
TEST_F(Av1Colour, ChromaOtherThanTheTrackSaysIsRefused) {
  const std::vector<uint8_t> b420 = encode(options(1, false)), b444 = encode(options(1, true));
  const container::Reader r420 = open(b420), r444 = open(b444);
  auto chunk_of = [](const container::Reader& r, uint32_t view, uint32_t face) {
    for (uint32_t id = 0; id < r.chunks().size(); ++id) {
      const container::ChunkKeys& k = r.chunks()[id].keys;
      if (k.stream == static_cast<uint16_t>(LightfieldStream::kColour) && k.view == view &&
          k.face == face && k.first_frame == 0) {
        return *r.read_chunk(id);
      }
    }
    return std::vector<uint8_t>{};
  };
  const std::vector<uint8_t> c420 = chunk_of(r420, 1, 2), c444 = chunk_of(r444, 1, 2);
  ASSERT_FALSE(c420.empty());
  ASSERT_FALSE(c444.empty());
  const auto in420 = with_colour_chunk(r420, 1, 2, [&](std::vector<uint8_t>& raw) { raw = c444; });
  const auto in444 = with_colour_chunk(r444, 1, 2, [&](std::vector<uint8_t>& raw) { raw = c420; });
  for (const auto* file : {&in420, &in444}) {
    const container::Reader damaged = open(*file);
    const decoder::LightfieldVerifyResult v = decoder::verify_lightfield_track(damaged, 0, true, 4);
    ASSERT_FALSE(v.problems.empty());
    const Status& p = v.problems[0];
    EXPECT_EQ(p.id(), ErrorId::kAv1Picture) << p.to_string();
    EXPECT_NE(p.message().find("view 1 face 2"), std::string::npos) << p.message();
    const bool track444 = file == &in444;
    EXPECT_NE(p.message().find(track444 ? "4:2:0 picture" : "4:4:4 picture"), std::string::npos)
        << p.message();
    EXPECT_NE(p.message().find(track444 ? "8-bit 4:4:4 expected" : "8-bit 4:2:0 expected"),
              std::string::npos)
        << p.message();
    EXPECT_EQ(p.to_string().find('\n'), std::string::npos);
  }
}

TEST_F(Av1Colour, BadOptionsAreRefused) {
  auto in = capture::CaptureSetReader::open(root_ / "set");
  ASSERT_TRUE(in.ok());
  encoder::LightfieldEncodeOptions o = options();
  o.av1.keyframe_interval = 0;
  EXPECT_EQ(encoder::analyse_lightfield(*in, o).status().id(), ErrorId::kEncoderOption);
  o = options();
  o.av1.crf = 64;
  EXPECT_EQ(encoder::analyse_lightfield(*in, o).status().id(), ErrorId::kEncoderOption);
  // libaom's cpu-used (4:4:4) goes up to 9, SVT-AV1's preset to 13.
  o = options(1, true);
  o.av1.preset = 10;
  EXPECT_EQ(encoder::analyse_lightfield(*in, o).status().id(), ErrorId::kEncoderOption);
  o.av1.preset = 9;
  EXPECT_TRUE(encoder::analyse_lightfield(*in, o).ok());
}

}  // namespace
}  // namespace calf
