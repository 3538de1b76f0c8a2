// HeadlessSession (calf/player/headless_session.h) on a committed lightfield conformance clip with
// the CPU renderer: a session renders every pose of its eye path and writes its frames, compares
// them with ground truth and reports the same figures it returns, and refuses a missing or bad
// eye path with the eye path's error id.
#include "calf/player/headless_session.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "calf/capture/eye_path.h"
#include "calf/player/playback.h"

namespace calf::player {
namespace {

namespace fs = std::filesystem;

fs::path clip_path() {
  const char* root = std::getenv("CALF_SOURCE_DIR");
  return fs::path(root ? root : ".") / "tests/conformance/lightfield/auto_raw16_static.calf";
}

std::unique_ptr<Playback> open_playback() {
  PlaybackOptions options;
  options.use_gl = false;
  auto play = Playback::open(clip_path().string(), options, nullptr);
  EXPECT_TRUE(play.ok()) << play.status().to_string();
  return play.ok() ? std::move(*play) : nullptr;
}

// A fresh scratch directory named after the test.
fs::path scratch(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("calf_headless_session_test_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

// `poses` poses at the centre of the clip's view volume, turning about the vertical axis, 16 x 12
// pixels; `image_pattern` names ground-truth images (empty: none).
capture::EyePath eye_path(const Playback& play, size_t poses, const std::string& image_pattern) {
  const Box3& box = play.view_volume();
  capture::EyePath path;
  path.width = 16;
  path.height = 12;
  path.image_pattern = image_pattern;
  for (size_t k = 0; k < poses; ++k) {
    capture::EyePose p;
    p.position = {(box.min.x + box.max.x) / 2, (box.min.y + box.max.y) / 2,
                  (box.min.z + box.max.z) / 2};
    const double a = 0.7 * static_cast<double>(k);
    p.forward = {std::sin(a), 0, -std::cos(a)};
    path.poses.push_back(p);
  }
  return path;
}

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream(file, std::ios::binary) << text;
}

struct Captured {
  std::string report;
  std::vector<std::string> notices;
  HeadlessSinks sinks() {
    return {.report = [this](std::string_view t) { report += t; },
            .notice = [this](std::string_view l) { notices.emplace_back(l); }};
  }
};

// Options that render `poses` poses of a path written into `dir` to `out`, as `files`.
HeadlessSessionOptions render_options(const Playback& play, const fs::path& dir, size_t poses,
                                      const fs::path& out, FrameFiles files) {
  write_text(dir / "path.json", capture::serialize_eye_path(eye_path(play, poses, "")));
  HeadlessSessionOptions o;
  o.eye_path = dir / "path.json";
  o.out = out;
  o.frame_files = files;
  return o;
}

// Opens a session on `play` with `o` and runs it into `c`.
Expected<HeadlessSummary> run_session(Playback& play, const HeadlessSessionOptions& o,
                                      Captured* c) {
  CALF_ASSIGN_OR_RETURN(HeadlessSession session, HeadlessSession::open(play, nullptr, nullptr, o));
  return session.run(c->sinks());
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

// A playback of the clip and a scratch directory named after the test.
class HeadlessSessionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    play_ = open_playback();
    ASSERT_NE(play_, nullptr);
    dir_ = scratch(::testing::UnitTest::GetInstance()->current_test_info()->name());
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::unique_ptr<Playback> play_;
  fs::path dir_;
};

TEST_F(HeadlessSessionTest, RendersEveryPoseAndWritesItsFrames) {
  Playback& play = *play_;
  const fs::path& dir = dir_;
  const HeadlessSessionOptions o = render_options(play, dir, 3, dir / "out", FrameFiles::kBoth);
  Captured c;
  auto summary = run_session(play, o, &c);
  ASSERT_TRUE(summary.ok()) << summary.status().to_string();
  ASSERT_EQ(summary->poses.size(), 3u);
  EXPECT_EQ(summary->files_written, 6u);
  EXPECT_EQ(summary->compared, 0u);
  for (size_t k = 0; k < 3; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%05zu", k);
    EXPECT_TRUE(fs::is_regular_file(o.out / (std::string(name) + ".png"))) << name;
    EXPECT_TRUE(fs::is_regular_file(o.out / (std::string(name) + ".exr"))) << name;
    EXPECT_EQ(summary->poses[k].pose, k);
    EXPECT_TRUE(std::isnan(summary->poses[k].psnr));
    EXPECT_NE(c.report.find("pose " + std::to_string(k) + " frame 0: "), std::string::npos);
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(o.out), fs::directory_iterator()), 6);
  // One line per pose, then the summary line.
  EXPECT_EQ(count(c.report, "\n"), 4u);
  EXPECT_NE(c.report.find("3 poses: mean decode "), std::string::npos) << c.report;
  EXPECT_EQ(c.report.find("PSNR"), std::string::npos);
  EXPECT_TRUE(c.notices.empty());
}

TEST_F(HeadlessSessionTest, ComparisonFiguresMatchTheReport) {
  Playback& play = *play_;
  const fs::path& dir = dir_;
  // Ground truth: the frames of a first session as EXR (half floats), under the path's pattern.
  Captured ground_truth;
  ASSERT_TRUE(
      run_session(play, render_options(play, dir, 2, dir / "gt", FrameFiles::kExr), &ground_truth)
          .ok());
  write_text(dir / "gt" / capture::kEyePathFileName,
             capture::serialize_eye_path(eye_path(play, 2, "frame_{pose:05}.exr")));
  HeadlessSessionOptions o;
  o.compare = dir / "gt";
  o.out = dir / "out";
  Captured c;
  auto summary = run_session(play, o, &c);
  ASSERT_TRUE(summary.ok()) << summary.status().to_string();
  EXPECT_EQ(summary->compared, 2u);
  // The same renders: only the ground truth's half-float rounding differs.
  EXPECT_GT(summary->mean_psnr, 40.0);
  EXPECT_GT(summary->mean_ssim, 0.99);
  // Two frames and two heat maps.
  EXPECT_EQ(summary->files_written, 4u);
  double sum = 0;
  for (const HeadlessPose& p : summary->poses) sum += p.psnr;
  EXPECT_DOUBLE_EQ(summary->mean_psnr, sum / 2);
  char line[128];
  std::snprintf(line, sizeof line, "mean PSNR %.2f dB, mean SSIM %.4f\n", summary->mean_psnr,
                summary->mean_ssim);
  EXPECT_NE(c.report.find(line), std::string::npos) << c.report;
  std::snprintf(line, sizeof line, ", PSNR %.2f dB, SSIM %.4f\n", summary->poses[1].psnr,
                summary->poses[1].ssim);
  EXPECT_NE(c.report.find(line), std::string::npos) << c.report;
  EXPECT_NE(c.report.find("noise floor: unknown"), std::string::npos);
}

TEST_F(HeadlessSessionTest, RefusesAMissingOrBadEyePath) {
  Playback& play = *play_;
  const fs::path& dir = dir_;
  HeadlessSessionOptions o;
  EXPECT_EQ(HeadlessSession::open(play, nullptr, nullptr, o).status().id(),
            ErrorId::kPlaybackOption);
  o.eye_path = dir / "missing.json";
  EXPECT_EQ(HeadlessSession::open(play, nullptr, nullptr, o).status().id(), ErrorId::kFileOpen);
  write_text(dir / "bad.json", "{\"format\": \"calf-eye-path\", ");
  o.eye_path = dir / "bad.json";
  EXPECT_EQ(HeadlessSession::open(play, nullptr, nullptr, o).status().id(),
            ErrorId::kManifestSyntax);
  // Ground truth asked for along a path that names no images.
  write_text(dir / "path.json", capture::serialize_eye_path(eye_path(play, 1, "")));
  o.eye_path = dir / "path.json";
  auto session = HeadlessSession::open(play, nullptr, nullptr, o);
  ASSERT_TRUE(session.ok()) << session.status().to_string();
  EXPECT_EQ(session->eye_path().poses.size(), 1u);
  o.compare = dir;
  EXPECT_EQ(HeadlessSession::open(play, nullptr, nullptr, o).status().id(),
            ErrorId::kPlaybackOption);
}

}  // namespace
}  // namespace calf::player
