#include "colour_av1.h"

#include <EbSvtAv1Enc.h>
#include <aom/aom_encoder.h>
#include <aom/aomcx.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <mutex>
#include <string>

namespace calf::encoder::av1_internal {
namespace {

Status svt_error(const std::string& call, int64_t code) {
  return Status(ErrorId::kEncoderAv1, "SVT-AV1 " + call + " failed (" + std::to_string(code) + ")");
}

Status aom_error(const std::string& call, aom_codec_ctx_t* ctx, aom_codec_err_t code) {
  const char* detail = ctx != nullptr ? aom_codec_error_detail(ctx) : nullptr;
  return Status(ErrorId::kEncoderAv1, "libaom " + call + " failed (" +
                                          aom_codec_err_to_string(code) +
                                          (detail ? std::string(": ") + detail : "") + ")");
}

// Reads a LEB128 value (AV1 §4.10.5) at `at`; false when it runs past the end.
bool leb128(std::span<const uint8_t> b, size_t& at, uint64_t& value) {
  value = 0;
  for (int i = 0; i < 8; ++i) {
    if (at >= b.size()) return false;
    const uint8_t byte = b[at++];
    value |= uint64_t{byte & 0x7Fu} << (7 * i);
    if (!(byte & 0x80)) return true;
  }
  return false;
}

Status output_error(const std::string& why) {
  return Status(ErrorId::kEncoderAv1, "the AV1 encoder's output: " + why);
}

// Splits an OBU stream into temporal units: each starts at a temporal delimiter OBU (type 2).
Expected<Gop> split_units(std::span<const uint8_t> stream) {
  Gop units;
  size_t at = 0;
  while (at < stream.size()) {
    const size_t start = at;
    const uint8_t header = stream[at++];
    const uint32_t type = (header >> 3) & 15;
    if (header & 4) ++at;  // extension byte
    uint64_t size = 0;
    if (!(header & 2) || !leb128(stream, at, size) ||
        size > stream.size() - std::min(at, stream.size())) {
      return output_error("an OBU without a size field or past the stream");
    }
    at += size;
    if (type == 2) units.emplace_back();
    if (units.empty()) return output_error("an OBU before the first temporal delimiter");
    units.back().insert(units.back().end(), stream.begin() + static_cast<ptrdiff_t>(start),
                        stream.begin() + static_cast<ptrdiff_t>(at));
  }
  return units;
}

// SVT-AV1 keeps process-wide state in creating and destroying encoders (two encoders torn down at
// once on worker threads double-free it under AddressSanitizer), so those steps take turns;
// encoding itself runs in parallel, one encoder per GOP.
std::mutex& svt_lifetime_mutex() {
  static std::mutex m;
  return m;
}

// One GOP by a fresh SVT-AV1 encoder: every picture W x H 4:2:0. `yuv` holds `count` pictures of
// `bits` (8: a byte a sample, 10: a uint16_t a sample), planes Y, Cb, Cr each.
Expected<Gop> encode_gop_svt(const uint8_t* yuv, uint32_t bits, uint32_t W, uint32_t H,
                             uint32_t count, uint32_t fps_numerator, uint32_t fps_denominator,
                             const Av1ColourOptions& o) {
  EbComponentType* handle = nullptr;
  EbSvtAv1EncConfiguration cfg;
  {
    const std::lock_guard<std::mutex> lock(svt_lifetime_mutex());
    if (EbErrorType e = svt_av1_enc_init_handle(&handle, nullptr, &cfg); e != EB_ErrorNone) {
      return svt_error("svt_av1_enc_init_handle", e);
    }
  }
  struct Closer {
    EbComponentType* h;
    bool initialised = false;
    ~Closer() {
      const std::lock_guard<std::mutex> lock(svt_lifetime_mutex());
      if (initialised) svt_av1_enc_deinit(h);
      svt_av1_enc_deinit_handle(h);
    }
  } closer{handle};
  cfg.enc_mode = static_cast<int8_t>(o.preset);
  cfg.source_width = W;
  cfg.source_height = H;
  cfg.frame_rate_numerator = fps_numerator;
  cfg.frame_rate_denominator = fps_denominator;
  cfg.encoder_bit_depth = bits;
  cfg.encoder_color_format = EB_YUV420;
  cfg.intra_period_length = -1;  // the GOP's first frame is its only key frame
  cfg.intra_refresh_type = SVT_AV1_KF_REFRESH;
  cfg.rate_control_mode = 0;
  if (o.qp > 0) {
    cfg.qp = static_cast<uint32_t>(o.qp);
    cfg.enable_adaptive_quantization = 0;  // fixed QP
  } else {
    cfg.qp = static_cast<uint32_t>(o.crf);
  }
  cfg.logical_processors = 1;  // one thread: the cells are coded in parallel instead
  cfg.color_primaries = EB_CICP_CP_BT_709;
  // The 10-bit codes are calf's own curve of half-float bits (§11.1.12), which CICP cannot name.
  cfg.transfer_characteristics = bits == 8 ? EB_CICP_TC_SRGB : EB_CICP_TC_UNSPECIFIED;
  cfg.matrix_coefficients = EB_CICP_MC_BT_709;
  cfg.color_range = EB_CR_FULL_RANGE;
  if (EbErrorType e = svt_av1_enc_set_parameter(handle, &cfg); e != EB_ErrorNone) {
    return svt_error("svt_av1_enc_set_parameter", e);
  }
  EbErrorType init_error;
  {
    const std::lock_guard<std::mutex> lock(svt_lifetime_mutex());
    init_error = svt_av1_enc_init(handle);
  }
  if (EbErrorType e = init_error; e != EB_ErrorNone) {
    return svt_error("svt_av1_enc_init", e);
  }
  closer.initialised = true;
  const size_t sample = bits == 8 ? 1 : 2;
  const size_t luma = size_t{W} * H * sample, chroma = luma / 4, picture = luma + 2 * chroma;
  std::vector<uint8_t> stream;
  bool done = false;
  auto drain = [&](bool all_sent) -> Status {
    for (;;) {
      EbBufferHeaderType* packet = nullptr;
      const EbErrorType e = svt_av1_enc_get_packet(handle, &packet, all_sent ? 1 : 0);
      if (e == EB_NoErrorEmptyQueue) return Status::Ok();
      if (e != EB_ErrorNone || packet == nullptr) return svt_error("svt_av1_enc_get_packet", e);
      const bool eos = packet->flags & EB_BUFFERFLAG_EOS;
      if (packet->flags & EB_BUFFERFLAG_ERROR_MASK) {
        svt_av1_enc_release_out_buffer(&packet);
        return svt_error("encoding (packet flags)", 0);
      }
      stream.insert(stream.end(), packet->p_buffer, packet->p_buffer + packet->n_filled_len);
      svt_av1_enc_release_out_buffer(&packet);
      if (eos) {
        done = true;
        return Status::Ok();
      }
    }
  };
  for (uint32_t i = 0; i < count; ++i) {
    EbSvtIOFormat io{};
    io.luma = const_cast<uint8_t*>(yuv + i * picture);
    io.cb = io.luma + luma;
    io.cr = io.cb + chroma;
    io.y_stride = W;
    io.cb_stride = io.cr_stride = W / 2;
    io.width = W;
    io.height = H;
    io.color_fmt = EB_YUV420;
    io.bit_depth = bits == 8 ? EB_EIGHT_BIT : EB_TEN_BIT;  // strides count samples
    EbBufferHeaderType in{};
    in.size = sizeof(EbBufferHeaderType);
    in.p_buffer = reinterpret_cast<uint8_t*>(&io);
    in.n_filled_len = static_cast<uint32_t>(picture);
    in.pts = i;
    in.pic_type = EB_AV1_INVALID_PICTURE;
    if (EbErrorType e = svt_av1_enc_send_picture(handle, &in); e != EB_ErrorNone) {
      return svt_error("svt_av1_enc_send_picture", e);
    }
    CALF_RETURN_IF_ERROR(drain(false));
  }
  EbBufferHeaderType eos{};
  eos.size = sizeof(EbBufferHeaderType);
  eos.flags = EB_BUFFERFLAG_EOS;
  eos.pic_type = EB_AV1_INVALID_PICTURE;
  if (EbErrorType e = svt_av1_enc_send_picture(handle, &eos); e != EB_ErrorNone) {
    return svt_error("svt_av1_enc_send_picture (end of stream)", e);
  }
  while (!done) CALF_RETURN_IF_ERROR(drain(true));
  CALF_ASSIGN_OR_RETURN(Gop units, split_units(stream));
  if (units.size() != count) {
    return svt_error("output (" + std::to_string(units.size()) + " temporal units for " +
                         std::to_string(count) + " frames)",
                     0);
  }
  return units;
}

// One GOP by a fresh libaom encoder (the AV1 High profile): every picture W x H 4:4:4, as
// encode_gop_svt's. One thread, no row or tile parallelism, fixed settings: the bytes depend on
// the pictures and the options only.
Expected<Gop> encode_gop_aom(const uint8_t* yuv, uint32_t bits, uint32_t W, uint32_t H,
                             uint32_t count, uint32_t fps_numerator, uint32_t fps_denominator,
                             const Av1ColourOptions& o) {
  aom_codec_iface_t* iface = aom_codec_av1_cx();
  aom_codec_enc_cfg_t cfg;
  if (aom_codec_err_t e = aom_codec_enc_config_default(iface, &cfg, AOM_USAGE_GOOD_QUALITY)) {
    return aom_error("aom_codec_enc_config_default", nullptr, e);
  }
  cfg.g_w = W;
  cfg.g_h = H;
  cfg.g_profile = 1;  // High: 4:4:4 at 8 and 10 bits
  cfg.g_bit_depth = bits == 8 ? AOM_BITS_8 : AOM_BITS_10;
  cfg.g_input_bit_depth = bits;
  cfg.g_timebase.num = static_cast<int>(fps_denominator);
  cfg.g_timebase.den = static_cast<int>(fps_numerator);
  cfg.g_threads = 1;  // one thread: the cells are coded in parallel instead
  cfg.g_pass = AOM_RC_ONE_PASS;
  cfg.rc_end_usage = AOM_Q;
  // The first frame is a key frame (libaom's first always is); no other, as the GOP ends before
  // the next would be due. (AOM_KF_DISABLED with a forced first key frame instead: 75,916 bytes
  // at 36.71 dB against 59,109 at 37.14 dB on docs/ENCODER.md's Blender set cap16 at CRF 20.)
  cfg.kf_mode = AOM_KF_AUTO;
  cfg.kf_min_dist = 0;
  cfg.kf_max_dist = count;
  const uint32_t q = o.qp > 0 ? o.qp : o.crf;
  if (o.qp > 0) cfg.rc_min_quantizer = cfg.rc_max_quantizer = q;
  aom_codec_ctx_t ctx;
  if (aom_codec_err_t e =
          aom_codec_enc_init(&ctx, iface, &cfg, bits == 8 ? 0 : AOM_CODEC_USE_HIGHBITDEPTH)) {
    return aom_error("aom_codec_enc_init", nullptr, e);
  }
  struct Closer {
    aom_codec_ctx_t* c;
    ~Closer() { aom_codec_destroy(c); }
  } closer{&ctx};
  auto control = [&](const char* name, aom_codec_err_t e) -> Status {
    return e == AOM_CODEC_OK ? Status::Ok() : aom_error(name, &ctx, e);
  };
  CALF_RETURN_IF_ERROR(control(
      "AOME_SET_CPUUSED", aom_codec_control(&ctx, AOME_SET_CPUUSED, static_cast<int>(o.preset))));
  CALF_RETURN_IF_ERROR(control("AOME_SET_CQ_LEVEL", aom_codec_control(&ctx, AOME_SET_CQ_LEVEL, q)));
  CALF_RETURN_IF_ERROR(control("AV1E_SET_ROW_MT", aom_codec_control(&ctx, AV1E_SET_ROW_MT, 0u)));
  if (o.qp > 0) {  // a fixed quantiser: no adaptive or per-block quantisation
    CALF_RETURN_IF_ERROR(
        control("AV1E_SET_AQ_MODE", aom_codec_control(&ctx, AV1E_SET_AQ_MODE, 0u)));
    CALF_RETURN_IF_ERROR(
        control("AV1E_SET_DELTAQ_MODE", aom_codec_control(&ctx, AV1E_SET_DELTAQ_MODE, 0u)));
  }
  CALF_RETURN_IF_ERROR(control(
      "AV1E_SET_COLOR_PRIMARIES",
      aom_codec_control(&ctx, AV1E_SET_COLOR_PRIMARIES, static_cast<int>(AOM_CICP_CP_BT_709))));
  // The 10-bit codes are calf's own curve of half-float bits (§11.1.12), which CICP cannot name.
  CALF_RETURN_IF_ERROR(control(
      "AV1E_SET_TRANSFER_CHARACTERISTICS",
      aom_codec_control(&ctx, AV1E_SET_TRANSFER_CHARACTERISTICS,
                        static_cast<int>(bits == 8 ? AOM_CICP_TC_SRGB : AOM_CICP_TC_UNSPECIFIED))));
  CALF_RETURN_IF_ERROR(control(
      "AV1E_SET_MATRIX_COEFFICIENTS",
      aom_codec_control(&ctx, AV1E_SET_MATRIX_COEFFICIENTS, static_cast<int>(AOM_CICP_MC_BT_709))));
  CALF_RETURN_IF_ERROR(control("AV1E_SET_COLOR_RANGE",
                               aom_codec_control(&ctx, AV1E_SET_COLOR_RANGE, 1)));  // full range
  const size_t sample = bits == 8 ? 1 : 2;
  const size_t plane = size_t{W} * H * sample, picture = 3 * plane;
  std::vector<uint8_t> stream;
  auto drain = [&]() {
    aom_codec_iter_t it = nullptr;
    while (const aom_codec_cx_pkt_t* pkt = aom_codec_get_cx_data(&ctx, &it)) {
      if (pkt->kind != AOM_CODEC_CX_FRAME_PKT) continue;
      const auto* b = static_cast<const uint8_t*>(pkt->data.frame.buf);
      stream.insert(stream.end(), b, b + pkt->data.frame.sz);
    }
  };
  for (uint32_t i = 0; i < count; ++i) {
    aom_image_t img;
    if (!aom_img_wrap(&img, bits == 8 ? AOM_IMG_FMT_I444 : AOM_IMG_FMT_I44416, W, H, 1,
                      const_cast<uint8_t*>(yuv + i * picture))) {
      return aom_error("aom_img_wrap", nullptr, AOM_CODEC_MEM_ERROR);
    }
    img.bit_depth = bits;
    img.range = AOM_CR_FULL_RANGE;
    if (aom_codec_err_t e = aom_codec_encode(&ctx, &img, i, 1, 0)) {
      return aom_error("aom_codec_encode", &ctx, e);
    }
    drain();
  }
  for (;;) {  // flush: the frames held back for look-ahead
    const size_t before = stream.size();
    if (aom_codec_err_t e = aom_codec_encode(&ctx, nullptr, 0, 0, 0)) {
      return aom_error("aom_codec_encode (flush)", &ctx, e);
    }
    drain();
    if (stream.size() == before) break;
  }
  CALF_ASSIGN_OR_RETURN(Gop units, split_units(stream));
  if (units.size() != count) {
    return output_error(std::to_string(units.size()) + " temporal units for " +
                        std::to_string(count) + " frames");
  }
  return units;
}

// One GOP of 4:2:0 (SVT-AV1) or 4:4:4 (libaom) pictures, as options.chroma444 says.
Expected<Gop> encode_gop(const uint8_t* yuv, uint32_t bits, uint32_t W, uint32_t H, uint32_t count,
                         uint32_t fps_numerator, uint32_t fps_denominator,
                         const Av1ColourOptions& o) {
  if (o.chroma444) {
    return encode_gop_aom(yuv, bits, W, H, count, fps_numerator, fps_denominator, o);
  }
  return encode_gop_svt(yuv, bits, W, H, count, fps_numerator, fps_denominator, o);
}

}  // namespace

namespace {

// BT.709 full range, 4:4:4: pixels of `channels` samples (RGB first) coded 0 … max, codes of the
// same range; neutral chroma (max+1)/2.
template <typename T>
void ycbcr444_of(const T* px, uint32_t channels, uint32_t W, uint32_t H, long max, T* y, T* cb,
                 T* cr) {
  constexpr double kr = 0.2126, kb = 0.0722, kg = 1 - kr - kb;
  const double neutral = static_cast<double>(max + 1) / 2;
  auto code = [max](double v) { return static_cast<T>(std::clamp(std::lround(v), 0L, max)); };
  for (size_t i = 0; i < size_t{W} * H; ++i) {
    const T* p = &px[i * channels];
    const double l = kr * p[0] + kg * p[1] + kb * p[2];
    y[i] = code(l);
    cb[i] = code(neutral + (p[2] - l) / (2 * (1 - kb)));
    cr[i] = code(neutral + (p[0] - l) / (2 * (1 - kr)));
  }
}

// The same, 4:2:0 with each chroma sample the mean of its 2 x 2 luma texels.
template <typename T>
void ycbcr420_of(const T* px, uint32_t channels, uint32_t W, uint32_t H, long max, T* y, T* cb,
                 T* cr) {
  constexpr double kr = 0.2126, kb = 0.0722, kg = 1 - kr - kb;
  const double neutral = static_cast<double>(max + 1) / 2;
  auto code = [max](double v) { return static_cast<T>(std::clamp(std::lround(v), 0L, max)); };
  for (uint32_t j = 0; j < H; j += 2) {
    for (uint32_t i = 0; i < W; i += 2) {
      double sb = 0, sr = 0;
      for (uint32_t dy = 0; dy < 2; ++dy) {
        for (uint32_t dx = 0; dx < 2; ++dx) {
          const T* p = &px[((size_t{j} + dy) * W + i + dx) * channels];
          const double l = kr * p[0] + kg * p[1] + kb * p[2];
          y[(size_t{j} + dy) * W + i + dx] = code(l);
          sb += (p[2] - l) / (2 * (1 - kb));
          sr += (p[0] - l) / (2 * (1 - kr));
        }
      }
      cb[size_t{j / 2} * (W / 2) + i / 2] = code(neutral + sb / 4);
      cr[size_t{j / 2} * (W / 2) + i / 2] = code(neutral + sr / 4);
    }
  }
}

}  // namespace

void rgba_to_ycbcr420(std::span<const uint8_t> rgba, uint32_t W, uint32_t H, uint8_t* y,
                      uint8_t* cb, uint8_t* cr) {
  ycbcr420_of(rgba.data(), 4, W, H, 255, y, cb, cr);
}

void rgb10_to_ycbcr420(std::span<const uint16_t> rgb, uint32_t W, uint32_t H, uint16_t* y,
                       uint16_t* cb, uint16_t* cr) {
  ycbcr420_of(rgb.data(), 3, W, H, 1023, y, cb, cr);
}

void rgba_to_ycbcr444(std::span<const uint8_t> rgba, uint32_t W, uint32_t H, uint8_t* y,
                      uint8_t* cb, uint8_t* cr) {
  ycbcr444_of(rgba.data(), 4, W, H, 255, y, cb, cr);
}

void rgb10_to_ycbcr444(std::span<const uint16_t> rgb, uint32_t W, uint32_t H, uint16_t* y,
                       uint16_t* cb, uint16_t* cr) {
  ycbcr444_of(rgb.data(), 3, W, H, 1023, y, cb, cr);
}

namespace {
uint16_t clamped_half(uint16_t h) {
  if (h & 0x8000) return 0;                   // negative (and -0, -NaN): 0
  return h >= 0x7C00 ? uint16_t{0x7BFF} : h;  // infinity, NaN: the greatest finite half
}
}  // namespace

lf::Av1HdrCurve hdr_curve(std::span<const uint16_t> half) {
  uint16_t lo = 0x7BFF, hi = 0;
  for (const uint16_t v : half) {
    const uint16_t c = clamped_half(v);
    lo = std::min(lo, c);
    hi = std::max(hi, c);
  }
  lf::Av1HdrCurve curve;
  curve.base = std::max<uint16_t>(lo, 0x0400);
  curve.shift = 0;
  while (curve.shift < 5 && uint32_t{curve.base} + (1023u << curve.shift) < hi) ++curve.shift;
  return curve;
}

uint16_t hdr_code(lf::Av1HdrCurve curve, uint16_t h) {
  const uint32_t c = clamped_half(h);
  if (c <= curve.base) return 0;
  const uint32_t code = (c - curve.base + ((1u << curve.shift) >> 1)) >> curve.shift;
  return static_cast<uint16_t>(std::min(code, 1023u));
}

Expected<HdrCell> encode_cell_hdr(std::span<const uint16_t> half, uint32_t w, uint32_t h,
                                  uint32_t frames, uint32_t fps_numerator, uint32_t fps_denominator,
                                  const Av1ColourOptions& options) {
  const uint32_t W = std::max(64u, (w + 7) / 8 * 8), H = std::max(64u, (h + 7) / 8 * 8);
  const size_t luma = size_t{W} * H, chroma = options.chroma444 ? luma : luma / 4,
               picture = luma + 2 * chroma;
  HdrCell cell;
  cell.curve = hdr_curve(half);
  std::vector<uint16_t> padded(luma * 3);
  for (uint32_t g0 = 0; g0 < frames; g0 += options.keyframe_interval) {
    const uint32_t count = std::min(options.keyframe_interval, frames - g0);
    std::vector<uint16_t> yuv(picture * count);
    for (uint32_t i = 0; i < count; ++i) {
      const uint16_t* src = &half[size_t{g0 + i} * w * h * 3];
      for (uint32_t y = 0; y < H; ++y) {
        const uint32_t sy = std::min(y, h - 1);
        for (uint32_t x = 0; x < W; ++x) {
          const uint32_t sx = std::min(x, w - 1);
          for (int c = 0; c < 3; ++c) {
            padded[(size_t{y} * W + x) * 3 + c] =
                hdr_code(cell.curve, src[(size_t{sy} * w + sx) * 3 + c]);
          }
        }
      }
      uint16_t* out = &yuv[i * picture];
      if (options.chroma444) {
        rgb10_to_ycbcr444(padded, W, H, out, out + luma, out + luma + chroma);
      } else {
        rgb10_to_ycbcr420(padded, W, H, out, out + luma, out + luma + chroma);
      }
    }
    CALF_ASSIGN_OR_RETURN(Gop gop, encode_gop(reinterpret_cast<const uint8_t*>(yuv.data()), 10, W,
                                              H, count, fps_numerator, fps_denominator, options));
    cell.gops.push_back(std::move(gop));
  }
  return cell;
}

Expected<std::vector<Gop>> encode_cell(std::span<const uint8_t> rgba, uint32_t w, uint32_t h,
                                       uint32_t frames, uint32_t fps_numerator,
                                       uint32_t fps_denominator, const Av1ColourOptions& options) {
  const uint32_t W = std::max(64u, (w + 7) / 8 * 8), H = std::max(64u, (h + 7) / 8 * 8);
  const size_t luma = size_t{W} * H, chroma = options.chroma444 ? luma : luma / 4,
               picture = luma + 2 * chroma;
  std::vector<uint8_t> padded(luma * 4);
  std::vector<Gop> gops;
  for (uint32_t g0 = 0; g0 < frames; g0 += options.keyframe_interval) {
    const uint32_t count = std::min(options.keyframe_interval, frames - g0);
    std::vector<uint8_t> yuv(picture * count);
    for (uint32_t i = 0; i < count; ++i) {
      const uint8_t* src = &rgba[size_t{g0 + i} * w * h * 4];
      for (uint32_t y = 0; y < H; ++y) {
        const uint32_t sy = std::min(y, h - 1);
        for (uint32_t x = 0; x < W; ++x) {
          const uint32_t sx = std::min(x, w - 1);
          std::copy_n(src + (size_t{sy} * w + sx) * 4, 4, &padded[(size_t{y} * W + x) * 4]);
        }
      }
      uint8_t* out = &yuv[i * picture];
      if (options.chroma444) {
        rgba_to_ycbcr444(padded, W, H, out, out + luma, out + luma + chroma);
      } else {
        rgba_to_ycbcr420(padded, W, H, out, out + luma, out + luma + chroma);
      }
    }
    CALF_ASSIGN_OR_RETURN(
        Gop gop, encode_gop(yuv.data(), 8, W, H, count, fps_numerator, fps_denominator, options));
    gops.push_back(std::move(gop));
  }
  return gops;
}

}  // namespace calf::encoder::av1_internal
