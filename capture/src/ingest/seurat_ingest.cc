// Seurat capture -> calf capture set: one view group becomes one viewpoint whose cube faces are
// resampled from the group's views (format/CAPTURE.md, "Ingest"). Every texel takes the view that
// sees its ray farthest from an image edge, colour bilinear, depth from the nearest pixel's
// surface point measured from the group's centre (radial depth).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "calf/capture/capture_set.h"
#include "calf/capture/image_budget.h"
#include "calf/capture/ingest.h"
#include "calf/format/cube.h"
#include "ingest_folder.h"
#include "ingest_image.h"

namespace calf::capture {
namespace {

using detail::NamedPlanes;
using detail::PngSamples;

std::string vec_text(const Vec3& p) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g)", p.x, p.y, p.z);
  return buf;
}

// A view ready for sampling: its projection reduced to the eye ray through an NDC position and
// back, its pose inverted, and its pixels as colour + radial depth from the group's centre.
struct PreparedView {
  uint32_t w = 0, h = 0;
  double q[6] =
      {};  // ndc_x = q0 x + q1 y - q2, ndc_y = q3 x + q4 y - q5 for the eye ray (x, y, -1)
  double a = 0, b = 0;  // window z: ndc_z = (a z + b) / -z
  double near = 0, far = 0;
  double rot[9] = {}, inv[9] = {};  // world_from_eye's 3x3 part and its inverse, row-major
  Vec3 origin;
  std::vector<float> rgb;     // 3 per pixel, row 0 at the top
  std::vector<float> radial;  // per pixel, +inf = no surface
};

Vec3 mul3(const double* m, const Vec3& v) {
  return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[3] * v.x + m[4] * v.y + m[5] * v.z,
          m[6] * v.x + m[7] * v.y + m[8] * v.z};
}

void invert3(const double* m, double* out) {
  const double det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6]) +
                     m[2] * (m[3] * m[7] - m[4] * m[6]);
  const double k = 1.0 / det;
  out[0] = (m[4] * m[8] - m[5] * m[7]) * k;
  out[1] = (m[2] * m[7] - m[1] * m[8]) * k;
  out[2] = (m[1] * m[5] - m[2] * m[4]) * k;
  out[3] = (m[5] * m[6] - m[3] * m[8]) * k;
  out[4] = (m[0] * m[8] - m[2] * m[6]) * k;
  out[5] = (m[2] * m[3] - m[0] * m[5]) * k;
  out[6] = (m[3] * m[7] - m[4] * m[6]) * k;
  out[7] = (m[1] * m[6] - m[0] * m[7]) * k;
  out[8] = (m[0] * m[4] - m[1] * m[3]) * k;
}

// Geometry only (no pixels): what the manifest alone says.
PreparedView prepare_geometry(const SeuratView& v) {
  PreparedView p;
  p.w = v.image_width;
  p.h = v.image_height;
  const auto& c = v.clip_from_eye;
  const double s = -c[14];
  p.q[0] = c[0] / s;
  p.q[1] = c[1] / s;
  p.q[2] = c[2] / s;
  p.q[3] = c[4] / s;
  p.q[4] = c[5] / s;
  p.q[5] = c[6] / s;
  p.a = c[10] / s;
  p.b = c[11] / s;
  p.near = p.b / (p.a - 1);
  p.far = p.a == -1 ? INFINITY : p.b / (p.a + 1);
  const auto& w = v.world_from_eye;
  const double rot[9] = {w[0], w[1], w[2], w[4], w[5], w[6], w[8], w[9], w[10]};
  std::copy(rot, rot + 9, p.rot);
  invert3(p.rot, p.inv);
  p.origin = {w[3], w[7], w[11]};
  return p;
}

// True when `path`, its symbolic links resolved, lies inside the folder `root` (as a scene file's
// paths must, E153); false too when either cannot be resolved.
bool resolves_inside(const std::filesystem::path& root, const std::filesystem::path& path) {
  std::error_code ec;
  const std::filesystem::path base = std::filesystem::weakly_canonical(root, ec);
  if (ec) return false;
  const std::filesystem::path full = std::filesystem::weakly_canonical(path, ec);
  if (ec) return false;
  return std::mismatch(base.begin(), base.end(), full.begin(), full.end()).first == base.end();
}

// Loads a view's images and turns every pixel into colour + radial depth from `centre`.
Status load_pixels(const SeuratView& v, const std::filesystem::path& dir, const Vec3& centre,
                   const std::string& where, uint64_t max_pixels, PreparedView* p) {
  // As a scene file's (E153): a path stays in the manifest's folder, through links too.
  for (const std::string* rel : {&v.color.path, &v.depth.path}) {
    const std::filesystem::path root = dir.empty() ? std::filesystem::path(".") : dir;
    if (!resolves_inside(root, root / *rel)) {
      return Status(ErrorId::kSeuratField, where + ": image '" + *rel +
                                               "' resolves (through a link) outside the "
                                               "manifest's folder");
    }
  }
  NamedPlanes colour, depth;
  // Each image's header is compared with its camera before a pixel of it is decoded.
  detail::ImageExpect expect;
  expect.width = v.image_width;
  expect.height = v.image_height;
  expect.wrong_size = ErrorId::kSeuratImageSize;
  expect.expected_by = "the camera says";
  expect.max_pixels = max_pixels;
  CALF_RETURN_IF_ERROR(detail::read_named_planes(dir / v.color.path, v.color.channels,
                                                 {PngSamples::kSrgbColour, PngSamples::kSrgbColour,
                                                  PngSamples::kSrgbColour, PngSamples::kLinear},
                                                 ErrorId::kSeuratChannel, expect, &colour));
  CALF_RETURN_IF_ERROR(detail::read_named_planes(dir / v.depth.path, v.depth.channels,
                                                 {PngSamples::kLinear}, ErrorId::kSeuratChannel,
                                                 expect, &depth));
  const std::string cpath = (dir / v.color.path).string(), dpath = (dir / v.depth.path).string();
  if (colour.width != depth.width || colour.height != depth.height) {
    return Status(ErrorId::kSeuratImageSize,
                  where + ": colour " + cpath + " is " + std::to_string(colour.width) + " x " +
                      std::to_string(colour.height) + " but depth " + dpath + " is " +
                      std::to_string(depth.width) + " x " + std::to_string(depth.height));
  }
  if (colour.width != v.image_width || colour.height != v.image_height) {
    return Status(ErrorId::kSeuratImageSize,
                  where + ": images are " + std::to_string(colour.width) + " x " +
                      std::to_string(colour.height) + " but the camera says " +
                      std::to_string(v.image_width) + " x " + std::to_string(v.image_height));
  }
  const size_t n = size_t{p->w} * p->h;
  p->rgb.resize(3 * n);
  p->radial.resize(n);
  const double det = p->q[0] * p->q[4] - p->q[1] * p->q[3];
  const double tolerance = 1e-3;  // relative slack at the near and far planes (float renderers)
  for (uint32_t j = 0; j < p->h; ++j) {
    for (uint32_t i = 0; i < p->w; ++i) {
      const size_t k = size_t{j} * p->w + i;
      for (int c = 0; c < 3; ++c) p->rgb[3 * k + c] = colour.planes[c][k];
      const float value = depth.planes[0][k];
      p->radial[k] = INFINITY;
      if (colour.planes[3][k] == 0) continue;  // alpha 0: Seurat drops the sample; calf: sky
      // The eye ray (x, y, -1) through the pixel centre (row 0 at the top: NDC y = +1).
      const double nx = 2.0 * (i + 0.5) / p->w - 1.0, ny = 1.0 - 2.0 * (j + 0.5) / p->h;
      const double rx = nx + p->q[2], ry = ny + p->q[5];
      const Vec3 e{(rx * p->q[4] - p->q[1] * ry) / det, (p->q[0] * ry - p->q[3] * rx) / det, -1};
      double eye_z = 0;  // distance along -z
      bool sky = false;
      switch (v.depth_type) {
        case SeuratDepthType::kEyeZ:
          sky = value == 0 || value == INFINITY;
          eye_z = value;
          break;
        case SeuratDepthType::kRayDepth:
          sky = value == 0 || value == INFINITY;
          eye_z = value / length(e);
          break;
        case SeuratDepthType::kWindowZ:
          sky = value == 1;
          eye_z = (value >= 0 && value <= 1) ? p->b / ((2.0 * value - 1.0) + p->a) : NAN;
          break;
      }
      if (sky) continue;
      if (!(eye_z >= p->near * (1 - tolerance)) || !(eye_z <= p->far * (1 + tolerance))) {
        char buf[160];
        std::snprintf(buf, sizeof buf,
                      ": pixel (%u, %u) depth %g is outside the frustum (eye z %g, near %g, "
                      "far %g)",
                      i, j, static_cast<double>(value), eye_z, p->near, p->far);
        return Status(ErrorId::kSeuratDepth, dpath + buf);
      }
      const Vec3 world = mul3(p->rot, e * eye_z) + p->origin;
      p->radial[k] = static_cast<float>(length(world - centre));
    }
  }
  return Status::Ok();
}

// Snaps a continuous pixel coordinate (centres at integers) onto a pixel centre within 1e-3 of a
// pixel, so that an exact cube map is copied bit for bit even when its matrices went through
// float (Unity writes cot(45 deg) as 0.99999994: 1e-4 of a pixel off at 1024 pixels).
double snap(double f) {
  const double r = std::round(f);
  return std::fabs(f - r) < 1e-3 ? r : f;
}

// Fills one viewpoint's faces from its prepared views. Returns E145 for a ray no view sees.
Status resample_group(const std::vector<PreparedView>& views, const std::string& where, uint32_t n,
                      ViewFrame* out, bool* exact) {
  *exact = true;
  for (int f = 0; f < kCubeFaceCount; ++f) {
    const CubeFace face = cube_face_from_index(f);
    for (uint32_t y = 0; y < n; ++y) {
      for (uint32_t x = 0; x < n; ++x) {
        const Vec3 d = direction_from_texel(face, x, y, n);
        int best = -1;
        double best_m = 0, best_nx = 0, best_ny = 0;
        for (size_t k = 0; k < views.size(); ++k) {
          const PreparedView& p = views[k];
          const Vec3 e = mul3(p.inv, d);
          if (!(e.z < 0)) continue;
          const double ex = e.x / -e.z, ey = e.y / -e.z;
          const double nx = p.q[0] * ex + p.q[1] * ey - p.q[2];
          const double ny = p.q[3] * ex + p.q[4] * ey - p.q[5];
          const double m = std::max(std::fabs(nx), std::fabs(ny));
          if (m <= 1 + 1e-9 && (best < 0 || m < best_m)) {
            best = static_cast<int>(k);
            best_m = m;
            best_nx = nx;
            best_ny = ny;
          }
        }
        if (best < 0) {
          return Status(ErrorId::kSeuratViewGroup,
                        where + ": no view sees direction " + vec_text(d) + " (face " +
                            cube_face_name(face) + " texel " + std::to_string(x) + ", " +
                            std::to_string(y) + "): a viewpoint needs views covering all of 360");
        }
        const PreparedView& p = views[static_cast<size_t>(best)];
        const double fx = snap((best_nx + 1) * 0.5 * p.w - 0.5);
        const double fy = snap((1 - best_ny) * 0.5 * p.h - 0.5);
        const auto clampi = [](double v, uint32_t size) {
          return static_cast<uint32_t>(std::clamp(v, 0.0, static_cast<double>(size - 1)));
        };
        const double x0 = std::floor(fx), y0 = std::floor(fy);
        const double tx = fx - x0, ty = fy - y0;
        if (tx != 0 || ty != 0) *exact = false;
        const uint32_t xa = clampi(x0, p.w), xb = clampi(x0 + 1, p.w);
        const uint32_t ya = clampi(y0, p.h), yb = clampi(y0 + 1, p.h);
        const size_t t = out->texel_index(face, x, y);
        for (int c = 0; c < 3; ++c) {
          const auto at = [&](uint32_t i, uint32_t j) {
            return static_cast<double>(p.rgb[3 * (size_t{j} * p.w + i) + c]);
          };
          const double v = (tx == 0 && ty == 0)
                               ? at(xa, ya)
                               : (1 - ty) * ((1 - tx) * at(xa, ya) + tx * at(xb, ya)) +
                                     ty * ((1 - tx) * at(xa, yb) + tx * at(xb, yb));
          out->color[3 * t + c] = static_cast<float>(v);
        }
        const uint32_t xi = clampi(std::floor(fx + 0.5), p.w),
                       yi = clampi(std::floor(fy + 0.5), p.h);
        out->depth[t] = p.radial[size_t{yi} * p.w + xi];
      }
    }
  }
  return Status::Ok();
}

}  // namespace

Status ingest_seurat(const std::filesystem::path& manifest_path,
                     const std::filesystem::path& out_dir, const IngestOptions& options,
                     IngestReport* report) {
  return ingest_seurat(std::vector<std::filesystem::path>{manifest_path}, out_dir, options, report);
}

namespace {

// One frame of a sequence: its manifest, parsed, and its views' geometry (no pixels yet).
struct SeuratFrame {
  std::string source;
  std::filesystem::path dir;
  SeuratCapture capture;
  std::vector<std::vector<PreparedView>> groups;
  std::vector<Vec3> centres;
  uint32_t density = 1;  // the largest pixel density of any view (the default face size)
};

Status prepare_frame(const std::filesystem::path& manifest_path, SeuratFrame* out) {
  out->source = manifest_path.string();
  const std::string& source = out->source;
  CALF_ASSIGN_OR_RETURN(std::string text, read_small_file(manifest_path));
  CALF_ASSIGN_OR_RETURN(out->capture, parse_seurat_manifest(text, source));
  out->dir = manifest_path.parent_path();
  for (size_t g = 0; g < out->capture.view_groups.size(); ++g) {
    std::vector<PreparedView> prepared;
    for (const SeuratView& v : out->capture.view_groups[g]) {
      prepared.push_back(prepare_geometry(v));
      const PreparedView& p = prepared.back();
      if (!(std::fabs(p.q[0] * p.q[4] - p.q[1] * p.q[3]) > 1e-12)) {
        return Status(ErrorId::kSeuratField, source + ": view_groups[" + std::to_string(g) +
                                                 "]: a clip_from_eye_matrix is singular in x, y");
      }
      const double side = std::max(p.w * std::fabs(p.q[0]), p.h * std::fabs(p.q[4]));
      out->density =
          std::max(out->density, static_cast<uint32_t>(std::min(std::round(side), 16384.0)));
    }
    const Vec3 centre = prepared[0].origin;
    const double tol = 1e-5 * std::max(1.0, length(centre));
    for (size_t k = 1; k < prepared.size(); ++k) {
      if (length(prepared[k].origin - centre) > tol) {
        return Status(ErrorId::kSeuratViewGroup,
                      source + ": view_groups[" + std::to_string(g) + "]: view " +
                          std::to_string(k) + " is at " + vec_text(prepared[k].origin) +
                          ", view 0 at " + vec_text(centre) +
                          ": a group's views must share one centre of projection");
      }
    }
    out->centres.push_back(centre);
    out->groups.push_back(std::move(prepared));
  }
  return Status::Ok();
}

// Frame `b` of a sequence against frame 0 (`a`): the same rig, view for view.
Status same_rig(const SeuratFrame& a, const SeuratFrame& b) {
  const std::string both =
      b.source + " (a frame of the sequence) against " + a.source + " (its first frame): ";
  if (a.groups.size() != b.groups.size()) {
    return Status(ErrorId::kSeuratViewGroup,
                  both + std::to_string(b.groups.size()) + " view group(s) against " +
                      std::to_string(a.groups.size()) + "; every frame must be the same rig");
  }
  for (size_t g = 0; g < a.groups.size(); ++g) {
    const std::string where = "view_groups[" + std::to_string(g) + "]";
    if (a.groups[g].size() != b.groups[g].size()) {
      return Status(ErrorId::kSeuratViewGroup,
                    both + where + " has " + std::to_string(b.groups[g].size()) +
                        " view(s) against " + std::to_string(a.groups[g].size()) +
                        "; every frame must be the same rig");
    }
    const double tol = 1e-5 * std::max(1.0, length(a.centres[g]));
    if (length(a.centres[g] - b.centres[g]) > tol) {
      return Status(ErrorId::kSeuratViewGroup, both + where + " is at " + vec_text(b.centres[g]) +
                                                   " against " + vec_text(a.centres[g]) +
                                                   "; every frame must be the same rig");
    }
    for (size_t k = 0; k < a.groups[g].size(); ++k) {
      const PreparedView &va = a.groups[g][k], &vb = b.groups[g][k];
      if (va.w != vb.w || va.h != vb.h) {
        return Status(ErrorId::kSeuratImageSize,
                      both + where + ".views[" + std::to_string(k) + "] is " +
                          std::to_string(vb.w) + " x " + std::to_string(vb.h) + " against " +
                          std::to_string(va.w) + " x " + std::to_string(va.h) +
                          "; every frame must have the same image sizes");
      }
    }
  }
  return Status::Ok();
}

}  // namespace

Status ingest_seurat(const std::vector<std::filesystem::path>& manifests,
                     const std::filesystem::path& out_dir, const IngestOptions& options,
                     IngestReport* report) {
  if (manifests.empty() || manifests.size() > 1000000) {
    return Status(ErrorId::kInvalidArgument, "a Seurat sequence needs 1..1000000 manifests, not " +
                                                 std::to_string(manifests.size()));
  }
  if (options.face_size) {
    CALF_RETURN_IF_ERROR(check_image_budget("face size " + std::to_string(options.face_size),
                                            options.face_size, options.face_size,
                                            options.max_image_pixels, 6));
  }
  // Geometry first, of every frame: centres, sizes and the view volume, before any image is read.
  std::vector<SeuratFrame> frames(manifests.size());
  for (size_t f = 0; f < manifests.size(); ++f) {
    CALF_RETURN_IF_ERROR(prepare_frame(manifests[f], &frames[f]));
    if (f) CALF_RETURN_IF_ERROR(same_rig(frames[0], frames[f]));
  }
  const std::string& source = frames[0].source;
  CaptureManifest m;
  m.frame_count = static_cast<uint32_t>(frames.size());
  m.fps = options.fps;
  m.generator = "calf-ingest";
  for (size_t g = 0; g < frames[0].centres.size(); ++g) {
    m.viewpoints.push_back({"group" + std::to_string(g), frames[0].centres[g]});
  }
  Box3 box{m.viewpoints[0].position, m.viewpoints[0].position};
  for (const Viewpoint& v : m.viewpoints) box = box_union(box, v.position);
  if (options.headbox_size > 0) {
    const Vec3 c = frames[0].capture.headbox_center.value_or((box.min + box.max) * 0.5);
    const double h = options.headbox_size * 0.5;
    m.view_volume = {c - Vec3{h, h, h}, c + Vec3{h, h, h}};
  } else {
    if (box.min == box.max) {
      return Status(ErrorId::kSeuratHeadbox,
                    source + ": the headbox has zero extent: all " +
                        std::to_string(m.viewpoints.size()) + " view group(s) are at " +
                        vec_text(box.min) +
                        " (capture groups spread over the headbox, or give --headbox-size)");
    }
    m.view_volume = box;
  }
  m.face_size = options.face_size ? options.face_size : frames[0].density;
  if (!options.face_size) {
    // The cameras' pixel density (a matrix term of 1e300 implies the largest face size).
    CALF_RETURN_IF_ERROR(check_image_budget(
        source + ": the face size the cameras imply, " + std::to_string(m.face_size), m.face_size,
        m.face_size, options.max_image_pixels, 6));
  }
  // A failed ingest removes the folders it created (remove_empty_folders after abandon()).
  std::vector<std::filesystem::path> created;
  CALF_ASSIGN_OR_RETURN(CaptureSetWriter writer,
                        detail::create_ingest_writer(out_dir, m, &created));

  ViewFrame frame;
  frame.resize(m.face_size, false);
  std::vector<bool> exact_always(m.viewpoints.size(), true);
  for (size_t f = 0; f < frames.size(); ++f) {
    SeuratFrame& sf = frames[f];
    for (size_t g = 0; g < sf.groups.size(); ++g) {
      const std::string where = sf.source + ": view_groups[" + std::to_string(g) + "]";
      Status s;
      for (size_t k = 0; k < sf.groups[g].size() && s.ok(); ++k) {
        s = load_pixels(sf.capture.view_groups[g][k], sf.dir, m.viewpoints[g].position,
                        where + ".views[" + std::to_string(k) + "]", options.max_image_pixels,
                        &sf.groups[g][k]);
      }
      bool exact = false;
      if (s.ok()) {
        s = resample_group(sf.groups[g], where, m.face_size, &frame, &exact);
      }
      sf.groups[g].clear();  // release the pixels: one group in memory at a time
      if (s.ok()) s = writer.write(static_cast<uint32_t>(g), static_cast<uint32_t>(f), frame);
      if (!s.ok()) {
        writer.abandon();
        detail::remove_empty_folders(created);
        return s;
      }
      exact_always[g] = exact_always[g] && exact;
    }
  }
  if (Status s = writer.finish(); !s.ok()) {
    writer.abandon();
    detail::remove_empty_folders(created);
    return s;
  }
  if (report) {
    *report = {static_cast<uint32_t>(m.viewpoints.size()), m.frame_count, m.face_size,
               static_cast<uint32_t>(std::count(exact_always.begin(), exact_always.end(), true))};
  }
  return Status::Ok();
}

}  // namespace calf::capture
