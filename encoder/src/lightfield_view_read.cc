#include <algorithm>
#include <bit>
#include <cmath>
#include <string>
#include <vector>

#include "calf/format/lightfield_layout.h"
#include "calf/format/log_depth.h"
#include "lightfield_internal.h"
#include "lightfield_view_pass.h"

namespace calf::encoder::lightfield_internal {
namespace {

// The coverage of view-frame `vf` as the stream codes it (SPEC §11.1.11): near and far shares
// whole sixteenths and near + far + the mask's cells = 16, else kEncoderCoverage.
Status coverage_texels(const capture::CaptureSetReader& input, uint32_t view, uint32_t frame,
                       const capture::ViewFrame& vf, lf::CoverageTexel* out) {
  const size_t n = vf.texel_count(), per_face = size_t{vf.face_size} * vf.face_size;
  for (size_t i = 0; i < n; ++i) {
    const float near = vf.coverage[3 * i] * 16, far = vf.coverage[3 * i + 1] * 16;
    const uint16_t mask = static_cast<uint16_t>(vf.coverage[3 * i + 2]);  // validated 0..65535
    // A sky texel has nothing farther than it (SPEC §11.1.11 "Coverage and depth").
    if (near != std::nearbyint(near) || far != std::nearbyint(far) ||
        near + far + static_cast<float>(std::popcount(mask)) != 16.0f ||
        (std::isinf(vf.depth[i]) && far != 0)) {
      const size_t texel = i % per_face;
      return Status(ErrorId::kEncoderCoverage,
                    input.image_path(view, frame).string() + ": face " +
                        std::to_string(i / per_face) + " texel (" +
                        std::to_string(texel % vf.face_size) + ", " +
                        std::to_string(texel / vf.face_size) + "): coverage near " +
                        std::to_string(vf.coverage[3 * i]) + ", far " +
                        std::to_string(vf.coverage[3 * i + 1]) + ", mask " + std::to_string(mask) +
                        " is not 16 cells of 1/16 (near + far + mask bits), or has cells "
                        "farther than its sky depth; --no-coverage drops coverage");
    }
    out[i] = {mask, static_cast<uint8_t>(near)};
  }
  return Status::Ok();
}

}  // namespace

Status read_view(const capture::CaptureSetReader& input, uint32_t view,
                 const LightfieldViewFacts& expected, bool with_coverage, uint32_t first_frame,
                 uint32_t frame_count, ViewData* out) {
  const capture::CaptureManifest& m = input.manifest();
  out->frames = frame_count;
  out->face_size = m.face_size;
  out->texels = size_t{6} * m.face_size * m.face_size;
  out->colour.assign(out->texels * 3 * frame_count, 0);
  out->material.clear();
  if (m.material) out->material.assign(out->texels * 3 * frame_count, 0);
  out->coverage.clear();
  if (with_coverage) out->coverage.resize(out->texels * frame_count);
  std::vector<float> depth(out->texels * frame_count);
  ViewFactsBuilder facts;
  capture::ViewFrame vf;
  for (uint32_t f = 0; f < frame_count; ++f) {
    CALF_RETURN_IF_ERROR(read_frame(input, view, first_frame + f, &vf));
    facts.add(vf);
    uint16_t* c = &out->colour[f * out->texels * 3];
    for (size_t i = 0; i < out->texels * 3; ++i) c[i] = half_from_colour(vf.color[i]);
    std::copy(vf.depth.begin(), vf.depth.end(), &depth[f * out->texels]);
    if (with_coverage) {
      CALF_RETURN_IF_ERROR(
          coverage_texels(input, view, first_frame + f, vf, &out->coverage[f * out->texels]));
    }
    if (m.material) {
      uint8_t* mc = &out->material[f * out->texels * 3];
      for (size_t i = 0; i < out->texels; ++i) {
        mc[3 * i] = lf::material_weight_code(vf.material[3 * i]);
        mc[3 * i + 1] = lf::material_weight_code(vf.material[3 * i + 1]);
        mc[3 * i + 2] = lf::material_ior_code(vf.material[3 * i + 2]);
      }
    }
  }
  CALF_ASSIGN_OR_RETURN(const LightfieldViewFacts seen, facts.finish());
  // All frames must say exactly what the analysis saw; a range of them only what fits it.
  const bool whole = first_frame == 0 && frame_count == m.frame_count;
  if (whole ? !same_facts(seen, expected) : !facts.within(expected)) {
    return Status(ErrorId::kEncoderInput,
                  "view " + std::to_string(view) + " (" + input.image_path(view, 0).string() +
                      ", ...): its depth range, material or HDR colour changed since the analysis");
  }
  out->range = expected.depth_range;
  out->has_material = expected.has_material;
  out->depth.assign(depth.size(), kLog16Sky);
  if (out->range) {
    const LogDepthRange& r = *out->range;
    for (size_t i = 0; i < depth.size(); ++i) out->depth[i] = r.encode_unchecked(depth[i]);
  }
  if (!out->has_material) out->material.clear();
  return Status::Ok();
}

}  // namespace calf::encoder::lightfield_internal
