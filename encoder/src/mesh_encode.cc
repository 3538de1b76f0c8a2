// The mesh track encoder: plan, independent parts, ordered assembly (rules in mesh_encode.h).
#include "calf/encoder/mesh_encode.h"

#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <string>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "calf/encoder/sphere_mesh.h"
#include "calf/format/clip_metadata.h"
#include "calf/format/coordinates.h"
#include "calf/format/files.h"
#include "calf/format/version.h"

namespace calf::encoder {
namespace {

using container::cat;
using container::ChunkKeys;
using container::MeshStream;
using container::StoredChunk;

Status input_error(const std::string& message) {
  return Status(ErrorId::kEncoderInput, message);
}

// Everything decided before any chunk is coded.
struct Plan {
  container::MeshTrackHeader header;
  mesh::IndexChunk index;
  std::vector<uint32_t> prototype_mesh;  // scene mesh of each prototype
  std::vector<MeshPrototypeArrays> prototypes;
  std::vector<mesh::Visibility> visibility;  // per kept object
};

// The transforms an object stores: one identity for none, one for frame_count equal ones.
std::vector<mesh::Transform> stored_transforms(const capture::SceneObject& o) {
  if (o.transforms.empty()) return {capture::kSceneIdentity};
  for (const auto& t : o.transforms) {
    if (t != o.transforms[0]) return {o.transforms.begin(), o.transforms.end()};
  }
  return {o.transforms[0]};
}

Expected<Plan> make_plan(const capture::SceneFile& scene,
                         const std::vector<std::vector<uint32_t>>* visible,
                         const MeshEncodeOptions& options) {
  CALF_RETURN_IF_ERROR(validate_scene_file(scene));
  if (visible && visible->size() != scene.objects.size()) {
    return input_error(cat("the visible set has ", visible->size(), " lists for ",
                           scene.objects.size(), " scene objects"));
  }
  if (scene.materials.size() > mesh::kMaxMaterials || scene.meshes.size() > mesh::kMaxPrototypes ||
      scene.objects.size() > mesh::kMaxObjects) {
    return Status(ErrorId::kMeshLimit,
                  "the scene has more materials, meshes or objects than a "
                  "mesh track holds (SPEC §11.4)");
  }
  Plan plan;
  auto& h = plan.header;
  h.frame_count = scene.frame_count;
  mesh_fps_fraction(scene.fps, &h.fps_numerator, &h.fps_denominator);
  h.segment_count = options.segment_count;
  h.flags = visible ? mesh::kHeaderVisibleSet : 0;
  auto& x = plan.index;
  const Box3& box = scene.view_volume;
  x.view_min[0] = box.min.x, x.view_min[1] = box.min.y, x.view_min[2] = box.min.z;
  x.view_max[0] = box.max.x, x.view_max[1] = box.max.y, x.view_max[2] = box.max.z;
  for (const auto& m : scene.materials) {
    mesh::MaterialRecord r;
    for (int c = 0; c < 3; ++c) {
      r.base_colour[c] = m.base_color[c];
      r.emission[c] = m.emission[c];
    }
    x.materials.push_back(r);
    x.material_textures.push_back(m.base_color_texture);
  }
  // Textures (layout 2): every scene texture, in scene order, with its pixels.
  for (size_t t = 0; t < scene.textures.size(); ++t) {
    const auto& st = scene.textures[t];
    if (st.width == 0 || st.height == 0 || st.width > mesh::kMaxTextureSize ||
        st.height > mesh::kMaxTextureSize || st.rgba.size() != size_t{4} * st.width * st.height) {
      return input_error(cat("scene texture ", t, " '", st.path, "': ", st.width, " x ", st.height,
                             " with ", st.rgba.size(),
                             " bytes of pixels (not loaded, or outside 1 .. 16384 per side)"));
    }
    mesh::TextureRecord r;
    r.width = st.width;
    r.height = st.height;
    x.textures.push_back(r);
  }
  // Scene meshes to prototypes: only those a kept object uses, in mesh order.
  std::vector<uint32_t> mesh_triangles(scene.meshes.size());
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const uint64_t t = scene.meshes[m].triangle_count() +
                       uint64_t{kSphereTriangles} * scene.meshes[m].spheres.size();
    if (t > UINT32_MAX) return input_error(cat("scene mesh ", m, " has ", t, " triangles"));
    mesh_triangles[m] = static_cast<uint32_t>(t);
  }
  std::vector<bool> kept(scene.objects.size(), true), used(scene.meshes.size(), false);
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    if (visible) {
      const auto& list = (*visible)[o];
      const uint32_t t = mesh_triangles[scene.objects[o].mesh];
      for (size_t i = 0; i < list.size(); ++i) {
        if (list[i] >= t || (i && list[i] <= list[i - 1])) {
          return input_error(cat("visible set of object ", o, ": entry ", i, " (triangle ", list[i],
                                 ") is not increasing or not below its mesh's ", t, " triangles"));
        }
      }
      kept[o] = !list.empty();
    }
    if (kept[o]) used[scene.objects[o].mesh] = true;
  }
  std::vector<uint32_t> prototype_of(scene.meshes.size(), UINT32_MAX);
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    if (!used[m]) continue;
    prototype_of[m] = static_cast<uint32_t>(plan.prototype_mesh.size());
    plan.prototype_mesh.push_back(static_cast<uint32_t>(m));
  }
  plan.prototypes.resize(plan.prototype_mesh.size());
  std::map<uint64_t, std::vector<uint32_t>> by_triangles;  // hash of the indices -> prototypes
  // The prototypes' arrays are built here already (in parallel by the caller's arena would gain
  // little: building is a copy; coding and compression are the parallel part).
  for (size_t p = 0; p < plan.prototype_mesh.size(); ++p) {
    const uint32_t m = plan.prototype_mesh[p];
    Expected<MeshPrototypeArrays> a = prototype_arrays(scene.meshes[m]);
    if (!a.ok()) return std::move(a).status().with_context(cat("scene mesh ", m));
    plan.prototypes[p] = std::move(*a);
    // Identical triangles (indices and triangle materials) are stored once: the first prototype
    // holding them keeps the chunk (SPEC §11.4.2 triangles_of).
    auto& record = plan.prototypes[p].record;
    record.triangles_of = static_cast<uint32_t>(p);
    const auto& tri = plan.prototypes[p].triangles;
    const uint64_t key = container::hash64(std::span<const uint8_t>(
        reinterpret_cast<const uint8_t*>(tri.indices.data()), 4 * tri.indices.size()));
    for (uint32_t q : by_triangles[key]) {
      const auto& other = plan.prototypes[q].triangles;
      if (other.indices == tri.indices && other.triangle_materials == tri.triangle_materials) {
        record.triangles_of = q;
        break;
      }
    }
    if (record.triangles_of == p) by_triangles[key].push_back(static_cast<uint32_t>(p));
    x.prototypes.push_back(record);
    h.vertex_count += plan.prototypes[p].record.vertex_count;
  }
  // Layout 1 unless something needs layout 2 (mesh_layout.h kLayoutVersionUntextured).
  bool textured = !x.textures.empty();
  for (const auto& p : x.prototypes) textured = textured || (p.flags & mesh::kHasUvs) != 0;
  for (uint32_t t : x.material_textures) textured = textured || t != mesh::kNoTexture;
  x.layout_version = textured ? mesh::kLayoutVersion : mesh::kLayoutVersionUntextured;
  if (!textured) x.material_textures.clear();
  for (size_t o = 0; o < scene.objects.size(); ++o) {
    if (!kept[o]) continue;
    const auto& so = scene.objects[o];
    mesh::ObjectRecord r;
    r.source_object = static_cast<uint32_t>(o);
    r.prototype = prototype_of[so.mesh];
    r.material = so.material;
    mesh::Visibility v;
    v.transforms = stored_transforms(so);
    r.transform_count = static_cast<uint32_t>(v.transforms.size());
    const uint32_t t = mesh_triangles[so.mesh];
    if (visible && (*visible)[o].size() < t) {
      r.flags = 0;
      v.triangles = (*visible)[o];
    }
    r.triangle_count = visible ? static_cast<uint32_t>((*visible)[o].size()) : t;
    h.triangle_count += r.triangle_count;
    if (mesh::visibility_chunk_min_size(r) + 8 * uint64_t{r.triangle_count} >
        container::kMaxRawChunkSize) {
      return Status(ErrorId::kMeshLimit, cat("object ", o,
                                             ": its visibility chunk would exceed "
                                             "the container's chunk limit"));
    }
    x.objects.push_back(r);
    plan.visibility.push_back(std::move(v));
  }
  return plan;
}

// One chunk ready to add, or the error of the task that made it.
struct Part {
  Status status;
  std::vector<std::pair<ChunkKeys, StoredChunk>> chunks;
};

Status add_part(container::Writer* writer, uint16_t track, Part& part, MeshEncodeStats& s) {
  CALF_RETURN_IF_ERROR(part.status);
  for (auto& [keys, chunk] : part.chunks) {
    keys.track = track;
    MeshStreamBytes* b =
        keys.stream == static_cast<uint16_t>(MeshStream::kIndex)       ? &s.index
        : keys.stream == static_cast<uint16_t>(MeshStream::kVertices)  ? &s.vertices_stream
        : keys.stream == static_cast<uint16_t>(MeshStream::kTriangles) ? &s.triangles_stream
        : keys.stream == static_cast<uint16_t>(MeshStream::kTextures)  ? &s.textures
                                                                       : &s.visibility;
    b->raw += chunk.raw_size;
    b->stored += chunk.bytes.size();
    b->chunks += 1;
    CALF_RETURN_IF_ERROR(writer->add_stored_chunk(keys, chunk).status());
  }
  return Status::Ok();
}

Status compress_into(Part& part, MeshStream stream, uint32_t region, std::span<const uint8_t> raw,
                     const MeshEncodeOptions& options, const std::string& what) {
  if (raw.size() > container::kMaxRawChunkSize)
    return Status(ErrorId::kMeshLimit, cat(what, ": ", raw.size(),
                                           " bytes exceed the "
                                           "container's chunk limit"));
  CALF_ASSIGN_OR_RETURN(StoredChunk c,
                        container::compress_chunk(raw, options.supercompression, options.levels));
  ChunkKeys keys;
  keys.stream = static_cast<uint16_t>(stream);
  keys.region = region;
  part.chunks.emplace_back(keys, std::move(c));
  return Status::Ok();
}

// The same for a chunk the layout encodes first; its raw bytes are released on return.
Status compress_into(Part& part, MeshStream stream, uint32_t region,
                     Expected<std::vector<uint8_t>> raw, const MeshEncodeOptions& options,
                     const std::string& what) {
  if (!raw.ok()) {
    const Status& st = raw.status();
    // A value the layout refuses came from the scene (e.g. a vertex beyond the coordinate bound).
    return st.id() == ErrorId::kContainerWriterMisuse ? input_error(what + ": " + st.message())
                                                      : st;
  }
  return compress_into(part, stream, region, std::span<const uint8_t>(*raw), options, what);
}

uint64_t plain_bytes(const Plan& plan) {
  uint64_t n = 0;
  for (const auto& p : plan.prototypes) {
    n += 4 * (p.vertices.positions.size() + p.vertices.normals.size() + p.vertices.colours.size() +
              p.vertices.state_times.size() + p.vertices.state_positions.size() +
              p.triangles.indices.size() + p.triangles.triangle_materials.size());
  }
  for (const auto& p : plan.prototypes) n += 4 * p.vertices.uvs.size();
  for (const auto& v : plan.visibility) n += 48 * v.transforms.size() + 4 * v.triangles.size();
  for (const auto& t : plan.index.textures) n += mesh::texture_chunk_size(t);
  return n;
}

}  // namespace

void mesh_fps_fraction(double fps, uint32_t* numerator, uint32_t* denominator) {
  const auto whole = [](double v) { return std::fabs(v - std::round(v)) <= 1e-9 * v; };
  if (whole(fps)) {
    *numerator = static_cast<uint32_t>(std::round(fps));
    *denominator = 1;
  } else if (whole(fps * 1001.0 / 1000.0)) {
    *numerator = static_cast<uint32_t>(std::round(fps * 1001.0 / 1000.0)) * 1000;
    *denominator = 1001;
  } else {
    uint64_t n = static_cast<uint64_t>(std::llround(fps * 1e6)), d = 1000000;
    const uint64_t g = std::gcd(n, d);
    *numerator = static_cast<uint32_t>(n / g);
    *denominator = static_cast<uint32_t>(d / g);
  }
}

Expected<MeshPrototypeArrays> prototype_arrays(const capture::SceneMesh& m) {
  MeshPrototypeArrays out;
  const uint64_t v = m.vertex_count() + uint64_t{kSphereVertices} * m.spheres.size();
  const uint64_t t = m.triangle_count() + uint64_t{kSphereTriangles} * m.spheres.size();
  if (v > UINT32_MAX || t > UINT32_MAX)
    return input_error(cat(v, " vertices and ", t, " triangles exceed u32 counts"));
  if (m.state_times.size() > mesh::kMaxStates)
    return Status(ErrorId::kMeshLimit, cat(m.state_times.size(), " vertex states"));
  auto& r = out.record;
  r.vertex_count = static_cast<uint32_t>(v);
  r.triangle_count = static_cast<uint32_t>(t);
  r.state_count = static_cast<uint32_t>(m.state_times.size());
  const bool normals = !m.normals.empty() || (m.indices.empty() && !m.spheres.empty());
  r.flags = (normals ? mesh::kHasNormals : 0u) | (m.colors.empty() ? 0u : mesh::kHasColours) |
            (m.triangle_materials.empty() ? 0u : mesh::kHasTriangleMaterials) |
            (m.uvs.empty() ? 0u : mesh::kHasUvs);
  auto& a = out.vertices;
  auto& tri = out.triangles;
  a.positions = m.positions;
  if (normals) a.normals = m.normals;
  a.colours = m.colors;
  tri.indices = m.indices;
  tri.triangle_materials = m.triangle_materials;
  std::vector<float> sphere_positions;
  for (const auto& s : m.spheres) {
    append_sphere_mesh(s.center.data(), s.radius, &sphere_positions, normals ? &a.normals : nullptr,
                       &tri.indices);
  }
  // Sphere triangles were numbered from 0 in sphere_positions: shift them after the mesh's own
  // vertices.
  const uint32_t base = static_cast<uint32_t>(m.vertex_count());
  for (size_t i = m.indices.size(); i < tri.indices.size(); ++i) tri.indices[i] += base;
  a.positions.insert(a.positions.end(), sphere_positions.begin(), sphere_positions.end());
  if (!m.colors.empty()) a.colours.resize(3 * v, 1.0f);
  // A sphere's vertices get UV (0, 0) (SPEC §11.4.3: spheres are not textured by the tracer).
  a.uvs = m.uvs;
  if (!m.uvs.empty()) a.uvs.resize(2 * v, 0.0f);
  if (!m.triangle_materials.empty()) tri.triangle_materials.resize(t, mesh::kObjectMaterial);
  a.state_times = m.state_times;
  if (!m.state_times.empty()) {
    // Spheres do not follow states (SCENE.md): their vertices are held in every state.
    const size_t own = m.positions.size();
    a.state_positions.reserve(3 * v * m.state_times.size());
    for (size_t k = 0; k < m.state_times.size(); ++k) {
      const float* state = m.state_positions.data() + k * own;
      a.state_positions.insert(a.state_positions.end(), state, state + own);
      a.state_positions.insert(a.state_positions.end(), sphere_positions.begin(),
                               sphere_positions.end());
    }
  }
  return out;
}

Status check_mesh_scene(const capture::SceneFile& scene) {
  std::vector<bool> used(scene.meshes.size(), false);
  for (const capture::SceneObject& o : scene.objects) {
    if (o.mesh < used.size()) used[o.mesh] = true;
  }
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    if (!used[m]) continue;
    const std::string what = cat("scene mesh ", m);
    Expected<MeshPrototypeArrays> a = prototype_arrays(scene.meshes[m]);
    if (!a.ok()) return std::move(a).status().with_context(what);
    // The layout's own checks, as compress_into() reports them.
    Expected<std::vector<uint8_t>> raw = mesh::encode_vertices(a->record, a->vertices);
    if (!raw.ok()) {
      return raw.status().id() == ErrorId::kContainerWriterMisuse
                 ? input_error(what + ": " + raw.status().message())
                 : raw.status();
    }
  }
  return Status::Ok();
}

Status encode_mesh_track(const capture::SceneFile& scene,
                         const std::vector<std::vector<uint32_t>>* visible,
                         const MeshEncodeOptions& options, container::Writer* writer,
                         MeshEncodeStats* stats) {
  if (options.threads > 256)
    return Status(ErrorId::kEncoderOption, cat("threads ", options.threads, " is above 256"));
  if (static_cast<uint16_t>(options.supercompression) >= container::kCompressionCount)
    return Status(ErrorId::kEncoderOption, "unknown supercompression");
  CALF_ASSIGN_OR_RETURN(Plan plan, make_plan(scene, visible, options));
  auto& x = plan.index;
  const size_t np = x.prototypes.size(), no = x.objects.size(), nt = x.textures.size();

  // Independent parts: prototypes, objects, then textures, each coded into its own slot. A
  // texture is coded both ways (SPEC §11.4.6) and keeps the one that stores fewer bytes after
  // supercompression (MED on a tie); the index, written after, records the choice.
  std::vector<Part> parts(np + no + nt);
  std::vector<uint32_t> codings(nt, mesh::kTextureSrgba8Med);
  tbb::task_arena arena(options.threads == 0 ? tbb::task_arena::automatic
                                             : static_cast<int>(options.threads));
  arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, np + no + nt, 1),
        [&](const tbb::blocked_range<size_t>& range) {
          for (size_t i = range.begin(); i < range.end(); ++i) {
            Part& part = parts[i];
            if (i < np) {
              const auto& p = plan.prototypes[i];
              const std::string what = cat("scene mesh ", plan.prototype_mesh[i]);
              const uint32_t region = static_cast<uint32_t>(i);
              part.status =
                  compress_into(part, MeshStream::kVertices, region,
                                mesh::encode_vertices(p.record, p.vertices), options, what);
              if (part.status.ok() && p.record.triangles_of == i) {
                part.status =
                    compress_into(part, MeshStream::kTriangles, region,
                                  mesh::encode_triangles(p.record, p.triangles), options, what);
              }
            } else if (i >= np + no) {
              const size_t t = i - np - no;
              const auto& st = scene.textures[t];
              const mesh::TextureTexels texels{st.width, st.height, st.rgba};
              Part ways[2];
              mesh::TextureRecord r = x.textures[t];
              r.coding = mesh::kTextureSrgba8Med;
              ways[0].status =
                  compress_into(ways[0], MeshStream::kTextures, static_cast<uint32_t>(t),
                                mesh::encode_texture(r, texels), options, cat("scene texture ", t));
              // The plain coding is the texels themselves (SPEC §11.4.6): compressed from the
              // scene's buffer, not from a copy of it.
              if (ways[0].status.ok()) {
                ways[1].status = compress_into(
                    ways[1], MeshStream::kTextures, static_cast<uint32_t>(t),
                    std::span<const uint8_t>(st.rgba), options, cat("scene texture ", t));
              }
              const bool plain =
                  ways[0].status.ok() && ways[1].status.ok() &&
                  ways[1].chunks[0].second.bytes.size() < ways[0].chunks[0].second.bytes.size();
              codings[t] = plain ? mesh::kTextureSrgba8Plain : mesh::kTextureSrgba8Med;
              part = std::move(ways[plain ? 1 : 0]);
            } else {
              const size_t o = i - np;
              const auto& r = x.objects[o];
              part.status = compress_into(
                  part, MeshStream::kVisibility, static_cast<uint32_t>(o),
                  mesh::encode_visibility(r, x.prototypes[r.prototype], plan.visibility[o]),
                  options, cat("scene object ", r.source_object));
            }
          }
        });
  });

  for (size_t t = 0; t < nt; ++t) x.textures[t].coding = codings[t];
  Part index_part;
  CALF_RETURN_IF_ERROR(compress_into(index_part, MeshStream::kIndex, 0,
                                     mesh::serialize_index(x, plan.header.frame_count), options,
                                     "mesh index"));
  CALF_ASSIGN_OR_RETURN(const uint16_t track, writer->add_track(plan.header));
  MeshEncodeStats s;
  s.materials = static_cast<uint32_t>(x.materials.size());
  s.prototypes = static_cast<uint32_t>(np);
  s.objects = static_cast<uint32_t>(no);
  s.vertices = plan.header.vertex_count;
  s.triangles = plan.header.triangle_count;
  for (const auto& o : scene.objects) {
    const auto& m = scene.meshes[o.mesh];
    s.scene_triangles += m.triangle_count() + uint64_t{kSphereTriangles} * m.spheres.size();
  }
  s.plain_bytes = plain_bytes(plan);
  CALF_RETURN_IF_ERROR(add_part(writer, track, index_part, s));
  for (Part& part : parts) CALF_RETURN_IF_ERROR(add_part(writer, track, part, s));
  if (stats) *stats = s;
  return Status::Ok();
}

Expected<MeshEncodeStats> encode_mesh_file(const std::filesystem::path& scene_dir,
                                           const std::string& out_path,
                                           const MeshEncodeOptions& options) {
  CALF_ASSIGN_OR_RETURN(const capture::SceneFile scene,
                        capture::read_scene_file(scene_dir, options.max_image_pixels));
  return encode_mesh_file(scene, scene_dir, out_path, nullptr, options);
}

Expected<MeshEncodeStats> encode_mesh_file(
    const capture::SceneFile& scene, const std::filesystem::path& scene_dir,
    const std::string& out_path, const std::vector<std::vector<uint32_t>>* visible,
    const MeshEncodeOptions& options,
    const std::vector<std::pair<std::string, std::string>>& extra_metadata,
    const std::vector<std::string>& more_inputs,
    const std::function<Status(container::Writer*)>& more_tracks) {
  // The output must not be one of the inputs (CALF-E007).
  std::vector<std::string> inputs = {scene_dir.string(),
                                     (scene_dir / capture::kSceneManifestFileName).string(),
                                     (scene_dir / capture::kSceneBufferFileName).string()};
  for (const auto& t : scene.textures) inputs.push_back((scene_dir / t.path).string());
  inputs.insert(inputs.end(), more_inputs.begin(), more_inputs.end());
  CALF_RETURN_IF_ERROR(files::check_output_not_input(out_path, inputs));
  CALF_ASSIGN_OR_RETURN(container::Writer writer,
                        container::Writer::create(out_path, options.levels));
  MeshEncodeStats stats;
  CALF_RETURN_IF_ERROR(encode_mesh_track(scene, visible, options, &writer, &stats));
  if (more_tracks) CALF_RETURN_IF_ERROR(more_tracks(&writer));
  CALF_RETURN_IF_ERROR(
      writer.set_metadata("encoder", std::string("calf-encode ") + kVersionString));
  if (!scene.name.empty()) CALF_RETURN_IF_ERROR(writer.set_metadata("source_scene", scene.name));
  CALF_RETURN_IF_ERROR(writer.set_metadata(std::string(container::kViewVolumeKey),
                                           container::format_view_volume(scene.view_volume)));
  for (const auto& [key, value] : extra_metadata)
    CALF_RETURN_IF_ERROR(writer.set_metadata(key, value));
  CALF_RETURN_IF_ERROR(writer.finish());
  return stats;
}

}  // namespace calf::encoder
