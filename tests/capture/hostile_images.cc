// A test tool: writes the small hostile images of tests/cli/hostile_images.sh into DIR, each a
// few bytes to a few hundred KB (tests/capture/hostile_images.h):
//   big.png         a PNG declaring 16384 x 16384 RGBA over 64 bytes of image data
//   cut.png         a 64 x 64 RGBA PNG whose image data stops half way (libpng's error)
//   ok.png          a valid 2 x 2 RGBA PNG
//   big.exr         an OpenEXR header (ZIP) of 16384 x 16384, channel R, without pixels
//   wide.exr        an OpenEXR header of 4096 x 4096 with R and 63 more channels
//   e000_00000.exr  an OpenEXR header of 16384 x 8192 with R G B Z (the equirectangular image)
//   attribute.exr   an OpenEXR header whose string attribute declares 2^31 - 1 bytes (100 bytes)
//   set/            a capture set manifest of face size 16384 and its one image, big_set.exr
//   set_exr/        a capture set of face size 16 whose one image is attribute.exr
//   seurat_*.json   Seurat manifests of 16 x 16 cameras naming them (seurat_focal.json: every
//                   focal term 1e6, which implies a face size of 16384)
//   equirect.json   an equirectangular set of one viewpoint naming it
//   model.obj/.mtl  a textured triangle whose map_Kd is named by the script
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "hostile_images.h"

namespace {

void write(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: hostile_images DIR\n");
    return 2;
  }
  namespace t = calf::test;
  const std::filesystem::path dir = argv[1];
  std::filesystem::create_directories(dir);
  write(dir / "big.png", t::png_declaring(16384, 16384));
  std::string raw;
  for (int y = 0; y < 64; ++y) raw += '\0' + std::string(4 * 64, '\x7f');
  const std::string stream = t::zlib_stored(raw);
  write(dir / "cut.png", t::png_file(64, 64, 8, 6, stream.substr(0, stream.size() / 2)));
  const std::string row = '\0' + std::string(8, '\x40');  // filter 0, two RGBA pixels
  write(dir / "ok.png", t::png_file(2, 2, 8, 6, t::zlib_stored(row + row)));
  write(dir / "big.exr", t::exr_header_only(16384, 16384, {"R"}));
  std::vector<std::string> many = {"R"};
  for (int c = 1; c < 64; ++c) many.push_back("C" + std::to_string(c));
  write(dir / "wide.exr", t::exr_header_only(4096, 4096, many));
  write(dir / "e000_00000.exr", t::exr_header_only(16384, 8192, {"B", "G", "R", "Z"}));
  const std::string attribute = t::exr_with("comments", "string", 0x7fffffff, "abc");
  write(dir / "attribute.exr", attribute);
  write(dir / "seurat_attribute.json", t::seurat_manifest(16, "attribute.exr", "attribute.exr"));
  for (const char* set : {"set", "set_exr"}) {
    const bool big = std::string(set) == "set";
    std::filesystem::create_directories(dir / set);
    write(dir / set / "manifest.json",
          "{\"format\": \"calf-capture-set\", \"version\": 1, \"frame_count\": 1, "
          "\"fps\": 30, \"face_size\": " +
              std::string(big ? "16384" : "16") +
              ", \"file_pattern\": \"view{view:03}_frame{frame:05}.exr\", \"material\": false, "
              "\"view_volume\": {\"min\": [-1, -1, -1], \"max\": [1, 1, 1]}, \"viewpoints\": "
              "[{\"name\": \"v\", \"position\": [0, 0, 0]}]}\n");
    write(dir / set / "view000_frame00000.exr",
          big ? t::exr_header_only(16384, 6 * 16384, {"B", "G", "R", "Z"}) : attribute);
  }
  write(dir / "seurat_png.json", t::seurat_manifest(16, "big.png", "big.exr"));
  write(dir / "seurat_exr.json", t::seurat_manifest(16, "big.exr", "big.exr"));
  write(dir / "seurat_wide.json", t::seurat_manifest(16, "wide.exr", "big.exr"));
  write(dir / "seurat_cut.json", t::seurat_manifest(64, "cut.png", "big.exr"));
  write(dir / "seurat_focal.json", t::seurat_manifest(16, "ok.png", "big.exr", 1e6));
  write(dir / "equirect.json",
        "{\"format\": \"calf-equirect-set\", \"version\": 1, \"frame_count\": 1, \"fps\": 30, "
        "\"file_pattern\": \"e{view:03}_{frame:05}.exr\", \"view_volume\": {\"min\": [-1, -1, -1], "
        "\"max\": "
        "[1, 1, 1]}, \"viewpoints\": [{\"name\": \"v\", \"position\": [0, 0, 0]}]}\n");
  write(dir / "model.obj",
        "mtllib model.mtl\nusemtl m\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
        "f 1/1 2/2 3/3\n");
  return 0;
}
