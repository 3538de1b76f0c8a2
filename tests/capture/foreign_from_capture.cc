// Test tool (not installed): rewrites a calf capture set as another renderer would have written the
// same capture, so that tests/cli/ingest_playback.sh can play the result of calf-ingest against
// the native set.
//   foreign_from_capture seurat CAPTURE_DIR OUT_DIR eye_z|ray_depth
//     a Seurat manifest in Unity's face order (front, back, left, right, bottom, top; Unity's and
//     Maya's face cameras, top and bottom with +Z up), row-major matrices, one colour EXR (R, G,
//     B) and one depth EXR (channel R) per face. Frame 0 only (Seurat captures are static).
//   foreign_from_capture equirect CAPTURE_DIR OUT_DIR WIDTH
//     a calf-equirect-set of WIDTH x WIDTH/2 images, each pixel the mean of 4 x 4 nearest-texel
//     colour samples of the (higher-resolution) capture, depth the centre ray's nearest texel.
#include <OpenImageIO/imageio.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/capture/ingest.h"
#include "calf/format/camera.h"
#include "calf/format/cube.h"

namespace {

using namespace calf;
namespace fs = std::filesystem;

[[noreturn]] void die(const std::string& what) {
  std::fprintf(stderr, "foreign_from_capture: %s\n", what.c_str());
  std::exit(1);
}

void write_exr(const fs::path& path, uint32_t w, uint32_t h, const std::vector<std::string>& names,
               const std::vector<float>& interleaved) {
  std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create("exr");
  OIIO::ImageSpec spec(static_cast<int>(w), static_cast<int>(h), static_cast<int>(names.size()),
                       OIIO::TypeDesc::FLOAT);
  spec.channelnames = names;
  spec.alpha_channel = -1;
  spec.z_channel = -1;
  if (!out || !out->open(path.string(), spec) ||
      !out->write_image(OIIO::TypeDesc::FLOAT, interleaved.data()) || !out->close()) {
    die("cannot write " + path.string());
  }
}

std::string number(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

void seurat(const capture::CaptureSetReader& reader, const fs::path& out, bool eye_z) {
  struct Face {
    const char* name;
    Vec3 forward, up;
  };
  const std::array<Face, 6> faces = {{{"Front", {0, 0, -1}, {0, 1, 0}},
                                      {"Back", {0, 0, 1}, {0, 1, 0}},
                                      {"Left", {-1, 0, 0}, {0, 1, 0}},
                                      {"Right", {1, 0, 0}, {0, 1, 0}},
                                      {"Bottom", {0, -1, 0}, {0, 0, 1}},
                                      {"Top", {0, 1, 0}, {0, 0, 1}}}};
  const capture::CaptureManifest& m = reader.manifest();
  const uint32_t n = m.face_size;
  const double near = 0.01, far = 1000;
  std::string json = "{\n  \"view_groups\": [\n";
  capture::ViewFrame frame;
  for (uint32_t v = 0; v < m.viewpoints.size(); ++v) {
    if (Status s = reader.read(v, 0, &frame); !s.ok()) die(s.to_string());
    json += std::string(v ? ",\n" : "") + "    {\"views\": [\n";
    for (size_t k = 0; k < faces.size(); ++k) {
      Camera cam;
      cam.forward = faces[k].forward;
      cam.up = faces[k].up;
      cam.fov_y = std::numbers::pi / 2;
      cam.width = cam.height = n;
      const CameraFrame cf = camera_frame(cam);
      std::vector<float> colour(size_t{n} * n * 3), depth(size_t{n} * n);
      for (uint32_t j = 0; j < n; ++j) {
        for (uint32_t i = 0; i < n; ++i) {
          const Vec3 d = camera_ray(cam, cf, i, j);
          const Texel t = texel_from_direction(d, n);
          const size_t src = frame.texel_index(t.face, t.x, t.y), dst = size_t{j} * n + i;
          for (int c = 0; c < 3; ++c) colour[3 * dst + c] = frame.color[3 * src + c];
          const float r = frame.depth[src];
          // Sky: Unity's depth camera clears to 0.
          depth[dst] =
              std::isinf(r) ? 0.0f : static_cast<float>(eye_z ? r * dot(d, cf.forward) : r);
        }
      }
      const std::string stem = "Cube_" + std::string(faces[k].name) + "_" + std::to_string(v);
      write_exr(out / (stem + "_Color.exr"), n, n, {"R", "G", "B"}, colour);
      write_exr(out / (stem + "_Depth.exr"), n, n, {"R"}, depth);
      const Vec3 cols[3] = {cf.right, cf.up, -cf.forward};
      const Vec3& p = m.viewpoints[v].position;
      std::string w = "[";
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) w += number(component(cols[c], r)) + ", ";
        w += number(component(p, r)) + ", ";
      }
      w += "0, 0, 0, 1]";
      json += std::string(k ? ",\n" : "") +
              "      {\"projective_camera\": {\"image_width\": " + std::to_string(n) +
              ", \"image_height\": " + std::to_string(n) +
              ", \"clip_from_eye_matrix\": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, " +
              number((near + far) / (near - far)) + ", " + number(2 * near * far / (near - far)) +
              ", 0, 0, -1, 0], \"world_from_eye_matrix\": " + w + ", \"depth_type\": \"" +
              (eye_z ? "EYE_Z" : "RAY_DEPTH") +
              "\"},\n       \"depth_image_file\": {\"color\": {\"path\": \"" + stem +
              "_Color.exr\", \"channel_0\": \"R\", \"channel_1\": \"G\", \"channel_2\": \"B\", "
              "\"channel_alpha\": \"CONSTANT_ONE\"}, \"depth\": {\"path\": \"" +
              stem + "_Depth.exr\", \"channel_0\": \"R\"}}}";
    }
    json += "\n    ]}";
  }
  const Vec3 c = (m.view_volume.min + m.view_volume.max) * 0.5;
  json += "\n  ],\n  \"headbox_center\": [" + number(c.x) + ", " + number(c.y) + ", " +
          number(c.z) + "]\n}\n";
  std::ofstream(out / "manifest.json") << json;
}

void equirect(const capture::CaptureSetReader& reader, const fs::path& out, uint32_t w) {
  const capture::CaptureManifest& m = reader.manifest();
  const uint32_t h = w / 2;
  capture::ViewFrame frame;
  for (uint32_t v = 0; v < m.viewpoints.size(); ++v) {
    for (uint32_t f = 0; f < m.frame_count; ++f) {
      if (Status s = reader.read(v, f, &frame); !s.ok()) die(s.to_string());
      std::vector<float> px(size_t{w} * h * 4);
      for (uint32_t j = 0; j < h; ++j) {
        for (uint32_t i = 0; i < w; ++i) {
          double sum[3] = {0, 0, 0};
          for (int b = 0; b < 4; ++b) {
            for (int a = 0; a < 4; ++a) {
              const Vec3 d =
                  capture::direction_from_equirect(i + (a + 0.5) / 4, j + (b + 0.5) / 4, w, h);
              const Texel t = texel_from_direction(d, m.face_size);
              const size_t src = frame.texel_index(t.face, t.x, t.y);
              for (int c = 0; c < 3; ++c) sum[c] += frame.color[3 * src + c];
            }
          }
          const size_t dst = size_t{j} * w + i;
          for (int c = 0; c < 3; ++c) px[4 * dst + c] = static_cast<float>(sum[c] / 16);
          const Texel t = texel_from_direction(
              capture::direction_from_equirect(i + 0.5, j + 0.5, w, h), m.face_size);
          px[4 * dst + 3] = frame.depth[frame.texel_index(t.face, t.x, t.y)];
        }
      }
      write_exr(out / ("pano_" + std::to_string(v) + "_" + std::to_string(f) + ".exr"), w, h,
                {"R", "G", "B", "Z"}, px);
    }
  }
  std::string json = "{\"format\": \"calf-equirect-set\", \"version\": 1, \"frame_count\": " +
                     std::to_string(m.frame_count) + ", \"fps\": " + number(m.fps) +
                     ", \"file_pattern\": \"pano_{view}_{frame}.exr\", \"view_volume\": "
                     "{\"min\": [" +
                     number(m.view_volume.min.x) + ", " + number(m.view_volume.min.y) + ", " +
                     number(m.view_volume.min.z) + "], \"max\": [" + number(m.view_volume.max.x) +
                     ", " + number(m.view_volume.max.y) + ", " + number(m.view_volume.max.z) +
                     "]}, \"viewpoints\": [";
  for (uint32_t v = 0; v < m.viewpoints.size(); ++v) {
    const Vec3& p = m.viewpoints[v].position;
    json += std::string(v ? ", " : "") + "{\"name\": \"" + m.viewpoints[v].name +
            "\", \"position\": [" + number(p.x) + ", " + number(p.y) + ", " + number(p.z) + "]}";
  }
  std::ofstream(out / "equirect.json") << json << "]}\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) die("usage: foreign_from_capture seurat|equirect CAPTURE_DIR OUT_DIR ARG");
  auto reader = capture::CaptureSetReader::open(argv[2]);
  if (!reader.ok()) die(reader.status().to_string());
  fs::create_directories(argv[3]);
  const std::string mode = argv[1], arg = argv[4];
  if (mode == "seurat" && (arg == "eye_z" || arg == "ray_depth")) {
    seurat(*reader, argv[3], arg == "eye_z");
  } else if (mode == "equirect") {
    equirect(*reader, argv[3], static_cast<uint32_t>(std::stoul(arg)));
  } else {
    die("unknown mode " + mode + " " + arg);
  }
  return 0;
}
