#include "calf/player/view_set.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdio>
#include <string>

namespace calf::player {
namespace {

// snprintf rather than string concatenation: GCC 12's -Wrestrict misfires on the latter at -O3.
std::string rect_text(const PixelRect& r) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "(%u, %u, %u x %u)", r.x, r.y, r.width, r.height);
  return buf;
}

template <typename T>
void copy_rect(std::vector<T>& face, uint32_t face_size, const PixelRect& rect, size_t channels,
               std::span<const T> src, size_t stride) {
  const size_t row = size_t{rect.width} * channels;
  for (uint32_t j = 0; j < rect.height; ++j) {
    const T* from = src.data() + j * stride;
    T* to = face.data() + (size_t{rect.y + j} * face_size + rect.x) * channels;
    std::copy(from, from + row, to);
  }
}

}  // namespace

Expected<View> View::make(const Vec3& position, const LogDepthRange& range, uint32_t face_size,
                          bool with_material) {
  if (face_size < 1 || face_size > kMaxFaceSize) {
    return Status(ErrorId::kPlayerViewSet, "face size " + std::to_string(face_size) +
                                               " is outside [1, " + std::to_string(kMaxFaceSize) +
                                               "]");
  }
  if (!std::isfinite(position.x) || !std::isfinite(position.y) || !std::isfinite(position.z)) {
    return Status(ErrorId::kPlayerViewSet, "view position is not finite");
  }
  View v;
  v.position_ = position;
  v.range_ = range;
  v.face_size_ = face_size;
  const size_t texels = size_t{face_size} * face_size;
  for (int f = 0; f < kCubeFaceCount; ++f) {
    v.colour_[f].assign(3 * texels, 0.0f);
    v.depth_[f].assign(texels, kLog16Sky);
    if (with_material) {
      v.material_[f].resize(3 * texels);
      for (size_t i = 0; i < texels; ++i) {
        v.material_[f][3 * i + 2] = 1.0f;
      }
    }
  }
  return v;
}

size_t View::texel_index(uint32_t x, uint32_t y) const {
  assert(x < face_size_ && y < face_size_);
  return size_t{y} * face_size_ + x;
}

Material View::material_at(CubeFace f, uint32_t x, uint32_t y) const {
  if (!has_material()) return {};
  const float* m = &material_[cube_face_index(f)][3 * texel_index(x, y)];
  return {m[0], m[1], m[2]};
}

Status View::check_rect(CubeFace face, const PixelRect& rect, size_t src_size, size_t channels,
                        size_t* stride) const {
  const int fi = cube_face_index(face);
  if (fi < 0 || fi >= kCubeFaceCount) {
    return Status(ErrorId::kPlayerRect, "face index " + std::to_string(fi) + " is not in [0, 6)");
  }
  // 64-bit sums: x + width cannot wrap.
  if (rect.width == 0 || rect.height == 0 || uint64_t{rect.x} + rect.width > face_size_ ||
      uint64_t{rect.y} + rect.height > face_size_) {
    return Status(ErrorId::kPlayerRect, std::string("rect ") + rect_text(rect) + " on face " +
                                            cube_face_name(face) + " is empty or leaves the " +
                                            std::to_string(face_size_) + "-texel face");
  }
  const size_t row = size_t{rect.width} * channels;
  if (*stride == 0) *stride = row;
  if (*stride < row) {
    return Status(ErrorId::kPlayerRect, "source stride " + std::to_string(*stride) +
                                            " is shorter than a row of " + std::to_string(row));
  }
  const size_t needed = (size_t{rect.height} - 1) * *stride + row;
  if (src_size < needed) {
    return Status(ErrorId::kPlayerRect, "source holds " + std::to_string(src_size) +
                                            " elements, rect " + rect_text(rect) + " needs " +
                                            std::to_string(needed));
  }
  return Status::Ok();
}

Status View::write_colour_rect(CubeFace face, const PixelRect& rect, std::span<const float> src,
                               size_t src_stride) {
  CALF_RETURN_IF_ERROR(check_rect(face, rect, src.size(), 3, &src_stride));
  copy_rect(colour_[cube_face_index(face)], face_size_, rect, 3, src, src_stride);
  return Status::Ok();
}

Status View::write_depth_rect(CubeFace face, const PixelRect& rect, std::span<const uint16_t> src,
                              size_t src_stride) {
  CALF_RETURN_IF_ERROR(check_rect(face, rect, src.size(), 1, &src_stride));
  copy_rect(depth_[cube_face_index(face)], face_size_, rect, 1, src, src_stride);
  return Status::Ok();
}

Status View::write_material_rect(CubeFace face, const PixelRect& rect, std::span<const float> src,
                                 size_t src_stride) {
  if (!has_material()) {
    return Status(ErrorId::kPlayerNoMaterial,
                  "material written to a view made without material faces");
  }
  CALF_RETURN_IF_ERROR(check_rect(face, rect, src.size(), 3, &src_stride));
  copy_rect(material_[cube_face_index(face)], face_size_, rect, 3, src, src_stride);
  return Status::Ok();
}

void View::add_coverage() {
  if (has_coverage()) return;
  for (auto& face : coverage_) face.assign(size_t{face_size_} * face_size_, Coverage{});
}

Status View::write_coverage_rect(CubeFace face, const PixelRect& rect, std::span<const float> src,
                                 size_t src_stride) {
  CALF_RETURN_IF_ERROR(check_rect(face, rect, src.size(), 3, &src_stride));
  add_coverage();
  for (uint32_t j = 0; j < rect.height; ++j) {
    for (uint32_t i = 0; i < rect.width; ++i) {
      const float* c = &src[j * src_stride + 3 * size_t{i}];
      Coverage& t = coverage_[cube_face_index(face)][texel_index(rect.x + i, rect.y + j)];
      t.near = c[0];
      t.far = c[1];
      t.mask = static_cast<uint16_t>(std::clamp(c[2], 0.0f, 65535.0f));
    }
  }
  return Status::Ok();
}

bool ViewSet::has_material() const {
  return std::any_of(views.begin(), views.end(), [](const View& v) { return v.has_material(); });
}

}  // namespace calf::player
