#include "calf/player/gl_views.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>

#include "calf/decoder/cpu_textures.h"
#include "calf/format/bc.h"
#include "calf/format/grid.h"
#include "calf/format/lightfield_layout.h"
#include "gl_errors.h"

// S3TC names come from an extension, not from the core header.
#ifndef GL_COMPRESSED_RGB_S3TC_DXT1_EXT
#define GL_COMPRESSED_RGB_S3TC_DXT1_EXT 0x83F0
#endif
#ifndef GL_COMPRESSED_SRGB_S3TC_DXT1_EXT
#define GL_COMPRESSED_SRGB_S3TC_DXT1_EXT 0x8C4C
#endif

namespace calf::player {

using container::PixelFormat;
using decoder::CellParams;
using decoder::TextureUpdate;
using decoder::UpdateTarget;
using internal::kGlCall;
using internal::kGlLayout;
using internal::kGlMissing;
using internal::kGlUpdate;

// GL reads 16-bit texels in host order; the decoder yields little-endian ones.
static_assert(std::endian::native == std::endian::little, "the GL upload path assumes LE");

namespace {

// How one storage format is allocated and uploaded.
struct GlFormat {
  GLenum internal = 0;
  bool compressed = false;
  size_t block_bytes = 0;       // compressed: bytes per 4x4 block
  GLenum format = 0, type = 0;  // uncompressed: client format / type
  size_t texel_bytes = 0;       // uncompressed: bytes per texel of an update
};

GlFormat colour_format(PixelFormat f) {
  switch (f) {
    case PixelFormat::kBc1:
      return {GL_COMPRESSED_SRGB_S3TC_DXT1_EXT, true, 8, 0, 0, 0};
    case PixelFormat::kBc7:
      return {GL_COMPRESSED_SRGB_ALPHA_BPTC_UNORM, true, 16, 0, 0, 0};
    case PixelFormat::kBc6h:
      return {GL_COMPRESSED_RGB_BPTC_UNSIGNED_FLOAT, true, 16, 0, 0, 0};
    case PixelFormat::kRgba8:
      return {GL_SRGB8_ALPHA8, false, 0, GL_RGBA, GL_UNSIGNED_BYTE, 4};
    case PixelFormat::kRgba16f:
      return {GL_RGBA16F, false, 0, GL_RGBA, GL_HALF_FLOAT, 8};
    default:
      return {};
  }
}

GlFormat depth_format(PixelFormat f) {
  switch (f) {
    case PixelFormat::kR16:
      return {GL_R16UI, false, 0, GL_RED_INTEGER, GL_UNSIGNED_SHORT, 2};
    case PixelFormat::kBc5:
      return {GL_COMPRESSED_RG_RGTC2, true, 16, 0, 0, 0};
    default:
      return {};
  }
}

GlFormat material_format(PixelFormat f) {
  switch (f) {
    case PixelFormat::kRgba8:
      return {GL_RGBA8, false, 0, GL_RGBA, GL_UNSIGNED_BYTE, 4};
    case PixelFormat::kBc1:
      return {GL_COMPRESSED_RGB_S3TC_DXT1_EXT, true, 8, 0, 0, 0};
    default:
      return {};
  }
}

// Coverage texels: the decoder's kCoverage bytes (lf::coverage_to_gpu) as unsigned integers.
constexpr GlFormat kCoverageFormat = {GL_RGBA8UI, false, 0, GL_RGBA_INTEGER, GL_UNSIGNED_BYTE, 4};

std::string format_name(PixelFormat f) {
  return container::pixel_format_name(static_cast<uint16_t>(f));
}

const char* target_name(UpdateTarget t) {
  return t == UpdateTarget::kColour     ? "colour"
         : t == UpdateTarget::kDepth    ? "depth"
         : t == UpdateTarget::kCoverage ? "coverage"
                                        : "material";
}

// Bytes of a rect of `width` x `height` texels in format `f` (compressed: whole blocks).
size_t rect_bytes(const GlFormat& f, uint32_t width, uint32_t height) {
  if (f.compressed)
    return size_t{bc::blocks_along(width)} * bc::blocks_along(height) * f.block_bytes;
  return size_t{width} * height * f.texel_bytes;
}

// The 8-bit material codes of format/SPEC.md §11.1.6.
uint8_t unit_code(float x) {
  return static_cast<uint8_t>(std::lround(255.0 * std::clamp(double{x}, 0.0, 1.0)));
}
uint8_t ior_code(float ior) {
  return unit_code(static_cast<float>((double{ior} - 1.0) / 2.0));
}

// A share of a texel's 16 cells as a count.
uint8_t cell_count(float share) {
  return static_cast<uint8_t>(std::lround(16.0 * std::clamp(double{share}, 0.0, 1.0)));
}

}  // namespace

Expected<GlTextureLayout> layout_for_clip(const container::LightfieldTrackHeader& header,
                                          std::span<const decoder::LightfieldViewInfo> views,
                                          bool keep_bc5_depth, bool coverage) {
  if (views.size() != header.view_count) {
    return Status(kGlLayout, "the clip has " + std::to_string(header.view_count) +
                                 " views, the layout was given " + std::to_string(views.size()));
  }
  GlTextureLayout layout;
  layout.colour_format = lf::colour_gpu_format(header.colour_format);
  const auto depth = static_cast<PixelFormat>(header.depth_format);
  layout.depth_format = depth == PixelFormat::kBc5 && keep_bc5_depth ? depth : PixelFormat::kR16;
  // r16p and r16pm (predicted) decode to the same r16 codes on the CPU: the textures never see
  // them (the LightfieldDecoder fills an r16pm rectangle's unchanged texels from its own tile
  // state).
  if (depth != PixelFormat::kR16 && depth != PixelFormat::kR16Predicted &&
      depth != PixelFormat::kR16PredictedMasked && depth != PixelFormat::kBc5) {
    return Status(kGlLayout,
                  "depth format " + format_name(depth) + " is not r16, r16p, r16pm or BC5");
  }
  const auto material = static_cast<PixelFormat>(header.material_format);
  if (material != PixelFormat::kNone) layout.material_format = material;
  layout.colour_two_slots = true;
  for (const decoder::LightfieldViewInfo& info : views) {
    GlViewInfo v;
    v.position = info.position;
    CALF_ASSIGN_OR_RETURN(v.range, LogDepthRange::make(info.z_near, info.z_far));
    v.face_size = header.face_size;
    v.cell_size = header.cell_size;
    v.has_material = info.has_material && material != PixelFormat::kNone;
    v.has_coverage = coverage;
    layout.views.push_back(v);
  }
  return layout;
}

Expected<ViewSetUpload> updates_from_view_set(const ViewSet& set) {
  if (set.views.empty()) return Status(kGlLayout, "the view set is empty");
  ViewSetUpload up;
  up.layout.colour_format = PixelFormat::kRgba16f;
  up.layout.depth_format = PixelFormat::kR16;
  up.layout.material_format = PixelFormat::kRgba8;
  up.layout.colour_two_slots = false;
  struct Pending {
    UpdateTarget target;
    uint32_t view;
    int face;
    PixelFormat format;
  };
  std::vector<Pending> pending;
  for (uint32_t vi = 0; vi < set.views.size(); ++vi) {
    const View& v = set.views[vi];
    const uint32_t n = v.face_size();
    up.layout.views.push_back({v.position(), v.range(), n, n, v.has_material(), v.has_coverage()});
    const size_t texels = size_t{n} * n;
    for (int f = 0; f < kCubeFaceCount; ++f) {
      const CubeFace face = cube_face_from_index(f);
      std::vector<uint8_t> colour(texels * 8);
      const std::span<const float> c = v.colour_face(face);
      for (size_t i = 0; i < texels; ++i) {
        const uint16_t h[4] = {bc::float_to_half(c[3 * i]), bc::float_to_half(c[3 * i + 1]),
                               bc::float_to_half(c[3 * i + 2]), bc::float_to_half(1.0f)};
        std::memcpy(&colour[8 * i], h, 8);
      }
      up.bytes.push_back(std::move(colour));
      pending.push_back({UpdateTarget::kColour, vi, f, PixelFormat::kRgba16f});
      std::vector<uint8_t> depth(texels * 2);
      std::memcpy(depth.data(), v.depth_face(face).data(), depth.size());
      up.bytes.push_back(std::move(depth));
      pending.push_back({UpdateTarget::kDepth, vi, f, PixelFormat::kR16});
      if (v.has_material()) {
        std::vector<uint8_t> codes(texels * 4);
        const std::span<const float> m = v.material_face(face);
        for (size_t i = 0; i < texels; ++i) {
          codes[4 * i] = unit_code(m[3 * i]);
          codes[4 * i + 1] = unit_code(m[3 * i + 1]);
          codes[4 * i + 2] = ior_code(m[3 * i + 2]);
          codes[4 * i + 3] = 255;
        }
        up.bytes.push_back(std::move(codes));
        pending.push_back({UpdateTarget::kMaterial, vi, f, PixelFormat::kRgba8});
      }
      if (v.has_coverage()) {
        std::vector<uint8_t> texels_gpu(texels * lf::kCoverageGpuBytes);
        for (uint32_t y = 0; y < n; ++y) {
          for (uint32_t x = 0; x < n; ++x) {
            const Coverage cov = v.coverage_at(face, x, y);
            uint8_t* p = &texels_gpu[(size_t{y} * n + x) * lf::kCoverageGpuBytes];
            p[0] = static_cast<uint8_t>(cov.mask);
            p[1] = static_cast<uint8_t>(cov.mask >> 8);
            p[2] = cell_count(cov.near);
            p[3] = cell_count(cov.far);
          }
        }
        up.bytes.push_back(std::move(texels_gpu));
        pending.push_back({UpdateTarget::kCoverage, vi, f, PixelFormat::kRgba8});
      }
      up.frame.cells.push_back({vi, face, 0, 0, 0});
    }
  }
  // Spans are taken only now: the byte vectors no longer move.
  for (size_t i = 0; i < pending.size(); ++i) {
    const Pending& p = pending[i];
    const uint32_t n = up.layout.views[p.view].face_size;
    TextureUpdate u;
    u.target = p.target;
    u.view = p.view;
    u.face = cube_face_from_index(p.face);
    u.rect = {0, 0, n, n};
    u.format = p.format;
    u.bytes = up.bytes[i];
    up.frame.updates.push_back(u);
  }
  return up;
}

GlViews::GlViews(const GlFunctions& gl, GlTextureLayout layout)
    : gl_(gl), layout_(std::move(layout)) {}

GlViews::~GlViews() {
  const GLuint names[] = {tex_.colour, tex_.depth, tex_.cells, tex_.material, tex_.coverage};
  for (GLuint t : names) {
    if (t != 0) gl_.DeleteTextures(1, &t);
  }
}

uint32_t GlViews::cells_per_side(uint32_t v) const {
  return cells_per_side_[v];
}

Expected<std::unique_ptr<GlViews>> GlViews::make(const GlFunctions& gl, GlTextureLayout layout) {
  if (layout.views.empty()) return Status(kGlLayout, "the texture layout has no views");
  const GlFormat colour = colour_format(layout.colour_format);
  const GlFormat depth = depth_format(layout.depth_format);
  const GlFormat material = material_format(layout.material_format);
  if (colour.internal == 0) {
    return Status(kGlLayout, "colour format " + format_name(layout.colour_format) +
                                 " is not BC1, BC7, BC6H, rgba8 or rgba16f");
  }
  if (depth.internal == 0) {
    return Status(kGlLayout,
                  "depth storage " + format_name(layout.depth_format) + " is not r16 or BC5");
  }
  const bool any_material = std::any_of(layout.views.begin(), layout.views.end(),
                                        [](const GlViewInfo& v) { return v.has_material; });
  const bool compressed =
      colour.compressed || depth.compressed || (any_material && material.compressed);
  uint32_t size = 0;
  for (size_t i = 0; i < layout.views.size(); ++i) {
    const GlViewInfo& v = layout.views[i];
    if (v.face_size < 1 || v.face_size > kMaxFaceSize || v.cell_size < 1 ||
        v.cell_size > kMaxFaceSize) {
      return Status(kGlLayout, "view " + std::to_string(i) + ": face size " +
                                   std::to_string(v.face_size) + " or cell size " +
                                   std::to_string(v.cell_size) + " is outside 1..16384");
    }
    if (size != 0 && v.face_size != size && compressed) {
      return Status(kGlLayout, "compressed textures need one face size for all views (view " +
                                   std::to_string(i) + " has " + std::to_string(v.face_size) +
                                   ", an earlier view " + std::to_string(size) + ")");
    }
    if (!FaceGrid::with_cell_size(v.face_size, v.cell_size).ok()) {
      return Status(kGlLayout, "view " + std::to_string(i) + ": no cell grid");
    }
    size = std::max(size, v.face_size);
  }
  if (any_material && material.internal == 0) {
    return Status(kGlLayout, "material storage " + format_name(layout.material_format) +
                                 " is not rgba8 or BC1");
  }
  const bool bc1 = layout.colour_format == PixelFormat::kBc1 ||
                   (any_material && layout.material_format == PixelFormat::kBc1);
  if (bc1 && !gl.s3tc) {
    return Status(kGlMissing, "BC1 textures need GL_EXT_texture_compression_s3tc");
  }
  if (layout.colour_format == PixelFormat::kBc1 && !gl.s3tc_srgb) {
    return Status(kGlMissing, "sRGB BC1 colour needs GL_EXT_texture_sRGB");
  }
  const uint64_t coverage_layers =
      6 * static_cast<uint64_t>(std::count_if(layout.views.begin(), layout.views.end(),
                                              [](const GlViewInfo& v) { return v.has_coverage; }));
  if (coverage_layers > static_cast<uint64_t>(gl.max_array_layers)) {
    return Status(kGlMissing, std::to_string(coverage_layers) +
                                  " coverage layers, the context allows " +
                                  std::to_string(gl.max_array_layers));
  }
  const uint64_t slots = layout.colour_two_slots ? 2 : 1;
  const uint64_t colour_layers = layout.views.size() * 6 * slots;
  if (colour_layers > static_cast<uint64_t>(gl.max_array_layers)) {
    return Status(kGlMissing, std::to_string(layout.views.size()) + " views need " +
                                  std::to_string(colour_layers) +
                                  " colour layers, the context allows " +
                                  std::to_string(gl.max_array_layers));
  }
  if (size > static_cast<uint32_t>(gl.max_texture_size)) {
    return Status(kGlMissing, "faces of " + std::to_string(size) +
                                  " texels exceed the context's texture size " +
                                  std::to_string(gl.max_texture_size));
  }
  std::unique_ptr<GlViews> views(new GlViews(gl, std::move(layout)));
  views->size_ = size;
  int next_material = 0;
  for (const GlViewInfo& v : views->layout_.views) {
    views->coverage_base_.push_back(v.has_coverage ? views->coverage_layers_ : -1);
    if (v.has_coverage) views->coverage_layers_ += 6;
    // The cell grid convention (calf/format/grid.h); the shader's x / cell_size agrees with it,
    // a cell larger than the face included.
    views->cells_per_side_.push_back(
        FaceGrid::with_cell_size(v.face_size, v.cell_size)->cells_per_side());
    views->material_base_.push_back(v.has_material ? next_material : -1);
    if (v.has_material) next_material += 6;
  }
  CALF_RETURN_IF_ERROR(views->allocate());
  return views;
}

Status GlViews::allocate() {
  const GlFormat colour = colour_format(layout_.colour_format);
  const GlFormat depth = depth_format(layout_.depth_format);
  const GlFormat material = material_format(layout_.material_format);
  const auto view_count = static_cast<GLsizei>(layout_.views.size());
  const GLsizei n = static_cast<GLsizei>(size_);
  for (uint32_t v = 0; v < layout_.views.size(); ++v) {
    cell_side_ = std::max(cell_side_, cells_per_side(v));
  }
  int material_layers = 0;
  for (int base : material_base_) material_layers = std::max(material_layers, base + 6);
  const auto make = [&](GLuint* name, GLenum internal, GLsizei w, GLsizei layers) {
    gl_.GenTextures(1, name);
    gl_.BindTexture(GL_TEXTURE_2D_ARRAY, *name);
    gl_.TexStorage3D(GL_TEXTURE_2D_ARRAY, 1, internal, w, w, layers);
    // texelFetch ignores filtering, but integer textures with a linear filter are incomplete.
    gl_.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    gl_.TexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  };
  const GLsizei colour_layers = view_count * 6 * static_cast<GLsizei>(colour_slots());
  make(&tex_.colour, colour.internal, n, colour_layers);
  make(&tex_.depth, depth.internal, n, view_count * 6);
  make(&tex_.cells, GL_R16UI, static_cast<GLsizei>(cell_side_), view_count * 6);
  // A 1-texel placeholder when no view has material, so that the sampler is always complete.
  make(&tex_.material, material_layers > 0 ? material.internal : GL_RGBA8,
       material_layers > 0 ? n : 1, std::max(material_layers, 1));
  // Coverage likewise (the shader reads it only for views with coverage).
  make(&tex_.coverage, kCoverageFormat.internal, coverage_layers_ > 0 ? n : 1,
       std::max(coverage_layers_, 1));
  CALF_RETURN_IF_ERROR(check_gl_error(gl_, "allocating the view textures"));

  // Initial contents: what a fresh View holds. Uncompressed textures are cleared; compressed ones
  // get blocks that decode to the same values (all-zero BC1 / BC6H / BC7 blocks are black; a BC5
  // block of channel endpoints 255, 255 and zero indices is 255 in both channels: sky).
  const uint16_t sky = kLog16Sky, zero16 = 0;
  const uint8_t plain_coverage[4] = {255, 255, 0, 0};  // every cell its own surface
  const uint8_t black[4] = {0, 0, 0, 255};
  const float zero[4] = {0, 0, 0, 0};
  const PixelRect face{0, 0, size_, size_};
  if (colour.compressed) {
    const std::vector<uint8_t> blocks(rect_bytes(colour, size_, size_), 0);
    for (GLsizei l = 0; l < colour_layers; ++l) {
      CALF_RETURN_IF_ERROR(
          upload(tex_.colour, colour.internal, true, 0, 0, face, l, blocks.data(), blocks.size()));
    }
  } else {
    gl_.ClearTexImage(tex_.colour, 0, GL_RGBA, GL_FLOAT, zero);
  }
  if (depth.compressed) {
    std::vector<uint8_t> blocks(rect_bytes(depth, size_, size_), 0);
    for (size_t b = 0; b < blocks.size(); b += 8) blocks[b] = blocks[b + 1] = 255;
    for (GLsizei l = 0; l < view_count * 6; ++l) {
      CALF_RETURN_IF_ERROR(
          upload(tex_.depth, depth.internal, true, 0, 0, face, l, blocks.data(), blocks.size()));
    }
  } else {
    gl_.ClearTexImage(tex_.depth, 0, GL_RED_INTEGER, GL_UNSIGNED_SHORT, &sky);
  }
  gl_.ClearTexImage(tex_.cells, 0, GL_RED_INTEGER, GL_UNSIGNED_SHORT, &zero16);
  if (material_layers > 0 && material.compressed) {
    const std::vector<uint8_t> blocks(rect_bytes(material, size_, size_), 0);
    for (int l = 0; l < material_layers; ++l) {
      CALF_RETURN_IF_ERROR(upload(tex_.material, material.internal, true, 0, 0, face, l,
                                  blocks.data(), blocks.size()));
    }
  } else {
    gl_.ClearTexImage(tex_.material, 0, GL_RGBA, GL_UNSIGNED_BYTE, black);
  }
  gl_.ClearTexImage(tex_.coverage, 0, GL_RGBA_INTEGER, GL_UNSIGNED_BYTE, plain_coverage);
  cells_.assign(size_t{cell_side_} * cell_side_ * layout_.views.size() * 6, 0);
  cells_dirty_.assign(layout_.views.size() * 6, 0);
  return check_gl_error(gl_, "initialising the view textures");
}

Status GlViews::upload(GLuint texture, GLenum storage, bool compressed, GLenum format, GLenum type,
                       const PixelRect& rect, int layer, const void* data, size_t size) {
  // Client memory, tightly packed, whatever pixel-store state the caller left behind.
  gl_.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
  gl_.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
  gl_.PixelStorei(GL_UNPACK_ROW_LENGTH, 0);
  gl_.PixelStorei(GL_UNPACK_IMAGE_HEIGHT, 0);
  gl_.PixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
  gl_.PixelStorei(GL_UNPACK_SKIP_ROWS, 0);
  gl_.PixelStorei(GL_UNPACK_SKIP_IMAGES, 0);
  gl_.BindTexture(GL_TEXTURE_2D_ARRAY, texture);
  const auto x = static_cast<GLint>(rect.x), y = static_cast<GLint>(rect.y);
  const auto w = static_cast<GLsizei>(rect.width), h = static_cast<GLsizei>(rect.height);
  if (compressed) {
    gl_.CompressedTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, x, y, layer, w, h, 1, storage,
                                static_cast<GLsizei>(size), data);
  } else {
    gl_.TexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, x, y, layer, w, h, 1, format, type, data);
  }
  return check_gl_error(gl_, "uploading a texture rect");
}

Status GlViews::apply(const decoder::LightfieldFrameUpdates& frame) {
  for (size_t i = 0; i < frame.updates.size(); ++i) {
    const Status s = apply_update(frame.updates[i]);
    if (!s.ok()) return s.with_context("update " + std::to_string(i));
  }
  return set_cells(frame.cells);
}

Status GlViews::apply_update(const TextureUpdate& u) {
  const auto fail = [&](const std::string& what) {
    return Status(kGlUpdate, std::string(target_name(u.target)) + " update of view " +
                                 std::to_string(u.view) + ": " + what);
  };
  if (u.view >= layout_.views.size()) {
    return fail("no such view (the layout has " + std::to_string(layout_.views.size()) + ")");
  }
  const int face = cube_face_index(u.face);
  if (face < 0 || face >= kCubeFaceCount) return fail("face index is not in [0, 6)");
  const GlViewInfo& v = layout_.views[u.view];
  const PixelRect& r = u.rect;
  if (r.width == 0 || r.height == 0 || uint64_t{r.x} + r.width > v.face_size ||
      uint64_t{r.y} + r.height > v.face_size) {
    return fail("rect (" + std::to_string(r.x) + ", " + std::to_string(r.y) + ", " +
                std::to_string(r.width) + " x " + std::to_string(r.height) +
                ") is empty or leaves the " + std::to_string(v.face_size) + "-texel face");
  }
  // What the update's format is, and what the storage is.
  GlFormat in, storage;
  GLuint texture = 0;
  int layer = 0;
  switch (u.target) {
    case UpdateTarget::kColour:
      if (u.slot >= colour_slots()) {
        return fail("slot " + std::to_string(u.slot) + " is not below the layout's " +
                    std::to_string(colour_slots()) + " keyframe slots");
      }
      if (u.format != layout_.colour_format) {
        return fail("format " + format_name(u.format) + " is not the layout's " +
                    format_name(layout_.colour_format));
      }
      in = storage = colour_format(layout_.colour_format);
      texture = tex_.colour;
      layer = static_cast<int>((u.view * 6 + face) * colour_slots() + u.slot);
      break;
    case UpdateTarget::kDepth:
      storage = depth_format(layout_.depth_format);
      in = depth_format(u.format);
      if (in.internal == 0 || (storage.compressed && u.format != layout_.depth_format)) {
        return fail("format " + format_name(u.format) + " does not go into " +
                    format_name(layout_.depth_format) + " storage");
      }
      texture = tex_.depth;
      layer = static_cast<int>(u.view * 6 + face);
      break;
    case UpdateTarget::kMaterial:
      if (material_base_[u.view] < 0) return fail("the view has no material");
      storage = material_format(layout_.material_format);
      in = material_format(u.format);
      if (in.internal == 0 || (storage.compressed && u.format != layout_.material_format)) {
        return fail("format " + format_name(u.format) + " does not go into " +
                    format_name(layout_.material_format) + " storage");
      }
      texture = tex_.material;
      layer = material_base_[u.view] + face;
      break;
    case UpdateTarget::kCoverage:
      if (coverage_base_[u.view] < 0) return fail("the view has no coverage");
      if (u.format != PixelFormat::kRgba8) {
        return fail("format " + format_name(u.format) + " is not rgba8");
      }
      in = storage = kCoverageFormat;
      texture = tex_.coverage;
      layer = coverage_base_[u.view] + face;
      break;
    default:
      return fail("unknown target");
  }
  if (u.target != UpdateTarget::kColour && u.slot != 0) return fail("slot must be 0");
  if (in.compressed) {
    const bool aligned = r.x % 4 == 0 && r.y % 4 == 0 &&
                         (r.width % 4 == 0 || r.x + r.width == v.face_size) &&
                         (r.height % 4 == 0 || r.y + r.height == v.face_size);
    if (!aligned) return fail("block rect is not 4-aligned");
  }
  const size_t need = rect_bytes(in, r.width, r.height);
  if (u.bytes.size() != need) {
    return fail(std::to_string(u.bytes.size()) + " bytes, the rect needs " + std::to_string(need));
  }
  if (in.compressed == storage.compressed) {
    return upload(texture, storage.internal, storage.compressed, storage.format, storage.type, r,
                  layer, u.bytes.data(), u.bytes.size());
  }
  // A block format into uncompressed storage: decoded on the CPU exactly as the decoder's CPU
  // image of the textures decodes it (calf/decoder/cpu_textures.h, calf/format/bc.h).
  const size_t texels = size_t{r.width} * r.height;
  if (u.target == UpdateTarget::kDepth) {
    std::vector<uint16_t> codes(texels);
    CALF_RETURN_IF_ERROR(decoder::decode_gpu_depth(u.format, u.bytes, r.width, r.height, codes));
    return upload(texture, storage.internal, false, storage.format, storage.type, r, layer,
                  codes.data(), codes.size() * 2);
  }
  std::vector<uint8_t> codes(3 * texels), rgba(4 * texels, 255);
  CALF_RETURN_IF_ERROR(decoder::decode_gpu_material(u.format, u.bytes, r.width, r.height, codes));
  for (size_t i = 0; i < texels; ++i) std::memcpy(&rgba[4 * i], &codes[3 * i], 3);
  return upload(texture, storage.internal, false, storage.format, storage.type, r, layer,
                rgba.data(), rgba.size());
}

Status GlViews::set_cells(std::span<const CellParams> cells) {
  for (const CellParams& c : cells) {
    const int face = cube_face_index(c.face);
    if (c.view >= layout_.views.size() || face < 0 || face >= kCubeFaceCount) {
      return Status(kGlUpdate, "cell of view " + std::to_string(c.view) + " face " +
                                   std::to_string(face) + " is out of range");
    }
    const uint32_t per_side = cells_per_side(c.view);
    if (c.cell >= per_side * per_side || c.a_slot > 1 ||
        (colour_slots() == 1 && (c.a_slot != 0 || c.t != 0))) {
      return Status(kGlUpdate, "cell " + std::to_string(c.cell) + " of view " +
                                   std::to_string(c.view) + " (t " + std::to_string(c.t) +
                                   ", slot " + std::to_string(c.a_slot) +
                                   ") is outside the grid or the slots");
    }
    const size_t layer = size_t{c.view} * 6 + face;
    const size_t texel = (size_t{c.cell / per_side} * cell_side_) + c.cell % per_side;
    cells_[layer * cell_side_ * cell_side_ + texel] = static_cast<uint16_t>(c.t | c.a_slot << 8);
    cells_dirty_[layer] = 1;
  }
  return upload_cells();
}

Status GlViews::upload_cells() {
  const PixelRect all{0, 0, cell_side_, cell_side_};
  const size_t per_layer = size_t{cell_side_} * cell_side_;
  for (size_t layer = 0; layer < cells_dirty_.size(); ++layer) {
    if (!cells_dirty_[layer]) continue;
    cells_dirty_[layer] = 0;
    CALF_RETURN_IF_ERROR(upload(tex_.cells, GL_R16UI, false, GL_RED_INTEGER, GL_UNSIGNED_SHORT, all,
                                static_cast<int>(layer), &cells_[layer * per_layer],
                                per_layer * 2));
  }
  return Status::Ok();
}

}  // namespace calf::player
