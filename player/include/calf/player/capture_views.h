// Capture sets straight into player views: the uncompressed path from calf-capture (or any
// renderer writing format/CAPTURE.md) to the renderers, with no encoder or decoder in between.
// It is what quality is measured on before compression enters (docs/RENDERING.md, "Quality"),
// and the reference the decoded path is compared with.
//
// One view-frame (viewpoint v at frame f) becomes one player View:
//   - position: the manifest's viewpoint position;
//   - colour: the image's linear RGB as float, HDR values kept;
//   - depth: log-16 codes (calf/format/log_depth.h) in a LogDepthRange that covers exactly the
//     finite depths of this view-frame (LogDepthRange::covering of their min and max, the
//     per-viewpoint z_near / z_far "measured from the data" of DESIGN.md); +inf (sky) is
//     kLog16Sky. A view-frame that is all sky gets the range [1, 2], which no code uses;
//   - material (reflect, refract, IOR) when the manifest says "material": true.
// Eye-path poses become cameras with capture::camera_from_pose() (calf/capture/eye_path.h), the
// one camera model, so a rendering lines up pixel for pixel with calf-capture's ground truth.
#pragma once

#include <cstdint>

#include "calf/capture/capture_set.h"
#include "calf/capture/eye_path.h"
#include "calf/format/status.h"
#include "calf/player/lightfield_cpu_renderer.h"
#include "calf/player/view_set.h"

namespace calf::player {

// The View of one decoded view-frame centred at `position`: colour copied, depth coded as above,
// material copied when the frame has it. Errors: CALF-E430 when the frame's buffers do not match
// its face size or a depth is invalid (NaN, <= 0, -inf), naming face, x and y; CALF-E400 for a
// face size or position the player does not accept. `context` (a file name) prefixes messages.
Expected<View> view_from_capture_frame(const capture::ViewFrame& frame, const Vec3& position,
                                       std::string_view context);

// Every viewpoint of `reader`'s capture set at frame `frame`, in manifest order. Errors name the
// image file: CALF-E430 for a frame outside the set; the reader's own errors (E135 missing file,
// E136 format, E137-E139 pixels); CALF-E400 as above.
Expected<ViewSet> load_capture_views(const capture::CaptureSetReader& reader, uint32_t frame);

// The capture frame to show at scene time `time` seconds: frame f is at f / fps (CAPTURE.md), so
// the nearest one, round(time * fps), clamped to [0, frame_count - 1] (NaN gives 0).
uint32_t capture_frame_at(const capture::CaptureManifest& manifest, double time);

// What a plain 360-degree video player shows with the eye at `view`'s centre: the view's own
// colour cube map sampled bilinearly along each of `camera`'s rays (seamless across faces, as
// GL filters cube maps; the same taps as the CPU renderer's colour), and as depth the view's
// nearest-texel depth (+inf for sky). Meant for camera.position == view.position(), where it is
// the reference a reconstruction at a viewpoint should reproduce: it isolates the renderer's
// errors from the capture's resolution (a point-sampled ground truth at a viewpoint differs from
// it at every edge). The camera must be valid (LightfieldCpuRenderer::render's rules).
RenderedImage reproject_view(const View& view, const Camera& camera);

}  // namespace calf::player
