// calf-export: a mesh track of a .calf clip (a full scene or its visible set) or a tiles track
// (layered quad tiles and their atlas) to glTF 2.0 (.glb / .gltf, written by tinygltf) or OBJ
// (+ .mtl, written by assimp's exporter) (calf/export/mesh_export.h, calf/export/tiles_export.h,
// docs/EXPORT.md). Errors are one line with a stable id and exit status 1; usage errors exit 2;
// every file is written whole or not at all.
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <variant>
#include <vector>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "calf/decoder/mesh_track.h"
#include "calf/decoder/tiles_track.h"
#include "calf/export/mesh_export.h"
#include "calf/export/tiles_export.h"
#include "calf/format/av1_hdr_colour.h"
#include "calf/format/container.h"
#include "calf/format/files.h"
#include "command_line.h"

namespace {

constexpr const char* kCommand = "calf-export";

int fail(const calf::Status& status) {
  return calf::tools::print_error(kCommand, status);
}

std::string file_name(const std::string& path) {
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// What a kind's export reads: the clip, the track and the command line.
struct ExportRequest {
  const calf::container::Reader& reader;
  const std::string& clip;
  const std::string& out;
  const std::string& base;  // OUT without its extension: side files are named after it
  uint16_t track;
  uint32_t frame;
  calf::exporter::MeshExportFormat format;
  calf::exporter::GltfOptions gltf;
  const CLI::App& app;
  double alpha_mask;
  const std::string& subdivide;
};

// What a kind's export made: its files (not yet written), the summary line and a warning.
struct ExportResult {
  std::vector<calf::exporter::ExportedFile> files;
  std::string summary, warning;
};

// A tiles track: one mesh of the tiles, the atlas as its texture. The exit status of an error
// (printed), or -1.
int export_tiles(const ExportRequest& r, ExportResult* result) {
  if (r.frame != 0) {
    return fail(calf::Status(
        calf::ErrorId::kExportInput,
        fmt::format("{}: frame {} is past the tiles track's 1 frame", r.clip, r.frame)));
  }
  auto set = calf::decoder::decode_tiles_track(r.reader, r.track);
  if (!set.ok()) return fail(set.status().with_context(r.clip));
  calf::exporter::TilesExportOptions options;
  options.gltf = r.gltf;
  if (r.app.get_option("--alpha-mask")->count() > 0) {
    if (!(r.alpha_mask > 0 && r.alpha_mask < 1)) {
      return calf::tools::print_error(
          kCommand,
          calf::Status(calf::ErrorId::kExportTilesOption,
                       fmt::format("alpha mask cutoff {} is not in (0, 1)", r.alpha_mask)),
          2);
    }
    options.alpha_cutoff = r.alpha_mask;
  }
  const std::string& subdivide = r.subdivide;
  if (subdivide != "auto") {
    uint32_t n = 0;
    const auto [end, ec] =
        std::from_chars(subdivide.data(), subdivide.data() + subdivide.size(), n);
    if (ec != std::errc() || end != subdivide.data() + subdivide.size() || n == 0) {
      return calf::tools::print_error(
          kCommand,
          calf::Status(calf::ErrorId::kExportTilesOption,
                       "subdivide " + subdivide + " is not auto or 1 .. 16"),
          2);
    }
    options.subdivide = n;
  }
  calf::exporter::TilesExportStats stats;
  auto files =
      calf::exporter::export_tile_set(set.value(), r.format, file_name(r.base), options, &stats);
  if (!files.ok()) {
    const bool usage = files.status().id() == calf::ErrorId::kExportTilesOption;
    return calf::tools::print_error(kCommand, files.status().with_context(r.clip), usage ? 2 : 1);
  }
  result->files = std::move(files.value());
  result->summary = fmt::format(
      "{}: {} tiles, {} vertices, {} triangles ({:.2f} x the {} of whole tiles, subdivision {} "
      "to {}), atlas {} x {}, largest affine texture error {:.3f} texels",
      r.out, stats.tiles, stats.vertices, stats.triangles,
      static_cast<double>(stats.triangles) / static_cast<double>(2 * stats.tiles), 2 * stats.tiles,
      stats.min_subdivide, stats.max_subdivide, stats.atlas_width, stats.atlas_height,
      stats.max_texel_error);
  if (options.subdivide != 0 && stats.max_texel_error > calf::exporter::kTilesTexelErrorWarning) {
    result->warning = fmt::format(
        "{}: warning: --subdivide {} leaves an affine texture error of {:.3f} texels (above "
        "{:.0f}); --subdivide auto keeps every tile within 1",
        kCommand, subdivide, stats.max_texel_error, calf::exporter::kTilesTexelErrorWarning);
  }
  return -1;
}

// A mesh track: its objects at --frame as nodes, prototypes as shared meshes.
int export_mesh(const ExportRequest& r, ExportResult* result) {
  auto mesh = calf::decoder::MeshTrack::open(r.reader, r.track);
  if (!mesh.ok()) return fail(mesh.status().with_context(r.clip));
  calf::exporter::MeshExportStats stats;
  auto files = calf::exporter::export_mesh_track(mesh.value(), r.frame, r.format, file_name(r.base),
                                                 &stats, r.gltf);
  if (!files.ok()) return fail(files.status().with_context(r.clip));
  result->files = std::move(files.value());
  result->summary = fmt::format(
      "{}: frame {}: {} objects, {} meshes, {} vertices, {} triangles, {} textures", r.out, r.frame,
      stats.objects, stats.meshes, stats.vertices, stats.triangles, stats.textures);
  return -1;
}

// The kinds calf-export writes, in the order their names are listed in messages: each with the
// options only it reads (given for a track of another kind: a usage error) and its export.
struct ExportKind {
  calf::container::TrackKind kind;
  const char* name;
  std::vector<const char*> own_options;
  int (*run)(const ExportRequest& request, ExportResult* result);
};

const std::vector<ExportKind>& export_kinds() {
  static const std::vector<ExportKind> kinds = {
      {calf::container::TrackKind::kMesh, "mesh", {}, export_mesh},
      {calf::container::TrackKind::kTiles, "tiles", {"--subdivide", "--alpha-mask"}, export_tiles},
  };
  return kinds;
}

// The entry of track kind number `kind`, or nullptr for a kind calf-export does not write.
const ExportKind* find_export_kind(uint16_t kind) {
  for (const ExportKind& k : export_kinds()) {
    if (static_cast<uint16_t>(k.kind) == kind) return &k;
  }
  return nullptr;
}

// --web DIR: the web player (web/index.html, web/src/*.js), the npm modules its page imports and
// the clip, in a folder any static web host serves. The files are looked up next to the
// executable's prefix (share/calf/web, cmake --install) and then in the source tree it was built
// from (web/, build/npm/node_modules).
namespace fs = std::filesystem;

// The npm modules' files the page loads, relative to node_modules (and to the folder's npm/).
constexpr const char* kWebNpmFiles[] = {
    "fzstd/esm/index.mjs",
    "fzstd/LICENSE",
    "hash-wasm/dist/index.esm.js",
    "hash-wasm/LICENSE",
    "xz-decompress/dist/package/xz-decompress.js",
    "xz-decompress/package.json",
};
// The WebAssembly AV1 decoder the page loads where the browser's WebCodecs does not decode a
// clip's AV1 colour (web/index.html: libav.js's av1-opus variant, its single-threaded WebAssembly
// build; package.json names its licence, LGPL-2.1): copied only for a clip with AV1 colour.
constexpr const char* kWebAv1Files[] = {
    "@libav.js/variant-av1-opus/dist/libav-av1-opus.mjs",
    "@libav.js/variant-av1-opus/dist/libav-6.10.9.0-av1-opus.wasm.mjs",
    "@libav.js/variant-av1-opus/dist/libav-6.10.9.0-av1-opus.wasm.wasm",
    "@libav.js/variant-av1-opus/package.json",
};
// What the page's imports of build/npm become in the folder.
constexpr const char* kWebNpmFrom = "../build/npm/node_modules/";
constexpr const char* kWebNpmTo = "./npm/";
constexpr const char* kWebClipMeta = "<meta name=\"calf-clip\" content=\"\">";

struct WebSources {
  fs::path web, npm;  // web/ (index.html, src/) and node_modules
};

// The first place holding every file (with `av1`, kWebAv1Files too), or CALF-E485 naming the
// first file missing in the last.
calf::Expected<WebSources> find_web_sources(bool av1) {
  std::vector<WebSources> candidates;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path share = exe.parent_path().parent_path() / "share" / "calf" / "web";
    candidates.push_back({share, share / "npm"});
  }
  candidates.push_back({CALF_WEB_SOURCE_DIR, CALF_WEB_NPM_DIR});
  std::string missing;
  for (const WebSources& c : candidates) {
    std::vector<fs::path> needed = {c.web / "index.html", c.web / "src" / "player.js"};
    for (const char* f : kWebNpmFiles) needed.push_back(c.npm / f);
    if (av1) {
      for (const char* f : kWebAv1Files) needed.push_back(c.npm / f);
    }
    missing.clear();
    for (const fs::path& f : needed) {
      if (!fs::is_regular_file(f, ec)) {
        missing = f.string();
        break;
      }
    }
    if (missing.empty()) return c;
  }
  return calf::Status(calf::ErrorId::kExportWebFiles,
                      "the web player's files are not installed or built: no " + missing +
                          " (tools/setup.sh installs build/npm)");
}

calf::Expected<std::string> read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) {
    return calf::Status(calf::ErrorId::kFileRead, "cannot read " + path.string());
  }
  return text;
}

// Replaces every `from` in `text` by `to`; the count replaced.
size_t replace_all(std::string* text, const std::string& from, const std::string& to) {
  size_t count = 0;
  for (size_t at = text->find(from); at != std::string::npos; at = text->find(from, at)) {
    text->replace(at, from.size(), to);
    at += to.size();
    ++count;
  }
  return count;
}

// `text` as one POSIX shell word: unchanged when it holds only characters no shell treats
// specially, else in single quotes (each ' written as '\'').
std::string shell_word(const std::string& text) {
  const bool plain = !text.empty() && std::all_of(text.begin(), text.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) ||
           (c != 0 && std::strchr("/._-+,:@%=", c) != nullptr);
  });
  if (plain) return text;
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

// A folder being written, removed unless committed.
class TempDir {
 public:
  explicit TempDir(fs::path path) : path_(std::move(path)) {}
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() {
    if (!path_.empty()) {
      std::error_code ec;
      fs::remove_all(path_, ec);
    }
  }
  const fs::path& path() const { return path_; }
  void release() { path_.clear(); }

 private:
  fs::path path_;
};

int export_web(const std::string& clip, const std::string& dir, bool quiet) {
  // The clip must be one calf reads (not a calf file, unreadable: its own id). A lightfield track
  // with AV1 colour takes the WebAssembly decoder along.
  bool av1 = false;
  {
    auto reader = calf::container::Reader::open(clip);
    if (!reader.ok()) return fail(reader.status());
    for (const auto& track : reader->tracks()) {
      const auto* lf = std::get_if<calf::container::LightfieldTrackHeader>(&track.header);
      if (lf != nullptr && calf::lf::is_av1_colour(lf->colour_format)) av1 = true;
    }
  }
  std::error_code ec;
  const fs::path target = fs::path(dir).lexically_normal();
  const fs::path target_name = target.filename().empty() ? target.parent_path() : target;
  const auto state = fs::symlink_status(target_name, ec);
  if (fs::exists(state)) {
    if (!fs::is_directory(state) || !fs::is_empty(target_name, ec) || ec) {
      return fail(calf::Status(calf::ErrorId::kExportWebFolder,
                               dir + " exists and is not an empty folder"));
    }
  }
  auto sources = find_web_sources(av1);
  if (!sources.ok()) return fail(sources.status());
  const WebSources& src = sources.value();

  // The clip's name in the folder: its file name, characters a URL would have to escape as _.
  std::string clip_name = file_name(clip);
  for (char& c : clip_name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '-' || c == '_')) {
      c = '_';
    }
  }
  auto page = read_text(src.web / "index.html");
  if (!page.ok()) return fail(page.status());
  std::string html = std::move(page.value());
  const size_t imports = replace_all(&html, kWebNpmFrom, kWebNpmTo);
  const size_t metas =
      replace_all(&html, kWebClipMeta, "<meta name=\"calf-clip\" content=\"" + clip_name + "\">");
  if (imports == 0 || metas != 1) {
    return fail(calf::Status(calf::ErrorId::kExportWebFiles,
                             (src.web / "index.html").string() +
                                 " is not the page calf-export knows (no npm imports or no "
                                 "calf-clip meta tag)"));
  }

  const fs::path parent = target_name.has_parent_path() ? target_name.parent_path() : ".";
  TempDir temp(parent / fmt::format(".{}.tmp-{}", target_name.filename().string(), getpid()));
  const auto write_error = [&](const std::string& what) {
    return fail(
        calf::Status(calf::ErrorId::kFileWrite,
                     fmt::format("cannot write {}: {}", what, ec ? ec.message() : "write failed")));
  };
  if (!fs::create_directory(temp.path(), ec) || ec) return write_error(temp.path().string());
  uint64_t files = 0, bytes = 0;
  const auto copy = [&](const fs::path& from, const fs::path& to) {
    fs::create_directories(to.parent_path(), ec);
    if (!ec) fs::copy_file(from, to, ec);
    if (ec) return false;
    ++files;
    bytes += fs::file_size(to, ec);
    return !ec;
  };
  {
    std::ofstream out(temp.path() / "index.html", std::ios::binary);
    out << html;
    out.close();
    if (!out) return write_error((temp.path() / "index.html").string());
    ++files;
    bytes += html.size();
  }
  for (const auto& entry : fs::directory_iterator(src.web / "src", ec)) {
    if (entry.path().extension() != ".js") continue;
    if (!copy(entry.path(), temp.path() / "src" / entry.path().filename())) {
      return write_error(entry.path().string());
    }
  }
  if (ec) return write_error((src.web / "src").string());
  for (const char* f : kWebNpmFiles) {
    if (!copy(src.npm / f, temp.path() / kWebNpmTo / f)) return write_error(f);
  }
  if (av1) {
    for (const char* f : kWebAv1Files) {
      if (!copy(src.npm / f, temp.path() / kWebNpmTo / f)) return write_error(f);
    }
  }
  if (!copy(clip, temp.path() / clip_name)) return write_error(clip);
  // Into place whole: a new folder, or over an empty one (rename(2) replaces an empty folder).
  fs::rename(temp.path(), target_name, ec);
  if (ec) return write_error(dir);
  temp.release();
  if (!quiet) {
    std::printf("%s: the web player and %s (%llu files, %llu bytes); serve it with:\n", dir.c_str(),
                clip_name.c_str(), static_cast<unsigned long long>(files),
                static_cast<unsigned long long>(bytes));
    std::printf(
        "python3 -m http.server --bind 127.0.0.1 --directory %s 8000  # then open "
        "http://127.0.0.1:8000/\n",
        shell_word(dir).c_str());
  }
  return calf::tools::kExitOk;
}

}  // namespace

static int command_main(int argc, char** argv) {
  CLI::App app{
      "calf-export: write a mesh track of a .calf clip (the full scene or its visible set, "
      "calf-encode --mode mesh) as glTF 2.0 or OBJ for engines (docs/EXPORT.md).\n"
      "The format follows the output's extension: .glb (binary glTF, one file), .gltf (glTF JSON "
      "with its buffer OUT.bin beside it) or .obj (with its material library OUT.mtl beside it). "
      "Objects become nodes with their transform at --frame; objects drawing a whole prototype "
      "share its mesh (glTF instancing); a visible-set object gets a mesh of its visible "
      "triangles only. Vertex colours, normals, UVs and material base colour / emission (clamped "
      "to 1) are kept, and base-colour textures as PNG (embedded in a .glb / .gltf's buffer; "
      "OUT_texture<n>.png beside an .obj).\n"
      "A tiles track (layered quad tiles, SPEC §11.2) becomes one mesh of two triangles per tile "
      "(2 x N^2 for a tile split N x N: --subdivide, by default each tile's own N), written back "
      "to front from the view region's centre, with one unlit material (KHR_materials_unlit): the "
      "atlas as PNG with straight "
      "alpha, alphaMode BLEND, single-sided (embedded in a .glb / .gltf; OUT_atlas.png beside an "
      ".obj, as map_Kd and map_d). Texture coordinates are the tiles' projective ones divided out "
      "per vertex (affine "
      "inside a triangle: --subdivide bounds the difference; the largest is printed in texels, "
      "and a warning when a fixed --subdivide leaves more than 2).\n"
      "A mesh track's glTF carries the lighting calf-play shades it with: its key light as a "
      "KHR_lights_punctual directional light, the ambient share as the scene's extras "
      "\"calf_ambient_radiance\" (glTF has no ambient light), and its materials as diffuse only "
      "(KHR_materials_specular factor 0), double-sided.\n"
      "--meshopt compresses a .glb / .gltf's vertex and index data losslessly with "
      "EXT_meshopt_compression (a required extension: the loader needs a meshoptimizer decoder, "
      "e.g. three.js's GLTFLoader.setMeshoptDecoder); the sizes are printed."
      " Each file is written whole or not at all (a temporary file renamed into "
      "place); an output or side file that is the input clip is refused (CALF-E007).\n"
      "--web DIR writes the web player with a copy of the clip (any clip calf reads) into a new "
      "or empty folder any static web host serves, and prints the command that serves it "
      "locally.\n" +
      std::string(calf::tools::kExitStatusHelp)};
  std::string clip, out;
  uint32_t frame = 0;
  int track_option = -1;
  bool quiet = false;
  bool meshopt = false;
  double alpha_mask = 0;
  std::string subdivide = "auto";
  std::string web;
  app.add_option("CLIP", clip, "input .calf holding a mesh or tiles track")->required();
  CLI::Option* output = app.add_option("-o,--output", out, "output .glb, .gltf or .obj");
  CLI::Option* web_option = app.add_option(
      "--web", web,
      "instead of -o: write DIR, a folder any static web host serves: the web player (its page, "
      "scripts and npm modules) and a copy of CLIP, which the page opens; a new or empty folder, "
      "written whole or not at all (docs/EXPORT.md)");
  web_option->excludes(output);
  app.add_option("--frame", frame,
                 "the frame whose transforms and vertex states are exported (default 0)")
      ->default_val(0);
  app.add_option("--track", track_option,
                 "index of the mesh or tiles track in the clip, 0..65535 (default: the first "
                 "mesh or tiles track)")
      ->check(CLI::Range(0, 65535));
  app.add_option("--subdivide", subdivide,
                 "tiles track: split each of a tile's two triangles into N x N, 1..16, to bound "
                 "the affine texture approximation, or auto: each tile the smallest N that keeps "
                 "its error within 1 atlas texel (default auto)")
      ->default_val("auto");
  app.add_option("--alpha-mask", alpha_mask,
                 "tiles track: alphaMode MASK with this alphaCutoff, in (0, 1), instead of BLEND: "
                 "alpha-tested tiles that need no draw order, with hard edges");
  app.add_flag("--meshopt", meshopt,
               ".glb / .gltf: compress vertex and index data with EXT_meshopt_compression "
               "(meshoptimizer; a required extension)");
  app.add_flag("-q,--quiet", quiet, "print nothing on success");
  if (const int exit = calf::tools::parse_command_line(app, kCommand, argc, argv); exit >= 0) {
    return exit;
  }
  if (web_option->count() > 0) {
    for (const char* option : {"--frame", "--track", "--subdivide", "--alpha-mask", "--meshopt"}) {
      if (app.get_option(option)->count() > 0) {
        return calf::tools::usage_error(kCommand,
                                        std::string(option) + " applies to -o, not to --web");
      }
    }
    return export_web(clip, web, quiet);
  }
  if (output->count() == 0) {
    return calf::tools::usage_error(kCommand, "--output or --web is required");
  }

  auto format = calf::exporter::mesh_export_format_from_path(out);
  if (!format.ok()) return calf::tools::print_error(kCommand, format.status(), 2);
  if (meshopt && format.value() == calf::exporter::MeshExportFormat::kObj) {
    return calf::tools::print_error(
        kCommand,
        calf::Status(calf::ErrorId::kExportInput,
                     "--meshopt applies to a .glb or .gltf output, not " + file_name(out)),
        2);
  }
  calf::exporter::GltfOptions gltf;
  gltf.meshopt = meshopt;
  auto reader = calf::container::Reader::open(clip);
  if (!reader.ok()) return fail(reader.status());
  const auto& tracks = reader.value().tracks();
  const auto exportable = [&](size_t t) {
    return find_export_kind(tracks[t].record.kind) != nullptr;
  };
  // "mesh or tiles", "no mesh track and no tiles track": the table's names.
  std::string kinds_or, no_kinds;
  for (const ExportKind& k : export_kinds()) {
    const bool first = kinds_or.empty();
    kinds_or += fmt::format("{}{}", first ? "" : " or ", k.name);
    no_kinds += fmt::format("{}{} track", first ? "no " : " and no ", k.name);
  }
  int track = track_option;
  if (track < 0) {
    for (size_t i = 0; i < tracks.size(); ++i) {
      if (exportable(i)) {
        track = static_cast<int>(i);
        break;
      }
    }
    if (track < 0) {
      return fail(calf::Status(calf::ErrorId::kExportInput, clip + ": the clip has " + no_kinds));
    }
  }
  if (static_cast<size_t>(track) >= tracks.size() || !exportable(track)) {
    return fail(calf::Status(calf::ErrorId::kExportInput,
                             fmt::format("{}: track {} is not a {} track", clip, track, kinds_or)));
  }
  const ExportKind& kind = *find_export_kind(tracks[track].record.kind);
  for (const ExportKind& other : export_kinds()) {
    if (&other == &kind) continue;
    for (const char* option : other.own_options) {
      if (app.get_option(option)->count() > 0) {
        return calf::tools::usage_error(
            kCommand, fmt::format("{} applies to a {} track; track {} is a {} track", option,
                                  other.name, track, kind.name));
      }
    }
  }

  // The side files (.bin of a .gltf, .mtl of an .obj) go beside the output, named after it.
  const std::string base = out.substr(0, out.find_last_of('.'));
  const ExportRequest request{.reader = reader.value(),
                              .clip = clip,
                              .out = out,
                              .base = base,
                              .track = static_cast<uint16_t>(track),
                              .frame = frame,
                              .format = format.value(),
                              .gltf = gltf,
                              .app = app,
                              .alpha_mask = alpha_mask,
                              .subdivide = subdivide};
  ExportResult exported;
  if (const int exit = kind.run(request, &exported); exit >= 0) return exit;
  const std::vector<calf::exporter::ExportedFile>& files = exported.files;

  // No output may replace the clip: neither OUT nor a side file beside it (CALF-E007), checked
  // for every file before any is written.
  std::vector<std::string> paths;
  for (const auto& file : files) paths.push_back(file.suffix.empty() ? out : base + file.suffix);
  const std::vector<std::string> inputs = {clip};
  for (const std::string& path : paths) {
    if (calf::Status s = calf::files::check_output_not_input(path, inputs); !s.ok()) return fail(s);
  }
  // Every file is written to its temporary name first and renamed only when all were written.
  std::vector<calf::files::TempFile> temps;
  for (size_t i = 0; i < paths.size(); ++i) {
    const auto& file = files[i];
    const std::string& path = paths[i];
    auto temp = calf::files::TempFile::create(path);
    if (!temp.ok()) return fail(temp.status());
    if (calf::Status s = temp.value().write(file.bytes); !s.ok()) return fail(s);
    temps.push_back(std::move(temp.value()));
  }
  for (auto& temp : temps) {
    if (calf::Status s = temp.commit(); !s.ok()) return fail(s);
  }
  if (meshopt) {
    uint64_t bytes = 0;
    for (const auto& file : files) bytes += file.bytes.size();
    exported.summary += fmt::format(" ({} bytes with EXT_meshopt_compression)", bytes);
  }
  if (!quiet) std::printf("%s\n", exported.summary.c_str());
  if (!exported.warning.empty()) std::fprintf(stderr, "%s\n", exported.warning.c_str());
  return calf::tools::kExitOk;
}

int main(int argc, char** argv) {
  return calf::tools::run_command("calf-export", [&] { return command_main(argc, argv); });
}
