// The GL texture state (calf/player/gl_views.h) fed by decoder-shaped texture updates: colour
// keyframes in two slots as BC1 / BC7 / BC6H / rgba8 blocks made by calf's encoders, per-cell
// (t, a_slot), depth as r16 or BC5 (decoded on the CPU, or kept compressed on the GPU), material
// as rgba8 or BC1, in partial, overlapping and edge rects. The GL renderer's image is compared
// with the CPU renderer's on a ViewSet holding what the updates mean, decoded by calf's CPU block
// decoders and blended per cell as SPEC §11.1.4 says. Malformed updates and layouts are refused
// with their error ids.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <list>
#include <string>

#include "../gl_test_context.h"
#include "../player/synthetic_scene.h"
#include "calf/encoder/bc_encode.h"
#include "calf/format/bc.h"
#include "calf/format/colour.h"
#include "calf/format/grid.h"
#include "calf/player/gl_context.h"
#include "calf/player/gl_views.h"
#include "calf/player/lightfield_cpu_renderer.h"
#include "calf/player/lightfield_gl_renderer.h"

namespace calf::player {
namespace {

using container::PixelFormat;
using decoder::CellParams;
using decoder::LightfieldFrameUpdates;
using decoder::TextureUpdate;
using decoder::UpdateTarget;

using ::calf::test::gl_context;

double psnr_vs(const std::vector<float>& ref, const std::vector<float>& test) {
  double peak = 1, se = 0;
  for (size_t i = 0; i < ref.size(); ++i) {
    peak = std::max(peak, double{ref[i]});
    se += (double{ref[i]} - test[i]) * (double{ref[i]} - test[i]);
  }
  const double mse = se / static_cast<double>(ref.size());
  return mse == 0 ? 200.0 : 10 * std::log10(peak * peak / mse);
}

// A face's texels as a rect, `channels` values per texel.
template <typename T>
std::vector<T> crop(const std::vector<T>& face, uint32_t n, const PixelRect& r, int channels) {
  std::vector<T> out;
  for (uint32_t y = r.y; y < r.y + r.height; ++y) {
    const T* row = &face[(size_t{y} * n + r.x) * channels];
    out.insert(out.end(), row, row + size_t{r.width} * channels);
  }
  return out;
}

// Builds updates like the decoder's and keeps the CPU image of what they mean.
class HandDecoder {
 public:
  HandDecoder(const std::vector<GlViewInfo>& views, PixelFormat colour, PixelFormat depth,
              PixelFormat material)
      : colour_(colour), depth_(depth), material_(material) {
    layout_.views = views;
    layout_.colour_format = colour;
    layout_.depth_format = PixelFormat::kR16;
    layout_.material_format = material;
    for (const GlViewInfo& v : views) {
      const size_t texels = size_t{v.face_size} * v.face_size;
      State s;
      for (auto& f : s.faces) {
        f.slot[0].assign(3 * texels, 0.0f);
        f.slot[1].assign(3 * texels, 0.0f);
        f.depth.assign(texels, kLog16Sky);
        f.material.assign(3 * texels, 0.0f);
        for (size_t i = 0; i < texels; ++i) f.material[3 * i + 2] = 1.0f;
        const uint32_t per_side =
            FaceGrid::with_cell_size(v.face_size, v.cell_size)->cells_per_side();
        f.t.assign(size_t{per_side} * per_side, 0);
        f.a.assign(size_t{per_side} * per_side, 0);
      }
      state_.push_back(std::move(s));
    }
  }

  GlTextureLayout& layout() { return layout_; }
  LightfieldFrameUpdates& frame() { return frame_; }

  // Colour keyframe `linear` (a whole face, 3 floats per texel) into `slot`, rect `r`.
  void colour(uint32_t view, int face, uint32_t slot, const PixelRect& r,
              const std::vector<float>& linear) {
    const uint32_t n = layout_.views[view].face_size;
    const std::vector<float> rgb = crop(linear, n, r, 3);
    const size_t texels = size_t{r.width} * r.height;
    std::vector<uint8_t> bytes;
    std::vector<float> shown(3 * texels);  // what the update decodes to, linear
    if (colour_ == PixelFormat::kBc6h) {
      bc::ImageF img{rgb.data(), r.width, r.height, size_t{r.width} * 3, 3};
      bytes.resize(bc::encode_bound(bc::Format::kBc6hUnsigned, r.width, r.height));
      EXPECT_TRUE(bc::encode_bc6h(img, bytes.data(), bytes.size(), {}).ok());
      std::vector<uint16_t> half(3 * texels);
      EXPECT_TRUE(bc::decode_image(bc::Format::kBc6hUnsigned, bytes.data(), bytes.size(), r.width,
                                   r.height, half.data(), half.size() * 2, size_t{r.width} * 6)
                      .ok());
      for (size_t i = 0; i < half.size(); ++i) shown[i] = bc::half_to_float(half[i]);
    } else {
      std::vector<uint8_t> srgb(4 * texels);
      for (size_t i = 0; i < texels; ++i) {
        for (int ch = 0; ch < 3; ++ch) srgb[4 * i + ch] = srgb8_from_linear(rgb[3 * i + ch]);
        srgb[4 * i + 3] = 255;
      }
      std::vector<uint8_t> decoded = srgb;
      if (colour_ == PixelFormat::kRgba8) {
        bytes = srgb;
      } else {
        const bc::Format f = colour_ == PixelFormat::kBc1 ? bc::Format::kBc1 : bc::Format::kBc7;
        const bc::Image8 img{srgb.data(), r.width, r.height, size_t{r.width} * 4, 4};
        bytes.resize(bc::encode_bound(f, r.width, r.height));
        EXPECT_TRUE((f == bc::Format::kBc1 ? bc::encode_bc1(img, bytes.data(), bytes.size(), {})
                                           : bc::encode_bc7(img, bytes.data(), bytes.size(), {}))
                        .ok());
        EXPECT_TRUE(bc::decode_image(f, bytes.data(), bytes.size(), r.width, r.height,
                                     decoded.data(), decoded.size(), size_t{r.width} * 4)
                        .ok());
      }
      for (size_t i = 0; i < texels; ++i) {
        for (int ch = 0; ch < 3; ++ch) shown[3 * i + ch] = linear_from_srgb8(decoded[4 * i + ch]);
      }
    }
    paste(state_[view].faces[face].slot[slot], n, r, 3, shown);
    push(UpdateTarget::kColour, view, face, slot, r, colour_, std::move(bytes));
  }

  // Depth codes of a whole face into rect `r`.
  void depth(uint32_t view, int face, const PixelRect& r, const std::vector<uint16_t>& codes) {
    const uint32_t n = layout_.views[view].face_size;
    std::vector<uint16_t> c = crop(codes, n, r, 1);
    std::vector<uint8_t> bytes(2 * c.size());
    if (depth_ == PixelFormat::kR16) {
      std::memcpy(bytes.data(), c.data(), bytes.size());
    } else {
      std::vector<uint8_t> hilo(2 * c.size());
      for (size_t i = 0; i < c.size(); ++i) hilo[2 * i] = c[i] >> 8, hilo[2 * i + 1] = c[i] & 255;
      const bc::Image8 img{hilo.data(), r.width, r.height, size_t{r.width} * 2, 2};
      bytes.resize(bc::encode_bound(bc::Format::kBc5, r.width, r.height));
      EXPECT_TRUE(bc::encode_bc5(img, bytes.data(), bytes.size(), {}).ok());
      EXPECT_TRUE(bc::decode_image(bc::Format::kBc5, bytes.data(), bytes.size(), r.width, r.height,
                                   hilo.data(), hilo.size(), size_t{r.width} * 2)
                      .ok());
      for (size_t i = 0; i < c.size(); ++i)
        c[i] = static_cast<uint16_t>(256 * hilo[2 * i] + hilo[2 * i + 1]);
    }
    paste(state_[view].faces[face].depth, n, r, 1, c);
    push(UpdateTarget::kDepth, view, face, 0, r, depth_, std::move(bytes));
  }

  // Material codes (reflect, refract, ior code per texel) of a whole face into rect `r`.
  void material(uint32_t view, int face, const PixelRect& r, const std::vector<uint8_t>& codes) {
    const uint32_t n = layout_.views[view].face_size;
    const std::vector<uint8_t> c = crop(codes, n, r, 3);
    std::vector<uint8_t> rgba;
    for (size_t k = 0; k < c.size(); k += 3)
      rgba.insert(rgba.end(), {c[k], c[k + 1], c[k + 2], 255});
    std::vector<uint8_t> bytes = rgba;
    if (material_ == PixelFormat::kBc1) {
      const bc::Image8 img{rgba.data(), r.width, r.height, size_t{r.width} * 4, 4};
      bytes.resize(bc::encode_bound(bc::Format::kBc1, r.width, r.height));
      EXPECT_TRUE(bc::encode_bc1(img, bytes.data(), bytes.size(), {}).ok());
      EXPECT_TRUE(bc::decode_image(bc::Format::kBc1, bytes.data(), bytes.size(), r.width, r.height,
                                   rgba.data(), rgba.size(), size_t{r.width} * 4)
                      .ok());
    }
    std::vector<float> m;
    for (size_t i = 0; i < rgba.size(); i += 4) {
      m.insert(m.end(), {rgba[i] / 255.0f, rgba[i + 1] / 255.0f, 1 + 2 * (rgba[i + 2] / 255.0f)});
    }
    paste(state_[view].faces[face].material, n, r, 3, m);
    push(UpdateTarget::kMaterial, view, face, 0, r, material_, std::move(bytes));
  }

  void cell(uint32_t view, int face, uint32_t cell, uint8_t t, uint8_t a) {
    state_[view].faces[face].t[cell] = t;
    state_[view].faces[face].a[cell] = a;
    frame_.cells.push_back({view, cube_face_from_index(face), cell, t, a});
  }

  // The CPU image: per texel mix(slot a, slot 1 - a, t / 255) of its cell, in float as the GPU.
  ViewSet view_set() const {
    ViewSet set;
    for (size_t v = 0; v < layout_.views.size(); ++v) {
      const GlViewInfo& info = layout_.views[v];
      const uint32_t n = info.face_size;
      const FaceGrid grid = *FaceGrid::with_cell_size(n, info.cell_size);
      View view = *View::make(info.position, info.range, n, info.has_material);
      for (int f = 0; f < kCubeFaceCount; ++f) {
        const auto& s = state_[v].faces[f];
        std::vector<float> c(3 * size_t{n} * n);
        for (uint32_t y = 0; y < n; ++y) {
          for (uint32_t x = 0; x < n; ++x) {
            const uint32_t cell = grid.cell_index_at_texel(x, y);
            const float t = s.t[cell] / 255.0f;
            const size_t k = 3 * (size_t{y} * n + x);
            for (int ch = 0; ch < 3; ++ch) {
              const float a = s.slot[s.a[cell]][k + ch], b = s.slot[1 - s.a[cell]][k + ch];
              c[k + ch] = a * (1 - t) + b * t;  // GLSL mix()
            }
          }
        }
        const CubeFace face = cube_face_from_index(f);
        EXPECT_TRUE(view.write_colour_rect(face, {0, 0, n, n}, c).ok());
        EXPECT_TRUE(view.write_depth_rect(face, {0, 0, n, n}, s.depth).ok());
        if (info.has_material) {
          EXPECT_TRUE(view.write_material_rect(face, {0, 0, n, n}, s.material).ok());
        }
      }
      set.views.push_back(std::move(view));
    }
    return set;
  }

 private:
  template <typename T>
  static void paste(std::vector<T>& face, uint32_t n, const PixelRect& r, int channels,
                    const std::vector<T>& src) {
    for (uint32_t y = 0; y < r.height; ++y) {
      std::copy_n(&src[size_t{y} * r.width * channels], size_t{r.width} * channels,
                  &face[(size_t{r.y + y} * n + r.x) * channels]);
    }
  }
  void push(UpdateTarget target, uint32_t view, int face, uint32_t slot, const PixelRect& r,
            PixelFormat format, std::vector<uint8_t> bytes) {
    storage_.push_back(std::move(bytes));
    TextureUpdate u;
    u.target = target;
    u.view = view;
    u.face = cube_face_from_index(face);
    u.slot = slot;
    u.rect = r;
    u.format = format;
    u.bytes = storage_.back();
    frame_.updates.push_back(u);
  }

  struct FaceState {
    std::vector<float> slot[2];
    std::vector<uint16_t> depth;
    std::vector<float> material;
    std::vector<uint8_t> t, a;
  };
  struct State {
    FaceState faces[kCubeFaceCount];
  };
  PixelFormat colour_, depth_, material_;
  GlTextureLayout layout_;
  LightfieldFrameUpdates frame_;
  std::list<std::vector<uint8_t>> storage_;  // stable addresses for the update spans
  std::vector<State> state_;
};

testing::Scene scene() {
  testing::Scene s;
  s.room_half = 3;
  s.mirror_floor = true;
  s.spheres = {{{0, -0.5, -1.8}, 0.7}, {{1.3, 0.6, -1.0}, 0.4}};
  return s;
}

// The colour, depth codes and material codes of a view, face by face, straight from the scene.
struct Captured {
  GlViewInfo info;
  std::vector<float> colour[6];
  std::vector<uint16_t> depth[6];
  std::vector<uint8_t> material[6];
};
Captured capture(const testing::Scene& s, const Vec3& position, uint32_t n, uint32_t cell,
                 bool with_material) {
  const View v = testing::make_view(s, position, n, true);
  Captured c;
  c.info = {position, v.range(), n, cell, with_material};
  for (int f = 0; f < 6; ++f) {
    const CubeFace face = cube_face_from_index(f);
    c.colour[f].assign(v.colour_face(face).begin(), v.colour_face(face).end());
    c.depth[f].assign(v.depth_face(face).begin(), v.depth_face(face).end());
    for (float m : v.material_face(face)) {
      c.material[f].push_back(static_cast<uint8_t>(std::lround(255 * std::clamp(m, 0.0f, 1.0f))));
    }
    // ior 1 is code 0 (the third value of each texel).
    for (size_t k = 2; k < c.material[f].size(); k += 3) c.material[f][k] = 0;
  }
  return c;
}

// Keyframe B of a view: keyframe A with a tint, so that slots and t visibly matter.
std::vector<float> tinted(const std::vector<float>& a, double scale) {
  std::vector<float> b(a.size());
  for (size_t i = 0; i < a.size(); ++i) {
    const double tint[3] = {0.55, 1.0, 1.35};
    b[i] = static_cast<float>(std::min(a[i] * tint[i % 3] * scale, scale > 1 ? 1e4 : 1.0));
  }
  return b;
}

struct Case {
  const char* name;
  PixelFormat colour, depth;
  bool keep_bc5;
  PixelFormat material;
  uint32_t face;
  double hdr_scale;  // colour scale (> 1: HDR for BC6H)
  // Besides the 45 dB acceptance bound: llvmpipe decodes BC7 / BC6H exactly (float rounding is
  // all that differs: 76-100+ dB with the sharp default depth_decay of 500), BC1 and sRGB8 with
  // its own rounding (~60 dB).
  double min_db;
};

// Fills a HandDecoder: per face, keyframe A into slot 0 and B into slot 1 in cell-sized rects
// (the last ones short at the edge), a stale update first that a later one overwrites, cells
// with t in {0, 64, 128, 255} and alternating a_slot; depth in two overlapping tile rects.
void fill(HandDecoder& hd, const std::vector<Captured>& views, double scale) {
  for (uint32_t v = 0; v < views.size(); ++v) {
    const GlViewInfo& info = views[v].info;
    const FaceGrid grid = *FaceGrid::with_cell_size(info.face_size, info.cell_size);
    const uint32_t n = info.face_size;
    for (int f = 0; f < 6; ++f) {
      std::vector<float> a = views[v].colour[f];
      for (float& x : a) x = static_cast<float>(x * scale);
      const std::vector<float> b = tinted(views[v].colour[f], scale);
      hd.colour(v, f, 0, {0, 0, n, n}, b);  // stale: overwritten below
      for (uint32_t cell = 0; cell < grid.cell_count(); ++cell) {
        const PixelRect r = *grid.cell_rect(cell);
        const uint8_t a_slot = (cell + f + v) % 2;
        hd.colour(v, f, a_slot, r, a);
        hd.colour(v, f, 1 - a_slot, r, b);
        const uint8_t ts[4] = {0, 64, 128, 255};
        hd.cell(v, f, cell, ts[(cell + v) % 4], a_slot);
      }
      const uint32_t half = (n / 2 + 3) / 4 * 4;
      hd.depth(v, f, {0, 0, n, n}, views[v].depth[f]);
      hd.depth(v, f, {half, 0, n - half, half}, views[v].depth[f]);
      if (info.has_material) hd.material(v, f, {0, 0, n, n}, views[v].material[f]);
    }
  }
}

TEST(GlUpdates, BlockFormatsKeyframeSlotsAndCellsMatchTheCpuRenderer) {
  CALF_REQUIRE_GL();
  const testing::Scene s = scene();
  const std::vector<Vec3> pos = {{-0.5, 0.2, 0.3}, {0.5, -0.2, 0.3}, {0.1, 0.4, -0.3}};
  const Case cases[] = {
      {"BC7 colour, r16 depth, rgba8 material", PixelFormat::kBc7, PixelFormat::kR16, false,
       PixelFormat::kRgba8, 32, 1, 70},
      {"BC1 colour, BC5 depth (CPU-decoded), BC1 material", PixelFormat::kBc1, PixelFormat::kBc5,
       false, PixelFormat::kBc1, 30, 1, 55},
      {"BC6H HDR colour x6, r16 depth", PixelFormat::kBc6h, PixelFormat::kR16, false,
       PixelFormat::kRgba8, 32, 6, 70},
      {"rgba8 colour, r16 depth, 28-texel faces", PixelFormat::kRgba8, PixelFormat::kR16, false,
       PixelFormat::kRgba8, 28, 1, 55},
      {"BC7 colour, BC5 depth kept on the GPU", PixelFormat::kBc7, PixelFormat::kBc5, true,
       PixelFormat::kRgba8, 32, 1, 0},
  };
  for (const Case& c : cases) {
    std::vector<Captured> views;
    for (size_t i = 0; i < pos.size(); ++i) views.push_back(capture(s, pos[i], c.face, 16, i != 1));
    std::vector<GlViewInfo> infos;
    for (const Captured& v : views) infos.push_back(v.info);
    HandDecoder hd(infos, c.colour, c.depth, c.material);
    if (c.keep_bc5) hd.layout().depth_format = PixelFormat::kBc5;
    fill(hd, views, c.hdr_scale);
    Expected<std::unique_ptr<GlViews>> gv = GlViews::make(gl_context()->gl(), hd.layout());
    ASSERT_TRUE(gv.ok()) << gv.status().to_string();
    const Status applied = (*gv)->apply(hd.frame());
    ASSERT_TRUE(applied.ok()) << c.name << ": " << applied.to_string();

    const ViewSet cpu_views = hd.view_set();
    Camera cam;
    cam.position = {0.05, 0.1, 0.1};
    cam.forward = {0.1, -0.5, -1};
    cam.width = cam.height = 64;
    for (bool rr : {false, true}) {
      LightfieldRenderOptions o = *march_range_for(cpu_views, cam.position, {});
      o.rr = rr;
      o.threads = 2;
      RenderedImage want, got;
      ASSERT_TRUE(LightfieldCpuRenderer::make(cpu_views, o)->render(cam, &want).ok());
      std::unique_ptr<LightfieldGlRenderer> r = *LightfieldGlRenderer::make(**gv, o);
      ASSERT_TRUE(r->render(cam, &got).ok());
      const double p = psnr_vs(want.color, got.color);
      size_t same_depth = 0;
      for (size_t k = 0; k < want.depth.size(); ++k) {
        same_depth += std::isinf(want.depth[k])
                          ? std::isinf(got.depth[k])
                          : std::fabs(got.depth[k] / want.depth[k] - 1) < 1e-3;
      }
      std::printf("%-52s %s: GL vs CPU PSNR %6.2f dB, depth agrees on %.2f %%\n", c.name,
                  rr ? "RR   " : "plain", p, 100.0 * same_depth / want.depth.size());
      if (c.keep_bc5) {
        // llvmpipe's BC5 interpolation rounds differently from the reference decoder (<= 2 LSB
        // of the high byte = 512 codes): the GPU-decoded depth may differ. Reported, not bound.
        continue;
      }
      EXPECT_GE(p, 45.0) << c.name;
      EXPECT_GE(p, c.min_db) << c.name;
      EXPECT_GE(same_depth, want.depth.size() * 99 / 100) << c.name;
    }
  }
}

// Slot and t are honoured: a cell showing slot 1 at t = 0 shows keyframe B, at t = 255 A.
TEST(GlUpdates, CellParametersSelectAndBlendTheSlots) {
  CALF_REQUIRE_GL();
  const testing::Scene s = scene();
  std::vector<Captured> views = {capture(s, {0, 0, 0}, 16, 16, false)};
  HandDecoder hd({views[0].info}, PixelFormat::kRgba8, PixelFormat::kR16, PixelFormat::kRgba8);
  std::vector<float> red(3 * 16 * 16, 0.0f), blue(3 * 16 * 16, 0.0f);
  for (size_t i = 0; i < red.size(); i += 3) red[i] = 1.0f, blue[i + 2] = 1.0f;
  for (int f = 0; f < 6; ++f) {
    hd.colour(0, f, 0, {0, 0, 16, 16}, red);
    hd.colour(0, f, 1, {0, 0, 16, 16}, blue);
    hd.depth(0, f, {0, 0, 16, 16}, views[0].depth[f]);
  }
  std::unique_ptr<GlViews> gv = *GlViews::make(gl_context()->gl(), hd.layout());
  ASSERT_TRUE(gv->apply(hd.frame()).ok());
  Camera cam;
  cam.position = {0.01, 0.02, 0.0};
  cam.width = cam.height = 8;
  std::unique_ptr<LightfieldGlRenderer> r =
      *LightfieldGlRenderer::make(*gv, *march_range_for(gv->layout(), cam.position, {}));
  const struct {
    uint8_t t, a;
    float red, blue;
  } expect[] = {{0, 0, 1, 0}, {0, 1, 0, 1}, {255, 1, 1, 0}, {255, 0, 0, 1}, {51, 0, 0.8f, 0.2f}};
  for (const auto& e : expect) {
    std::vector<CellParams> cells;
    for (int f = 0; f < 6; ++f) cells.push_back({0, cube_face_from_index(f), 0, e.t, e.a});
    ASSERT_TRUE(gv->set_cells(cells).ok());
    RenderedImage img;
    ASSERT_TRUE(r->render(cam, &img).ok());
    for (size_t k = 0; k < img.depth.size(); ++k) {
      ASSERT_TRUE(std::isfinite(img.depth[k]));
      ASSERT_NEAR(img.color[3 * k], e.red, 1e-5) << int(e.t) << " " << int(e.a);
      ASSERT_NEAR(img.color[3 * k + 2], e.blue, 1e-5) << int(e.t) << " " << int(e.a);
    }
  }
}

TEST(GlUpdates, RefusesUpdatesThatDoNotFit) {
  CALF_REQUIRE_GL();
  GlTextureLayout layout;
  layout.views = {{{0, 0, 0}, *LogDepthRange::make(0.5, 10), 32, 16, false},
                  {{1, 0, 0}, *LogDepthRange::make(0.5, 10), 32, 16, true}};
  layout.colour_format = PixelFormat::kBc7;
  std::unique_ptr<GlViews> gv = *GlViews::make(gl_context()->gl(), layout);
  const std::vector<uint8_t> blocks(64 * 16, 0), codes(32 * 32 * 2, 0), rgba(32 * 32 * 4, 0);
  const auto update = [&](UpdateTarget target, uint32_t view, uint32_t slot, PixelRect r,
                          PixelFormat format, std::span<const uint8_t> bytes) {
    TextureUpdate u;
    u.target = target;
    u.view = view;
    u.slot = slot;
    u.rect = r;
    u.format = format;
    u.bytes = bytes;
    return gv->apply_update(u);
  };
  const auto colour = UpdateTarget::kColour;
  EXPECT_TRUE(update(colour, 0, 1, {0, 0, 32, 32}, PixelFormat::kBc7, blocks).ok());
  EXPECT_TRUE(update(colour, 1, 0, {8, 4, 8, 8}, PixelFormat::kBc7, {blocks.data(), 64}).ok());
  const struct {
    const char* what;
    Status s;
  } bad[] = {
      {"view", update(colour, 2, 0, {0, 0, 32, 32}, PixelFormat::kBc7, blocks)},
      {"slot", update(colour, 0, 2, {0, 0, 32, 32}, PixelFormat::kBc7, blocks)},
      {"format", update(colour, 0, 0, {0, 0, 32, 32}, PixelFormat::kBc1, blocks)},
      {"bytes", update(colour, 0, 0, {0, 0, 32, 32}, PixelFormat::kBc7, {blocks.data(), 1000})},
      {"align", update(colour, 0, 0, {2, 0, 8, 8}, PixelFormat::kBc7, {blocks.data(), 64})},
      {"short", update(colour, 0, 0, {0, 0, 6, 8}, PixelFormat::kBc7, {blocks.data(), 64})},
      {"leaves", update(colour, 0, 0, {28, 0, 8, 8}, PixelFormat::kBc7, {blocks.data(), 64})},
      {"empty", update(colour, 0, 0, {0, 0, 0, 8}, PixelFormat::kBc7, {})},
      {"depth slot", update(UpdateTarget::kDepth, 0, 1, {0, 0, 32, 32}, PixelFormat::kR16, codes)},
      {"depth format",
       update(UpdateTarget::kDepth, 0, 0, {0, 0, 32, 32}, PixelFormat::kRgba8, rgba)},
      {"no material",
       update(UpdateTarget::kMaterial, 0, 0, {0, 0, 32, 32}, PixelFormat::kRgba8, rgba)},
      {"material format",
       update(UpdateTarget::kMaterial, 1, 0, {0, 0, 32, 32}, PixelFormat::kR16, codes)},
  };
  for (const auto& b : bad) {
    EXPECT_EQ(b.s.number(), 411) << b.what << ": " << b.s.to_string();
  }
  EXPECT_TRUE(
      update(UpdateTarget::kMaterial, 1, 0, {0, 0, 32, 32}, PixelFormat::kRgba8, rgba).ok());
  const CellParams bad_cells[] = {
      {2, CubeFace::kPosX, 0, 0, 0}, {0, CubeFace::kPosX, 4, 0, 0}, {0, CubeFace::kPosX, 0, 0, 2}};
  for (const CellParams& c : bad_cells) {
    EXPECT_EQ(gv->set_cells({&c, 1}).number(), 411);
  }
  const CellParams good = {1, CubeFace::kNegZ, 3, 200, 1};
  EXPECT_TRUE(gv->set_cells({&good, 1}).ok());
}

TEST(GlUpdates, RefusesLayoutsTheGpuCannotHold) {
  CALF_REQUIRE_GL();
  const GlFunctions& gl = gl_context()->gl();
  const GlViewInfo v{{0, 0, 0}, *LogDepthRange::make(0.5, 10), 32, 16, false};
  GlTextureLayout layout;
  EXPECT_EQ(GlViews::make(gl, layout).status().number(), 410);  // no views
  layout.views = {v, v};
  layout.views[1].face_size = 16;
  layout.colour_format = PixelFormat::kBc7;
  EXPECT_EQ(GlViews::make(gl, layout).status().number(), 410);  // mixed sizes, compressed
  layout.colour_format = PixelFormat::kRgba16f;
  EXPECT_TRUE(GlViews::make(gl, layout).ok());  // mixed sizes, uncompressed
  layout.colour_format = PixelFormat::kR16;
  EXPECT_EQ(GlViews::make(gl, layout).status().number(), 410);  // not a colour format
  layout.colour_format = PixelFormat::kRgba8;
  layout.depth_format = PixelFormat::kRgba8;
  EXPECT_EQ(GlViews::make(gl, layout).status().number(), 410);
  layout.depth_format = PixelFormat::kR16;
  layout.views[0].cell_size = 0;
  EXPECT_EQ(GlViews::make(gl, layout).status().number(), 410);
  EXPECT_EQ(updates_from_view_set(ViewSet{}).status().number(), 410);
  // A clip header's layout.
  container::LightfieldTrackHeader h;
  h.view_count = 2;
  h.face_size = 64;
  h.cell_size = 32;
  h.colour_format = static_cast<uint16_t>(PixelFormat::kBc1);
  h.depth_format = static_cast<uint16_t>(PixelFormat::kBc5);
  h.material_format = static_cast<uint16_t>(PixelFormat::kBc1);
  std::vector<decoder::LightfieldViewInfo> infos(2);
  infos[1].has_material = true;
  infos[1].z_near = 0.25f;
  infos[1].z_far = 40.0f;
  Expected<GlTextureLayout> l = layout_for_clip(h, infos);
  ASSERT_TRUE(l.ok()) << l.status().to_string();
  EXPECT_EQ(l->depth_format, PixelFormat::kR16);  // BC5 decoded on the CPU by default
  EXPECT_EQ(layout_for_clip(h, infos, true)->depth_format, PixelFormat::kBc5);
  EXPECT_FALSE(l->views[0].has_material);
  EXPECT_TRUE(l->views[1].has_material);
  EXPECT_EQ(l->views[1].range.z_far(), 40.0f);
  EXPECT_TRUE(GlViews::make(gl, *l).ok());
  EXPECT_EQ(layout_for_clip(h, {infos.data(), 1}).status().number(), 410);
  // Predicted depth (r16p) is decoded to r16 codes on the CPU, kept compressed or not.
  h.depth_format = static_cast<uint16_t>(PixelFormat::kR16Predicted);
  EXPECT_EQ(layout_for_clip(h, infos)->depth_format, PixelFormat::kR16);
  EXPECT_EQ(layout_for_clip(h, infos, true)->depth_format, PixelFormat::kR16);
  // So is r16pm: the LightfieldDecoder sends whole rectangles of r16 codes, their unchanged texels
  // from its copy of the tile
  // (LightfieldDecoder.MaskedDepthDecodesToRaw16CodesFromAnyFrameOfTheWindow).
  h.depth_format = static_cast<uint16_t>(PixelFormat::kR16PredictedMasked);
  EXPECT_EQ(layout_for_clip(h, infos)->depth_format, PixelFormat::kR16);
  EXPECT_EQ(layout_for_clip(h, infos, true)->depth_format, PixelFormat::kR16);
  h.depth_format = static_cast<uint16_t>(PixelFormat::kBc1);
  EXPECT_EQ(layout_for_clip(h, infos).status().number(), 410);
}

}  // namespace
}  // namespace calf::player
