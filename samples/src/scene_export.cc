// samples::Scene -> capture::SceneFile (format/SCENE.md). The scene model holds its animation as
// functions of time; a scene file holds samples, one per frame, so that any tool can read it.
#include "calf/samples/scene_export.h"

#include <algorithm>
#include <string>
#include <unordered_map>
#include <vector>

namespace calf::samples {

namespace {

capture::SceneFloat3 float3(const glm::vec3& v) {
  return {v.x, v.y, v.z};
}

std::vector<float> flatten(const std::vector<glm::vec3>& v) {
  std::vector<float> out;
  out.reserve(v.size() * 3);
  for (const glm::vec3& p : v) out.insert(out.end(), {p.x, p.y, p.z});
  return out;
}

// glm matrices are column-major (m[column][row]); a scene transform is row-major 3 x 4.
capture::SceneTransform row_major(const glm::mat4& m) {
  capture::SceneTransform t{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) t[static_cast<size_t>(r * 4 + c)] = m[c][r];
  }
  return t;
}

// Samples per frame; one sample when they are all equal.
template <typename T>
std::vector<T> collapse(std::vector<T> samples) {
  if (std::all_of(samples.begin(), samples.end(), [&](const T& s) { return s == samples[0]; })) {
    samples.resize(1);
  }
  return samples;
}

}  // namespace

Expected<capture::SceneFile> export_scene(const Scene& scene, uint32_t frames) {
  if (frames < 1 || frames > capture::kSceneMaxFrames) {
    return Status(ErrorId::kCaptureOption,
                  "scene export: " + std::to_string(frames) + " frames is outside 1..1000000");
  }
  capture::SceneFile out;
  out.name = scene.name;
  out.description = scene.description;
  out.generator = "calf-capture";
  out.fps = scene.fps;
  out.frame_count = frames;
  out.view_volume = scene.default_rig.view_volume;
  capture::SceneEnvironment& e = out.environment;
  e.zenith = float3(scene.sky.zenith);
  e.horizon = float3(scene.sky.horizon);
  e.ground = float3(scene.sky.ground);
  e.sun_direction = float3(scene.sky.sun_direction);
  e.sun_irradiance = float3(scene.sky.sun_irradiance);
  e.sun_disc_radiance = scene.sky.sun_disc_radiance;
  e.sun_cos_radius = scene.sky.sun_cos_radius;
  e.ambient = float3(scene.ambient);
  e.ao_distance = scene.ao_distance;
  for (const Material& m : scene.materials) {
    capture::SceneMaterial sm;
    sm.base_color = float3(m.albedo);
    sm.emission = float3(m.emission);
    sm.reflect = m.reflect;
    sm.refract = m.refract;
    sm.ior = m.ior;
    sm.base_color_texture = m.base_color_texture;
    out.materials.push_back(sm);
  }
  // The sRGB bytes as loaded: the export neither re-encodes nor resamples. A texture without a
  // scene-file name (a scene built in memory) gets one by its index.
  for (size_t i = 0; i < scene.textures.size(); ++i) {
    capture::SceneTexture t = scene.textures[i]->image;
    if (t.path.empty()) t.path = "textures/texture" + std::to_string(i) + ".png";
    out.textures.push_back(std::move(t));
  }
  auto time_of = [&](uint32_t f) { return static_cast<double>(f) / scene.fps; };
  // A shared mesh becomes one scene-file mesh at its first use; later objects point at it.
  std::unordered_map<const TriangleMesh*, uint32_t> mesh_of;
  for (const Object& o : scene.objects) {
    capture::SceneObject object;
    object.name = o.name;
    object.material = o.material;
    auto found = o.shared_mesh ? mesh_of.find(o.shared_mesh.get()) : mesh_of.end();
    if (found != mesh_of.end()) {
      object.mesh = found->second;
    } else {
      object.mesh = static_cast<uint32_t>(out.meshes.size());
      if (o.shared_mesh) mesh_of.emplace(o.shared_mesh.get(), object.mesh);
      const TriangleMesh& source = o.triangle_mesh();
      capture::SceneMesh mesh;
      mesh.name = o.shared_mesh && !source.name.empty() ? source.name : o.name;
      mesh.positions = flatten(source.positions);
      for (const glm::vec2& uv : source.uvs) mesh.uvs.insert(mesh.uvs.end(), {uv.x, uv.y});
      mesh.indices.reserve(source.triangles.size() * 3);
      for (const glm::uvec3& t : source.triangles)
        mesh.indices.insert(mesh.indices.end(), {t.x, t.y, t.z});
      for (const Sphere& s : o.spheres) mesh.spheres.push_back({float3(s.center), s.radius});
      mesh.state_times = source.state_times;
      mesh.state_positions = flatten(source.state_positions);
      out.meshes.push_back(std::move(mesh));
    }
    if (o.transform) {
      std::vector<capture::SceneTransform> samples(frames);
      for (uint32_t f = 0; f < frames; ++f) samples[f] = row_major(o.transform(time_of(f)));
      samples = collapse(std::move(samples));
      if (!(samples.size() == 1 && samples[0] == capture::kSceneIdentity)) {
        object.transforms = std::move(samples);
      }
    }
    out.objects.push_back(std::move(object));
  }
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const PointLight& l = scene.lights[i];
    capture::SceneLight light;
    light.name = "light" + std::to_string(i);
    std::vector<capture::SceneFloat3> positions(frames), intensities(frames);
    for (uint32_t f = 0; f < frames; ++f) {
      positions[f] = l.position ? float3(l.position(time_of(f))) : capture::SceneFloat3{0, 0, 0};
      intensities[f] =
          l.intensity ? float3(l.intensity(time_of(f))) : capture::SceneFloat3{0, 0, 0};
    }
    light.positions = collapse(std::move(positions));
    light.intensities = collapse(std::move(intensities));
    out.lights.push_back(std::move(light));
  }
  CALF_RETURN_IF_ERROR(
      capture::validate_scene_file(out).with_context("scene '" + scene.name + "' export"));
  return out;
}

Status write_scene(const Scene& scene, uint32_t frames, const std::filesystem::path& directory) {
  CALF_ASSIGN_OR_RETURN(capture::SceneFile file, export_scene(scene, frames));
  return capture::write_scene_file(file, directory);
}

}  // namespace calf::samples
