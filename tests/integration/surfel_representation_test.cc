// The surfel representation's choices (player/surfel_representation.h) on a clip made here: a row
// of plates at 5 units in front of the eye, one prototype with surfels. Fixed foveation (paper 001
// Sec. 4.4) leaves the centre's prefix alone and shortens the periphery's by the square of its
// point-size factor; the frame-time controller moves the point size towards the target and stays
// within its clamp; bad options give CALF-E461 naming the option.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "calf/capture/scene_file.h"
#include "calf/encoder/mesh_encode.h"
#include "calf/encoder/surfels_encode.h"
#include "calf/format/container.h"
#include "calf/format/container_io.h"
#include "calf/player/rendered_image.h"
#include "calf/player/surfel_representation.h"

namespace calf {
namespace {

using player::SurfelOptions;
using player::SurfelRepresentation;

constexpr double kPi = 3.14159265358979323846;
// Plate centres along x at z = -5: the eye looks down -z from the origin.
constexpr float kPlateX[] = {0.0f, 1.5f, 2.5f, 6.0f};
constexpr int kGrid = 64;  // surfels per side of the plate's grid

// A 0.4 x 0.4 plate in the xy plane facing +z, placed at each kPlateX.
capture::SceneFile plates() {
  capture::SceneFile s;
  s.name = "plates";
  s.frame_count = 1;
  s.view_volume = {{-0.1, -0.1, -0.1}, {0.1, 0.1, 0.1}};
  s.materials.push_back({"grey", {0.5f, 0.5f, 0.5f}, capture::kNoTexture, {0, 0, 0}, 0, 0, 1.5f});
  capture::SceneMesh plate;
  plate.name = "plate";
  plate.positions = {-0.2f, -0.2f, 0, 0.2f, -0.2f, 0, 0.2f, 0.2f, 0, -0.2f, 0.2f, 0};
  plate.indices = {0, 1, 2, 0, 2, 3};
  s.meshes.push_back(plate);
  for (float x : kPlateX) {
    capture::SceneObject o;
    o.name = "plate";
    o.transforms.push_back({1, 0, 0, x, 0, 1, 0, 0, 0, 0, 1, -5});
    s.objects.push_back(o);
  }
  return s;
}

// The plate as a kGrid² grid of surfels in a scrambled order; r_m is the grid step (the median
// nearest-neighbour distance of a grid's points, exactly).
encoder::SurfelsTrackInput plate_surfels() {
  encoder::SurfelsTrackInput in;
  in.frame_count = 1;
  encoder::SurfelPrototypeInput p;
  const float step = 0.4f / kGrid;
  for (int k = 0; k < kGrid * kGrid; ++k) {
    const int i = (k * 2731) % (kGrid * kGrid);  // 2731 is prime to 4096: a permutation
    p.positions.insert(p.positions.end(),
                       {-0.2f + step * (static_cast<float>(i % kGrid) + 0.5f),
                        -0.2f + step * (static_cast<float>(i / kGrid) + 0.5f), 0.0f});
    p.normals.insert(p.normals.end(), {0, 0, 1});
    p.colours.insert(p.colours.end(), {0.5f, 0.5f, 0.5f});
  }
  p.prefix_count = kGrid * kGrid;
  p.prefix_radius = step;
  p.colour_is_base = true;
  in.prototypes.push_back(p);
  return in;
}

std::vector<uint8_t> plate_clip() {
  std::vector<uint8_t> file;
  auto w = container::Writer::create(container::memory_sink(&file));
  EXPECT_TRUE(w.ok());
  Status st = encoder::encode_mesh_track(plates(), nullptr, {}, &*w);
  EXPECT_TRUE(st.ok()) << st.to_string();
  st = encoder::encode_surfels_track(plate_surfels(), {}, &*w);
  EXPECT_TRUE(st.ok()) << st.to_string();
  EXPECT_TRUE(w->finish().ok());
  return file;
}

Camera eye() {
  Camera c;
  c.position = {0, 0, 0};
  c.forward = {0, 0, -1};
  c.fov_y = kPi / 3;  // tan(30 deg) = 0.577 both ways at a square image
  c.width = c.height = 64;
  return c;
}

struct Fixture {
  std::vector<uint8_t> file = plate_clip();
  container::Reader reader =
      std::move(*container::Reader::open(container::memory_source(std::span<const uint8_t>(file))));

  // The prefix length of each plate after one prepare.
  std::vector<uint32_t> counts(const SurfelOptions& options) {
    auto rep = SurfelRepresentation::open(reader, 1, options, player::RenderBackend::kCpu, nullptr);
    EXPECT_TRUE(rep.ok()) << rep.status().to_string();
    if (!rep.ok()) return {};
    const Camera c = eye();
    EXPECT_TRUE((*rep)->prepare(0, std::span<const Camera>(&c, 1)).ok());
    std::vector<uint32_t> out;
    for (const auto& o : (*rep)->draw_list().objects) out.push_back(o.count);
    return out;
  }
};

TEST(SurfelRepresentation, FoveationShortensOnlyPeripheralPrefixes) {
  Fixture f;
  SurfelOptions plain;
  plain.point_size = 1.0;
  const auto off = f.counts(plain);
  ASSERT_EQ(off.size(), 4u);
  // Off: the same distance gives about the same prefix everywhere (the plates farther off-axis
  // are a little farther away).
  EXPECT_GT(off[0], 0u);
  EXPECT_LE(off[2], off[0]);
  SurfelOptions fov = plain;
  fov.foveation = {.enabled = true, .inner = 0.35, .outer = 0.75, .periphery_scale = 2.0};
  const auto on = f.counts(fov);
  ASSERT_EQ(on.size(), 4u);
  // e of each plate centre: |x| / 5 over the half-diagonal tan(30 deg) * sqrt(2) = 0.8165.
  const double half_diagonal = std::tan(kPi / 6) * std::sqrt(2.0);
  for (size_t k = 0; k < 4; ++k) {
    SCOPED_TRACE("plate at x = " + std::to_string(kPlateX[k]));
    const double e = kPlateX[k] / 5 / half_diagonal;
    const double factor = e <= 0.35 ? 1 : e >= 0.75 ? 2 : 1 + (e - 0.35) / 0.4;
    if (factor == 1) {
      EXPECT_EQ(on[k], off[k]);
    } else {
      // Eq. 1: the prefix goes as 1 / r², each rounded up to a whole surfel.
      EXPECT_LT(on[k], off[k]);
      EXPECT_NEAR(on[k], off[k] / (factor * factor), 1.0 + 0.01 * off[k]);
    }
  }
  // The second plate (e = 0.37) is just past the fovea, the third (0.61) between, the last off
  // screen (1.47) at the periphery factor.
  EXPECT_GT(on[1], on[2]);
}

// The numbers reports compute with (FrameFigures): the points drawn are the draw list's prefixes,
// at the fixed point size; no quads.
TEST(SurfelRepresentation, FiguresAreTheDrawListsPoints) {
  Fixture f;
  SurfelOptions o;
  o.point_size = 2.0;
  auto rep = SurfelRepresentation::open(f.reader, 1, o, player::RenderBackend::kCpu, nullptr);
  ASSERT_TRUE(rep.ok()) << rep.status().to_string();
  const Camera c = eye();
  ASSERT_TRUE((*rep)->prepare(0, std::span<const Camera>(&c, 1)).ok());
  player::RenderedImage out;
  ASSERT_TRUE((*rep)->render(c, &out).ok());
  uint64_t prefixes = 0;
  for (const auto& obj : (*rep)->draw_list().objects) prefixes += obj.count;
  const player::FrameFigures fig = (*rep)->figures();
  ASSERT_TRUE(fig.points.has_value());
  EXPECT_GT(fig.points->drawn, 0u);
  EXPECT_EQ(fig.points->drawn, prefixes);
  EXPECT_EQ(fig.points->point_size, 2.0);
  EXPECT_EQ(fig.points->peripheral_objects, 0u);   // no foveation
  EXPECT_EQ(fig.points->predicted_frame_ms, 0.0);  // no target
  EXPECT_FALSE(fig.quads.has_value());
}

// The controller's wiring (its law is tested on a simulated cost in
// tests/player/frame_controller_test.cc): prepare asks it for the size, report_frame_time
// feeds it the frame and the passes' times; far too slow frames drive the size to its maximum,
// fast ones to its minimum.
TEST(SurfelRepresentation, ControllerMovesThePointSizeTowardsTheTargetWithinItsClamp) {
  Fixture f;
  const Camera c = eye();
  const std::span<const Camera> eyes(&c, 1);
  player::RenderedImage image;
  // Renders one frame and reports `frame_ms` for it (the CPU clock ignores the value).
  const auto frame = [&](SurfelRepresentation& r, double frame_ms) {
    ASSERT_TRUE(r.prepare(0, eyes).ok());
    ASSERT_TRUE(r.render(c, &image).ok());
    const player::SurfelPassTimes t = r.last_pass_times();
    EXPECT_GE(t.frame_ms, t.surfels_ms + t.mesh_ms);
    EXPECT_GT(t.surfels_ms, 0) << "the plates are drawn as surfels";
    ASSERT_TRUE(r.report_frame_time(frame_ms).ok());
  };
  SurfelOptions o;
  o.point_size = 2;
  o.target_frame_ms = 10;
  auto rep = SurfelRepresentation::open(f.reader, 1, o, player::RenderBackend::kCpu, nullptr);
  ASSERT_TRUE(rep.ok()) << rep.status().to_string();
  SurfelRepresentation& r = **rep;
  frame(r, 40);
  EXPECT_EQ(r.point_size(), 2.0) << "no model before the first report";
  frame(r, 40);  // 4x too slow: the next prepare picks a larger size
  EXPECT_GT(r.point_size(), 2.0);
  EXPECT_GT(r.predicted_frame_ms(), 0);
  for (int i = 0; i < 10; ++i) frame(r, 1000);
  EXPECT_EQ(r.point_size(), 16.0) << "clamped at max_point_size";
  EXPECT_EQ(r.report_frame_time(-1).id(), ErrorId::kViewSelectFrameTime);
  EXPECT_EQ(r.report_frame_time(std::nan("")).id(), ErrorId::kViewSelectFrameTime);

  // A target far above what the plates cost: the smallest size, the best image; with either clock.
  for (const player::SurfelClock clock : {player::SurfelClock::kWall, player::SurfelClock::kCpu}) {
    o.target_frame_ms = 10000;
    o.point_size = 4;
    o.controller_clock = clock;
    auto fast = SurfelRepresentation::open(f.reader, 1, o, player::RenderBackend::kCpu, nullptr);
    ASSERT_TRUE(fast.ok()) << fast.status().to_string();
    for (int i = 0; i < 3; ++i) frame(**fast, 0.5);
    EXPECT_EQ((*fast)->point_size(), 1.0) << "clamped at min_point_size";
  }

  // A larger point size means shorter prefixes (the controller's lever).
  SurfelOptions small, large;
  small.point_size = 1;
  large.point_size = 4;
  const auto a = f.counts(small), b = f.counts(large);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_GT(a[0], b[0]);
}

TEST(SurfelRepresentation, BadOptionsNameTheOption) {
  Fixture f;
  struct Case {
    const char* what;
    void (*edit)(SurfelOptions*);
  };
  const Case cases[] = {
      {"foveation zones", [](SurfelOptions* o) { o->foveation.inner = 0.8; }},
      {"foveation zones", [](SurfelOptions* o) { o->foveation.outer = 5; }},
      {"foveation periphery scale", [](SurfelOptions* o) { o->foveation.periphery_scale = 0.5; }},
      {"foveation periphery scale", [](SurfelOptions* o) { o->foveation.periphery_scale = 17; }},
      {"target frame time", [](SurfelOptions* o) { o->target_frame_ms = -1; }},
      {"point size", [](SurfelOptions* o) { o->point_size = 100; }},
      {"controller deadband", [](SurfelOptions* o) { o->controller_deadband = 1; }},
  };
  for (const Case& c : cases) {
    SurfelOptions o;
    o.foveation.enabled = true;
    c.edit(&o);
    const Status s = player::validate_surfel_options(o);
    EXPECT_EQ(s.id(), ErrorId::kPlaybackOption) << c.what;
    EXPECT_NE(s.message().find(c.what), std::string::npos) << s.message();
    auto rep = SurfelRepresentation::open(f.reader, 1, o, player::RenderBackend::kCpu, nullptr);
    EXPECT_EQ(rep.status().id(), ErrorId::kPlaybackOption) << c.what;
  }
}

}  // namespace
}  // namespace calf
