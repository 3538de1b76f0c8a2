// The GLSL mirror of the conventions (calf/player/glsl_conventions.h) against the C++ ones, run
// as a compute shader in an OSMesa GL 4.5 core context: cube-face lookups on thousands of
// directions including exact seams and corners, the inverse mapping, every log-16 code of the
// depth functions the ray-march shader calls, and the rasterisers' camera against
// format/camera.h's pixel rays.
#include <GL/gl.h>
#include <GL/glext.h>
#include <GL/osmesa.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "calf/format/camera.h"
#include "calf/format/cube.h"
#include "calf/format/log_depth.h"
#include "calf/player/glsl_conventions.h"

namespace calf::player {
namespace {

// GL 4.3+ entry points, resolved through OSMesa (the process may also link a GL dispatch library
// that knows nothing of OSMesa contexts).
struct Gl {
  PFNGLCREATESHADERPROC CreateShader;
  PFNGLSHADERSOURCEPROC ShaderSource;
  PFNGLCOMPILESHADERPROC CompileShader;
  PFNGLGETSHADERIVPROC GetShaderiv;
  PFNGLGETSHADERINFOLOGPROC GetShaderInfoLog;
  PFNGLCREATEPROGRAMPROC CreateProgram;
  PFNGLATTACHSHADERPROC AttachShader;
  PFNGLLINKPROGRAMPROC LinkProgram;
  PFNGLGETPROGRAMIVPROC GetProgramiv;
  PFNGLGETPROGRAMINFOLOGPROC GetProgramInfoLog;
  PFNGLUSEPROGRAMPROC UseProgram;
  PFNGLGENBUFFERSPROC GenBuffers;
  PFNGLBINDBUFFERBASEPROC BindBufferBase;
  PFNGLBINDBUFFERPROC BindBuffer;
  PFNGLBUFFERDATAPROC BufferData;
  PFNGLGETBUFFERSUBDATAPROC GetBufferSubData;
  PFNGLDISPATCHCOMPUTEPROC DispatchCompute;
  PFNGLMEMORYBARRIERPROC MemoryBarrier;
  PFNGLGETUNIFORMLOCATIONPROC GetUniformLocation;
  PFNGLUNIFORM1UIPROC Uniform1ui;
  PFNGLUNIFORM1FPROC Uniform1f;
  PFNGLUNIFORM3FPROC Uniform3f;
};

class Context {
 public:
  Context() {
    const int attribs[] = {OSMESA_FORMAT,
                           OSMESA_RGBA,
                           OSMESA_DEPTH_BITS,
                           0,
                           OSMESA_PROFILE,
                           OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION,
                           4,
                           OSMESA_CONTEXT_MINOR_VERSION,
                           5,
                           0};
    ctx_ = OSMesaCreateContextAttribs(attribs, nullptr);
    if (!ctx_ || !OSMesaMakeCurrent(ctx_, pixels_, GL_UNSIGNED_BYTE, 1, 1)) return;
#define CALF_GL(name)                                                              \
  gl.name = reinterpret_cast<decltype(gl.name)>(OSMesaGetProcAddress("gl" #name)); \
  if (!gl.name) return
    CALF_GL(CreateShader);
    CALF_GL(ShaderSource);
    CALF_GL(CompileShader);
    CALF_GL(GetShaderiv);
    CALF_GL(GetShaderInfoLog);
    CALF_GL(CreateProgram);
    CALF_GL(AttachShader);
    CALF_GL(LinkProgram);
    CALF_GL(GetProgramiv);
    CALF_GL(GetProgramInfoLog);
    CALF_GL(UseProgram);
    CALF_GL(GenBuffers);
    CALF_GL(BindBufferBase);
    CALF_GL(BindBuffer);
    CALF_GL(BufferData);
    CALF_GL(GetBufferSubData);
    CALF_GL(DispatchCompute);
    CALF_GL(MemoryBarrier);
    CALF_GL(GetUniformLocation);
    CALF_GL(Uniform1ui);
    CALF_GL(Uniform1f);
    CALF_GL(Uniform3f);
#undef CALF_GL
    ok_ = true;
  }
  ~Context() {
    if (ctx_) OSMesaDestroyContext(ctx_);
  }
  bool ok() const {
    return ok_;
  }
  Gl gl{};

 private:
  OSMesaContext ctx_ = nullptr;
  unsigned char pixels_[4] = {};
  bool ok_ = false;
};

Context& context() {
  static Context c;
  return c;
}

// Compiles `body` (after the version line and the conventions) as a compute shader; "" + log on
// failure.
GLuint compute_program(const std::string& body, std::string* log) {
  Gl& gl = context().gl;
  const std::string src = std::string("#version 450 core\n") + kGlslConventions + "\n" + body;
  const char* p = src.c_str();
  const GLuint sh = gl.CreateShader(GL_COMPUTE_SHADER);
  gl.ShaderSource(sh, 1, &p, nullptr);
  gl.CompileShader(sh);
  GLint ok = 0;
  gl.GetShaderiv(sh, GL_COMPILE_STATUS, &ok);
  char buf[4096] = {};
  if (!ok) {
    gl.GetShaderInfoLog(sh, sizeof buf, nullptr, buf);
    *log = buf;
    return 0;
  }
  const GLuint prog = gl.CreateProgram();
  gl.AttachShader(prog, sh);
  gl.LinkProgram(prog);
  gl.GetProgramiv(prog, GL_LINK_STATUS, &ok);
  if (!ok) {
    gl.GetProgramInfoLog(prog, sizeof buf, nullptr, buf);
    *log = buf;
    return 0;
  }
  return prog;
}

GLuint ssbo(GLuint binding, size_t bytes, const void* data) {
  Gl& gl = context().gl;
  GLuint b = 0;
  gl.GenBuffers(1, &b);
  gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, b);
  gl.BufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(bytes), data, GL_DYNAMIC_COPY);
  gl.BindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, b);
  return b;
}

template <typename T>
std::vector<T> read_back(GLuint b, size_t count) {
  Gl& gl = context().gl;
  std::vector<T> out(count);
  gl.BindBuffer(GL_SHADER_STORAGE_BUFFER, b);
  gl.GetBufferSubData(GL_SHADER_STORAGE_BUFFER, 0, static_cast<GLsizeiptr>(count * sizeof(T)),
                      out.data());
  return out;
}

#define REQUIRE_GL() \
  if (!context().ok()) GTEST_SKIP() << "no OSMesa GL 4.5 core context";

// Directions: random ones, exact seams (two equal magnitudes) and corners (three), axis
// directions, and points near seams; all as floats, since that is what the shader sees.
std::vector<float> test_directions() {
  std::vector<float> d;
  const auto add = [&](double x, double y, double z) {
    d.insert(d.end(), {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z), 0});
  };
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int i = 0; i < 4000; ++i) add(u(rng), u(rng), u(rng));
  for (int sx : {-1, 1}) {
    for (int sy : {-1, 1}) {
      for (int sz : {-1, 1}) {
        add(sx, sy, sz);  // corners
        for (double t : {0.0, 0.25, 0.5, 0.999, 1.0}) {
          add(sx, sy, sz * t), add(sx, sy * t, sz), add(sx * t, sy, sz);  // seams
          add(sx * 3.0, sy * 3.0, sz * 3.0 * t);                          // scaled seams
        }
        add(sx, sy * (1 - 1e-7), sz * 0.3), add(sx * (1 - 1e-7), sy, sz * 0.3);  // just off
      }
    }
    add(sx, 0, 0), add(0, sx, 0), add(0, 0, sx);
  }
  for (int i = 0; i < 2000; ++i) {  // near seams: one component equal to another +- tiny
    const double a = u(rng), b = u(rng);
    const double e = std::ldexp(u(rng), -20);
    add(a, a + e, b), add(a, b, -a + e), add(b, a, a * (1 + e));
  }
  return d;
}

TEST(GlslConventions, CubeFacesMatchCpp) {
  REQUIRE_GL();
  std::string log;
  const GLuint prog = compute_program(R"(
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer In { vec4 dirs[]; };
layout(std430, binding = 1) writeonly buffer Out { vec4 res[]; };
layout(std430, binding = 2) writeonly buffer Back { vec4 back[]; };
uniform uint count;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  vec3 d = dirs[i].xyz;
  int f = calf_face_from_direction(d);
  vec2 st = calf_st_from_direction(d, f);
  res[i] = vec4(float(f), st, 0.0);
  back[i] = vec4(calf_direction_from_st(f, st), 0.0);
}
)",
                                      &log);
  ASSERT_NE(prog, 0u) << log;
  const std::vector<float> dirs = test_directions();
  const size_t n = dirs.size() / 4;
  Gl& gl = context().gl;
  ssbo(0, dirs.size() * 4, dirs.data());
  const GLuint out = ssbo(1, n * 16, nullptr);
  const GLuint back = ssbo(2, n * 16, nullptr);
  gl.UseProgram(prog);
  gl.Uniform1ui(gl.GetUniformLocation(prog, "count"), static_cast<GLuint>(n));
  gl.DispatchCompute(static_cast<GLuint>((n + 63) / 64), 1, 1);
  gl.MemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  const std::vector<float> res = read_back<float>(out, 4 * n);
  const std::vector<float> dir_back = read_back<float>(back, 4 * n);
  double worst_st = 0, worst_dir = 0;
  size_t face_mismatches = 0;
  for (size_t i = 0; i < n; ++i) {
    const Vec3 d{dirs[4 * i], dirs[4 * i + 1], dirs[4 * i + 2]};
    if (d.x == 0 && d.y == 0 && d.z == 0) continue;
    const FaceCoord c = face_coord_from_direction(d);
    if (static_cast<int>(res[4 * i]) != cube_face_index(c.face)) {
      if (++face_mismatches < 5) {
        ADD_FAILURE() << "face of (" << d.x << ", " << d.y << ", " << d.z << "): GLSL "
                      << res[4 * i] << ", C++ " << cube_face_name(c.face);
      }
      continue;
    }
    worst_st =
        std::max({worst_st, std::fabs(res[4 * i + 1] - c.s), std::fabs(res[4 * i + 2] - c.t)});
    const Vec3 back_cpp = direction_from_face_coord(c);
    worst_dir = std::max({worst_dir, std::fabs(dir_back[4 * i] - back_cpp.x),
                          std::fabs(dir_back[4 * i + 1] - back_cpp.y),
                          std::fabs(dir_back[4 * i + 2] - back_cpp.z)});
  }
  std::printf("%zu directions: face mismatches %zu, max |st| diff %.3g, max |dir| diff %.3g\n", n,
              face_mismatches, worst_st, worst_dir);
  EXPECT_EQ(face_mismatches, 0u);
  // Float against double: s and t in [0, 1] within a few ulps of 1 (2^-23 = 1.2e-7).
  EXPECT_LE(worst_st, 5e-7);
  EXPECT_LE(worst_dir, 1e-6);
}

// The depth functions the ray-march shader calls, on every code of three ranges, with the range
// constants as the GL renderer passes them (glsl_log_range()).
TEST(GlslConventions, LogDepthMatchesCppForEveryCode) {
  REQUIRE_GL();
  std::string log;
  const GLuint prog = compute_program(R"(
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer In { float depth_in[]; };
layout(std430, binding = 1) writeonly buffer Dec { vec2 decoded[]; };
layout(std430, binding = 2) writeonly buffer Enc { float code_of[]; };
uniform uint count;
uniform CalfLogRange range;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  float log_z = i == CALF_LOG16_SKY ? 0.0 : calf_log_depth_from_code(i, range);
  decoded[i] = vec2(calf_depth_from_code(i, range), log_z);
  code_of[i] = calf_code_from_log_depth(log(depth_in[i]), range);
}
)",
                                      &log);
  ASSERT_NE(prog, 0u) << log;
  Gl& gl = context().gl;
  for (const auto& [zn, zf] :
       {std::pair{0.1f, 100.0f}, std::pair{1e-4f, 1e6f}, std::pair{2.0f, 2.002f}}) {
    const LogDepthRange range = *LogDepthRange::make(zn, zf);
    const GlslLogRange shader_range = glsl_log_range(range);
    const size_t n = 65536;
    std::vector<float> depth(n);
    for (size_t c = 0; c < n; ++c) depth[c] = range.decode(static_cast<uint16_t>(c));
    ssbo(0, n * 4, depth.data());
    const GLuint dec = ssbo(1, n * 8, nullptr);
    const GLuint enc = ssbo(2, n * 4, nullptr);
    gl.UseProgram(prog);
    gl.Uniform1ui(gl.GetUniformLocation(prog, "count"), static_cast<GLuint>(n));
    const auto set = [&](const char* name, float v) {
      const GLint loc = gl.GetUniformLocation(prog, name);
      ASSERT_GE(loc, 0) << name;
      gl.Uniform1f(loc, v);
    };
    set("range.z_near", shader_range.z_near);
    set("range.z_far", shader_range.z_far);
    set("range.log_near", shader_range.log_near);
    set("range.step", shader_range.step);
    set("range.inv_step", shader_range.inv_step);
    gl.DispatchCompute(static_cast<GLuint>(n / 64), 1, 1);
    gl.MemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    const std::vector<float> decoded = read_back<float>(dec, 2 * n);
    const std::vector<float> code_of = read_back<float>(enc, n);
    const double log_ratio = std::log(double{zf} / zn);
    double worst_rel = 0, worst_log = 0, worst_code = 0;
    size_t off_by_one = 0, wrong = 0;
    for (size_t c = 0; c < n; ++c) {
      if (c == kLog16Sky) {
        EXPECT_TRUE(std::isinf(decoded[2 * c]) && decoded[2 * c] > 0);
        continue;
      }
      worst_rel = std::max(worst_rel, std::fabs(double{decoded[2 * c]} / depth[c] - 1));
      // ln z against the exact log-16 value (Eq. 13), not against ln of the float depth.
      const double exact_log = std::log(double{zn}) + static_cast<double>(c) * log_ratio / 65534;
      worst_log = std::max(worst_log, std::fabs(decoded[2 * c + 1] - exact_log));
      // The continuous code of each code's own depth: c again, up to float resolution; rounded
      // (what the shader's comparisons amount to) one code off at most, at half-code boundaries.
      const double cpp_code = range.normalized_from_depth(depth[c]) * 65534;
      worst_code = std::max(worst_code, std::fabs(code_of[c] - cpp_code));
      const int64_t diff = static_cast<int64_t>(std::floor(double{code_of[c]} + 0.5)) - int64_t(c);
      off_by_one += diff != 0 && std::abs(diff) <= 1;
      wrong += std::abs(diff) > 1;
    }
    EXPECT_EQ(decoded[0], zn);
    EXPECT_EQ(decoded[2 * kLog16MaxFinite], zf);
    std::printf(
        "range [%g, %g]: max rel decode diff %.3g, max ln z diff %.3g, codes off by one %zu, more "
        "%zu, max continuous code diff %.3g\n",
        zn, zf, worst_rel, worst_log, off_by_one, wrong, worst_code);
    EXPECT_LE(worst_rel, 4e-6);
    // A float depth resolves relative steps of 2^-23; where one code is finer than that (the
    // narrow range: 1.5e-8 per code) codes can only come back within float resolution, and
    // ln(z) - ln(z_near) cancels float digits (the continuous code's error grows as
    // ulp(ln z) / step). The GL renderer compares in code space, where this is far below one
    // ray-march step.
    const double ulp = std::ldexp(1.0, -23);
    const double ln_scale = std::fabs(std::log(double{zn})) + log_ratio + 1;
    EXPECT_LE(worst_log, 4 * ulp * ln_scale);
    if (range.relative_step() > 4 * ulp) {  // else: reported above, not bounded
      EXPECT_EQ(wrong, 0u);
      EXPECT_LE(off_by_one, n / 100);
    }
    EXPECT_LE(worst_code / 65534,
              4e-6 + 8 * ulp * (std::fabs(std::log(double{zf})) + 1) / log_ratio);
  }
}

// calf_raster_position() against format/camera.h: a point on the ray camera_ray_at(x, y) at any
// distance lands at window position (x, height - y) (GL's rows run bottom-up) with window depth
// near / z, z its distance along forward, for cameras of several orientations, fields of view and
// aspects; points nearer than `near` have a window depth above 1 (clipped).
TEST(GlslConventions, RasterCameraMatchesCameraRays) {
  REQUIRE_GL();
  std::string log;
  const GLuint prog = compute_program(R"(
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer In { vec4 rel[]; };
layout(std430, binding = 1) writeonly buffer Out { vec4 clip[]; };
uniform uint count;
uniform CalfRasterCamera calf_camera;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= count) return;
  clip[i] = calf_raster_position(rel[i].xyz, calf_camera);
}
)",
                                      &log);
  ASSERT_NE(prog, 0u) << log;
  Gl& gl = context().gl;
  std::mt19937 rng(47);
  std::uniform_real_distribution<double> u(0, 1);
  struct Case {
    Vec3 forward, up;
    double fov_y;
    uint32_t width, height;
    double near;
  };
  for (const Case& k : {Case{{0, 0, -1}, {0, 1, 0}, 1.5707963267948966, 64, 64, 0.05},
                        Case{{1, 0.2, 0.3}, {0, 1, 0}, 1.2, 1280, 720, 0.01},
                        Case{{-0.3, -0.9, 0.1}, {0, 0, 1}, 0.4, 300, 900, 0.5},
                        Case{{0.5, 0.5, 0.5}, {1, 0, 0}, 2.5, 4096, 2048, 1e-3}}) {
    Camera camera;
    camera.position = {1.5, -2, 3};  // the shader sees points relative to the eye
    camera.forward = k.forward;
    camera.up = k.up;
    camera.fov_y = k.fov_y;
    camera.width = k.width;
    camera.height = k.height;
    ASSERT_TRUE(validate_camera(camera).ok());
    const CameraFrame frame = camera_frame(camera);
    const size_t n = 4096;
    std::vector<float> rel(4 * n);
    std::vector<double> xs(n), ys(n), zs(n);
    for (size_t i = 0; i < n; ++i) {
      xs[i] = u(rng) * camera.width;
      ys[i] = u(rng) * camera.height;
      const Vec3 d = camera_ray_at(camera, frame, xs[i], ys[i]);
      const double t = k.near * std::exp(u(rng) * 12 - 1);  // some nearer than `near`
      const Vec3 p = d * t;
      rel[4 * i] = static_cast<float>(p.x);
      rel[4 * i + 1] = static_cast<float>(p.y);
      rel[4 * i + 2] = static_cast<float>(p.z);
      const Vec3 pf{rel[4 * i], rel[4 * i + 1], rel[4 * i + 2]};
      zs[i] = pf.x * frame.forward.x + pf.y * frame.forward.y + pf.z * frame.forward.z;
    }
    ssbo(0, n * 16, rel.data());
    const GLuint out = ssbo(1, n * 16, nullptr);
    gl.UseProgram(prog);
    gl.Uniform1ui(gl.GetUniformLocation(prog, "count"), static_cast<GLuint>(n));
    const GlslRasterCamera c = glsl_raster_camera(camera, k.near);
    const auto loc = [&](const char* name) {
      const GLint l = gl.GetUniformLocation(prog, name);
      EXPECT_GE(l, 0) << name;
      return l;
    };
    gl.Uniform3f(loc("calf_camera.right"), c.right[0], c.right[1], c.right[2]);
    gl.Uniform3f(loc("calf_camera.up"), c.up[0], c.up[1], c.up[2]);
    gl.Uniform3f(loc("calf_camera.forward"), c.forward[0], c.forward[1], c.forward[2]);
    gl.Uniform1f(loc("calf_camera.scale_x"), c.scale_x);
    gl.Uniform1f(loc("calf_camera.scale_y"), c.scale_y);
    gl.Uniform1f(loc("calf_camera.near_distance"), c.near_distance);
    gl.DispatchCompute(static_cast<GLuint>(n / 64), 1, 1);
    gl.MemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    const std::vector<float> clip = read_back<float>(out, 4 * n);
    double worst_px = 0, worst_depth = 0;
    size_t clipped = 0;
    for (size_t i = 0; i < n; ++i) {
      const double w = clip[4 * i + 3];
      ASSERT_GT(w, 0);
      const double wx = (clip[4 * i] / w + 1) / 2 * camera.width;
      const double wy = (clip[4 * i + 1] / w + 1) / 2 * camera.height;
      const double depth = clip[4 * i + 2] / w;
      worst_px =
          std::max({worst_px, std::fabs(wx - xs[i]), std::fabs(wy - (camera.height - ys[i]))});
      worst_depth = std::max(worst_depth, std::fabs(depth * zs[i] / k.near - 1));
      clipped += depth > 1;
      EXPECT_EQ(depth > 1, zs[i] < k.near * (1 - 1e-6)) << i;
    }
    std::printf(
        "camera %u x %u, fov %.2f: max window position diff %.3g px, max rel depth diff "
        "%.3g, %zu of %zu nearer than near\n",
        camera.width, camera.height, k.fov_y, worst_px, worst_depth, clipped, n);
    // Float rounding of the point and the axes: a few ulps of the image side.
    EXPECT_LT(worst_px, 2e-6 * std::max(camera.width, camera.height) + 1e-4);
    EXPECT_LT(worst_depth, 1e-5);
    EXPECT_GT(clipped, 0u);
  }
}

}  // namespace
}  // namespace calf::player
