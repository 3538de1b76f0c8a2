// Sharded capture and encode (docs/FARM.md; calf/encoder/lightfield_shard.h and
// calf/capture/capture_shard.h): on every built-in scene, clips merged from 1, 2 and 3 view
// shards equal a one-machine encode byte for byte; frame-range shards equal a one-machine encode
// with the same closed segment length; capture shards joined equal a one-machine capture; and the
// merge's errors (missing, mismatched, overlapping shards) are one line with their ids.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <variant>
#include <vector>

#include "../scratch_dir.h"
#include "calf/capture/capture_set.h"
#include "calf/capture/capture_shard.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/encoder/lightfield_shard.h"
#include "calf/format/container.h"
#include "calf/samples/render.h"
#include "calf/samples/scene.h"

namespace calf {
namespace {

namespace fs = std::filesystem;

fs::path scratch() {
  return test::scratch_dir("calf_lightfield_shard_test");
}

std::string bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

samples::CaptureRequest tiny_request(const samples::Scene& scene, uint32_t frames) {
  samples::CaptureRequest r;
  r.face_size = 8;
  r.frames = frames;
  r.rig = scene.default_rig;
  r.render.spp = 1;
  r.render.min_spp = 1;
  r.render.ao_samples = 1;
  r.render.threads = 2;
  return r;
}

// Renders `name` at face 8 into scratch()/<tag>-<name> (once per process).
fs::path capture_of(const std::string& name, uint32_t frames, const std::string& tag) {
  const fs::path dir = scratch() / (tag + "-" + name);
  if (fs::exists(dir / capture::kManifestFileName)) return dir;
  auto scene = samples::make_builtin_scene(name);
  EXPECT_TRUE(scene.ok()) << scene.status().to_string();
  if (!scene.ok()) return dir;
  auto stats = samples::render_capture_set(*scene, tiny_request(*scene, frames), dir, nullptr);
  EXPECT_TRUE(stats.ok()) << stats.status().to_string();
  return dir;
}

void expect_one_line(const Status& s, ErrorId id) {
  EXPECT_EQ(s.id(), id) << s.to_string();
  EXPECT_EQ(s.to_string().find('\n'), std::string::npos) << s.to_string();
}

// Views [0, n) split into k contiguous shards of near-equal size.
std::vector<std::vector<uint32_t>> split(uint32_t n, uint32_t k) {
  std::vector<std::vector<uint32_t>> out(k);
  for (uint32_t v = 0; v < n; ++v) out[static_cast<size_t>(v) * k / n].push_back(v);
  return out;
}

// Codes frames [first, first + 2) of the analysis's views in two view groups, one shard per group
// and first frame (in the order of `firsts`), named PREFIX<group>-<first>.calf in `work`.
void encode_frame_shards(const fs::path& dir, const encoder::LightfieldAnalysisFile& a,
                         std::initializer_list<uint32_t> firsts, uint32_t threads,
                         const char* prefix, const fs::path& work,
                         std::vector<std::string>* shards) {
  const auto groups = split(a.analysis.header.view_count, 2);
  for (uint32_t g = 0; g < 2; ++g) {
    for (uint32_t first : firsts) {
      std::string name = prefix;  // append, not operator+: GCC 12 -O3 misfires -Wrestrict on it
      name += std::to_string(g);
      name += '-';
      name += std::to_string(first);
      name += ".calf";
      const std::string path = (work / name).string();
      auto s = encoder::encode_lightfield_shard(dir, a, groups[g], first, 2, threads, path);
      ASSERT_TRUE(s.ok()) << s.status().to_string();
      shards->push_back(path);
    }
  }
}

class LightfieldShardScenes : public ::testing::TestWithParam<std::string> {};

TEST_P(LightfieldShardScenes, MergedViewShardsEqualOneMachineEncode) {
  const std::string name = GetParam();
  const fs::path dir = capture_of(name, 2, "views");
  ASSERT_TRUE(fs::exists(dir / capture::kManifestFileName));
  const fs::path work = scratch() / ("work-" + name);
  fs::create_directories(work);
  encoder::LightfieldEncodeOptions o;
  o.threads = 2;
  const std::string one = (work / "one.calf").string();
  ASSERT_TRUE(encoder::encode_lightfield_file(dir, one, o).ok());
  const std::string expected = bytes_of(one);
  ASSERT_GT(expected.size(), 0u);

  auto written = encoder::write_lightfield_analysis(dir, (work / "analysis.calf").string(), o);
  ASSERT_TRUE(written.ok()) << written.status().to_string();
  auto analysis = encoder::read_lightfield_analysis((work / "analysis.calf").string());
  ASSERT_TRUE(analysis.ok()) << analysis.status().to_string();
  EXPECT_EQ(analysis->id, written->id);
  const uint32_t views = analysis->analysis.header.view_count;
  const uint32_t frames = analysis->analysis.header.frame_count;
  for (uint32_t k = 1; k <= 3; ++k) {
    SCOPED_TRACE(name + ", " + std::to_string(k) + " shards");
    std::vector<std::string> shards;
    const auto groups = split(views, k);
    for (uint32_t i = 0; i < k; ++i) {
      const std::string path =
          (work / ("shard" + std::to_string(k) + "-" + std::to_string(i) + ".calf")).string();
      // Thread counts differ per shard: never part of the bytes.
      auto s =
          encoder::encode_lightfield_shard(dir, *analysis, groups[i], 0, frames, 1 + i % 2, path);
      ASSERT_TRUE(s.ok()) << s.status().to_string();
      shards.insert(shards.begin(), path);  // merged in reverse order: order is not significant
    }
    const std::string merged = (work / ("merged" + std::to_string(k) + ".calf")).string();
    const Status m = encoder::merge_lightfield_shards(*analysis, shards, merged);
    ASSERT_TRUE(m.ok()) << m.to_string();
    EXPECT_TRUE(bytes_of(merged) == expected) << "merged clip differs from the one-machine encode";
  }
}

std::vector<std::string> builtin_scene_names() {
  std::vector<std::string> names;
  for (const auto& s : samples::builtin_scenes()) names.push_back(s.name);
  return names;
}

std::string test_name(const ::testing::TestParamInfo<std::string>& p) {
  std::string n = p.param;
  for (char& c : n) c = c == '-' ? '_' : c;
  return n;
}

INSTANTIATE_TEST_SUITE_P(EveryBuiltInScene, LightfieldShardScenes,
                         ::testing::ValuesIn(builtin_scene_names()), test_name);

// Frame-range shards with closed segments of 2 frames against one encode with the same segments;
// views x frame ranges in every combination of 2 x 2, with depth format r16pm. Depth groups are 1
// frame, so static tiles merge two groups inside a segment (SPEC §11.1.2) but never across one:
// shards that end at a segment boundary would otherwise code them apart.
TEST(LightfieldShardFrames, FrameRangeShardsEqualSegmentedEncode) {
  const fs::path dir = capture_of("mirror-box", 4, "frames");
  ASSERT_TRUE(fs::exists(dir / capture::kManifestFileName));
  const fs::path work = scratch() / "frames-work";
  fs::create_directories(work);
  encoder::LightfieldEncodeOptions o;
  o.threads = 2;
  o.segment_frames = 2;
  o.depth_keyframe_interval = 1;
  // Masked predicted depth (r16pm, the last encoder::DepthCoding): the analysis file records it and
  // the shards code its chunks as one encode does (view shards of raw16 above).
  o.depth = encoder::DepthCoding::kRaw16PredictedMasked;
  const std::string one = (work / "one.calf").string();
  auto stats = encoder::encode_lightfield_file(dir, one, o);
  ASSERT_TRUE(stats.ok()) << stats.status().to_string();
  {
    auto r = container::Reader::open(one);
    ASSERT_TRUE(r.ok()) << r.status().to_string();
    uint32_t merged_groups = 0;
    for (const auto& e : r->chunks()) {
      if (e.keys.stream != static_cast<uint16_t>(container::LightfieldStream::kDepth)) continue;
      EXPECT_TRUE(e.keys.first_frame / 2 == (e.keys.first_frame + e.keys.frame_count - 1) / 2)
          << "a depth chunk crosses a segment boundary: frames " << e.keys.first_frame << " + "
          << e.keys.frame_count;
      merged_groups += e.keys.frame_count > 1;
    }
    EXPECT_GT(merged_groups, 0u);
  }
  // Closed segments: every cell has a keyframe at frames 0 and 2.
  EXPECT_GE(stats->colour_keyframes, 2 * stats->colour_cells);

  ASSERT_TRUE(encoder::write_lightfield_analysis(dir, (work / "a.calf").string(), o).ok());
  auto a = encoder::read_lightfield_analysis((work / "a.calf").string());
  ASSERT_TRUE(a.ok()) << a.status().to_string();
  EXPECT_EQ(a->options.segment_frames, 2u);
  EXPECT_EQ(a->options.depth, encoder::DepthCoding::kRaw16PredictedMasked);
  const auto groups = split(a->analysis.header.view_count, 2);
  std::vector<std::string> shards;
  ASSERT_NO_FATAL_FAILURE(encode_frame_shards(dir, *a, {2u, 0u}, 2, "s", work, &shards));
  const std::string merged = (work / "merged.calf").string();
  const Status m = encoder::merge_lightfield_shards(*a, shards, merged);
  ASSERT_TRUE(m.ok()) << m.to_string();
  EXPECT_TRUE(bytes_of(merged) == bytes_of(one));

  // A range that is not whole segments is refused.
  auto odd =
      encoder::encode_lightfield_shard(dir, *a, groups[0], 1, 2, 1, (work / "odd.calf").string());
  ASSERT_FALSE(odd.ok());
  expect_one_line(odd.status(), ErrorId::kEncoderInput);
  // Overlapping frame ranges of one view, and a gap.
  const std::string whole0 = (work / "whole0.calf").string();
  ASSERT_TRUE(encoder::encode_lightfield_shard(dir, *a, groups[0], 0, 4, 1, whole0).ok());
  std::vector<std::string> overlap = shards;
  overlap.push_back(whole0);
  expect_one_line(encoder::merge_lightfield_shards(*a, overlap, (work / "x.calf").string()),
                  ErrorId::kShardOverlap);
  std::vector<std::string> gap = {shards[0], shards[2], shards[3]};  // view group 0 lacks 0-1
  expect_one_line(encoder::merge_lightfield_shards(*a, gap, (work / "x.calf").string()),
                  ErrorId::kShardMissing);
  EXPECT_FALSE(fs::exists(work / "x.calf"));
}

// A 4-frame mirror-box capture with per-frame render noise in `dir`, unless one is there.
void make_noisy_mirror_box(const fs::path& dir) {
  if (fs::exists(dir / capture::kManifestFileName)) return;
  auto scene = samples::make_builtin_scene("mirror-box");
  ASSERT_TRUE(scene.ok()) << scene.status().to_string();
  samples::CaptureRequest r = tiny_request(*scene, 4);
  r.render.noise = 0.05f;
  ASSERT_TRUE(samples::render_capture_set(*scene, r, dir, nullptr).ok());
}

// What --psnr auto gives that capture (Q 42.7 dB, the noise-aware test at its 45.7 dB estimate,
// factor 3), in segments of 2 frames with a depth keyframe every frame, so that frame-range
// shards can split it.
encoder::LightfieldEncodeOptions noise_aware_options() {
  encoder::LightfieldEncodeOptions o;
  o.threads = 2;
  o.segment_frames = 2;
  o.depth_keyframe_interval = 1;
  o.min_psnr_db = 42.7;
  o.noise_psnr_db = 45.7;
  o.noise_factor = 3;
  return o;
}

// The noise-aware keyframe test (--psnr auto on a capture with per-frame render noise): the
// analysis file records the noise estimate and factor, and frame-range shards code each segment's
// cells as one encode does (each segment measures its own cells' noise).
TEST(LightfieldShardFrames, NoiseAwareShardsEqualOneMachineEncode) {
  const fs::path dir = scratch() / "noisy-mirror-box";
  ASSERT_NO_FATAL_FAILURE(make_noisy_mirror_box(dir));
  const fs::path work = scratch() / "noisy-work";
  fs::create_directories(work);
  encoder::LightfieldEncodeOptions o = noise_aware_options();
  const std::string one = (work / "one.calf").string();
  ASSERT_TRUE(encoder::encode_lightfield_file(dir, one, o).ok());
  encoder::LightfieldEncodeOptions plain = o;
  plain.noise_psnr_db = 0;
  const std::string plain_path = (work / "plain.calf").string();
  ASSERT_TRUE(encoder::encode_lightfield_file(dir, plain_path, plain).ok());
  EXPECT_FALSE(bytes_of(plain_path) == bytes_of(one)) << "the noise-aware test changed nothing";

  ASSERT_TRUE(encoder::write_lightfield_analysis(dir, (work / "a.calf").string(), o).ok());
  auto a = encoder::read_lightfield_analysis((work / "a.calf").string());
  ASSERT_TRUE(a.ok()) << a.status().to_string();
  EXPECT_EQ(a->options.noise_psnr_db, 45.7);
  EXPECT_EQ(a->options.noise_factor, 3.0);
  std::vector<std::string> shards;
  ASSERT_NO_FATAL_FAILURE(encode_frame_shards(dir, *a, {0u, 2u}, 1, "n", work, &shards));
  const std::string merged = (work / "merged.calf").string();
  const Status m = encoder::merge_lightfield_shards(*a, shards, merged);
  ASSERT_TRUE(m.ok()) << m.to_string();
  EXPECT_TRUE(bytes_of(merged) == bytes_of(one));
}

// The temporal pre-filter (denoise_window, calf/encoder/colour_denoise.h) on the same noisy
// capture: the analysis file records the window, and frame-range shards filter each segment as one
// encode does (no window crosses a segment).
TEST(LightfieldShardFrames, DenoisedShardsEqualOneMachineEncode) {
  const fs::path dir = scratch() / "noisy-mirror-box";
  ASSERT_NO_FATAL_FAILURE(make_noisy_mirror_box(dir));
  const fs::path work = scratch() / "denoise-work";
  fs::create_directories(work);
  encoder::LightfieldEncodeOptions o = noise_aware_options();
  o.denoise_window = 4;
  const std::string one = (work / "one.calf").string();
  auto stats = encoder::encode_lightfield_file(dir, one, o);
  ASSERT_TRUE(stats.ok()) << stats.status().to_string();
  EXPECT_GT(stats->colour_denoised, 0u);
  encoder::LightfieldEncodeOptions off = o;
  off.denoise_window = 0;
  const std::string off_path = (work / "off.calf").string();
  ASSERT_TRUE(encoder::encode_lightfield_file(dir, off_path, off).ok());
  EXPECT_FALSE(bytes_of(off_path) == bytes_of(one)) << "the pre-filter changed nothing";

  const std::string a_path = (work / "a.calf").string();
  ASSERT_TRUE(encoder::write_lightfield_analysis(dir, a_path, o).ok());
  auto a = encoder::read_lightfield_analysis(a_path);
  ASSERT_TRUE(a.ok()) << a.status().to_string();
  EXPECT_EQ(a->options.denoise_window, 4u);
  std::vector<std::string> shards;
  ASSERT_NO_FATAL_FAILURE(encode_frame_shards(dir, *a, {2u, 0u}, 1, "d", work, &shards));
  const std::string merged = (work / "merged.calf").string();
  const Status m = encoder::merge_lightfield_shards(*a, shards, merged);
  ASSERT_TRUE(m.ok()) << m.to_string();
  EXPECT_TRUE(bytes_of(merged) == bytes_of(one));

  // An analysis file of the record version before baked unmixing (7) is refused, naming it.
  auto reader = container::Reader::open(a_path);
  ASSERT_TRUE(reader.ok());
  const std::string* record = reader->find_metadata("calf.lightfield_analysis");
  const std::string* id = reader->find_metadata("calf.lightfield_analysis_id");
  ASSERT_TRUE(record && id);
  std::string old = *record;
  ASSERT_EQ(old.rfind("calf-lightfield-analysis 8\n", 0), 0u);
  old.replace(0, std::string("calf-lightfield-analysis 8").size(), "calf-lightfield-analysis 7");
  const size_t line = old.find("\ncoverage_unmix 0 ");
  ASSERT_NE(line, std::string::npos);
  old.erase(line, old.find('\n', line + 1) - line);
  const std::string v7 = (work / "v7.calf").string();
  {
    auto w = container::Writer::create(v7);
    ASSERT_TRUE(w.ok());
    const auto* header = std::get_if<container::LightfieldTrackHeader>(&reader->tracks()[0].header);
    ASSERT_NE(header, nullptr);
    ASSERT_TRUE(w->add_track(*header).ok());
    ASSERT_TRUE(w->set_metadata("calf.lightfield_analysis", old).ok());
    ASSERT_TRUE(w->set_metadata("calf.lightfield_analysis_id", *id).ok());
    ASSERT_TRUE(w->finish().ok());
  }
  auto refused = encoder::read_lightfield_analysis(v7);
  ASSERT_FALSE(refused.ok());
  expect_one_line(refused.status(), ErrorId::kShardFile);
  EXPECT_NE(refused.status().message().find("record version '7'"), std::string::npos)
      << refused.status().to_string();
}

TEST(LightfieldShardErrors, MergeRefusesMissingForeignAndOverlappingShards) {
  const fs::path dir = capture_of("turntable", 2, "views");
  ASSERT_TRUE(fs::exists(dir / capture::kManifestFileName));
  const fs::path work = scratch() / "errors";
  fs::create_directories(work);
  encoder::LightfieldEncodeOptions o;
  o.threads = 2;
  ASSERT_TRUE(encoder::write_lightfield_analysis(dir, (work / "a.calf").string(), o).ok());
  encoder::LightfieldEncodeOptions other = o;
  other.min_psnr_db = 40;  // another analysis of the same capture set
  ASSERT_TRUE(encoder::write_lightfield_analysis(dir, (work / "b.calf").string(), other).ok());
  auto a = encoder::read_lightfield_analysis((work / "a.calf").string());
  auto b = encoder::read_lightfield_analysis((work / "b.calf").string());
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_NE(a->id, b->id);
  const uint32_t n = a->analysis.header.view_count, frames = a->analysis.header.frame_count;
  const auto groups = split(n, 2);
  const std::string s0 = (work / "s0.calf").string(), s1 = (work / "s1.calf").string();
  const std::string b1 = (work / "b1.calf").string(), all = (work / "all.calf").string();
  ASSERT_TRUE(encoder::encode_lightfield_shard(dir, *a, groups[0], 0, frames, 1, s0).ok());
  ASSERT_TRUE(encoder::encode_lightfield_shard(dir, *a, groups[1], 0, frames, 1, s1).ok());
  ASSERT_TRUE(encoder::encode_lightfield_shard(dir, *b, groups[1], 0, frames, 1, b1).ok());
  std::vector<uint32_t> every(n);
  for (uint32_t v = 0; v < n; ++v) every[v] = v;
  ASSERT_TRUE(encoder::encode_lightfield_shard(dir, *a, every, 0, frames, 1, all).ok());
  const std::string out = (work / "out.calf").string();

  expect_one_line(encoder::merge_lightfield_shards(*a, std::vector<std::string>{s0}, out),
                  ErrorId::kShardMissing);
  expect_one_line(encoder::merge_lightfield_shards(*a, std::vector<std::string>{s0, b1}, out),
                  ErrorId::kShardMismatch);
  expect_one_line(encoder::merge_lightfield_shards(*a, std::vector<std::string>{s0, s1, all}, out),
                  ErrorId::kShardOverlap);
  // A clip or the analysis file is not a shard; a shard is not an analysis file.
  expect_one_line(encoder::merge_lightfield_shards(
                      *a, std::vector<std::string>{s0, (work / "a.calf").string()}, out),
                  ErrorId::kShardFile);
  expect_one_line(encoder::read_lightfield_analysis(s0).status(), ErrorId::kShardFile);
  EXPECT_FALSE(fs::exists(out));
  // The analysis file is an input of a shard and of a merge: neither may write over it.
  const std::string a_path = (work / "a.calf").string();
  const std::string a_bytes = bytes_of(a_path);
  expect_one_line(
      encoder::encode_lightfield_shard(dir, *a, groups[0], 0, frames, 1, a_path).status(),
      ErrorId::kOutputIsInput);
  expect_one_line(encoder::merge_lightfield_shards(*a, std::vector<std::string>{s0, s1}, a_path),
                  ErrorId::kOutputIsInput);
  EXPECT_EQ(bytes_of(a_path), a_bytes);
  // The shard list and view lists.
  expect_one_line(capture::parse_index_list("0-2,2", 9, "views").status(), ErrorId::kShardRange);
  expect_one_line(capture::parse_index_list("3-1", 9, "views").status(), ErrorId::kShardRange);
  expect_one_line(capture::parse_index_list("9", 9, "views").status(), ErrorId::kShardRange);
  auto list = capture::parse_index_list("0-2,5,7-8", 9, "views");
  ASSERT_TRUE(list.ok());
  EXPECT_EQ(*list, (std::vector<uint32_t>{0, 1, 2, 5, 7, 8}));
  EXPECT_EQ(capture::index_list_text(*list), "0-2,5,7-8");
  ASSERT_TRUE(encoder::merge_lightfield_shards(*a, std::vector<std::string>{s1, s0}, out).ok());
}

// Two captures of one manifest whose pixels differ (one colour texel of view 0, frame 0: the
// views' facts stay the same) give analyses with other ids: their shards do not merge, and a
// shard of the other capture coded with the first analysis is refused where it reads the changed
// image.
TEST(LightfieldShardErrors, AnalysisIdentifiesThePixels) {
  const fs::path dir = capture_of("turntable", 2, "views");
  ASSERT_TRUE(fs::exists(dir / capture::kManifestFileName));
  const fs::path work = scratch() / "pixels";
  fs::remove_all(work);
  fs::create_directories(work);
  const fs::path other = work / "other-capture";
  {
    auto reader = capture::CaptureSetReader::open(dir);
    ASSERT_TRUE(reader.ok());
    auto writer = capture::CaptureSetWriter::create(other, reader->manifest());
    ASSERT_TRUE(writer.ok());
    for (uint32_t v = 0; v < reader->manifest().viewpoints.size(); ++v) {
      for (uint32_t f = 0; f < reader->manifest().frame_count; ++f) {
        capture::ViewFrame frame;
        ASSERT_TRUE(reader->read(v, f, &frame).ok());
        if (v == 0 && f == 0) frame.color[0] = frame.color[0] > 0.5f ? 0.25f : 0.75f;
        ASSERT_TRUE(writer->write(v, f, frame).ok());
      }
    }
    ASSERT_TRUE(writer->finish().ok());
  }
  EXPECT_EQ(bytes_of(other / capture::kManifestFileName),
            bytes_of(dir / capture::kManifestFileName));
  encoder::LightfieldEncodeOptions o;
  o.threads = 2;
  const std::string a_path = (work / "a.calf").string(), b_path = (work / "b.calf").string();
  ASSERT_TRUE(encoder::write_lightfield_analysis(dir, a_path, o).ok());
  ASSERT_TRUE(encoder::write_lightfield_analysis(other, b_path, o).ok());
  auto a = encoder::read_lightfield_analysis(a_path);
  auto b = encoder::read_lightfield_analysis(b_path);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_NE(a->id, b->id);
  const uint32_t n = a->analysis.header.view_count, frames = a->analysis.header.frame_count;
  const auto groups = split(n, 2);
  const std::string s0 = (work / "s0.calf").string(), s1 = (work / "s1-other.calf").string();
  ASSERT_TRUE(encoder::encode_lightfield_shard(dir, *a, groups[0], 0, frames, 1, s0).ok());
  ASSERT_TRUE(encoder::encode_lightfield_shard(other, *b, groups[1], 0, frames, 1, s1).ok());
  const std::string out = (work / "mixed.calf").string();
  expect_one_line(encoder::merge_lightfield_shards(*a, std::vector<std::string>{s0, s1}, out),
                  ErrorId::kShardMismatch);
  EXPECT_FALSE(fs::exists(out));
  // View 0 of the other capture, coded with the first analysis.
  const Status s = encoder::encode_lightfield_shard(other, *a, groups[0], 0, frames, 1,
                                                    (work / "s0-other.calf").string())
                       .status();
  expect_one_line(s, ErrorId::kShardMismatch);
  EXPECT_NE(s.message().find("view 0 frames 0-1 are not the images analysed"), std::string::npos)
      << s.to_string();
  // Views whose files the change did not touch still code (their files are rewritten from the
  // same pixels, byte-identical when the EXR writer is deterministic).
  auto reader = capture::CaptureSetReader::open(dir);
  ASSERT_TRUE(reader.ok());
  const std::string last = reader->image_path(n - 1, 0).filename().string();
  if (bytes_of(dir / last) == bytes_of(other / last)) {
    EXPECT_TRUE(encoder::encode_lightfield_shard(other, *a, groups[1], 0, frames, 1,
                                                 (work / "s1-same.calf").string())
                    .ok());
  }
}

// Capture shards (2 view groups x 2 frame ranges) rendered into one folder and joined hold the
// very files of a one-machine capture; a join with a shard missing writes no manifest.
TEST(CaptureShards, JoinedShardsEqualOneMachineCapture) {
  auto scene = samples::make_builtin_scene("spheres");
  ASSERT_TRUE(scene.ok());
  const fs::path one = scratch() / "capture-one", sharded = scratch() / "capture-sharded";
  samples::CaptureRequest r = tiny_request(*scene, 4);
  ASSERT_TRUE(samples::render_capture_set(*scene, r, one, nullptr).ok());
  const uint32_t n = static_cast<uint32_t>(r.rig.viewpoints.size());
  const auto groups = split(n, 2);
  for (uint32_t g = 0; g < 2; ++g) {
    for (uint32_t first : {0u, 2u}) {
      samples::CaptureRequest s = r;
      s.shard = true;
      s.views = groups[g];
      s.first_frame = first;
      s.last_frame = first + 1;
      if (g == 1 && first == 2) {
        // Before the last shard: the join names a missing image and writes nothing.
        auto early = capture::join_capture_shards(sharded);
        ASSERT_FALSE(early.ok());
        expect_one_line(early.status(), ErrorId::kShardMissing);
        EXPECT_FALSE(fs::exists(sharded / capture::kManifestFileName));
      }
      ASSERT_TRUE(samples::render_capture_set(*scene, s, sharded, nullptr).ok());
      EXPECT_FALSE(fs::exists(sharded / capture::kManifestFileName));
    }
  }
  auto joined = capture::join_capture_shards(sharded);
  ASSERT_TRUE(joined.ok()) << joined.status().to_string();
  EXPECT_EQ(*joined, 4u);
  size_t files = 0;
  for (const auto& e : fs::directory_iterator(one)) {
    ++files;
    EXPECT_TRUE(bytes_of(e.path()) == bytes_of(sharded / e.path().filename()))
        << e.path().filename();
  }
  size_t sharded_files = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(sharded)) ++sharded_files;
  EXPECT_EQ(files, sharded_files);  // markers removed
  EXPECT_EQ(files, size_t{n} * 4 + 1);

  // Markers of two different captures in one folder.
  const fs::path mixed = scratch() / "capture-mixed";
  samples::CaptureRequest s = r;
  s.shard = true;
  s.views = groups[0];
  s.first_frame = 0;
  s.last_frame = 3;
  ASSERT_TRUE(samples::render_capture_set(*scene, s, mixed, nullptr).ok());
  s.views = groups[1];
  s.frames = 5;  // another set: 5 frames
  ASSERT_TRUE(samples::render_capture_set(*scene, s, mixed, nullptr).ok());
  auto bad = capture::join_capture_shards(mixed);
  ASSERT_FALSE(bad.ok());
  expect_one_line(bad.status(), ErrorId::kShardMismatch);
}

}  // namespace
}  // namespace calf
