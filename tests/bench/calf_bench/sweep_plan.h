// calf-bench: which points a scene's sweep measures. The base configuration first, then for each
// chosen knob the base with that knob set to each of its values; a value that gives the base
// configuration again (Q 50, cell 32, ...) is not measured twice: its table row is the base
// point's.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "sweep.h"

namespace calf::bench {

// One AV1 colour point: 4:2:0 (SVT-AV1) or 4:4:4 (libaom) and the CRF ("420:32").
struct Av1Point {
  bool chroma444 = false;
  uint32_t crf = 32;
  friend bool operator==(const Av1Point&, const Av1Point&) = default;
};

// The values each knob takes, and the base they vary around.
struct SweepValues {
  EncodeConfig base_encode;  // calf-encode's defaults, with cell 32
  PlayConfig base_play;      // calf-play's defaults (9 views, 64 steps)
  std::vector<Knob> knobs;   // which knobs to sweep (table order is all_knobs()'s)
  std::vector<double> q = {35, 40, 45, 50, 55};
  std::vector<uint32_t> cells = {16, 32, 64};
  std::vector<uint32_t> windows = {1, 2, 4};
  std::vector<uint32_t> aabbs = {1, 2, 4};
  std::vector<encoder::DepthCoding> depth = {encoder::DepthCoding::kRaw16,
                                             encoder::DepthCoding::kBc5};
  std::vector<encoder::ColourCoding> colour = {
      encoder::ColourCoding::kAuto, encoder::ColourCoding::kBc1, encoder::ColourCoding::kBc7};
  std::vector<container::Compression> super = {container::Compression::kZstd,
                                               container::Compression::kLzma2};
  std::vector<uint32_t> views = {1, 2, 4, 0};  // 0 = all of the scene's views
  std::vector<uint32_t> steps = {16, 32, 64, 128};
  std::vector<Av1Point> av1 = {{false, 20}, {false, 32}, {true, 32}};
  // The AV1 points' cell (the capture's face size: one stream per face) and key-frame interval
  // (the capture's frame count: one key frame per stream).
  uint32_t av1_cell = 128, av1_keyframe_interval = 8;
  std::vector<uint32_t> denoise = {0, 4, 16};  // --denoise-window at the base's Q
  std::vector<double> margins = {2, 4};        // --psnr auto --psnr-noise-margin
};

// A scene's points and, per knob, the rows of its table (indices into `points`, in the order of
// the knob's values; the base point's index where a value is the base's, and first in the av1
// and margin tables, whose values never are).
struct ScenePlan {
  std::vector<SweepPoint> points;  // points[0] is the base
  std::vector<std::pair<Knob, std::vector<size_t>>> tables;
};

// The plan for a scene with `view_count` viewpoints (the view knob's "all" and values above the
// count become the count).
ScenePlan plan_scene(const SweepValues& values, uint32_t view_count);

// The items of a comma-separated list, empty ones kept ("" is one empty item).
std::vector<std::string> split_commas(const std::string& text);

// Parses a comma-separated knob list ("q,cell,views" or "all"); the error names the bad item
// and lists the known knobs.
// "all" is default_knobs(noisy).
bool parse_knobs(const std::string& text, bool noisy, std::vector<Knob>* out, std::string* error);

// Parses AV1 points "CHROMA:CRF,..." (CHROMA 420 or 444, CRF 1..63); the error names the item.
bool parse_av1_points(const std::string& text, std::vector<Av1Point>* out, std::string* error);

}  // namespace calf::bench
