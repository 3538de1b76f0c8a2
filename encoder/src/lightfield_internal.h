// Private to the light-field encoder: what its analysis pass (lightfield_analysis.cc) and its view
// pass (lightfield_encode.cc) share, so that both read and judge the images the same way.
#pragma once

#include <cstdint>
#include <limits>

#include "calf/capture/capture_set.h"
#include "calf/encoder/lightfield_encode.h"
#include "calf/format/status.h"

namespace calf::encoder::lightfield_internal {

// kEncoderOption for an option outside its range (the message names the command-line flag).
Status validate_options(const LightfieldEncodeOptions& options);

// Reads view-frame (view, frame) into `out` and checks it against the manifest: kEncoderInput
// when its face size or material presence differs.
Status read_frame(const capture::CaptureSetReader& input, uint32_t view, uint32_t frame,
                  capture::ViewFrame* out);

// Gathers the facts of one view frame by frame: both passes feed it every frame, so the view pass
// sees exactly what the analysis saw (or that the images changed in between).
class ViewFactsBuilder {
 public:
  void add(const capture::ViewFrame& frame);
  // The facts of the frames added (kDepthRange when the depths admit no range).
  Expected<LightfieldViewFacts> finish() const;
  // Whether the frames added could be some of the frames of a view with facts `whole`: no
  // material or HDR colour it lacks, every finite depth inside its range.
  bool within(const LightfieldViewFacts& whole) const;

 private:
  float lo_ = std::numeric_limits<float>::infinity(), hi_ = 0;  // finite depths seen
  bool has_material_ = false, hdr_ = false;
};

// Whether two views' facts agree (ranges compared by their z_near and z_far).
bool same_facts(const LightfieldViewFacts& a, const LightfieldViewFacts& b);

}  // namespace calf::encoder::lightfield_internal
