#include "tiles_mode.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string_view>
#include <system_error>

#include "calf/capture/capture_set.h"
#include "calf/format/container.h"
#include "calf/format/version.h"
#include "command_line.h"

namespace calf::tools {

namespace {

int fail(const Status& status) {
  return print_error("calf-encode", status);
}

}  // namespace

int encode_tiles(const std::string& input, const std::string& out,
                 const TilesModeOptions& options) {
  std::filesystem::path dir = input;
  if (dir.filename() == capture::kManifestFileName) dir = dir.parent_path();
  if (dir.empty()) dir = ".";
  const auto start = std::chrono::steady_clock::now();
  auto reader = capture::CaptureSetReader::open(dir, options.max_image_pixels);
  if (!reader.ok()) return fail(reader.status());

  encoder::TilesBuildOptions build = options.build;
  // One progress line rewritten in place: the build of a 512² capture takes minutes.
  std::string_view last_stage;
  if (!options.quiet) {
    build.progress = [&last_stage](std::string_view stage, double fraction) {
      std::fprintf(stderr, "\rcalf-encode: tiles %-12.*s %3.0f %%", static_cast<int>(stage.size()),
                   stage.data(), 100.0 * fraction);
      last_stage = stage;
    };
  }
  encoder::TilesBuildReport report;
  auto tiles = encoder::build_tiles(*reader, options.frame, build, &report);
  if (!last_stage.empty()) std::fputc('\n', stderr);
  if (!tiles.ok()) return fail(tiles.status());

  auto writer = container::Writer::create(out, options.encode.levels);
  if (!writer.ok()) return fail(writer.status());
  encoder::TilesEncodeOptions encode = options.encode;
  const double fps = reader->manifest().fps;
  if (fps > 0 && fps <= 1e6) {
    // The frame's rate as a fraction over 1000 (the track's timing is informative for one frame).
    encode.fps_numerator = static_cast<uint32_t>(fps * 1000.0 + 0.5);
    encode.fps_denominator = 1000;
  }
  encoder::TilesEncodeStats stats;
  if (Status s = encoder::encode_tiles_track(*tiles, encode, &*writer, &stats); !s.ok()) {
    return fail(s);
  }
  if (Status s = writer->set_metadata("encoder", std::string("calf-encode ") + kVersionString);
      !s.ok()) {
    return fail(s);
  }
  if (Status s = writer->set_metadata("tiles_frame", std::to_string(options.frame)); !s.ok()) {
    return fail(s);
  }
  if (Status s = writer->finish(); !s.ok()) return fail(s);

  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::error_code ec;  // the size is informative: 0 if the file cannot be stat'ed
  const uintmax_t size = std::filesystem::file_size(out, ec);
  const uint64_t bytes = ec ? 0 : size;
  std::fprintf(stderr, "%s", encoder::format_tiles_report(report).c_str());
  std::fprintf(
      stderr,
      "calf-encode: wrote %s in %.2f s (tiles: %u tiles, %u triangles, atlas %u x %u "
      "%s at %.2f dB; %llu bytes: quads %llu, atlas %llu)\n",
      out.c_str(), seconds, stats.tiles, 2 * stats.tiles, stats.atlas_width, stats.atlas_height,
      encode.atlas_format == encoder::TilesAtlasFormat::kBc7 ? "BC7" : "RGBA8", stats.atlas_psnr_db,
      static_cast<unsigned long long>(bytes), static_cast<unsigned long long>(stats.quads_stored),
      static_cast<unsigned long long>(stats.atlas_stored));
  return 0;
}

}  // namespace calf::tools
