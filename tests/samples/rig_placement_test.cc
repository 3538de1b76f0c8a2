// Camera placement (calf/samples/rig_placement.h, paper 002 Alg. 1): known answers on a scene
// whose pillar hides part of the floor from one side of the view volume, the specular and dynamic
// variants, the curve's monotonicity, the stopping rule, determinism, the Hammersley comparison
// rig, a model file's rig whatever its unit, and the errors.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <tuple>

#include "../scratch_dir.h"
#include "calf/samples/rig_placement.h"

namespace calf::samples {
namespace {

// A pillar (a closed box x in [1, 2], y in [0, 2], z in [-1, 1]) standing on a floor y = 0 over
// x in [-2, 3], z in [-1, 1]. The view volume is the segment y = 1, z = 0, x in [-2, 3], which
// passes through the pillar (its candidates there are inside geometry, never chosen). Left of the
// pillar: 6 units of floor and its 4-unit left face, seen only from the left; right: 2 units of
// floor and the 4-unit right face, seen only from the right. With `pillar_moves`, the pillar
// stands 100 units away at time 0 and in place from time 1 on (fps 1).
constexpr double kPillarLeft = 1, kPillarRight = 2;

Scene pillar_scene(bool pillar_moves = false) {
  Scene s;
  s.name = "pillar";
  s.materials.push_back(Material{});
  s.fps = 1;
  s.frame_count = 2;
  Object floor;
  floor.name = "floor";
  add_quad(&floor.mesh, {-2, 0, 1}, {3, 0, 1}, {3, 0, -1}, {-2, 0, -1});
  s.objects.push_back(floor);
  Object pillar;
  pillar.name = "pillar";
  add_box(&pillar.mesh, glm::vec3(kPillarLeft, 0, -1), glm::vec3(kPillarRight, 2, 1));
  if (pillar_moves) {
    pillar.transform = [](double t) {
      glm::mat4 m(1);
      if (t < 0.5) m[3] = glm::vec4(100, 0, 0, 1);
      return m;
    };
  }
  s.objects.push_back(pillar);
  s.default_rig = list_rig({{-2, 1, 0}, {3, 1, 0}});
  return s;
}

PlacementOptions pillar_options() {
  PlacementOptions o;
  o.text = "auto (test)";
  o.candidates = 51;  // every 0.1 along the segment
  o.samples = 2048;
  o.k = 0.1;
  o.has_volume = true;
  o.volume = {{-2, 1, 0}, {3, 1, 0}};
  o.threads = 2;
  return o;
}

TEST(RigPlacement, SecondCameraGoesWhereOnlyOneSideSees) {
  const Scene scene = pillar_scene();
  auto r = place_cameras(scene, pillar_options(), 1);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  ASSERT_GE(r->curve.size(), 2u);
  // The larger part (10 of 16 units) is left of the pillar; the rest only a camera right of it
  // sees.
  EXPECT_LT(r->curve[0].position.x, kPillarLeft);
  EXPECT_GT(r->curve[1].position.x, kPillarRight);
  EXPECT_GT(r->curve[0].gain, 0.5);
  EXPECT_LT(r->curve[0].gain, 0.7);
  EXPECT_GT(r->curve[1].coverage, 0.95);
  ASSERT_EQ(r->rig.viewpoints.size(), r->curve.size());
  EXPECT_EQ(r->rig.viewpoints[1].position, r->curve[1].position);
  EXPECT_EQ(r->rig.view_volume, pillar_options().volume);
  // The hand-made rig (both ends) sees both sides as well, but from farther away.
  EXPECT_EQ(r->hand_made_count, 2u);
  EXPECT_GT(r->hand_made_coverage, 0.8);
}

TEST(RigPlacement, CoverageIsMonotoneAndTheStoppingRuleStops) {
  const Scene scene = pillar_scene();
  PlacementOptions o = pillar_options();
  o.k = 2;  // proximity matters: every new camera nearer some point gains a little
  o.max_cameras = 40;
  o.stop = 0.02;
  auto r = place_cameras(scene, o, 1);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  ASSERT_GE(r->curve.size(), 3u);
  EXPECT_LT(r->curve.size(), 40u) << r->stop_reason;
  EXPECT_NE(r->stop_reason.find("stop="), std::string::npos) << r->stop_reason;
  double previous = 0;
  for (const CoverageRow& row : r->curve) {
    EXPECT_GE(row.gain, o.stop);
    EXPECT_GE(row.coverage, previous);
    EXPECT_LE(row.coverage, 1 + 1e-9);
    EXPECT_LE(row.hammersley, 1 + 1e-9);
    previous = row.coverage;
  }
  // The paper's own rule (stop only at zero gain) with visibility alone: two cameras see all.
  o.k = 0;
  o.stop = 0;
  auto plain = place_cameras(scene, o, 1);
  ASSERT_TRUE(plain.ok());
  EXPECT_EQ(plain->curve.size(), 2u) << plain->stop_reason;
  EXPECT_NEAR(plain->curve.back().coverage, 1, 1e-9);
}

TEST(RigPlacement, SpecularVariantWantsMoreDirections) {
  const Scene scene = pillar_scene();
  PlacementOptions o = pillar_options();
  o.k = 0;
  o.stop = 0.01;
  o.max_cameras = 12;
  auto diffuse = place_cameras(scene, o, 1);
  o.specular = true;
  o.theta_degrees = 50;
  auto specular = place_cameras(scene, o, 1);
  ASSERT_TRUE(diffuse.ok() && specular.ok());
  EXPECT_EQ(diffuse->curve.size(), 2u);
  EXPECT_GT(specular->curve.size(), 2u);
  // A point seen from several directions counts once per direction.
  EXPECT_GT(specular->curve.back().coverage, 1.0);
  // A smaller theta asks for still more directions.
  o.theta_degrees = 25;
  auto finer = place_cameras(scene, o, 1);
  ASSERT_TRUE(finer.ok());
  EXPECT_GT(finer->curve.size(), specular->curve.size());
}

TEST(RigPlacement, DynamicSceneIntegratesOverFrames) {
  // The pillar stands between the sides only from frame 1 on: frame 0 alone needs one camera,
  // Eq. 7 over both frames a second one right of the pillar.
  const Scene scene = pillar_scene(/*pillar_moves=*/true);
  PlacementOptions o = pillar_options();
  o.k = 0;
  o.stop = 0;
  auto first_frame = place_cameras(scene, o, 2);
  ASSERT_TRUE(first_frame.ok()) << first_frame.status().to_string();
  EXPECT_EQ(first_frame->curve.size(), 1u) << first_frame->stop_reason;
  o.frames = 2;
  auto both = place_cameras(scene, o, 2);
  ASSERT_TRUE(both.ok());
  ASSERT_EQ(both->curve.size(), 2u) << both->stop_reason;
  EXPECT_LT(both->curve[0].position.x, kPillarLeft);
  EXPECT_GT(both->curve[1].position.x, kPillarRight);
}

TEST(RigPlacement, SameResultForAnyThreadCount) {
  const Scene scene = pillar_scene();
  PlacementOptions o = pillar_options();
  o.k = 1;
  o.max_cameras = 6;
  o.stop = 0;
  o.threads = 1;
  auto one = place_cameras(scene, o, 1);
  o.threads = 3;
  auto three = place_cameras(scene, o, 1);
  ASSERT_TRUE(one.ok() && three.ok());
  ASSERT_EQ(one->curve.size(), three->curve.size());
  for (size_t i = 0; i < one->curve.size(); ++i) {
    EXPECT_EQ(one->curve[i].position, three->curve[i].position);
    EXPECT_EQ(one->curve[i].gain, three->curve[i].gain);
    EXPECT_EQ(one->curve[i].coverage, three->curve[i].coverage);
    EXPECT_EQ(one->curve[i].hammersley, three->curve[i].hammersley);
  }
  EXPECT_EQ(placement_table(*one), placement_table(*three));
}

TEST(RigPlacement, HammersleyPoints) {
  const Box3 unit{{0, 0, 0}, {1, 1, 1}};
  // (i / n, base-2 and base-3 radical inverses of i).
  EXPECT_EQ(hammersley_point(0, 4, unit), (Vec3{0, 0, 0}));
  EXPECT_EQ(hammersley_point(1, 4, unit), (Vec3{0.25, 0.5, 1.0 / 3}));
  const Vec3 p3 = hammersley_point(3, 4, unit);
  EXPECT_EQ(p3.x, 0.75);
  EXPECT_EQ(p3.y, 0.75);
  EXPECT_NEAR(p3.z, 1.0 / 9, 1e-15);
  const Box3 box{{-1, 2, 10}, {1, 2, 14}};
  EXPECT_EQ(hammersley_point(1, 2, box), (Vec3{0, 2, 10 + 4.0 / 3}));

  const Scene scene = pillar_scene();
  auto spec = parse_placement("hammersley:5:samples=1024:candidates=11:volume=-2,1,0,3,1,0");
  ASSERT_TRUE(spec.ok()) << spec.status().to_string();
  auto r = place_cameras(scene, *spec, 1);
  ASSERT_TRUE(r.ok()) << r.status().to_string();
  ASSERT_EQ(r->rig.viewpoints.size(), 5u);
  std::set<std::tuple<double, double, double>> distinct;
  for (const capture::Viewpoint& v : r->rig.viewpoints) {
    EXPECT_TRUE(r->rig.view_volume.contains(v.position));
    distinct.insert({v.position.x, v.position.y, v.position.z});
  }
  EXPECT_EQ(distinct.size(), 5u);
  EXPECT_EQ(r->hammersley_coverage, r->curve.back().hammersley);
}

TEST(RigPlacement, ParsesOptions) {
  auto o = parse_placement(
      "auto:max=9:k=0.5:stop=0.05:candidates=100:samples=4096:frames=3:"
      "theta=40:seed=7:volume=-1,0,-1,1,2,1");
  ASSERT_TRUE(o.ok()) << o.status().to_string();
  EXPECT_EQ(o->kind, PlacementOptions::Kind::kAuto);
  EXPECT_EQ(o->max_cameras, 9u);
  EXPECT_EQ(o->k, 0.5);
  EXPECT_EQ(o->stop, 0.05);
  EXPECT_EQ(o->candidates, 100u);
  EXPECT_EQ(o->samples, 4096u);
  EXPECT_EQ(o->frames, 3u);
  EXPECT_TRUE(o->specular);
  EXPECT_EQ(o->theta_degrees, 40);
  EXPECT_EQ(o->seed, 7u);
  EXPECT_TRUE(o->has_volume);
  EXPECT_EQ(o->volume.max, (Vec3{1, 2, 1}));
  auto d = parse_placement("auto");
  ASSERT_TRUE(d.ok());
  EXPECT_EQ(d->max_cameras, 16u);
  EXPECT_EQ(d->k, 1);
  EXPECT_EQ(d->stop, 0.01);
  EXPECT_FALSE(d->specular);
  EXPECT_EQ(d->theta_degrees, 50);
  auto s = parse_placement("auto:specular");
  ASSERT_TRUE(s.ok());
  EXPECT_TRUE(s->specular);
  EXPECT_TRUE(is_placement_rig("auto:max=3"));
  EXPECT_TRUE(is_placement_rig("hammersley:4"));
  EXPECT_FALSE(is_placement_rig("automatic"));
  EXPECT_FALSE(is_placement_rig("box:0,0,0,1,1,1"));
}

TEST(RigPlacement, BadSpecsAreOneLineErrors) {
  for (const char* bad : {"auto:max=0",
                          "auto:max=257",
                          "auto:max=2.5",
                          "auto:k=-1",
                          "auto:k=nan",
                          "auto:stop=2",
                          "auto:theta=0",
                          "auto:theta=181",
                          "auto:candidates=0",
                          "auto:samples=8",
                          "auto:frames=0",
                          "auto:foo=1",
                          "auto:max",
                          "auto:",
                          "auto:volume=1,2,3",
                          "auto:volume=1,0,0,0,0,0",
                          "auto:volume=0,0,0,1,1,1,1",
                          "auto:volume=0,0,0,1e13,1,1",
                          "hammersley",
                          "hammersley:0",
                          "hammersley:x",
                          "hammersley:4:max=3",
                          "autox",
                          "auto:seed=-1"}) {
    auto r = parse_placement(bad);
    ASSERT_FALSE(r.ok()) << bad;
    EXPECT_EQ(r.status().id(), ErrorId::kPlacementSyntax) << bad;
    EXPECT_EQ(r.status().message().find('\n'), std::string::npos) << bad;
    EXPECT_NE(r.status().message().find(bad), std::string::npos) << bad;
  }
}

TEST(RigPlacement, VolumeInsideGeometryIsAnError) {
  Scene s;
  s.name = "closed";
  s.materials.push_back(Material{});
  Object box;
  box.name = "box";
  add_box(&box.mesh, glm::vec3(-1), glm::vec3(1));
  s.objects.push_back(box);
  s.default_rig = list_rig({{5, 0, 0}});
  PlacementOptions o;
  o.text = "auto";
  o.candidates = 8;
  o.samples = 64;
  o.max_cameras = 2;
  o.has_volume = true;
  o.volume = {{-0.5, -0.5, -0.5}, {0.5, 0.5, 0.5}};
  auto r = place_cameras(s, o, 1);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().id(), ErrorId::kPlacementVolume);
}

// A model file as a user brings one: a 4 x 4 floor with a 1 x 1 x 1 box on it, as OBJ text in
// units where the floor is 4 * scale wide (scale 100: the same model in centimetres). Every
// coordinate is exact in float at both scales.
std::string floor_and_box_obj(double scale) {
  std::string text;
  auto v = [&](double x, double y, double z) {
    text += "v " + std::to_string(x * scale) + " " + std::to_string(y * scale) + " " +
            std::to_string(z * scale) + "\n";
  };
  v(-2, 0, -2), v(2, 0, -2), v(2, 0, 2), v(-2, 0, 2);  // floor: 1-4
  for (int i = 0; i < 8; ++i) v(i & 1 ? 0.5 : -0.5, i & 2 ? 1 : 0, i & 4 ? 0.5 : -0.5);  // 5-12
  text += "f 1 4 3\nf 1 3 2\n";
  // The box's six faces (vertex 5 + bits: x = 1, y = 2, z = 4), wound outwards.
  const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    text += "f " + std::to_string(5 + q[0]) + " " + std::to_string(5 + q[1]) + " " +
            std::to_string(5 + q[2]) + " " + std::to_string(5 + q[3]) + "\n";
  }
  return text;
}

Expected<PlacementResult> place_on_model(double scale) {
  const std::filesystem::path file = test::scratch_dir("calf_rig_placement_test") /
                                     ("floor_and_box_x" + std::to_string(int(scale)) + ".obj");
  std::ofstream(file) << floor_and_box_obj(scale);
  Expected<Scene> scene = load_scene_file(file);
  if (!scene.ok()) return scene.status();
  PlacementOptions o;
  o.text = "auto (test)";
  o.candidates = 128;
  o.samples = 2048;
  o.max_cameras = 4;
  o.stop = 0;
  o.threads = 2;
  return place_cameras(*scene, o, 1);
}

// With k per scene unit and a view volume holding the model, in centimetres every camera's
// suitability would underflow but the nearest ones', the ring the model file comes with would
// score coverage 0.000000 and Alg. 1 would put cameras between the spider's legs (7.94 dB on
// docs/RENDERING.md's protocol). Here k is per the model's bounding radius and no camera goes
// inside its bounding sphere: the same model in any unit gets the same rig, scaled.
TEST(RigPlacement, ModelFileGetsTheSameRigInAnyUnit) {
  auto metres = place_on_model(1);
  auto centimetres = place_on_model(100);
  ASSERT_TRUE(metres.ok()) << metres.status().to_string();
  ASSERT_TRUE(centimetres.ok()) << centimetres.status().to_string();
  const Rig& rig = metres->rig;
  // The bounding box (-2, 0, -2) .. (2, 1, 2): half its diagonal, sqrt(33) / 2.
  const double radius = std::sqrt(33.0) / 2;
  ASSERT_NEAR(rig.keep_out_radius, radius, 1e-6 * radius);
  EXPECT_NEAR(metres->length_scale, radius, 1e-6 * radius);
  EXPECT_NEAR(centimetres->rig.keep_out_radius, 100 * radius, 1e-4 * radius);
  EXPECT_NEAR(centimetres->length_scale, 100 * radius, 1e-4 * radius);
  ASSERT_EQ(metres->curve.size(), 4u) << metres->stop_reason;
  ASSERT_EQ(centimetres->curve.size(), metres->curve.size());
  for (size_t i = 0; i < metres->curve.size(); ++i) {
    const CoverageRow& m = metres->curve[i];
    const CoverageRow& c = centimetres->curve[i];
    EXPECT_NEAR(c.position.x, 100 * m.position.x, 1e-6 * rig.keep_out_radius * 100) << i;
    EXPECT_NEAR(c.position.y, 100 * m.position.y, 1e-6 * rig.keep_out_radius * 100) << i;
    EXPECT_NEAR(c.position.z, 100 * m.position.z, 1e-6 * rig.keep_out_radius * 100) << i;
    EXPECT_NEAR(c.coverage, m.coverage, 1e-4) << i;
    EXPECT_NEAR(c.hand_made, m.hand_made, 1e-4) << i;
    // Outside the model's bounding sphere, where a viewer walking around it can be.
    EXPECT_GE(length(m.position - rig.keep_out_center), rig.keep_out_radius) << i;
  }
  // The model's own ring (8 views at twice the radius) covers a real share, in both units.
  EXPECT_GT(metres->hand_made_coverage, 0.1);
  EXPECT_NEAR(centimetres->hand_made_coverage, metres->hand_made_coverage, 1e-4);
  EXPECT_GT(metres->curve.back().coverage, metres->hand_made_coverage * 0.5);
}

TEST(RigPlacement, ReportFiles) {
  const Scene scene = pillar_scene();
  auto r = place_cameras(scene, pillar_options(), 1);
  ASSERT_TRUE(r.ok());
  const std::string table = placement_table(*r);
  EXPECT_EQ(table.rfind("cameras\tx\ty\tz\tgain\tcoverage\thammersley\thand_made\n", 0), 0u);
  size_t lines = 0;
  for (char c : table) lines += c == '\n';
  EXPECT_EQ(lines, r->curve.size() + 1);
  const std::string svg = placement_svg(*r, "a <title> & more");
  EXPECT_EQ(svg.rfind("<svg ", 0), 0u);
  EXPECT_NE(svg.find("a &lt;title&gt; &amp; more"), std::string::npos);
  EXPECT_NE(svg.find("</svg>"), std::string::npos);
}

}  // namespace
}  // namespace calf::samples
