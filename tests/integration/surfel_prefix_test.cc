// Any prefix of a built surfel buffer renders (the acceptance: "any prefix renders (property test),
// and prefixes of one buffer are nested"): candidates on two surfaces are ordered by the surfel
// sampler (calf/encoder/surfel_sampler.h, every method) and drawn by the player's CPU splatter
// (calf/player/surfel_renderer.h; the GL one too where OSMesa gives a context) at many prefix
// lengths, each a level of detail:
// - every prefix, from none to the whole buffer, renders without error;
// - the pixels a prefix covers are a subset of those a longer prefix covers (a surfel added can
//   only hide what lies behind it), every pixel's depth never grows with the prefix, and where
//   the depth stays the colour stays (the first surfel drawn keeps a tie);
// - the prefix the player would pick for a disc radius r (paper 001 Eq. 1, p = p_m (r_m / r)^2)
//   leaves no hole on a smooth closed surface when the order is a greedy permutation.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "calf/encoder/surfel_sampler.h"
#include "calf/format/camera.h"
#include "calf/player/gl_context.h"
#include "calf/player/surfel_renderer.h"

namespace calf {
namespace {

// splitmix64: the same prefix lengths on every machine.
struct Rng {
  uint64_t s;
  uint64_t next() {
    uint64_t z = (s += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }
};

// The candidates of one object: a unit sphere (Fibonacci lattice, outward normals) above a
// 3 x 3 square at y = -1.2 facing up, colours varying over both (so a change of disc shows).
struct Candidates {
  std::vector<Vec3> position, normal, colour;
};

Candidates sphere_on_a_floor(int sphere_points, int floor_side) {
  Candidates c;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < sphere_points; ++i) {
    const double y = 1.0 - 2.0 * (i + 0.5) / sphere_points, s = std::sqrt(1.0 - y * y);
    const Vec3 p{s * std::cos(golden * i), y, s * std::sin(golden * i)};
    c.position.push_back(p);
    c.normal.push_back(p);
    c.colour.push_back({0.5 + 0.4 * p.x, 0.5 + 0.4 * p.y, 0.5 + 0.4 * p.z});
  }
  for (int j = 0; j < floor_side; ++j) {
    for (int i = 0; i < floor_side; ++i) {
      const double u = (i + 0.5) / floor_side, v = (j + 0.5) / floor_side;
      c.position.push_back({3 * u - 1.5, -1.2, 3 * v - 1.5});
      c.normal.push_back({0, 1, 0});
      c.colour.push_back({0.2 + 0.6 * u, 0.3, 0.2 + 0.6 * v});
    }
  }
  return c;
}

// The draw list of one object drawing the first `count` surfels of `order` as discs of `radius`.
player::SurfelDrawList draw_list(const Candidates& c, const std::vector<uint32_t>& order,
                                 uint32_t count, float radius) {
  player::SurfelDrawList list;
  player::SurfelDrawPrototype p;
  for (uint32_t id : order) {
    const Vec3 *a = &c.position[id], *n = &c.normal[id], *k = &c.colour[id];
    p.positions.insert(p.positions.end(), {float(a->x), float(a->y), float(a->z)});
    p.normals.insert(p.normals.end(), {float(n->x), float(n->y), float(n->z)});
    p.colours.insert(p.colours.end(), {float(k->x), float(k->y), float(k->z)});
  }
  list.prototypes.push_back(std::move(p));
  player::SurfelDrawObject o;
  o.count = count;
  o.radius = radius;
  list.objects.push_back(o);
  return list;
}

Camera camera() {
  Camera cam;
  cam.position = {0.4, 1.6, 3.2};
  cam.forward = {-0.4, -1.6, -3.2};
  cam.up = {0, 1, 0};
  cam.fov_y = 0.9;
  cam.width = 72;
  cam.height = 54;
  return cam;
}

player::RenderedImage render(const player::SurfelDrawList& list) {
  player::RenderedImage out;
  const Status s = player::render_surfels_cpu(list, camera(), {}, &out);
  EXPECT_TRUE(s.ok()) << s.message();
  return out;
}

// Prefix lengths: the ends, the smallest, and random ones in between, ascending.
std::vector<uint32_t> prefix_lengths(uint32_t n) {
  Rng rng{20};
  std::vector<uint32_t> lengths = {0, 1, 2, n};
  for (int i = 0; i < 8; ++i) lengths.push_back(static_cast<uint32_t>(rng.next() % (n + 1)));
  std::sort(lengths.begin(), lengths.end());
  lengths.erase(std::unique(lengths.begin(), lengths.end()), lengths.end());
  return lengths;
}

// Renders the prefixes of `order` in ascending length with `render_one` and checks that each
// renders and that they nest (see the top of the file). `slack` > 0 relaxes "never farther" to
// within that relative depth and drops the colour condition: the GL splatter decides between
// nearly coplanar discs with its depth buffer, not with the radial distance it writes out.
template <typename Render>
void check_prefixes_nest(const Candidates& c, const std::vector<uint32_t>& order, float slack,
                         Render render_one) {
  player::RenderedImage previous;
  uint32_t previous_length = 0;
  size_t previous_covered = 0;
  for (uint32_t length : prefix_lengths(static_cast<uint32_t>(order.size()))) {
    SCOPED_TRACE(length);
    player::RenderedImage im;
    ASSERT_TRUE(render_one(draw_list(c, order, length, 0.09f), &im));
    size_t covered = 0;
    for (float d : im.depth) covered += std::isfinite(d) ? 1 : 0;
    if (length == 0) {
      EXPECT_EQ(covered, 0u);
    } else {
      // Nested: what the shorter prefix covers stays covered, never farther, and keeps its
      // colour where its depth is unchanged.
      size_t broken = 0;
      for (size_t k = 0; k < im.depth.size(); ++k) {
        const float before = previous.depth[k], now = im.depth[k];
        if (!std::isfinite(before)) continue;
        bool ok = std::isfinite(now) && now <= before * (1 + slack);
        if (ok && now == before && slack == 0)
          for (int ch = 0; ch < 3; ++ch)
            ok = ok && im.color[3 * k + ch] == previous.color[3 * k + ch];
        broken += ok ? 0 : 1;
      }
      EXPECT_EQ(broken, 0u) << "from prefix " << previous_length;
      EXPECT_GE(covered, previous_covered);
    }
    previous = im;
    previous_length = length;
    previous_covered = covered;
  }
  EXPECT_GT(previous_covered, previous.depth.size() / 4);  // the whole buffer is no speck
}

TEST(SurfelPrefixProperty, EveryPrefixRendersAndPrefixesNest) {
  const Candidates c = sphere_on_a_floor(2500, 40);
  for (encoder::SurfelOrderMethod m :
       {encoder::SurfelOrderMethod::kGreedyTree, encoder::SurfelOrderMethod::kProgressive,
        encoder::SurfelOrderMethod::kRandom}) {
    SCOPED_TRACE(encoder::surfel_order_method_name(m));
    encoder::SurfelSamplerOptions o;
    o.method = m;
    auto built = encoder::order_surfels(c.position, 900, o);
    ASSERT_TRUE(built.ok()) << built.status().to_string();
    check_prefixes_nest(c, built->order, 0.0f, [](const player::SurfelDrawList& l, auto* im) {
      const Status s = player::render_surfels_cpu(l, camera(), {}, im);
      EXPECT_TRUE(s.ok()) << s.message();
      return s.ok();
    });
  }
}

// The same with the GL splatter (the player's product), one upload and a prefix per render:
// coverage nests exactly, depth within 1e-4 (the tolerance of the GL-vs-CPU test,
// tests/player/surfel_renderer_test.cc).
TEST(SurfelPrefixProperty, EveryPrefixRendersAndPrefixesNestOnGl) {
  Expected<std::unique_ptr<player::OsMesaContext>> context = player::OsMesaContext::make();
  if (!context.ok()) GTEST_SKIP() << "no OSMesa GL 4.5 core context";
  const Candidates c = sphere_on_a_floor(2500, 40);
  auto built = encoder::order_surfels(c.position, 900, {});
  ASSERT_TRUE(built.ok()) << built.status().to_string();
  auto gl = player::GlSurfelRenderer::make((*context)->gl());
  ASSERT_TRUE(gl.ok()) << gl.status().message();
  ASSERT_TRUE((*gl)->upload(draw_list(c, built->order, 0, 0.09f)).ok());
  check_prefixes_nest(c, built->order, 1e-4f, [&](const player::SurfelDrawList& l, auto* im) {
    const Status s = (*gl)->render(l, camera(), {}, im);
    EXPECT_TRUE(s.ok()) << s.message();
    return s.ok();
  });
}

// The prefix for a radius (paper 001 Sec. 4.1: p(r) = p_m (r_m / r)^2, r_m the median
// nearest-neighbour distance of the first p_m surfels) drawn at that radius covers the unit
// sphere without holes when the order is a greedy permutation: its prefixes are r-nets, every
// candidate within about the spacing of a surfel, and a disc of radius r around each covers it
// (Eq. 1 budgets 4 surfels of radius r/2 per disc of radius r). Judged on the pixels whose ray
// meets the sphere at least 2 pixels inside its silhouette (the rim is seen edge-on).
TEST(SurfelPrefixProperty, PrefixForARadiusCoversTheSphere) {
  const Candidates c = sphere_on_a_floor(6000, 0);
  encoder::SurfelSamplerOptions o;  // the default: the greedy permutation
  o.p_m = 200;
  auto built = encoder::order_surfels(c.position, 3000, o);
  ASSERT_TRUE(built.ok()) << built.status().to_string();
  const Camera cam = camera();
  for (double r : {0.25, 0.15, 0.1}) {
    SCOPED_TRACE(r);
    const double p = built->p_m * std::pow(built->r_m / r, 2.0);
    const auto length = static_cast<uint32_t>(std::ceil(p));
    ASSERT_LE(length, 3000u);
    const player::RenderedImage im = render(draw_list(c, built->order, length, float(r)));
    // The sphere seen from the camera: a pixel's ray (camera_ray) meets the unit sphere when its
    // distance to the centre is below 1; inside by a margin of 2 pixels' angle.
    const double dist = std::sqrt(0.4 * 0.4 + 1.6 * 1.6 + 3.2 * 3.2);
    const double pixel = 2 * std::tan(cam.fov_y / 2) / cam.height;  // radians a pixel, about
    size_t inside = 0, holes = 0;
    for (uint32_t j = 0; j < cam.height; ++j) {
      for (uint32_t i = 0; i < cam.width; ++i) {
        const Vec3 d = camera_ray(cam, i, j);
        const double len = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
        // The angle between the ray and the direction to the centre.
        const Vec3 to{-cam.position.x, -cam.position.y, -cam.position.z};
        const double cosang = (d.x * to.x + d.y * to.y + d.z * to.z) / (len * dist);
        const double ang = std::acos(std::min(1.0, cosang));
        if (ang > std::asin(1.0 / dist) - 2 * pixel) continue;
        ++inside;
        holes += std::isfinite(im.depth[size_t{j} * cam.width + i]) ? 0 : 1;
      }
    }
    EXPECT_GT(inside, 300u);
    EXPECT_EQ(holes, 0u) << "of " << inside << " pixels, prefix " << length;
  }
}

}  // namespace
}  // namespace calf
