#include "calf_play/play_window.h"

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "calf/format/colour.h"
#include "calf/player/display_clock.h"

namespace calf::player {
namespace {

// GL entry points the window needs beyond the renderer's table (display texture, clearing).
struct DisplayGl {
  void (*TexImage2D)(GLenum, GLint, GLint, GLsizei, GLsizei, GLint, GLenum, GLenum, const void*);
  void (*Clear)(GLbitfield);
  void (*ClearColor)(GLfloat, GLfloat, GLfloat, GLfloat);
};

std::string glfw_error() {
  const char* text = nullptr;
  glfwGetError(&text);
  return text ? text : "unknown GLFW error";
}

// Unit `a`, or straight ahead (-Z) when `a` is zero (looking straight up or down).
Vec3 normalized(const Vec3& a) {
  const double l = length(a);
  return l > 0 ? a * (1 / l) : Vec3{0, 0, -1};
}

struct CameraState {
  bool orbit = false;
  double yaw = 0, pitch = 0;  // radians; yaw 0 looks down -Z
  Vec3 position;              // fly
  Vec3 centre;                // orbit target
  double radius = 1;          // orbit distance
  Vec3 forward() const {
    return {std::sin(yaw) * std::cos(pitch), std::sin(pitch), -std::cos(yaw) * std::cos(pitch)};
  }
  Vec3 eye() const { return orbit ? centre + forward() * -radius : position; }
};

}  // namespace

void warn_dropped_views(const Playback& play) {
  if (play.lightfield() == nullptr) return;
  for (const auto& [view, problem] : play.lightfield()->dropped_views()) {
    std::fprintf(stderr, "calf-play: warning: view %u dropped, the others play: %s\n", view,
                 problem.to_string().c_str());
  }
}

Status run_window(const std::string& clip_path, const PlaybackOptions& options,
                  const WindowOptions& wo) {
  if (!glfwInit()) {
    return Status(ErrorId::kPlayerGl,
                  "cannot open a window (no display? use --headless): " + glfw_error());
  }
  struct GlfwGuard {
    ~GlfwGuard() { glfwTerminate(); }
  } glfw_guard;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 5);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  GLFWwindow* window = glfwCreateWindow(static_cast<int>(wo.width), static_cast<int>(wo.height),
                                        "calf-play", nullptr, nullptr);
  if (window == nullptr) {
    return Status(ErrorId::kPlayerGl, "no OpenGL 4.5 core window: " + glfw_error());
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(1);
  CALF_ASSIGN_OR_RETURN(GlFunctions gl,
                        load_gl_functions(reinterpret_cast<GlGetProc>(glfwGetProcAddress)));
  DisplayGl dgl{};
  dgl.TexImage2D = reinterpret_cast<decltype(dgl.TexImage2D)>(glfwGetProcAddress("glTexImage2D"));
  dgl.Clear = reinterpret_cast<decltype(dgl.Clear)>(glfwGetProcAddress("glClear"));
  dgl.ClearColor = reinterpret_cast<decltype(dgl.ClearColor)>(glfwGetProcAddress("glClearColor"));
  if (!dgl.TexImage2D || !dgl.Clear || !dgl.ClearColor) {
    return Status(ErrorId::kPlayerGl, "glTexImage2D / glClear missing from the context");
  }
  CALF_ASSIGN_OR_RETURN(std::unique_ptr<Playback> play, Playback::open(clip_path, options, &gl));
  warn_dropped_views(*play);

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // write nothing into the working directory
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 450");
  struct ImGuiGuard {
    ~ImGuiGuard() {
      ImGui_ImplOpenGL3_Shutdown();
      ImGui_ImplGlfw_Shutdown();
      ImGui::DestroyContext();
    }
  } imgui_guard;

  GLuint display = 0;
  gl.GenTextures(1, &display);
  CameraState cam;
  // The light field's knobs (RR, view selection) act on the clip's first lightfield track.
  LightfieldRepresentation* lf = play->lightfield();
  const auto& [lo, hi] = play->view_volume();
  cam.centre = (lo + hi) * 0.5;
  cam.position = cam.centre;
  cam.radius = std::max(0.5, std::hypot(hi.x - lo.x, hi.y - lo.y, hi.z - lo.z));
  bool stereo = wo.stereo, paused = false, show_hud = true;
  double clip_time = 0;
  auto last = std::chrono::steady_clock::now();
  // The HUD's fps and the frame budgets' reports: wall time between displayed frames (swaps).
  DisplayClock display_clock;
  std::vector<uint8_t> pixels;
  RenderedImage image;
  std::string warning;
  uint64_t frames = 0;
  bool key_down[GLFW_KEY_LAST + 1] = {};
  // The coverage mode the C key turns on: --coverage's, or the grown cell mask.
  const uint32_t coverage_on =
      lf != nullptr && lf->options().render.coverage != 0 ? lf->options().render.coverage : 3;
  // The sharpening the K key turns on: --colour-sharpen's, or the measured best 0.2.
  const double sharpen_on = lf != nullptr && lf->options().render.colour_sharpen > 0
                                ? lf->options().render.colour_sharpen
                                : 0.2;
  while (!glfwWindowShouldClose(window)) {
    glfwPollEvents();
    const auto now = std::chrono::steady_clock::now();
    const double dt = std::chrono::duration<double>(now - last).count();
    last = now;
    ImGuiIO& io = ImGui::GetIO();
    // Keys through GLFW (this ImGui predates named keys); pressed = went down this frame.
    auto held = [&](int key) { return glfwGetKey(window, key) == GLFW_PRESS; };
    auto pressed = [&](int key) {
      const bool down = held(key), was = key_down[key];
      key_down[key] = down;
      return down && !was;
    };
    const bool shift = held(GLFW_KEY_LEFT_SHIFT) || held(GLFW_KEY_RIGHT_SHIFT);
    if (!io.WantCaptureKeyboard) {
      if (pressed(GLFW_KEY_ESCAPE)) glfwSetWindowShouldClose(window, 1);
      if (pressed(GLFW_KEY_SPACE)) paused = !paused;
      if (pressed(GLFW_KEY_O)) cam.orbit = !cam.orbit;
      if (pressed(GLFW_KEY_H)) show_hud = !show_hud;
      if (pressed(GLFW_KEY_S) && shift) stereo = !stereo;
      if (pressed(GLFW_KEY_R) && lf != nullptr) {
        LightfieldRenderOptions r = lf->options().render;
        r.rr = !r.rr;
        if (r.rr && !lf->has_material()) warning = "the clip has no material: RR does nothing";
        (void)lf->set_render_options(r);
      }
      if (pressed(GLFW_KEY_C) && lf != nullptr) {
        LightfieldRenderOptions r = lf->options().render;
        r.coverage = r.coverage == 0 ? coverage_on : 0;
        if (r.coverage != 0 && !lf->has_coverage()) {
          warning = "the clip has no coverage stream: coverage does nothing";
        }
        (void)lf->set_render_options(r);
      }
      if (pressed(GLFW_KEY_K) && lf != nullptr) {
        LightfieldRenderOptions r = lf->options().render;
        r.colour_sharpen = r.colour_sharpen > 0 ? 0 : sharpen_on;
        (void)lf->set_render_options(r);
      }
      const bool key_v = pressed(GLFW_KEY_V);
      const bool more = pressed(GLFW_KEY_EQUAL) | pressed(GLFW_KEY_KP_ADD);
      const bool fewer = pressed(GLFW_KEY_MINUS) | pressed(GLFW_KEY_KP_SUBTRACT);
      if ((key_v || more || fewer) && lf != nullptr) {
        ViewSelectionOptions s = lf->selector().options();
        if (key_v) {
          s.priority = s.priority == ViewPriority::kDistance ? ViewPriority::kAngle
                                                             : ViewPriority::kDistance;
          s.reference_point = cam.centre;
        }
        if (more) s.max_active = std::min<uint32_t>(s.max_active + 1, kMaxViewpoints);
        if (fewer && s.max_active > 1) {
          s.max_active -= 1;
          s.min_active = std::min(s.min_active, s.max_active);
        }
        (void)lf->selector().set_options(s);
      }
      const double speed = cam.radius * 0.5 * dt;
      const Vec3 f = cam.forward(), right = normalized(cross(f, {0, 1, 0}));
      if (cam.orbit) {
        if (held(GLFW_KEY_W)) cam.radius = std::max(0.05, cam.radius - speed);
        if (held(GLFW_KEY_S) && !shift) cam.radius += speed;
      } else {
        if (held(GLFW_KEY_W)) cam.position += f * speed;
        if (held(GLFW_KEY_S) && !shift) cam.position += f * -speed;
        if (held(GLFW_KEY_D)) cam.position += right * speed;
        if (held(GLFW_KEY_A)) cam.position += right * -speed;
        if (held(GLFW_KEY_E)) cam.position.y += speed;
        if (held(GLFW_KEY_Q)) cam.position.y -= speed;
      }
    }
    if (!io.WantCaptureMouse && ImGui::IsMouseDragging(ImGuiMouseButton_Left)) {
      const ImVec2 d = io.MouseDelta;
      cam.yaw += d.x * 0.005;
      cam.pitch = std::clamp(cam.pitch - d.y * 0.005, -1.5, 1.5);
    }
    if (!paused) clip_time += dt;
    const double duration = play->frame_count() / play->fps();
    const uint32_t frame = play->frame_at_time(std::fmod(clip_time, duration));

    int fb_w = 0, fb_h = 0;
    glfwGetFramebufferSize(window, &fb_w, &fb_h);
    const uint32_t eyes_n = stereo ? 2 : 1;
    const uint32_t eye_w = std::max(1, fb_w / static_cast<int>(eyes_n));
    std::vector<Camera> eyes;
    const Vec3 f = cam.forward(), right = normalized(cross(f, {0, 1, 0}));
    for (uint32_t e = 0; e < eyes_n; ++e) {
      Camera c;
      const double offset = stereo ? (e == 0 ? -0.5 : 0.5) * wo.ipd : 0;
      c.position = cam.eye() + right * offset;
      c.forward = cam.orbit ? f : f;
      c.up = {0, 1, 0};
      c.fov_y = wo.fov_y_degrees * M_PI / 180;
      c.width = eye_w;
      c.height = static_cast<uint32_t>(std::max(1, fb_h));
      eyes.push_back(c);
    }
    CALF_RETURN_IF_ERROR(play->prepare(frame, eyes));
    // Both eyes into one sRGB8 image, shown through ImGui's background draw list.
    const uint32_t width = eye_w * eyes_n, height = eyes[0].height;
    pixels.assign(size_t{width} * height * 4, 255);
    for (uint32_t e = 0; e < eyes_n; ++e) {
      CALF_RETURN_IF_ERROR(play->render(eyes[e], &image));
      for (uint32_t y = 0; y < height; ++y) {
        for (uint32_t x = 0; x < eye_w; ++x) {
          const float* c = &image.color[(size_t{y} * eye_w + x) * 3];
          uint8_t* p = &pixels[(size_t{y} * width + e * eye_w + x) * 4];
          for (int k = 0; k < 3; ++k) p[k] = srgb8_from_linear(c[k]);
        }
      }
    }
    gl.BindTexture(GL_TEXTURE_2D, display);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    dgl.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, static_cast<GLsizei>(width),
                   static_cast<GLsizei>(height), 0, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    ImGui::GetBackgroundDrawList()->AddImage(
        reinterpret_cast<ImTextureID>(static_cast<intptr_t>(display)), ImVec2(0, 0),
        ImVec2(static_cast<float>(fb_w), static_cast<float>(fb_h)));
    if (show_hud) {
      // Generic: each representation says what it has to say (representation.h).
      ImGui::Begin("calf-play");
      const double fps = display_clock.fps();
      if (fps > 0) {
        ImGui::Text("%.1f fps (%.1f ms a frame)   frame %u / %u%s", fps,
                    display_clock.last_frame_ms(), frame, play->frame_count(),
                    paused ? "  (paused)" : "");
      } else {
        ImGui::Text("-- fps   frame %u / %u%s", frame, play->frame_count(),
                    paused ? "  (paused)" : "");
      }
      ImGui::Text("camera %s, stereo %s, render %.1f ms per eye", cam.orbit ? "orbit" : "fly",
                  stereo ? "on" : "off", play->last_render_ms());
      for (const RepresentationStats& rs : play->stats()) {
        ImGui::Separator();
        ImGui::TextUnformatted(rs.title.c_str());
        for (const Statistic& st : rs.entries) {
          if (st.alert) {
            ImGui::TextColored({1, 0.3f, 0.3f, 1}, "%s: %s", st.name.c_str(), st.value.c_str());
          } else {
            ImGui::Text("%s: %s", st.name.c_str(), st.value.c_str());
          }
        }
      }
      if (!play->inside_view_volume(cam.eye())) {
        ImGui::TextColored({1, 0.6f, 0, 1}, "eye outside the view volume");
      }
      if (!warning.empty()) ImGui::TextColored({1, 0.6f, 0, 1}, "%s", warning.c_str());
      ImGui::End();
    }
    ImGui::Render();
    gl.Viewport(0, 0, fb_w, fb_h);
    dgl.ClearColor(0, 0, 0, 1);
    dgl.Clear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    glfwSwapBuffers(window);
    display_clock.displayed(std::chrono::steady_clock::now());
    if (display_clock.has_interval()) (void)play->report_frame_time(display_clock.last_frame_ms());
    if (wo.max_frames != 0 && ++frames >= wo.max_frames) break;
  }
  gl.DeleteTextures(1, &display);
  glfwDestroyWindow(window);
  return Status::Ok();
}

}  // namespace calf::player
