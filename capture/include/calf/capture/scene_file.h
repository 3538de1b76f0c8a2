// Scene files (format/SCENE.md): an animated mesh scene on disk, so that the builders of the mesh
// representations (surfels, visible sets) read the same scene the ray tracer rendered, without
// linking the sample scenes. The flow stays samples -> files -> encoder.
//
// A scene file is a folder: DIR/scene.json (the manifest, written last), little-endian binary
// buffers (calf writes one, DIR/scene.bin) and base-colour textures, all named by relative paths
// confined to DIR. The in-memory model below is what the manifest and its buffers describe:
//
//   meshes     prototypes: triangles, optional normals / colours / UVs / per-triangle material
//              ids, analytic spheres, and piecewise-linear vertex states (paper 004, Eqs. 3-4);
//   objects    an instance of a mesh with a material and an object-to-world transform sampled
//              per frame (instances share their mesh, so a 20 M-triangle factory of a few
//              hundred parts stores each part once);
//   materials  base colour (+ texture), emission, mirror / glass weights (CAPTURE.md material);
//   lights     point lights sampled per frame; the environment (sky, sun, ambient);
//   timing     fps and frame count; the view region, the box the eye may move in.
//
// Units and axes as in calf/samples/scene.h: scene units (metres for the built-ins), right-handed,
// +Y up. Frame f is at time f / fps seconds.
//
// Errors: CALF-E150-E161 (docs/ERRORS.md), each message naming the file and the JSON field or the
// element at fault. Nothing here throws.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "calf/capture/image_budget.h"
#include "calf/format/geometry.h"
#include "calf/format/status.h"

namespace calf::capture {

inline constexpr const char* kSceneManifestFileName = "scene.json";
inline constexpr const char* kSceneBufferFileName = "scene.bin";
inline constexpr uint32_t kSceneFileVersion = 1;
inline constexpr uint32_t kNoTexture = 0xffffffffu;

// Limits (SCENE.md "Limits"); larger files are refused with CALF-E160 before any allocation.
inline constexpr uint32_t kSceneMaxFrames = 1000000;
inline constexpr uint32_t kSceneMaxMeshes = 1u << 20;
inline constexpr uint32_t kSceneMaxObjects = 1u << 24;
inline constexpr uint32_t kSceneMaxMaterials = 1u << 16;
inline constexpr uint32_t kSceneMaxTextures = 1u << 12;
inline constexpr uint32_t kSceneMaxLights = 1u << 12;
inline constexpr uint32_t kSceneMaxBuffers = 1u << 10;
inline constexpr uint32_t kSceneMaxStates = 1u << 12;
inline constexpr uint32_t kSceneMaxTextureSize = 16384;  // texels per side

using SceneFloat3 = std::array<float, 3>;

// An object-to-world affine transform, row-major 3 x 4: world = M * (x, y, z, 1). Rigid or
// uniformly scaled (a sphere's radius scales by the cube root of the determinant of the 3 x 3
// part, as in samples::TransformAt).
using SceneTransform = std::array<float, 12>;
inline constexpr SceneTransform kSceneIdentity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};

struct SceneSphere {
  SceneFloat3 center{0, 0, 0};  // object space
  float radius = 1;             // > 0
  friend bool operator==(const SceneSphere&, const SceneSphere&) = default;
};

// A prototype mesh in object space. Flat float arrays, three (two for UVs) per vertex, as they lie
// in the buffers. Front faces wind counter-clockwise seen from outside.
struct SceneMesh {
  std::string name;
  std::vector<float> positions;   // 3 per vertex, finite
  std::vector<float> normals;     // empty, or 3 per vertex: finite, non-zero (empty: face normals)
  std::vector<float> colors;      // empty, or 3 per vertex: linear RGB in [0, 1], multiplies the
                                  // material's base colour
  std::vector<float> uvs;         // empty, or 2 per vertex: finite (texture space, v down)
  std::vector<uint32_t> indices;  // 3 per triangle, each < vertex_count()
  std::vector<uint32_t> triangle_materials;  // empty, or 1 per triangle: a material index that
                                             // replaces the object's material for that triangle
  std::vector<SceneSphere> spheres;          // analytic spheres (exact depth)
  // Piecewise-linear vertex states: state k gives every vertex's position at state_times[k]
  // seconds; between two states a vertex moves linearly in time, before the first and after the
  // last it is held. Empty: `positions` at every time. Times finite, >= 0, strictly increasing;
  // state_positions holds state_times.size() * vertex_count() * 3 finite floats, state-major.
  std::vector<float> state_times;
  std::vector<float> state_positions;

  size_t vertex_count() const { return positions.size() / 3; }
  size_t triangle_count() const { return indices.size() / 3; }
  friend bool operator==(const SceneMesh&, const SceneMesh&) = default;
};

// An instance: a mesh placed by a transform. `transforms` is empty (identity at every frame), one
// entry (static) or frame_count entries (entry f at frame f, times between frames are the
// renderer's business: calf samples, it does not interpolate).
struct SceneObject {
  std::string name;
  uint32_t mesh = 0;      // index into SceneFile::meshes
  uint32_t material = 0;  // index into SceneFile::materials
  std::vector<SceneTransform> transforms;
  friend bool operator==(const SceneObject&, const SceneObject&) = default;
};

// A base-colour texture: 8-bit RGBA, sRGB-encoded as in glTF, row 0 at the top.
struct SceneTexture {
  std::string path;  // relative to the scene folder (SCENE.md "Paths"); the writer
                     // writes PNG and needs a name ending in ".png"
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;  // width * height * 4; empty when not loaded (parse_scene_file)
  friend bool operator==(const SceneTexture&, const SceneTexture&) = default;
};

// Decodes an image file into `texture`'s width, height and 8-bit RGBA by SCENE.md "Texture"'s
// rules (grey spreads to RGB, missing alpha is opaque, at most 16384 x 16384); `path` is left
// alone. The header's size is checked before any pixel is decoded: E159 when it cannot be
// decoded or is too large, E012 when it has more pixels than `max_image_pixels`
// (image_budget.h). PNG is read by libpng (a PNG whose image data cannot hold the rows it
// declares is refused before its buffer exists), other formats by OpenImageIO. read_scene_file
// reads textures with it.
Status read_texture_image(const std::filesystem::path& path, SceneTexture* texture,
                          uint64_t max_image_pixels = kDefaultMaxImagePixels);
// The same for an image in memory (one embedded in a model file): PNG and JPEG are recognised by
// their first bytes, anything else OpenImageIO reads from memory by `format_hint` (an extension
// such as "png", without the dot). `name` names the image in messages. E159 / E012 as above.
Status decode_texture_image(std::span<const uint8_t> bytes, std::string_view format_hint,
                            std::string_view name, SceneTexture* texture,
                            uint64_t max_image_pixels = kDefaultMaxImagePixels);

// A surface (samples::Material plus a texture). Weights as CAPTURE.md "Conventions".
struct SceneMaterial {
  std::string name;
  SceneFloat3 base_color{0.7f, 0.7f, 0.7f};  // linear diffuse reflectance, [0, 1]
  uint32_t base_color_texture = kNoTexture;  // index into SceneFile::textures; multiplies
  SceneFloat3 emission{0, 0, 0};             // emitted radiance, finite, >= 0 (HDR)
  float reflect = 0;                         // mirror weight [0, 1]
  float refract = 0;                         // glass weight [0, 1], reflect + refract <= 1
  float ior = 1.5f;                          // index of refraction of the inside, > 0
  friend bool operator==(const SceneMaterial&, const SceneMaterial&) = default;
};

// A point light: radiant intensity (radiance x distance squared), sampled per frame: each array
// holds one entry (constant) or frame_count entries.
struct SceneLight {
  std::string name;
  std::vector<SceneFloat3> positions;    // finite
  std::vector<SceneFloat3> intensities;  // finite, >= 0
  friend bool operator==(const SceneLight&, const SceneLight&) = default;
};

// Background and ambient lighting (samples::Sky, Scene::ambient / ao_distance).
struct SceneEnvironment {
  SceneFloat3 zenith{0.35f, 0.5f, 0.8f};
  SceneFloat3 horizon{0.75f, 0.8f, 0.85f};
  SceneFloat3 ground{0.25f, 0.22f, 0.2f};
  SceneFloat3 sun_direction{0.4f, 0.8f, 0.3f};  // towards the sun, non-zero
  SceneFloat3 sun_irradiance{0, 0, 0};          // 0: no sun
  float sun_disc_radiance = 40;
  float sun_cos_radius = 0.9995f;  // in [-1, 1]
  SceneFloat3 ambient{0.2f, 0.2f, 0.2f};
  float ao_distance = 1;  // > 0
  friend bool operator==(const SceneEnvironment&, const SceneEnvironment&) = default;
};

struct SceneFile {
  std::string name;          // informative, e.g. "interior"
  std::string description;   // informative
  std::string generator;     // informative: the program that wrote it
  double fps = 30;           // (0, 1000]
  uint32_t frame_count = 1;  // 1 .. kSceneMaxFrames
  // The box the eye may move in (min <= max componentwise), e.g. a capture rig's view volume;
  // the file's "view_region" (SCENE.md).
  Box3 view_volume;
  SceneEnvironment environment;
  std::vector<SceneMaterial> materials;
  std::vector<SceneTexture> textures;
  std::vector<SceneMesh> meshes;
  std::vector<SceneObject> objects;
  std::vector<SceneLight> lights;

  size_t triangle_count() const;       // over objects (instances counted each time)
  size_t mesh_triangle_count() const;  // over meshes (each prototype once)
  friend bool operator==(const SceneFile&, const SceneFile&) = default;
};

// ---- reading the samples: the one interpretation of SCENE.md's timing rules ----

// The object-to-world transform of `object` at frame f: identity without transforms, the one
// transform when static, else transforms[f] (f clamped to the last).
const SceneTransform& transform_at(const SceneObject& object, uint32_t frame);

// The vertex positions of `mesh` at `time` seconds (3 floats per vertex) into `out`: `positions`
// without states; else linear between the two states around `time`, held before the first and
// after the last (paper 004, Eqs. 3-4).
void positions_at(const SceneMesh& mesh, double time, std::vector<float>* out);

// One sample of a per-frame array that holds one entry (constant) or one per frame.
inline const SceneFloat3& sample_at(const std::vector<SceneFloat3>& samples, uint32_t frame) {
  return samples[samples.size() == 1 ? 0 : std::min<size_t>(frame, samples.size() - 1)];
}

// Checks every rule of SCENE.md on an in-memory scene: array sizes (E161), finite values and
// ranges (E157), indices (E158), counts (E152 / E160), texture paths (E153) and, where pixels are
// loaded, their size (E161). The writer calls it first; the readers call it after decoding.
Status validate_scene_file(const SceneFile& scene);

// The manifest and the one buffer calf writes for a scene (texture pixels are not part of it).
struct EncodedScene {
  std::string manifest;  // scene.json text
  std::string buffer;    // scene.bin bytes
};
// Validates and serialises: deterministic, the same scene gives the same bytes. Views are laid
// out in the order of SCENE.md "Buffers" with empty arrays omitted.
Expected<EncodedScene> encode_scene_file(const SceneFile& scene);

// Decodes a manifest whose buffers are given in memory (buffers[i] is the content of the i-th
// entry of "buffers"; its uri is checked, not opened). Textures keep their paths with width,
// height and pixels empty. `source` names the manifest in messages. This is what the fuzz target
// runs; read_scene_file is the same decoder reading buffer files in place.
Expected<SceneFile> parse_scene_file(std::string_view manifest,
                                     std::span<const std::string_view> buffers,
                                     std::string_view source);

// Reads DIR/scene.json, its buffers (each file's size must equal its byte_length: E155; reads go
// straight from the file into the arrays, after every view was checked against the sizes) and
// decodes every texture (E154 missing, E159 undecodable or too large, E012 over
// `max_image_pixels`). A path that resolves (through links) outside DIR is E153.
Expected<SceneFile> read_scene_file(const std::filesystem::path& directory,
                                    uint64_t max_image_pixels = kDefaultMaxImagePixels);

// Writes the scene into DIR (created if missing): removes an old DIR/scene.json first, then
// writes each texture as PNG, DIR/scene.bin and DIR/scene.json last, each whole (temporary file
// + rename), so that a folder with a scene.json is complete. Every texture needs its pixels.
Status write_scene_file(const SceneFile& scene, const std::filesystem::path& directory);

}  // namespace calf::capture
