#include "colour_av1.h"

#include <dav1d/dav1d.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace calf::decoder {
namespace {

Status decode_error(const std::string& what, const std::string& why, int code) {
  return Status(ErrorId::kAv1Decode, what + ": " + why + " (dav1d " + std::to_string(code) + ")");
}

void quiet(void*, const char*, va_list) {}

uint8_t clamp8(int32_t v) {
  return static_cast<uint8_t>(std::clamp(v, 0, 255));
}

}  // namespace

void av1_ycbcr_to_rgb(uint8_t y, uint8_t cb, uint8_t cr, uint8_t rgb[3]) {
  // BT.709 full range in 16 fractional bits; >> of a negative value is floor division (C++20).
  const int32_t u = int32_t{cb} - 128, v = int32_t{cr} - 128;
  rgb[0] = clamp8(y + ((103206 * v + 32768) >> 16));
  rgb[1] = clamp8(y - ((12276 * u + 30679 * v + 32768) >> 16));
  rgb[2] = clamp8(y + ((121609 * u + 32768) >> 16));
}

void av1_ycbcr10_to_rgb(uint16_t y, uint16_t cb, uint16_t cr, uint16_t rgb[3]) {
  const int32_t u = int32_t{cb} - 512, v = int32_t{cr} - 512;
  auto clamp10 = [](int32_t c) { return static_cast<uint16_t>(std::clamp(c, 0, 1023)); };
  rgb[0] = clamp10(y + ((103206 * v + 32768) >> 16));
  rgb[1] = clamp10(y - ((12276 * u + 30679 * v + 32768) >> 16));
  rgb[2] = clamp10(y + ((121609 * u + 32768) >> 16));
}

struct Av1CellDecoder::Impl {
  Dav1dContext* context = nullptr;
  Dav1dPicture picture{};
  bool has_picture = false;
  ~Impl() {
    if (has_picture) dav1d_picture_unref(&picture);
    if (context) dav1d_close(&context);
  }
};

Av1CellDecoder::Av1CellDecoder(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Av1CellDecoder::Av1CellDecoder(Av1CellDecoder&&) noexcept = default;
Av1CellDecoder& Av1CellDecoder::operator=(Av1CellDecoder&&) noexcept = default;
Av1CellDecoder::~Av1CellDecoder() = default;

Expected<Av1CellDecoder> Av1CellDecoder::create() {
  Dav1dSettings s;
  dav1d_default_settings(&s);
  s.n_threads = 1;
  s.max_frame_delay = 1;
  s.apply_grain = 0;
  s.all_layers = 0;
  s.logger.cookie = nullptr;
  s.logger.callback = quiet;
  auto impl = std::make_unique<Impl>();
  if (int r = dav1d_open(&impl->context, &s); r < 0) {
    return decode_error("AV1 colour", "dav1d_open failed", r);
  }
  return Av1CellDecoder(std::move(impl));
}

void Av1CellDecoder::reset() {
  if (impl_->has_picture) dav1d_picture_unref(&impl_->picture);
  impl_->has_picture = false;
  dav1d_flush(impl_->context);
}

Status Av1CellDecoder::decode(std::span<const uint8_t> unit, const std::string& what) {
  Impl& d = *impl_;
  if (d.has_picture) dav1d_picture_unref(&d.picture);
  d.has_picture = false;
  Dav1dData data{};
  uint8_t* buf = dav1d_data_create(&data, unit.size());
  if (buf == nullptr) return decode_error(what, "no memory for a temporal unit", 0);
  std::memcpy(buf, unit.data(), unit.size());
  int pictures = 0;
  Status result = Status::Ok();
  auto take = [&]() -> bool {  // false on an error
    Dav1dPicture p{};
    const int r = dav1d_get_picture(d.context, &p);
    if (r == DAV1D_ERR(EAGAIN)) return true;
    if (r < 0) {
      result = decode_error(what, "the temporal unit does not decode", r);
      return false;
    }
    if (++pictures > 1) {
      dav1d_picture_unref(&p);
      result = decode_error(what, "the temporal unit gives more than one picture", 0);
      return false;
    }
    d.picture = p;
    d.has_picture = true;
    return true;
  };
  while (data.sz > 0) {
    const int r = dav1d_send_data(d.context, &data);
    if (r < 0 && r != DAV1D_ERR(EAGAIN)) {
      dav1d_data_unref(&data);
      return decode_error(what, "the temporal unit does not decode", r);
    }
    if (!take()) {
      dav1d_data_unref(&data);
      return result;
    }
  }
  // With a frame delay of 1 the unit's picture is out once its data is in; drain what is left.
  if (!take()) return result;
  if (pictures == 0 && !d.has_picture) {
    return decode_error(what, "the temporal unit gives no picture", 0);
  }
  return Status::Ok();
}

namespace {

// The picture's layout and bit depth against the track's: a 4:4:4 stream where the track says
// 4:2:0 (or the reverse), another bit depth, or a picture smaller than the cell is CALF-E302.
Status check_picture(const Dav1dPictureParameters& p, int bits, bool chroma444, uint32_t w,
                     uint32_t h, const std::string& what) {
  const Dav1dPixelLayout layout = chroma444 ? DAV1D_PIXEL_LAYOUT_I444 : DAV1D_PIXEL_LAYOUT_I420;
  if (p.bpc == bits && p.layout == layout && p.w >= 0 && p.h >= 0 &&
      static_cast<uint32_t>(p.w) >= w && static_cast<uint32_t>(p.h) >= h) {
    return Status::Ok();
  }
  auto layout_name = [](int l) -> std::string {
    return l == DAV1D_PIXEL_LAYOUT_I420   ? "4:2:0"
           : l == DAV1D_PIXEL_LAYOUT_I444 ? "4:4:4"
           : l == DAV1D_PIXEL_LAYOUT_I422 ? "4:2:2"
                                          : "4:0:0";
  };
  return Status(ErrorId::kAv1Picture,
                what + ": a " + std::to_string(p.w) + " x " + std::to_string(p.h) + " " +
                    layout_name(p.layout) + " picture of " + std::to_string(p.bpc) +
                    " bits for a " + std::to_string(w) + " x " + std::to_string(h) + " cell (" +
                    std::to_string(bits) + "-bit " + layout_name(layout) +
                    " expected by the track's colour format)");
}

}  // namespace

Status Av1CellDecoder::rgba8(uint32_t w, uint32_t h, bool chroma444, std::vector<uint8_t>& out,
                             const std::string& what) const {
  const Impl& d = *impl_;
  if (!d.has_picture) return Status(ErrorId::kAv1Picture, what + ": no decoded picture");
  CALF_RETURN_IF_ERROR(check_picture(d.picture.p, 8, chroma444, w, h, what));
  out.resize(size_t{w} * h * 4);
  const auto* ys = static_cast<const uint8_t*>(d.picture.data[0]);
  const auto* us = static_cast<const uint8_t*>(d.picture.data[1]);
  const auto* vs = static_cast<const uint8_t*>(d.picture.data[2]);
  const ptrdiff_t ly = d.picture.stride[0], lc = d.picture.stride[1];
  const uint32_t sub = chroma444 ? 0 : 1;  // chroma sample (x >> sub, y >> sub)
  for (uint32_t y = 0; y < h; ++y) {
    const uint8_t* yr = ys + y * ly;
    const uint8_t* ur = us + (y >> sub) * lc;
    const uint8_t* vr = vs + (y >> sub) * lc;
    uint8_t* o = &out[size_t{y} * w * 4];
    for (uint32_t x = 0; x < w; ++x) {
      av1_ycbcr_to_rgb(yr[x], ur[x >> sub], vr[x >> sub], o + 4 * x);
      o[4 * x + 3] = 255;
    }
  }
  return Status::Ok();
}

Status Av1CellDecoder::rgba16f(uint32_t w, uint32_t h, bool chroma444, lf::Av1HdrCurve curve,
                               std::vector<uint8_t>& out, const std::string& what) const {
  const Impl& d = *impl_;
  if (!d.has_picture) return Status(ErrorId::kAv1Picture, what + ": no decoded picture");
  CALF_RETURN_IF_ERROR(check_picture(d.picture.p, 10, chroma444, w, h, what));
  // The half float bits of every code, once per picture.
  uint16_t half[1024];
  for (uint32_t c = 0; c < 1024; ++c) half[c] = lf::av1_hdr_half_bits(curve, c);
  out.resize(size_t{w} * h * 8);
  // dav1d's high-bit-depth planes hold one uint16_t a sample; strides are in bytes.
  const auto* ys = static_cast<const uint8_t*>(d.picture.data[0]);
  const auto* us = static_cast<const uint8_t*>(d.picture.data[1]);
  const auto* vs = static_cast<const uint8_t*>(d.picture.data[2]);
  const ptrdiff_t ly = d.picture.stride[0], lc = d.picture.stride[1];
  auto sample = [](const uint8_t* row, uint32_t x) {
    uint16_t v;
    std::memcpy(&v, row + 2 * size_t{x}, 2);
    return static_cast<uint16_t>(v & 1023);
  };
  const uint32_t sub = chroma444 ? 0 : 1;
  for (uint32_t y = 0; y < h; ++y) {
    const uint8_t* yr = ys + y * ly;
    const uint8_t* ur = us + (y >> sub) * lc;
    const uint8_t* vr = vs + (y >> sub) * lc;
    uint8_t* o = &out[size_t{y} * w * 8];
    for (uint32_t x = 0; x < w; ++x) {
      uint16_t rgb[3];
      av1_ycbcr10_to_rgb(sample(yr, x), sample(ur, x >> sub), sample(vr, x >> sub), rgb);
      const uint16_t texel[4] = {half[rgb[0]], half[rgb[1]], half[rgb[2]], 0x3C00};
      for (int c = 0; c < 4; ++c) {
        o[8 * x + 2 * c] = static_cast<uint8_t>(texel[c]);
        o[8 * x + 2 * c + 1] = static_cast<uint8_t>(texel[c] >> 8);
      }
    }
  }
  return Status::Ok();
}

Status Av1CellDecoder::gpu_bytes(uint16_t colour_format, uint32_t w, uint32_t h,
                                 lf::Av1HdrCurve curve, std::vector<uint8_t>& out,
                                 const std::string& what) const {
  const bool chroma444 = lf::is_av1_chroma444(colour_format);
  if (lf::is_av1_hdr_colour(colour_format)) return rgba16f(w, h, chroma444, curve, out, what);
  return rgba8(w, h, chroma444, out, what);
}

}  // namespace calf::decoder
