// The "factory" scene (the surfel mode's heavy scene): a machine hall of 72 m x 72 m
// whose rows of machines are built from a handful of detailed CAD-like parts (factory_parts.h),
// each part made once and instanced thousands of times with rigid transforms. Counting
// instances it is about 30 M triangles, far more than a rasteriser on llvmpipe draws at
// interactive rates; the unique geometry is a few hundred thousand triangles.
//
// Layout: 8 rows of 12 machines along X (5 m pitch) at z = +-4.5, +-12.5, +-20.5, +-28.5, each
// facing the nearest aisle (z = 0, +-16.5, +-32.5); conveyor lines between the rows' backs (z =
// +-8.5, +-24.5); steel columns on the conveyor lines carrying roof girders at 9 m (the roof is
// open: the sun lights the hall); pallet racks along the walls at x = +-36. A machine is a
// ribbed bed with headstock, tailstock and control cabinet, a finned motor, a train of three
// meshing gears on its front turning at their tooth ratios, eight threaded studs on its top
// flange and a pipe with bends from its end into the floor. The view region is the middle of the
// central aisle at eye height; the validation path walks along it.
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "factory_parts.h"
#include "procedural.h"
#include "visibility_scenes.h"

namespace calf::samples {

namespace {

using procedural::pick;
using procedural::stream_of;

constexpr double kTau = 6.283185307179586;
constexpr float kHall = 36;  // half the hall's side
constexpr int kMachinesPerRow = 12;
constexpr float kMachinePitch = 5;
constexpr float kRows[] = {-28.5f, -20.5f, -12.5f, -4.5f, 4.5f, 12.5f, 20.5f, 28.5f};
constexpr float kConveyorLines[] = {-24.5f, -8.5f, 8.5f, 24.5f};
constexpr float kColumnsX[] = {-30, -15, 0, 15, 30};
constexpr float kBedLength = 2.6f;
constexpr float kGearModule = 0.011f, kGearWidth = 0.05f;
constexpr uint32_t kGearTeeth[3] = {24, 40, 32};  // driver, driven, idler

enum : uint32_t {
  kConcrete,
  kFloorLine,
  kWall,
  kPaint0,  // kPaints machine colours follow
  kPaints = 4,
  kSteel = kPaint0 + kPaints,
  kDarkSteel,
  kMotor0,  // kMotors motor colours follow
  kMotors = 2,
  kPipe0 = kMotor0 + kMotors,  // kPipes pipe colours follow
  kPipes = 3,
  kConveyorGrey = kPipe0 + kPipes,
  kColumnGrey,
  kWood,
  kRackOrange,
};

Object placed(std::string name, uint32_t material, std::shared_ptr<const TriangleMesh> mesh,
              TransformAt transform) {
  Object o;
  o.name = std::move(name);
  o.material = material;
  o.shared_mesh = std::move(mesh);
  o.transform = std::move(transform);
  return o;
}

TransformAt still(const glm::mat4& m) {
  return [m](double) { return m; };
}

struct Parts {
  std::shared_ptr<TriangleMesh> bed, motor, stud, conveyor, column, girder;
  std::shared_ptr<TriangleMesh> gears[3], pipes[2];
  factory::RackMeshes racks[2];
};

// Places one machine: `cell` maps the machine's frame (bed along X, front +Z) into the hall.
void add_machine(Scene* s, const Parts& parts, const std::string& name, const glm::mat4& cell,
                 uint64_t st) {
  const uint32_t paint = kPaint0 + pick(st, 0, kPaints);
  s->objects.push_back(placed(name + "-bed", paint, parts.bed, still(cell)));
  const float motor_x = -kBedLength / 2 - 0.45f;
  s->objects.push_back(placed(name + "-motor", kMotor0 + pick(st, 1, kMotors), parts.motor,
                              still(glm::translate(cell, {motor_x, 0, 0}))));
  // The gear train on the front, axles along +Z: each gear turns at the driver's speed times the
  // inverse tooth ratio, neighbours in opposite senses; the driver's phase varies per machine.
  const float r0 = factory::gear_pitch_radius(kGearTeeth[0], kGearModule);
  const float r1 = factory::gear_pitch_radius(kGearTeeth[1], kGearModule);
  const float r2 = factory::gear_pitch_radius(kGearTeeth[2], kGearModule);
  const glm::vec3 centres[3] = {
      {-0.9f, 0.4f, 0.48f},
      {-0.9f + r0 + r1, 0.4f, 0.48f},
      {-0.9f + r0 + r1 + (r1 + r2) * 0.766f, 0.4f + (r1 + r2) * 0.643f, 0.48f}};
  const double speed = 1.2 + 0.2 * pick(st, 2, 4);  // rad/s of the driver
  const double senses[3] = {1, -1, 1};
  const double phase = procedural::uniform(st, 3, 0, 1);
  for (int g = 0; g < 3; ++g) {
    const double omega = senses[g] * speed * kGearTeeth[0] / kGearTeeth[g];
    const glm::mat4 at = glm::translate(cell, centres[g]);
    // Half a tooth of offset on the driven gear so that teeth sit in gaps.
    const double offset = (g == 1 ? 0.5 * kTau / kGearTeeth[1] : 0) + phase;
    s->objects.push_back(placed(
        name + "-gear-" + std::to_string(g), kSteel, parts.gears[g], [at, omega, offset](double t) {
          const glm::mat4 spin =
              glm::rotate(at, static_cast<float>(offset + omega * t), glm::vec3(0, 0, 1));
          return glm::rotate(spin, static_cast<float>(kTau / 4), glm::vec3(1, 0, 0));
        }));
  }
  // Studs on the top flange (y = 0.85).
  const float stud_x[4] = {-1.05f, -0.45f, 0.15f, 0.75f};
  for (int i = 0; i < 8; ++i) {
    const glm::vec3 p(stud_x[i % 4], 0.85f, i < 4 ? 0.4f : -0.4f);
    const glm::mat4 m =
        glm::rotate(glm::translate(cell, p), 0.37f * static_cast<float>(i), glm::vec3(0, 1, 0));
    s->objects.push_back(
        placed(name + "-stud-" + std::to_string(i), kDarkSteel, parts.stud, still(m)));
  }
  // The pipe leaves the bed's +X end going +X (its frame's +Y) and bends down into the floor.
  const glm::mat4 pipe = glm::rotate(glm::translate(cell, {kBedLength / 2 - 0.03f, 0.45f, 0.1f}),
                                     static_cast<float>(-kTau / 4), glm::vec3(0, 0, 1));
  s->objects.push_back(placed(name + "-pipe", kPipe0 + pick(st, 4, kPipes),
                              parts.pipes[pick(st, 5, 2)], still(pipe)));
}

}  // namespace

Scene factory_scene() {
  Scene s;
  s.name = "factory";
  s.materials = {procedural::diffuse(0.5f, 0.5f, 0.48f),   procedural::diffuse(0.85f, 0.7f, 0.1f),
                 procedural::diffuse(0.7f, 0.68f, 0.62f),  procedural::diffuse(0.25f, 0.45f, 0.35f),
                 procedural::diffuse(0.35f, 0.42f, 0.5f),  procedural::diffuse(0.8f, 0.45f, 0.15f),
                 procedural::diffuse(0.8f, 0.78f, 0.68f),  procedural::diffuse(0.62f, 0.63f, 0.65f),
                 procedural::diffuse(0.25f, 0.25f, 0.27f), procedural::diffuse(0.15f, 0.3f, 0.55f),
                 procedural::diffuse(0.3f, 0.32f, 0.3f),   procedural::diffuse(0.6f, 0.12f, 0.1f),
                 procedural::diffuse(0.85f, 0.7f, 0.15f),  procedural::diffuse(0.15f, 0.35f, 0.6f),
                 procedural::diffuse(0.35f, 0.37f, 0.4f),  procedural::diffuse(0.45f, 0.5f, 0.55f),
                 procedural::diffuse(0.55f, 0.42f, 0.28f), procedural::diffuse(0.85f, 0.4f, 0.1f)};

  // Floor, walls 8 m high and painted lines along the aisles.
  Object floor;
  floor.name = "floor";
  floor.material = kConcrete;
  add_quad(&floor.mesh, {-kHall, 0, -kHall}, {-kHall, 0, kHall}, {kHall, 0, kHall},
           {kHall, 0, -kHall});
  s.objects.push_back(std::move(floor));
  Object walls;
  walls.name = "walls";
  walls.material = kWall;
  add_box(&walls.mesh, {-kHall - 0.3f, -0.1f, -kHall - 0.3f}, {-kHall, 8, kHall + 0.3f});
  add_box(&walls.mesh, {kHall, -0.1f, -kHall - 0.3f}, {kHall + 0.3f, 8, kHall + 0.3f});
  add_box(&walls.mesh, {-kHall, -0.1f, -kHall - 0.3f}, {kHall, 8, -kHall});
  add_box(&walls.mesh, {-kHall, -0.1f, kHall}, {kHall, 8, kHall + 0.3f});
  s.objects.push_back(std::move(walls));
  Object lines;
  lines.name = "aisle-lines";
  lines.material = kFloorLine;
  for (float aisle : {-32.5f, -16.5f, 0.0f, 16.5f, 32.5f}) {
    for (float side : {-1.8f, 1.8f}) {
      const float z = aisle + side;
      if (std::fabs(z) > kHall - 0.5f) continue;
      add_box(&lines.mesh, {-kHall + 1.5f, -0.001f, z - 0.05f}, {kHall - 1.5f, 0.003f, z + 0.05f});
    }
  }
  s.objects.push_back(std::move(lines));

  Parts parts;
  parts.bed = factory::make_machine_bed(kBedLength);
  parts.motor = factory::make_motor(0.18f, 0.7f, 0.3f);
  parts.stud = factory::make_stud(0.036f, 0.072f);
  const char* gear_names[3] = {"gear-24", "gear-40", "gear-32"};
  for (int g = 0; g < 3; ++g) {
    parts.gears[g] = factory::make_gear(gear_names[g], kGearTeeth[g], kGearModule, kGearWidth);
  }
  for (uint32_t v = 0; v < 2; ++v) parts.pipes[v] = factory::make_pipe(0.05f, v);
  parts.conveyor = factory::make_conveyor(3.5f);
  parts.column = factory::make_column(9.02f);
  parts.girder = factory::make_girder(2 * kHall);
  for (uint32_t v = 0; v < 2; ++v) parts.racks[v] = factory::make_rack(4, v);

  // Machines: fronts towards the nearest aisle (rows at |z| = 4.5 and 20.5 face the origin's
  // side, the others away from it).
  for (size_t r = 0; r < std::size(kRows); ++r) {
    const float z = kRows[r];
    const bool towards_origin =
        std::fabs(std::fabs(z) - 4.5f) < 1 || std::fabs(std::fabs(z) - 20.5f) < 1;
    const bool front_plus_z = (z < 0) == towards_origin;
    for (int i = 0; i < kMachinesPerRow; ++i) {
      const float x = (static_cast<float>(i) - (kMachinesPerRow - 1) / 2.0f) * kMachinePitch;
      glm::mat4 cell = glm::translate(glm::mat4(1), {x, 0, z});
      if (!front_plus_z) cell = glm::rotate(cell, static_cast<float>(kTau / 2), glm::vec3(0, 1, 0));
      add_machine(&s, parts, "machine-" + std::to_string(r) + "-" + std::to_string(i), cell,
                  stream_of(0xFAC7, r, static_cast<uint64_t>(i)));
    }
  }
  // Conveyor lines: sections between the columns (which stand on the lines at kColumnsX).
  for (size_t l = 0; l < std::size(kConveyorLines); ++l) {
    for (size_t c = 0; c + 1 < std::size(kColumnsX); ++c) {
      for (int k = 0; k < 4; ++k) {
        const float x = kColumnsX[c] + 0.5f + 3.5f * (static_cast<float>(k) + 0.5f);
        s.objects.push_back(placed(
            "conveyor-" + std::to_string(l) + "-" + std::to_string(c) + "-" + std::to_string(k),
            kConveyorGrey, parts.conveyor,
            still(glm::translate(glm::mat4(1), {x, 0, kConveyorLines[l]}))));
      }
    }
  }
  // Columns on the conveyor lines and girders across the hall on them.
  for (size_t c = 0; c < std::size(kColumnsX); ++c) {
    for (size_t l = 0; l < std::size(kConveyorLines); ++l) {
      s.objects.push_back(
          placed("column-" + std::to_string(c) + "-" + std::to_string(l), kColumnGrey, parts.column,
                 still(glm::translate(glm::mat4(1), {kColumnsX[c], 0, kConveyorLines[l]}))));
    }
    s.objects.push_back(placed("girder-" + std::to_string(c), kColumnGrey, parts.girder,
                               still(glm::translate(glm::mat4(1), {kColumnsX[c], 9, 0}))));
  }
  // Racks along the walls at x = +-36, backs to the wall.
  for (int side = 0; side < 2; ++side) {
    const float sign = side ? 1.0f : -1.0f;
    for (int j = 0; j < 6; ++j) {
      const float z = (static_cast<float>(j) - 2.5f) * 11.4f;
      glm::mat4 m = glm::translate(glm::mat4(1), {sign * (kHall - 1.16f), 0, z});
      m = glm::rotate(m, static_cast<float>(-sign * kTau / 4), glm::vec3(0, 1, 0));
      const factory::RackMeshes& rack = parts.racks[(j + side) % 2];
      const std::string name = "rack-" + std::to_string(side) + "-" + std::to_string(j);
      s.objects.push_back(placed(name, kRackOrange, rack.frame, still(m)));
      s.objects.push_back(placed(name + "-loads", kWood, rack.loads, still(m)));
    }
  }

  s.sky.sun_direction = {0.35f, 0.85f, 0.25f};
  s.sky.sun_irradiance = {3.0f, 2.9f, 2.6f};
  s.ambient = {0.3f, 0.31f, 0.34f};
  s.ao_distance = 1.0f;
  s.fps = 24;
  s.frame_count = 24;
  // The middle of the central aisle at eye height: 12 m x 2 m, 1.6 .. 1.8 m high.
  s.default_rig = box_rig({0, 1.7, 0}, {6, 0.1, 1});
  // A walk along the central aisle, the gaze sweeping from one row of machines to the other.
  s.validation_path = [](uint32_t frames, double fps, uint32_t w, uint32_t h) {
    capture::EyePath path;
    path.width = w, path.height = h;
    for (uint32_t f = 0; f < frames; ++f) {
      const double u = frames > 1 ? static_cast<double>(f) / (frames - 1) : 0.5;
      // Inside the region and away from its viewpoints (the centre is passed 0.36 m aside).
      const glm::dvec3 p(-5 + 10 * u, 1.7, 0.5 * std::sin(kTau * u + 0.8));
      const double yaw = 0.7 * std::sin(kTau * u + 0.5);
      path.poses.push_back(
          look_at_pose(f / fps, p, p + glm::dvec3(std::cos(yaw), -0.12, std::sin(yaw)), 70));
    }
    return path;
  };
  s.description = "a machine hall of " + std::to_string(std::size(kRows) * kMachinesPerRow) +
                  " machines built from instanced CAD parts (gears, threaded studs, finned "
                  "motors, bent pipes), conveyors and racks, seen from an aisle at eye height: " +
                  procedural::with_thousands(s.triangle_count()) + " triangles";
  return s;
}

}  // namespace calf::samples
