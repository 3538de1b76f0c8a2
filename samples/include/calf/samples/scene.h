// Sample scenes for calf-capture: the scene model the ray tracer renders, the built-in animated
// scenes (procedural, no external assets), scenes loaded from files through assimp, and camera
// rigs (where the 360-degree viewpoints of a capture set go).
//
// Everything is a pure function of time: an object's transform, a light's position and power are
// std::functions of scene time in seconds, evaluated at frame f as f / fps. That keeps rendering
// deterministic and lets any frame be rendered alone, in any order, on any thread.
//
// Units and axes: scene units (the built-in scenes use metres), right-handed, +Y up.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "calf/capture/capture_set.h"
#include "calf/capture/eye_path.h"
#include "calf/capture/image_budget.h"
#include "calf/format/status.h"
#include "calf/samples/texture.h"

namespace calf::samples {

// A surface. The colour at a hit is emission + (1 - reflect - refract) * diffuse shading +
// reflect * (mirror ray) + refract * (refracted ray); the weights are what a capture set's material
// channels record at a primary hit (paper 002, Sec. 6.1). No Fresnel term: the weights are the
// same from every direction, so that a reconstruction from the material stream can match.
// The diffuse reflectance is albedo x the base-colour texture (when there is one and the hit
// triangle's mesh has UVs), filtered at the hit (texture.h); glTF's base colour factor, OBJ's Kd.
struct Material {
  glm::vec3 albedo{0.7f};  // diffuse reflectance (factor), each channel in [0, 1]
  // Index into Scene::textures, or capture::kNoTexture.
  uint32_t base_color_texture = capture::kNoTexture;
  glm::vec3 emission{0.0f};  // emitted radiance, may exceed 1 (HDR)
  float reflect = 0;         // mirror weight in [0, 1]
  float refract = 0;         // glass weight in [0, 1], reflect + refract <= 1
  float ior = 1.5f;          // index of refraction of the inside (> 0)
};

// Object-space triangles. Front faces wind counter-clockwise seen from outside (the right-hand
// normal cross(v1 - v0, v2 - v0) points out); closed objects must be consistently wound because
// the inside-geometry check counts back-face hits.
//
// Optional piecewise-linear vertex states (format/SCENE.md "Vertex states", paper 004 Eqs. 3-4):
// state k gives every vertex's object-space position at state_times[k] seconds; between two
// states a vertex moves linearly in time, before the first and after the last it is held. The
// times are floats, as a scene file stores them, so that an exported scene moves exactly as the
// ray tracer rendered it. Without states `positions` is the position at every time; with them it
// is the rest pose (what a reader without animation uses), and the tracer ignores it.
struct TriangleMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::uvec3> triangles;
  // Empty, or one finite texture coordinate per vertex: a scene file's convention (u from the
  // image's left edge, v down from its top row; texture.h). Vertex states do not move UVs.
  std::vector<glm::vec2> uvs;
  std::vector<float> state_times;          // empty, or 1..4096 finite, >= 0, increasing
  std::vector<glm::vec3> state_positions;  // state_times.size() * positions.size(), state-major
  std::string name;                        // informative: the scene-file name of a shared mesh
};

// The positions of `mesh` at `time` seconds into `out`: `positions` without states, else linear
// between the two states around `time` (held outside them). The arithmetic is that of
// capture::positions_at (scene_file.h), so both give the same floats.
void positions_at(const TriangleMesh& mesh, double time, std::vector<glm::vec3>* out);

// An analytic sphere (exact radial depth; Embree's sphere primitive).
struct Sphere {
  glm::vec3 center{0.0f};
  float radius = 1;
};

// Object-to-world transform at a time in seconds. Rigid or uniformly scaled: sphere radii are
// scaled by the cube root of the determinant.
using TransformAt = std::function<glm::mat4(double time)>;

// An object: its own triangles and spheres, or an instance of a shared mesh (a prototype that
// many objects place, each with its own transform and material). The ray tracer builds a shared
// mesh once per frame and instances it; the scene-file export stores it once (format/SCENE.md
// "Instancing and large scenes"). So a field of 5 M triangles made of a few patches costs the
// patches' memory, not the field's.
struct Object {
  std::string name;
  TriangleMesh mesh;
  std::vector<Sphere> spheres;
  uint32_t material = 0;  // index into Scene::materials
  TransformAt transform;  // empty: identity at every time
  // Set: the object's triangles are this mesh's, and `mesh` and `spheres` must be empty (E174).
  std::shared_ptr<const TriangleMesh> shared_mesh;

  // The triangles the object places: *shared_mesh when set, else mesh.
  const TriangleMesh& triangle_mesh() const { return shared_mesh ? *shared_mesh : mesh; }
};

// A point light; radiant intensity in scene radiance units times distance squared.
struct PointLight {
  std::function<glm::vec3(double time)> position;
  std::function<glm::vec3(double time)> intensity;
};

// Background radiance for rays that hit nothing (depth +inf): a vertical gradient with an optional
// sun disc. The sun also lights surfaces as a shadowed directional light.
struct Sky {
  glm::vec3 zenith{0.35f, 0.5f, 0.8f};
  glm::vec3 horizon{0.75f, 0.8f, 0.85f};
  glm::vec3 ground{0.25f, 0.22f, 0.2f};
  glm::vec3 sun_direction{0.4f, 0.8f, 0.3f};  // towards the sun; normalised on use
  glm::vec3 sun_irradiance{0.0f};             // 0: no sun
  float sun_disc_radiance = 40;               // HDR radiance of the visible disc
  float sun_cos_radius = 0.9995f;             // cosine of the disc's angular radius
};

// A camera rig: the capture viewpoints and the view volume the viewer may move in.
struct Rig {
  std::vector<capture::Viewpoint> viewpoints;
  Box3 view_volume;
  // A ball inside the view volume where no viewer goes: the object a viewer walks around (a
  // model file's bounding sphere; camera placement puts no camera in it and measures each surface
  // point's minimum viewer distance to its boundary). Radius 0: none (the whole box is open).
  Vec3 keep_out_center;
  double keep_out_radius = 0;
  std::string description;  // the --rig text that makes it, e.g. "box:0,1.6,0,0.5,0.3,0.5"
};

// The validation eye path of a scene: poses inside the view volume, away from the default
// viewpoints, one per frame, at `width` x `height` pixels.
using EyePathAt =
    std::function<capture::EyePath(uint32_t frames, double fps, uint32_t width, uint32_t height)>;

struct Scene {
  std::string name;
  std::string description;
  std::vector<Material> materials;
  // Base-colour textures, shared (a texture is decoded and mip-mapped once, at load).
  std::vector<std::shared_ptr<const Texture>> textures;
  std::vector<Object> objects;
  std::vector<PointLight> lights;
  Sky sky;
  // Ambient radiance for the ambient-occlusion term: surfaces receive albedo * ambient * (share of
  // AO rays that travel ao_distance unobstructed), so a moving object darkens what it nears.
  glm::vec3 ambient{0.2f};
  float ao_distance = 1;
  double fps = 30;
  uint32_t frame_count = 30;
  Rig default_rig;
  EyePathAt validation_path;
  // A length typical of the scene, in scene units, for the knobs that would otherwise depend on
  // the unit a file happens to use (camera placement's proximity decay k is per this length):
  // 1 for the built-in scenes (metres), a model file's bounding radius (a model in centimetres
  // and the same model in metres then get the same rig, scaled).
  double length_scale = 1;

  // Whether any material reflects or refracts: only then does a capture carry material channels.
  bool has_mirror_or_glass() const;
  // Triangles over objects, an instanced mesh counted once per object that places it.
  size_t triangle_count() const;
  // Analytic spheres over objects.
  size_t sphere_count() const;
};

// Checks indices, finiteness, radii, material ranges, texture indices and sizes, UVs (one finite
// pair per vertex, or none) and vertex states (times finite, >= 0,
// strictly increasing, at most 4096; one finite position per vertex per state) at time 0, each
// shared mesh once. Errors: E173 empty, E174 (naming the object and what is wrong).
Status validate_scene(const Scene& scene);

// ---- built-in scenes ---------------------------------------------------------------------------

struct SceneInfo {
  const char* name;
  const char* description;
};
// The built-in scenes, in --list-scenes order: "turntable", "interior", "mirror-box" (paper 002's
// cases), then the heavy scenes of the visible-set mode (paper 004): "city" (streets of
// instanced buildings, most of it hidden from a street crossing), "blades" (a field of swaying
// grass blades in vertex states) and "spheres" (bouncing analytic spheres among occluders); then
// the surfel mode's "factory" (a machine hall of ~28 M instanced triangles of CAD-like parts).
// Each description gives the scene's triangle count.
const std::vector<SceneInfo>& builtin_scenes();
// Builds a built-in scene (E170 for an unknown name).
Expected<Scene> make_builtin_scene(std::string_view name);

// Loads glTF / GLB / OBJ / PLY / FBX (anything assimp imports) with the node animations of its
// first animation (sampled with linear / spherical interpolation, held at the ends). Materials: the
// diffuse (glTF: base colour factor) and emissive colours; reflectivity as mirror weight;
// 1 - opacity as glass weight with the file's refraction index; the base-colour texture (glTF
// baseColorTexture, else the diffuse texture: OBJ map_Kd, FBX DiffuseColor) with the mesh's UV
// channel 0, which the colour multiplies (FBX: the texture replaces the colour, as FBX tools
// show it). A texture is an external file (relative to the model; backslashes read as '/'; then
// the file's name alone in the model's folder) or one embedded in the model (GLB, FBX), decoded
// by OpenImageIO (PNG, JPEG, ...). Lights and cameras in the file are ignored: the scene gets a sun
// and sky, a ring rig around the model's bounds and a validation path between its viewpoints. Frame
// count: the animation's duration at 30 fps (at least 1 frame), capped at 300. Errors: E002 missing
// file, E172 unsupported extension, E171 import failure, E173 no triangles, E174 bad geometry
// (non-finite UVs too), E190 a referenced texture file is missing, E191 a texture cannot be
// decoded or is larger than 16384 x 16384 (each naming the texture and the material), E012 a
// texture with more pixels than `max_image_pixels` (calf/capture/image_budget.h).
Expected<Scene> load_scene_file(const std::filesystem::path& path,
                                uint64_t max_image_pixels = capture::kDefaultMaxImagePixels);

// A built-in name, else a file path. E170 when it is neither.
Expected<Scene> load_scene(std::string_view name_or_path,
                           uint64_t max_image_pixels = capture::kDefaultMaxImagePixels);

// ---- rigs --------------------------------------------------------------------------------------

// Parses a --rig description (kRigSyntaxHelp); E175 on any error, with the accepted forms.
Expected<Rig> parse_rig(std::string_view text);
// The accepted --rig forms, for --help.
extern const char* const kRigSyntaxHelp;

// The paper's interior rig: the centre of a box then its 8 corners (view volume: the box).
Rig box_rig(const glm::dvec3& center, const glm::dvec3& half_size);
// n viewpoints on a horizontal circle of radius r around `center`, at angles 2 pi i / n from +X
// towards +Z. View volume: the circle's bounding box, r / 2 high.
Rig ring_rig(uint32_t n, double radius, const glm::dvec3& center);
// n viewpoints spread evenly on a sphere (Fibonacci lattice). View volume: the enclosing cube.
Rig sphere_rig(uint32_t n, double radius, const glm::dvec3& center);
// nx * ny * nz viewpoints on a regular grid spanning [lo, hi] (a count of 1 puts that axis at
// the middle). View volume: [lo, hi].
Rig grid_rig(const glm::uvec3& counts, const glm::dvec3& lo, const glm::dvec3& hi);
// Explicit positions. View volume: their bounding box.
Rig list_rig(const std::vector<glm::dvec3>& positions);

// ---- procedural geometry (used by the built-in scenes and by tests) ---------------------------

// The cube [-1, 1]^3 mapped through `m`, outward facing.
void add_box(TriangleMesh* mesh, const glm::mat4& m);
// The axis-aligned box [lo, hi], outward facing.
void add_box(TriangleMesh* mesh, const glm::vec3& lo, const glm::vec3& hi);
// The inside of the box [lo, hi] (faces pointing in): a room.
void add_room(TriangleMesh* mesh, const glm::vec3& lo, const glm::vec3& hi);
// A capped cylinder of radius 1 along y in [-1, 1] mapped through `m`, `segments` sides.
void add_cylinder(TriangleMesh* mesh, const glm::mat4& m, uint32_t segments);
// A quad p0 p1 p2 p3 (counter-clockwise seen from its front).
void add_quad(TriangleMesh* mesh, const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2,
              const glm::vec3& p3);

// A pose looking from `position` at `target` (up +Y) at `time`.
capture::EyePose look_at_pose(double time, const glm::dvec3& position, const glm::dvec3& target,
                              double fov_y_degrees);

}  // namespace calf::samples
