// Scene export (calf/samples/scene_export.h): every built-in scene becomes a scene file whose
// counts, materials, transforms, vertex states and lights are the scene's own, sampled per frame,
// with each shared mesh stored once; and the built calf-capture --export-scene writes a folder the
// scene-file reader accepts.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include <OpenImageIO/imageio.h>
#include <glm/gtc/matrix_transform.hpp>

#include "calf/capture/scene_file.h"
#include "calf/samples/scene.h"
#include "calf/samples/scene_export.h"

namespace calf::samples {
namespace {

namespace fs = std::filesystem;

// The scene's own transform of object `o` at frame f, as the export must have sampled it.
glm::mat4 transform_at(const Scene& s, size_t o, uint32_t f) {
  const Object& object = s.objects[o];
  return object.transform ? object.transform(f / s.fps) : glm::mat4(1.0f);
}

void expect_same_counts(const Scene& scene, const capture::SceneFile& file, uint32_t frames) {
  EXPECT_EQ(file.name, scene.name);
  EXPECT_EQ(file.frame_count, frames);
  EXPECT_EQ(file.fps, scene.fps);
  ASSERT_EQ(file.objects.size(), scene.objects.size());
  // One mesh per object, except that a shared mesh is stored once.
  std::set<const TriangleMesh*> shared;
  size_t own = 0;
  for (const Object& object : scene.objects) {
    if (object.shared_mesh) {
      shared.insert(object.shared_mesh.get());
    } else {
      ++own;
    }
  }
  ASSERT_EQ(file.meshes.size(), own + shared.size());
  ASSERT_EQ(file.materials.size(), scene.materials.size());
  ASSERT_EQ(file.lights.size(), scene.lights.size());
  size_t triangles = 0;
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    const Object& object = scene.objects[o];
    const TriangleMesh& source = object.triangle_mesh();
    const capture::SceneMesh& mesh = file.meshes[file.objects[o].mesh];
    EXPECT_EQ(mesh.vertex_count(), source.positions.size()) << object.name;
    EXPECT_EQ(mesh.triangle_count(), source.triangles.size()) << object.name;
    EXPECT_EQ(mesh.spheres.size(), object.spheres.size()) << object.name;
    EXPECT_EQ(mesh.state_times, source.state_times) << object.name;
    EXPECT_EQ(file.objects[o].material, object.material);
    triangles += source.triangles.size();
  }
  EXPECT_EQ(file.triangle_count(), triangles);
  EXPECT_EQ(file.triangle_count(), scene.triangle_count());
  EXPECT_EQ(file.view_volume.min.x, scene.default_rig.view_volume.min.x);
  EXPECT_EQ(file.view_volume.max.y, scene.default_rig.view_volume.max.y);
}

TEST(SceneExport, BuiltinScenesKeepTheirContent) {
  for (const SceneInfo& info : builtin_scenes()) {
    SCOPED_TRACE(info.name);
    auto scene = make_builtin_scene(info.name);
    ASSERT_TRUE(scene.ok());
    const uint32_t frames = 4;
    auto file = export_scene(*scene, frames);
    ASSERT_TRUE(file.ok()) << file.status().to_string();
    expect_same_counts(*scene, *file, frames);
    bool some_animated = false;
    for (size_t o = 0; o < scene->objects.size(); ++o) {
      const capture::SceneObject& object = file->objects[o];
      for (uint32_t f = 0; f < frames; ++f) {
        glm::mat4 m = transform_at(*scene, o, f);
        const capture::SceneTransform& t =
            object.transforms.empty() ? capture::kSceneIdentity
                                      : object.transforms[object.transforms.size() == 1 ? 0 : f];
        // Row-major 3 x 4 against glm's column-major m[column][row].
        EXPECT_EQ(t[3], m[3][0]);
        EXPECT_EQ(t[7], m[3][1]);
        EXPECT_EQ(t[1], m[1][0]);
        EXPECT_EQ(t[4], m[0][1]);
        EXPECT_EQ(t[10], m[2][2]);
      }
      // Moving transforms, or vertex states (the swaying blades).
      some_animated = some_animated || object.transforms.size() == frames ||
                      !file->meshes[object.mesh].state_times.empty();
    }
    EXPECT_TRUE(some_animated) << "every built-in scene moves something";
    for (size_t m = 0; m < scene->materials.size(); ++m) {
      EXPECT_EQ(file->materials[m].base_color[1], scene->materials[m].albedo.y);
      EXPECT_EQ(file->materials[m].reflect, scene->materials[m].reflect);
      EXPECT_EQ(file->materials[m].ior, scene->materials[m].ior);
    }
    for (size_t l = 0; l < scene->lights.size(); ++l) {
      const capture::SceneLight& light = file->lights[l];
      uint32_t f = frames - 1;
      glm::vec3 p = scene->lights[l].position(f / scene->fps);
      glm::vec3 i = scene->lights[l].intensity(f / scene->fps);
      const capture::SceneFloat3& fp = light.positions[light.positions.size() == 1 ? 0 : f];
      const capture::SceneFloat3& fi = light.intensities[light.intensities.size() == 1 ? 0 : f];
      EXPECT_EQ(fp, (capture::SceneFloat3{p.x, p.y, p.z}));
      EXPECT_EQ(fi, (capture::SceneFloat3{i.x, i.y, i.z}));
    }
  }
}

TEST(SceneExport, RefusesZeroFrames) {
  auto scene = make_builtin_scene("interior");
  ASSERT_TRUE(scene.ok());
  EXPECT_EQ(export_scene(*scene, 0).status().id(), ErrorId::kCaptureOption);
}

TEST(SceneExport, CalfCaptureWritesAReadableSceneFile) {
  const fs::path dir =
      fs::temp_directory_path() / ("calf_scene_export_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  std::string cmd = CALF_CAPTURE_EXE;
  cmd.append(" --scene turntable --frames 3 --quiet --export-scene ").append(dir.string());
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  EXPECT_FALSE(fs::exists(dir / "manifest.json")) << "without --out nothing is rendered";
  auto file = capture::read_scene_file(dir);
  ASSERT_TRUE(file.ok()) << file.status().to_string();
  auto scene = make_builtin_scene("turntable");
  ASSERT_TRUE(scene.ok());
  expect_same_counts(*scene, *file, 3);
  auto direct = export_scene(*scene, 3);
  ASSERT_TRUE(direct.ok());
  EXPECT_EQ(*file, *direct);
  fs::remove_all(dir);
}

TEST(SceneExport, CalfCaptureExportsAnAssimpScene) {
  const fs::path dir =
      fs::temp_directory_path() / ("calf_scene_export_obj_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path obj = dir / "cube.obj";
  std::ofstream(obj) << "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\n"
                        "v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
                        "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n";
  std::string cmd = CALF_CAPTURE_EXE;
  cmd.append(" --quiet --scene ").append(obj.string()).append(" --export-scene ");
  cmd.append((dir / "scene").string());
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  auto file = capture::read_scene_file(dir / "scene");
  ASSERT_TRUE(file.ok()) << file.status().to_string();
  auto scene = load_scene(obj.string());
  ASSERT_TRUE(scene.ok());
  expect_same_counts(*scene, *file, scene->frame_count);
  EXPECT_EQ(file->triangle_count(), 12u);
  fs::remove_all(dir);
}

TEST(SceneExport, CalfCaptureExportsATexturedModel) {
  // A textured OBJ quad: calf-capture --export-scene writes its UVs and its texture (as PNG), and
  // the folder reads back equal to the in-process export, pixels included.
  const fs::path dir =
      fs::temp_directory_path() / ("calf_scene_export_tex_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  capture::SceneTexture tex;
  tex.width = 2, tex.height = 2;
  tex.rgba = {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255};
  {
    auto out = OIIO::ImageOutput::create("png");
    ASSERT_TRUE(out);
    ASSERT_TRUE(
        out->open((dir / "checker.png").string(), OIIO::ImageSpec(2, 2, 4, OIIO::TypeDesc::UINT8)));
    ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT8, tex.rgba.data()));
    ASSERT_TRUE(out->close());
  }
  std::ofstream(dir / "quad.mtl") << "newmtl quad\nKd 1 1 1\nmap_Kd checker.png\n";
  std::ofstream(dir / "quad.obj") << "mtllib quad.mtl\nv -1 1 0\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\n"
                                     "vt 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nusemtl quad\n"
                                     "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
  std::string cmd = CALF_CAPTURE_EXE;
  cmd.append(" --quiet --scene ").append((dir / "quad.obj").string()).append(" --export-scene ");
  cmd.append((dir / "scene").string());
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  auto file = capture::read_scene_file(dir / "scene");
  ASSERT_TRUE(file.ok()) << file.status().to_string();
  ASSERT_EQ(file->textures.size(), 1u);
  EXPECT_EQ(file->textures[0].rgba, tex.rgba);
  ASSERT_EQ(file->meshes.size(), 1u);
  EXPECT_EQ(file->meshes[0].uvs.size(), 2 * file->meshes[0].vertex_count());
  auto scene = load_scene((dir / "quad.obj").string());
  ASSERT_TRUE(scene.ok()) << scene.status().to_string();
  auto direct = export_scene(*scene, scene->frame_count);
  ASSERT_TRUE(direct.ok());
  EXPECT_EQ(*file, *direct);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace calf::samples
