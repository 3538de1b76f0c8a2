#include "calf/decoder/cpu_textures.h"

#include <cstring>
#include <string>

#include "calf/format/bc.h"
#include "calf/format/colour.h"
#include "calf/format/log_depth.h"

namespace calf::decoder {
namespace {

using container::PixelFormat;

Status wrong_size(const char* what, size_t got, size_t expected) {
  return Status(ErrorId::kLightfieldChunk, std::string(what) + " update of " + std::to_string(got) +
                                               " bytes, expected " + std::to_string(expected));
}

Status unsupported(const char* what, PixelFormat f) {
  return Status(ErrorId::kLightfieldFormat,
                std::string(what) + " update in format " +
                    container::pixel_format_name(static_cast<uint16_t>(f)));
}

size_t texels_of(uint32_t w, uint32_t h) {
  return size_t{w} * h;
}

// Decodes whole-block bytes into `texel_bytes` per texel, row-major, through calf/format/bc.h.
Status decode_blocks(bc::Format f, std::span<const uint8_t> bytes, uint32_t w, uint32_t h,
                     size_t texel_bytes, std::vector<uint8_t>& out, const char* what) {
  const size_t expected = size_t{bc::blocks_along(w)} * bc::blocks_along(h) *
                          (f == bc::Format::kBc1 || f == bc::Format::kBc4 ? 8 : 16);
  if (bytes.size() != expected) return wrong_size(what, bytes.size(), expected);
  out.resize(texels_of(w, h) * texel_bytes);
  return bc::decode_image(f, bytes.data(), bytes.size(), w, h, out.data(), out.size(),
                          size_t{w} * texel_bytes);
}

}  // namespace

Status decode_gpu_colour(PixelFormat format, std::span<const uint8_t> bytes, uint32_t width,
                         uint32_t height, std::span<float> rgb) {
  const size_t n = texels_of(width, height);
  if (rgb.size() < n * 3) return Status(ErrorId::kInvalidArgument, "colour output too small");
  std::vector<uint8_t> tmp;
  switch (format) {
    case PixelFormat::kBc1:
    case PixelFormat::kBc7: {
      CALF_RETURN_IF_ERROR(
          decode_blocks(format == PixelFormat::kBc1 ? bc::Format::kBc1 : bc::Format::kBc7, bytes,
                        width, height, 4, tmp, "colour"));
      for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) rgb[3 * i + c] = linear_from_srgb8(tmp[4 * i + c]);
      }
      return Status::Ok();
    }
    case PixelFormat::kBc6h: {
      CALF_RETURN_IF_ERROR(
          decode_blocks(bc::Format::kBc6hUnsigned, bytes, width, height, 6, tmp, "colour"));
      for (size_t i = 0; i < n * 3; ++i) {
        uint16_t h;
        std::memcpy(&h, &tmp[2 * i], 2);
        rgb[i] = bc::half_to_float(h);
      }
      return Status::Ok();
    }
    case PixelFormat::kRgba8:
      if (bytes.size() != n * 4) return wrong_size("colour", bytes.size(), n * 4);
      for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) rgb[3 * i + c] = linear_from_srgb8(bytes[4 * i + c]);
      }
      return Status::Ok();
    case PixelFormat::kRgba16f:
      if (bytes.size() != n * 8) return wrong_size("colour", bytes.size(), n * 8);
      for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) {
          const size_t k = 2 * (4 * i + c);
          rgb[3 * i + c] = bc::half_to_float(static_cast<uint16_t>(bytes[k] | bytes[k + 1] << 8));
        }
      }
      return Status::Ok();
    default:
      return unsupported("colour", format);
  }
}

Status decode_gpu_depth(PixelFormat format, std::span<const uint8_t> bytes, uint32_t width,
                        uint32_t height, std::span<uint16_t> codes) {
  const size_t n = texels_of(width, height);
  if (codes.size() < n) return Status(ErrorId::kInvalidArgument, "depth output too small");
  if (format == PixelFormat::kR16) {
    if (bytes.size() != n * 2) return wrong_size("depth", bytes.size(), n * 2);
    for (size_t i = 0; i < n; ++i)
      codes[i] = static_cast<uint16_t>(bytes[2 * i] | bytes[2 * i + 1] << 8);
    return Status::Ok();
  }
  if (format == PixelFormat::kBc5) {
    std::vector<uint8_t> tmp;
    CALF_RETURN_IF_ERROR(decode_blocks(bc::Format::kBc5, bytes, width, height, 2, tmp, "depth"));
    for (size_t i = 0; i < n; ++i)
      codes[i] = static_cast<uint16_t>(tmp[2 * i] << 8 | tmp[2 * i + 1]);
    return Status::Ok();
  }
  return unsupported("depth", format);
}

Status decode_gpu_material(PixelFormat format, std::span<const uint8_t> bytes, uint32_t width,
                           uint32_t height, std::span<uint8_t> codes) {
  const size_t n = texels_of(width, height);
  if (codes.size() < n * 3) return Status(ErrorId::kInvalidArgument, "material output too small");
  std::vector<uint8_t> tmp;
  std::span<const uint8_t> rgba = bytes;
  if (format == PixelFormat::kBc1) {
    CALF_RETURN_IF_ERROR(decode_blocks(bc::Format::kBc1, bytes, width, height, 4, tmp, "material"));
    rgba = tmp;
  } else if (format != PixelFormat::kRgba8) {
    return unsupported("material", format);
  } else if (bytes.size() != n * 4) {
    return wrong_size("material", bytes.size(), n * 4);
  }
  for (size_t i = 0; i < n; ++i) std::memcpy(&codes[3 * i], &rgba[4 * i], 3);
  return Status::Ok();
}

CpuTextures::CpuTextures(const container::LightfieldTrackHeader& header,
                         std::span<const LightfieldViewInfo> views)
    : face_size_(header.face_size) {
  if (auto grid = FaceGrid::with_cell_size(header.face_size, header.cell_size); grid.ok()) {
    cells_ = *grid;
  }
  const size_t texels = size_t{face_size_} * face_size_;
  views_.resize(views.size());
  for (size_t v = 0; v < views.size(); ++v) {
    ViewState& s = views_[v];
    for (int f = 0; f < kCubeFaceCount; ++f) {
      for (auto& slot : s.slots[f]) slot.assign(texels * 3, 0.0f);
      s.depth[f].assign(texels, kLog16Sky);
      if (views[v].has_material) s.material[f].assign(texels * 3, 0);
      s.cells[f].resize(cells_.cell_count());
      for (uint32_t c = 0; c < cells_.cell_count(); ++c) {
        s.cells[f][c].view = static_cast<uint32_t>(v);
        s.cells[f][c].face = static_cast<CubeFace>(f);
        s.cells[f][c].cell = c;
      }
    }
  }
}

Status CpuTextures::apply(const LightfieldFrameUpdates& frame) {
  std::vector<float> rgb;
  std::vector<uint16_t> codes;
  std::vector<uint8_t> mat;
  for (const TextureUpdate& u : frame.updates) {
    const int f = cube_face_index(u.face);
    const PixelRect& r = u.rect;
    if (u.view >= views_.size() || u.slot > 1 || r.width == 0 || r.height == 0 ||
        r.x + r.width > face_size_ || r.y + r.height > face_size_ ||
        (u.target == UpdateTarget::kMaterial && views_[u.view].material[f].empty())) {
      return Status(ErrorId::kDecoderArgument, "update outside the texture state: view " +
                                                   std::to_string(u.view) + " face " +
                                                   std::to_string(f));
    }
    ViewState& s = views_[u.view];
    const size_t n = texels_of(r.width, r.height);
    switch (u.target) {
      case UpdateTarget::kColour: {
        rgb.resize(n * 3);
        CALF_RETURN_IF_ERROR(decode_gpu_colour(u.format, u.bytes, r.width, r.height, rgb));
        std::vector<float>& dst = s.slots[f][u.slot];
        for (uint32_t y = 0; y < r.height; ++y) {
          std::memcpy(&dst[(size_t{r.y + y} * face_size_ + r.x) * 3], &rgb[size_t{y} * r.width * 3],
                      size_t{r.width} * 3 * sizeof(float));
        }
        break;
      }
      case UpdateTarget::kDepth: {
        codes.resize(n);
        CALF_RETURN_IF_ERROR(decode_gpu_depth(u.format, u.bytes, r.width, r.height, codes));
        for (uint32_t y = 0; y < r.height; ++y) {
          std::memcpy(&s.depth[f][size_t{r.y + y} * face_size_ + r.x], &codes[size_t{y} * r.width],
                      size_t{r.width} * sizeof(uint16_t));
        }
        break;
      }
      case UpdateTarget::kCoverage: {
        if (u.format != PixelFormat::kRgba8 || u.bytes.size() != n * lf::kCoverageGpuBytes) {
          return wrong_size("coverage", u.bytes.size(), n * lf::kCoverageGpuBytes);
        }
        if (s.coverage[0].empty()) {
          for (auto& face : s.coverage) face.assign(size_t{face_size_} * face_size_, {});
        }
        for (uint32_t y = 0; y < r.height; ++y) {
          for (uint32_t x = 0; x < r.width; ++x) {
            s.coverage[f][size_t{r.y + y} * face_size_ + r.x + x] =
                lf::coverage_from_gpu(&u.bytes[(size_t{y} * r.width + x) * lf::kCoverageGpuBytes]);
          }
        }
        break;
      }
      case UpdateTarget::kMaterial: {
        mat.resize(n * 3);
        CALF_RETURN_IF_ERROR(decode_gpu_material(u.format, u.bytes, r.width, r.height, mat));
        for (uint32_t y = 0; y < r.height; ++y) {
          std::memcpy(&s.material[f][(size_t{r.y + y} * face_size_ + r.x) * 3],
                      &mat[size_t{y} * r.width * 3], size_t{r.width} * 3);
        }
        break;
      }
    }
  }
  for (const CellParams& c : frame.cells) {
    if (c.view >= views_.size() || c.cell >= cells_.cell_count() || c.a_slot > 1) {
      return Status(ErrorId::kDecoderArgument, "cell parameters outside the texture state");
    }
    views_[c.view].cells[cube_face_index(c.face)][c.cell] = c;
  }
  return Status::Ok();
}

namespace {

// One cell of the displayed colour: per texel mix(slot a, slot 1 - a, t / 255) over `r`, written
// to dst + ((y - r.y) * dst_row + (x - r.x)) * 3 for texel (x, y).
void mix_cell(const std::vector<float>& a, const std::vector<float>& b, const CellParams& p,
              const PixelRect& r, uint32_t face_size, float* dst, size_t dst_row) {
  // The same arithmetic as the reference decoder (SPEC §11.1.4): w = t / 255 in float.
  const float w = p.t / 255.0f;
  for (uint32_t y = 0; y < r.height; ++y) {
    const size_t from = (size_t{r.y + y} * face_size + r.x) * 3;
    float* to = dst + y * dst_row * 3;
    for (size_t i = 0; i < size_t{r.width} * 3; ++i) {
      to[i] = p.t == 0 ? a[from + i] : (1.0f - w) * a[from + i] + w * b[from + i];
    }
  }
}

}  // namespace

std::vector<float> CpuTextures::colour(uint32_t view, CubeFace face) const {
  const ViewState& s = views_[view];
  const int f = cube_face_index(face);
  std::vector<float> out(s.slots[f][0].size());
  for (uint32_t cy = 0; cy < cells_.cells_per_side(); ++cy) {
    for (uint32_t cx = 0; cx < cells_.cells_per_side(); ++cx) {
      const PixelRect r = cells_.cell_rect(cx, cy);
      const CellParams& p = s.cells[f][cells_.cell_index(cx, cy)];
      mix_cell(s.slots[f][p.a_slot], s.slots[f][1 - p.a_slot], p, r, face_size_,
               &out[(size_t{r.y} * face_size_ + r.x) * 3], face_size_);
    }
  }
  return out;
}

void CpuTextures::colour_cell(uint32_t view, CubeFace face, uint32_t cell,
                              std::vector<float>* rgb) const {
  const ViewState& s = views_[view];
  const int f = cube_face_index(face);
  const uint32_t per_side = cells_.cells_per_side();
  const PixelRect r = cells_.cell_rect(cell % per_side, cell / per_side);
  const CellParams& p = s.cells[f][cell];
  rgb->resize(size_t{r.width} * r.height * 3);
  mix_cell(s.slots[f][p.a_slot], s.slots[f][1 - p.a_slot], p, r, face_size_, rgb->data(), r.width);
}

std::span<const float> CpuTextures::colour_slot(uint32_t view, CubeFace face, uint32_t slot) const {
  return views_[view].slots[cube_face_index(face)][slot];
}
std::span<const uint16_t> CpuTextures::depth(uint32_t view, CubeFace face) const {
  return views_[view].depth[cube_face_index(face)];
}
std::span<const uint8_t> CpuTextures::material(uint32_t view, CubeFace face) const {
  return views_[view].material[cube_face_index(face)];
}
std::span<const lf::CoverageTexel> CpuTextures::coverage(uint32_t view, CubeFace face) const {
  return views_[view].coverage[cube_face_index(face)];
}
CellParams CpuTextures::cell(uint32_t view, CubeFace face, uint32_t cell) const {
  return views_[view].cells[cube_face_index(face)][cell];
}

}  // namespace calf::decoder
