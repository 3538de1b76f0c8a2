#include "sweep_plan.h"

#include <algorithm>
#include <cstdlib>

#include <fmt/format.h>

namespace calf::bench {

const char* knob_name(Knob knob) {
  switch (knob) {
    case Knob::kBase:
      return "base";
    case Knob::kQ:
      return "q";
    case Knob::kCell:
      return "cell";
    case Knob::kWindow:
      return "window";
    case Knob::kAabbs:
      return "aabbs";
    case Knob::kDepth:
      return "depth";
    case Knob::kColour:
      return "colour";
    case Knob::kSuper:
      return "super";
    case Knob::kViews:
      return "views";
    case Knob::kSteps:
      return "steps";
    case Knob::kAv1:
      return "av1";
    case Knob::kDenoise:
      return "denoise";
    case Knob::kMargin:
      return "margin";
  }
  return "?";
}

const char* knob_title(Knob knob) {
  switch (knob) {
    case Knob::kBase:
      return "base configuration";
    case Knob::kQ:
      return "PSNR threshold Q (dB, calf-encode --psnr)";
    case Knob::kCell:
      return "colour cell size (px, calf-encode --cell)";
    case Knob::kWindow:
      return "depth window W (calf-encode --depth-window)";
    case Knob::kAabbs:
      return "AABB limit A (calf-encode --max-aabbs)";
    case Knob::kDepth:
      return "depth format (calf-encode --depth-format)";
    case Knob::kColour:
      return "colour format (calf-encode --color-format)";
    case Knob::kSuper:
      return "supercompression (calf-encode --supercompression)";
    case Knob::kViews:
      return "active views (calf-play --views)";
    case Knob::kSteps:
      return "ray-march steps (calf-play --steps)";
    case Knob::kAv1:
      return "AV1 colour, chroma:CRF (calf-encode --colour-codec av1 --av1-chroma --av1-crf, "
             "one stream per face)";
    case Knob::kDenoise:
      return "render-noise pre-filter window (calf-encode --denoise-window, Q as the base's)";
    case Knob::kMargin:
      return "noise margin (calf-encode --psnr auto --psnr-noise-margin, --denoise-window auto)";
  }
  return "?";
}

bool is_encode_knob(Knob knob) {
  return knob != Knob::kViews && knob != Knob::kSteps;
}

const std::vector<Knob>& all_knobs() {
  static const std::vector<Knob> knobs = {
      Knob::kQ,     Knob::kCell,  Knob::kWindow, Knob::kAabbs, Knob::kDepth,   Knob::kColour,
      Knob::kSuper, Knob::kViews, Knob::kSteps,  Knob::kAv1,   Knob::kDenoise, Knob::kMargin};
  return knobs;
}

bool is_noise_knob(Knob knob) {
  return knob == Knob::kDenoise || knob == Knob::kMargin;
}

std::vector<Knob> default_knobs(bool noisy) {
  std::vector<Knob> knobs;
  for (Knob k : all_knobs()) {
    if (k != Knob::kAv1 && (noisy || !is_noise_knob(k))) knobs.push_back(k);
  }
  return knobs;
}

const char* colour_coding_name(encoder::ColourCoding c) {
  switch (c) {
    case encoder::ColourCoding::kAuto:
      return "auto";
    case encoder::ColourCoding::kBc1:
      return "bc1";
    case encoder::ColourCoding::kBc7:
      return "bc7";
    case encoder::ColourCoding::kBc6h:
      return "bc6h";
    case encoder::ColourCoding::kRgba8:
      return "rgba8";
    case encoder::ColourCoding::kRgba16f:
      return "rgba16f";
    case encoder::ColourCoding::kAv1:
      return "av1";
  }
  return "?";
}

const char* depth_coding_name(encoder::DepthCoding d) {
  return d == encoder::DepthCoding::kBc5 ? "bc5" : "raw16";
}

const char* super_name(container::Compression c) {
  switch (c) {
    case container::Compression::kZstd:
      return "zstd";
    case container::Compression::kLzma2:
      return "lzma2";
    default:
      return "none";
  }
}

namespace {

std::string number(double v) {
  return fmt::format("{:g}", v);
}

// The base with knob `k` set to its i-th value; `value` and `label` as the tables print them.
SweepPoint varied(const SweepValues& s, Knob k, size_t i, uint32_t view_count) {
  SweepPoint p;
  p.knob = k;
  p.encode = s.base_encode;
  p.play = s.base_play;
  switch (k) {
    case Knob::kQ:
      p.encode.q = s.q[i];
      p.value = number(s.q[i]);
      p.label = fmt::format("Q{}", p.value);
      break;
    case Knob::kCell:
      p.encode.cell = s.cells[i];
      p.value = number(s.cells[i]);
      p.label = fmt::format("c{}", p.value);
      break;
    case Knob::kWindow:
      p.encode.window = s.windows[i];
      p.value = number(s.windows[i]);
      p.label = fmt::format("W{}", p.value);
      break;
    case Knob::kAabbs:
      p.encode.aabbs = s.aabbs[i];
      p.value = number(s.aabbs[i]);
      p.label = fmt::format("A{}", p.value);
      break;
    case Knob::kDepth:
      p.encode.depth = s.depth[i];
      p.value = p.label = depth_coding_name(s.depth[i]);
      break;
    case Knob::kColour:
      p.encode.colour = s.colour[i];
      p.value = p.label = colour_coding_name(s.colour[i]);
      break;
    case Knob::kSuper:
      p.encode.super = s.super[i];
      p.value = p.label = super_name(s.super[i]);
      break;
    case Knob::kViews: {
      const uint32_t v = s.views[i];
      p.play.views = v == 0 ? view_count : std::min(v, view_count);
      p.value = p.play.views == view_count ? fmt::format("{} (all)", view_count) : number(v);
      p.label = fmt::format("v{}", p.play.views);
      break;
    }
    case Knob::kSteps:
      p.play.steps = s.steps[i];
      p.value = number(s.steps[i]);
      p.label = fmt::format("s{}", p.value);
      break;
    case Knob::kAv1:
      p.encode.colour = encoder::ColourCoding::kAv1;
      p.encode.cell = s.av1_cell;
      p.encode.av1_444 = s.av1[i].chroma444;
      p.encode.av1_crf = s.av1[i].crf;
      p.encode.av1_keyframe_interval = s.av1_keyframe_interval;
      p.value = fmt::format("{}:{}", s.av1[i].chroma444 ? 444 : 420, s.av1[i].crf);
      p.label = "av1 " + p.value;
      break;
    case Knob::kDenoise:
      p.encode.denoise_window = s.denoise[i];
      p.value = number(s.denoise[i]);
      p.label = fmt::format("dn{}", p.value);
      break;
    case Knob::kMargin:
      p.encode.psnr_auto = true;
      p.encode.noise_margin = s.margins[i];
      p.value = number(s.margins[i]);
      p.label = fmt::format("m{}", p.value);
      break;
    case Knob::kBase:
      break;
  }
  return p;
}

size_t value_count(const SweepValues& s, Knob k) {
  switch (k) {
    case Knob::kQ:
      return s.q.size();
    case Knob::kCell:
      return s.cells.size();
    case Knob::kWindow:
      return s.windows.size();
    case Knob::kAabbs:
      return s.aabbs.size();
    case Knob::kDepth:
      return s.depth.size();
    case Knob::kColour:
      return s.colour.size();
    case Knob::kSuper:
      return s.super.size();
    case Knob::kViews:
      return s.views.size();
    case Knob::kSteps:
      return s.steps.size();
    case Knob::kAv1:
      return s.av1.size();
    case Knob::kDenoise:
      return s.denoise.size();
    case Knob::kMargin:
      return s.margins.size();
    case Knob::kBase:
      break;
  }
  return 0;
}

}  // namespace

ScenePlan plan_scene(const SweepValues& s, uint32_t view_count) {
  ScenePlan plan;
  SweepPoint base;
  base.encode = s.base_encode;
  base.play = s.base_play;
  // The base's view count as a player sees it: asking for more views than exist gives all.
  base.play.views = std::min(base.play.views, view_count);
  base.value = "base";
  base.label = "base";
  plan.points.push_back(base);
  for (Knob k : all_knobs()) {
    if (std::find(s.knobs.begin(), s.knobs.end(), k) == s.knobs.end()) continue;
    std::vector<size_t> rows;
    // AV1 colour and --psnr auto have no value equal to the base's: their tables start with the
    // base's row (BC colour, Q 50) to compare with.
    if (k == Knob::kAv1 || k == Knob::kMargin) rows.push_back(0);
    for (size_t i = 0; i < value_count(s, k); ++i) {
      SweepPoint p = varied(s, k, i, view_count);
      size_t at = plan.points.size();
      // The same configuration as an earlier point (the base, or a repeated value) is measured
      // once.
      for (size_t j = 0; j < plan.points.size(); ++j) {
        if ((j == 0 || plan.points[j].knob == k) && plan.points[j].encode == p.encode &&
            plan.points[j].play == p.play) {
          at = j;
          break;
        }
      }
      if (at == plan.points.size()) plan.points.push_back(p);
      rows.push_back(at);
    }
    plan.tables.emplace_back(k, rows);
  }
  return plan;
}

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> out;
  size_t at = 0;
  while (at <= text.size()) {
    size_t comma = text.find(',', at);
    if (comma == std::string::npos) comma = text.size();
    out.push_back(text.substr(at, comma - at));
    at = comma + 1;
  }
  return out;
}

bool parse_knobs(const std::string& text, bool noisy, std::vector<Knob>* out, std::string* error) {
  out->clear();
  for (const std::string& item : split_commas(text)) {
    if (item == "all") {
      for (Knob k : default_knobs(noisy)) {
        if (std::find(out->begin(), out->end(), k) == out->end()) out->push_back(k);
      }
    } else {
      const auto& known = all_knobs();
      auto it =
          std::find_if(known.begin(), known.end(), [&](Knob k) { return item == knob_name(k); });
      if (it == known.end()) {
        std::string names;
        for (Knob k : known) names += std::string(names.empty() ? "" : ", ") + knob_name(k);
        *error = fmt::format("unknown knob '{}' in --knobs (known: {}, all)", item, names);
        return false;
      }
      if (std::find(out->begin(), out->end(), *it) == out->end()) out->push_back(*it);
    }
  }
  return true;
}

bool parse_av1_points(const std::string& text, std::vector<Av1Point>* out, std::string* error) {
  out->clear();
  for (const std::string& item : split_commas(text)) {
    const size_t colon = item.find(':');
    const std::string chroma = item.substr(0, colon);
    const std::string crf = colon == std::string::npos ? "" : item.substr(colon + 1);
    char* end = nullptr;
    const unsigned long v = std::strtoul(crf.c_str(), &end, 10);
    if ((chroma != "420" && chroma != "444") || crf.empty() || *end != 0 || crf[0] == '-' ||
        crf[0] == '+' || v < 1 || v > 63) {
      *error =
          fmt::format("--av1: '{}' is not CHROMA:CRF with CHROMA 420 or 444 and CRF 1..63", item);
      return false;
    }
    out->push_back({chroma == "444", static_cast<uint32_t>(v)});
  }
  return true;
}

}  // namespace calf::bench
