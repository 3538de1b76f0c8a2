"""Renders calf capture sets and ground truth with Cycles (format/CAPTURE.md, docs/BLENDER.md).

Everything here runs inside Blender (bpy). Each view-frame is six renders of an upright 90 degree
camera (calf's face order, convention.FACE_CAMERAS) plus six one-sample depth renders through the
pixel centres, read back from uncompressed multilayer EXRs and written as one calf image: colour
scene-linear (the Combined pass, before any view transform), depth radial with sky +inf, faces in
calf's texel order. The manifest is written last, through a temporary file.
"""

import json
import math
import os
import shutil
import sys
import tempfile
import time

import bpy
import mathutils

from . import convention, exr

FILE_PATTERN = "view{view:03}_frame{frame:05}.exr"
GT_PATTERN = "gt_{pose:05}.exr"
NOISE_FLOOR_DIR = "noise-floor"
MAX_FACE_SIZE = 16384   # calf's kMaxFaceSize
MAX_IMAGE_SIDE = 16384  # calf's ground-truth image side limit
HALF_MAX = 65504.0
# Cycles' adaptive sampling (noise threshold; 0 turns it off, so that every pixel gets --samples):
# off for ground truth, whose noise floor must fall as samples rise (docs/BLENDER.md, "Cost and
# quality").
GT_ADAPTIVE_THRESHOLD = 0.0
CAPTURE_ADAPTIVE_THRESHOLD = 0.0


class CaptureError(Exception):
    """One clear line for the user: a calf error id and the message; `usage` errors exit 2."""

    def __init__(self, error_id, message, usage=False):
        super().__init__("%s %s" % (error_id, message))
        self.error_id = error_id
        self.usage = usage


class CaptureOptions:
    """What to capture; every field has the default that cli.py's --help states."""

    def __init__(self):
        self.out = ""
        self.rig = ""             # a calf rig string (calf coordinates), or
        self.collection = ""      # the name of a collection whose empties are the viewpoints
        self.volume_object = ""   # an object whose world bounding box is the view volume, or
        self.volume = None        # ((x0, y0, z0), (x1, y1, z1)) in calf coordinates; else the
        #                           viewpoints' bounding box
        self.frames = None        # (first, last) scene frames, inclusive; None: the scene's range
        self.face_size = 64
        self.samples = 64
        self.seed = 0
        self.clip_start = 0.01
        self.clip_end = 1e5
        self.threads = 0          # 0: Blender's automatic thread count
        self.coverage = False     # also write coverage (a version-2 set) from a 4x finer depth
        self.adaptive_threshold = CAPTURE_ADAPTIVE_THRESHOLD  # 0: Cycles' adaptive sampling off


def _fmt(p):
    return "[%s]" % ", ".join(repr(float(v)) for v in p)


def check_cycles(scene=None):
    """CaptureError E014 unless this Blender can render with Cycles (built with it, and the Cycles
    add-on enabled: the engine can be selected)."""
    if not getattr(bpy.app.build_options, "cycles", False):
        raise CaptureError("CALF-E014", "this Blender (%s) is built without Cycles; the add-on "
                           "renders with Cycles only" % bpy.app.version_string)
    scene = scene or bpy.context.scene
    engine = scene.render.engine
    try:
        scene.render.engine = "CYCLES"
    except TypeError:
        raise CaptureError("CALF-E014", "Cycles is not available in this Blender (%s): enable the "
                           "Cycles add-on (Preferences > Add-ons)" % bpy.app.version_string)
    finally:
        if scene.render.engine != engine:
            scene.render.engine = engine


def check_output_dir(path):
    """Creates `path` and proves it writable (CaptureError E004 otherwise)."""
    try:
        os.makedirs(path, exist_ok=True)
        probe = os.path.join(path, ".calf_capture_probe.tmp")
        with open(probe, "wb") as f:
            f.write(b"calf")
        os.remove(probe)
    except OSError as e:
        raise CaptureError("CALF-E004", "%s: cannot write the output folder: %s" %
                           (path, e.strerror or e))


def write_json_atomically(path, value):
    tmp = path + ".tmp"
    try:
        with open(tmp, "w", encoding="utf-8") as f:
            json.dump(value, f, indent=2)
            f.write("\n")
        os.replace(tmp, path)
    except OSError as e:
        try:
            os.remove(tmp)
        except OSError:
            pass
        raise CaptureError("CALF-E004", "%s: cannot write: %s" % (path, e.strerror or e))


class _Settings:
    """Sets scene attributes for a render and puts every one back afterwards."""

    def __init__(self):
        self._old = []

    def set(self, owner, name, value):
        self._old.append((owner, name, getattr(owner, name)))
        setattr(owner, name, value)

    def restore(self):
        for owner, name, value in reversed(self._old):
            try:
                setattr(owner, name, value)
            except (AttributeError, TypeError, ValueError):
                pass
        self._old = []


class _Renderer:
    """A temporary camera and the render settings the add-on needs; render() returns the colour
    (RGB list) and the planar depth of the camera's W x H image, row 0 at the top."""

    def __init__(self, scene, samples, seed, clip_start, clip_end, threads, adaptive_threshold):
        check_cycles(scene)
        self.scene = scene
        self.samples = samples
        self.seed = seed
        self.settings = _Settings()
        self.tmpdir = tempfile.mkdtemp(prefix="calf_capture_")
        self.camera_data = bpy.data.cameras.new("calf_capture_camera")
        self.camera_data.type = "PERSP"
        self.camera_data.clip_start = clip_start
        self.camera_data.clip_end = clip_end
        self.camera_data.shift_x = self.camera_data.shift_y = 0.0
        self.camera = bpy.data.objects.new("calf_capture_camera", self.camera_data)
        scene.collection.objects.link(self.camera)
        s, r, c = self.settings, scene.render, scene.cycles
        s.set(scene, "camera", self.camera)
        s.set(r, "engine", "CYCLES")
        s.set(c, "device", "CPU")
        s.set(c, "use_denoising", False)
        s.set(c, "use_animated_seed", False)
        # A scene's render time limit would stop a render before its samples: off, so that every
        # face and ground-truth pose gets the samples asked for.
        s.set(c, "time_limit", 0.0)
        # Adaptive sampling stops a pixel once its noise is below the threshold, whatever the
        # samples; with the threshold 0 every pixel gets every sample.
        s.set(c, "use_adaptive_sampling", adaptive_threshold > 0)
        if adaptive_threshold > 0:
            s.set(c, "adaptive_threshold", adaptive_threshold)
            s.set(c, "adaptive_min_samples", 0)  # Cycles' automatic minimum
        s.set(r, "resolution_percentage", 100)
        s.set(r, "pixel_aspect_x", 1.0)
        s.set(r, "pixel_aspect_y", 1.0)
        s.set(r, "use_border", False)
        s.set(r, "film_transparent", False)
        s.set(r, "use_motion_blur", False)
        s.set(r, "use_compositing", False)
        s.set(r, "use_sequencer", False)
        s.set(r, "use_multiview", False)
        s.set(r, "use_single_layer", True)
        s.set(r, "use_persistent_data", True)
        s.set(r, "use_file_extension", False)
        s.set(r, "threads_mode", "FIXED" if threads else "AUTO")
        if threads:
            s.set(r, "threads", threads)
        # The Combined pass of a multilayer EXR is scene-linear whatever the view transform; the
        # transform is set to Standard without look or exposure all the same, so that nothing the
        # scene's colour management does can reach the numbers.
        vs = scene.view_settings
        s.set(vs, "view_transform", "Standard")
        s.set(vs, "look", "None")
        s.set(vs, "exposure", 0.0)
        s.set(vs, "gamma", 1.0)
        s.set(vs, "use_curve_mapping", False)
        f = r.image_settings
        s.set(f, "file_format", "OPEN_EXR_MULTILAYER")
        s.set(f, "color_depth", "32")
        s.set(f, "exr_codec", "NONE")
        s.set(f, "color_mode", "RGBA")
        s.set(scene.view_layers[0] if bpy.context.view_layer is None else bpy.context.view_layer,
              "use_pass_z", True)
        self.view_layer = bpy.context.view_layer.name if bpy.context.view_layer else \
            scene.view_layers[0].name
        s.set(r, "filepath", os.path.join(self.tmpdir, "face.exr"))

    def close(self):
        self.settings.restore()
        bpy.data.objects.remove(self.camera)
        bpy.data.cameras.remove(self.camera_data)
        shutil.rmtree(self.tmpdir, ignore_errors=True)

    def _render_once(self, width, height, samples, filter_width, seed):
        r, c = self.scene.render, self.scene.cycles
        r.resolution_x, r.resolution_y = width, height
        c.samples = samples
        c.filter_width = filter_width
        c.seed = seed
        with _quiet():
            bpy.ops.render.render(write_still=True)
        w, h, channels = exr.read_exr(r.filepath)
        os.remove(r.filepath)
        return channels

    def _channel(self, channels, pass_name, channel):
        key = "%s.%s.%s" % (self.view_layer, pass_name, channel)
        if key not in channels:
            matches = [k for k in channels if k.endswith(".%s.%s" % (pass_name, channel))]
            if not matches:
                raise CaptureError("CALF-E005", "the render has no %s.%s channel (has %s)" %
                                   (pass_name, channel, ", ".join(sorted(channels))))
            key = matches[0]
        return channels[key]

    def depth(self, matrix, fov_y, width, height):
        """Only the planar depth through the pixel centres of a W x H image."""
        self.camera_data.sensor_fit = "VERTICAL"
        self.camera_data.angle_y = fov_y
        self.camera.matrix_world = matrix
        channels = self._render_once(width, height, 1, 0.01, self.seed)
        return list(self._channel(channels, "Depth", "Z"))

    def render(self, matrix, fov_y, width, height, seed_offset=0):
        cam = self.camera_data
        cam.sensor_fit = "VERTICAL"
        cam.angle_y = fov_y
        self.camera.matrix_world = matrix
        colour = self._render_once(width, height, self.samples, 1.5, self.seed + seed_offset)
        rgb = [0.0] * (3 * width * height)
        for k, name in enumerate("RGB"):
            values = self._channel(colour, "Combined", name)
            rgb[k::3] = [v if v < HALF_MAX else HALF_MAX if v == v else 0.0 for v in
                         (max(0.0, x) if x == x else 0.0 for x in values)]
        # Depth through the pixel centres: one sample with the narrowest pixel filter (the
        # colour render's depth pass comes from jittered samples).
        depth = self._render_once(width, height, 1, 0.01, self.seed + seed_offset)
        return rgb, list(self._channel(depth, "Depth", "Z"))


class _quiet:
    """Sends what Blender prints while rendering (a line per tile and sample) to /dev/null, so
    that the add-on's own progress lines stay readable."""

    def __enter__(self):
        sys.stdout.flush()
        self.saved = os.dup(1)
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, 1)
        os.close(devnull)

    def __exit__(self, *exc):
        sys.stdout.flush()
        os.dup2(self.saved, 1)
        os.close(self.saved)
        return False


def _matrix(position_calf, forward, up):
    rot = convention.camera_rotation(forward, up)
    m = mathutils.Matrix(rot).to_4x4()
    m.translation = convention.blender_from_calf(position_calf)
    return m


def _set_time(scene, frame_float):
    whole = math.floor(frame_float)
    scene.frame_set(int(whole), subframe=frame_float - whole)


def scene_fps(scene):
    return scene.render.fps / scene.render.fps_base


def viewpoints(scene, options):
    """[(name, calf position)] and the default view volume (the viewpoints' box)."""
    if options.rig:
        try:
            return convention.parse_rig(options.rig)
        except ValueError as e:
            raise CaptureError("CALF-E006", "--rig: %s" % e, usage=True)
    if not options.collection:
        raise CaptureError("CALF-E006", "give the viewpoints: --rig STRING or --collection NAME",
                           usage=True)
    coll = bpy.data.collections.get(options.collection)
    if coll is None:
        raise CaptureError("CALF-E006", "--collection: no collection named '%s'" %
                           options.collection, usage=True)
    empties = sorted((o for o in coll.all_objects if o.type == "EMPTY"), key=lambda o: o.name)
    if not empties:
        raise CaptureError("CALF-E006", "--collection '%s' holds no empties (one empty per "
                           "viewpoint)" % options.collection, usage=True)
    views = [(o.name[:200], convention.calf_from_blender(tuple(o.matrix_world.translation)))
             for o in empties]
    lo = tuple(min(p[k] for _, p in views) for k in range(3))
    hi = tuple(max(p[k] for _, p in views) for k in range(3))
    return views, (lo, hi)


def view_volume(scene, options, default):
    if options.volume_object:
        obj = bpy.data.objects.get(options.volume_object)
        if obj is None:
            raise CaptureError("CALF-E006", "--volume-object: no object named '%s'" %
                               options.volume_object, usage=True)
        corners = [convention.calf_from_blender(tuple(obj.matrix_world @ mathutils.Vector(c)))
                   for c in obj.bound_box]
        return (tuple(min(c[k] for c in corners) for k in range(3)),
                tuple(max(c[k] for c in corners) for k in range(3)))
    if options.volume:
        lo, hi = options.volume
        if not all(lo[k] <= hi[k] for k in range(3)):
            raise CaptureError("CALF-E006", "--volume: min must not exceed max on any axis",
                               usage=True)
        return options.volume
    return default


def frame_range(scene, options):
    first, last = options.frames if options.frames else (scene.frame_start, scene.frame_end)
    if last < first:
        raise CaptureError("CALF-E006", "the frame range %d-%d is empty" % (first, last),
                           usage=True)
    if last - first + 1 > 1000000:
        raise CaptureError("CALF-E006", "%d frames: calf takes at most 1000000" %
                           (last - first + 1), usage=True)
    return first, last


def check_adaptive_threshold(value):
    """CaptureError E006 unless 0 <= value <= 1 (Cycles' range; 0 turns adaptive sampling off)."""
    if not 0.0 <= value <= 1.0:
        raise CaptureError("CALF-E006", "--adaptive-threshold %r is outside 0..1 (0: adaptive "
                           "sampling off)" % value, usage=True)


def check_size(name, value, limit):
    if not 1 <= value <= limit:
        raise CaptureError("CALF-E006", "%s %d is outside calf's range 1..%d" %
                           (name, value, limit), usage=True)


class Progress:
    """One line per unit of work with the elapsed time and an ETA from the mean so far."""

    def __init__(self, total, log):
        self.total, self.done, self.start, self.log = total, 0, time.monotonic(), log

    def step(self, what):
        self.done += 1
        elapsed = time.monotonic() - self.start
        eta = elapsed / self.done * (self.total - self.done)
        self.log("calf-blender: %s done (%d/%d), %.1f s elapsed, %.2f s per item, ETA %.1f s" %
                 (what, self.done, self.total, elapsed, elapsed / self.done, eta))


def capture_set(scene, options, log=print):
    """Renders the capture set `options` describes into options.out; returns the manifest."""
    check_cycles(scene)
    check_size("face size", options.face_size, MAX_FACE_SIZE)
    if options.samples < 1:
        raise CaptureError("CALF-E006", "--samples must be >= 1", usage=True)
    check_adaptive_threshold(options.adaptive_threshold)
    first, last = frame_range(scene, options)
    views, box = viewpoints(scene, options)
    if len(views) > 4096:
        raise CaptureError("CALF-E006", "%d viewpoints: calf takes at most 4096" % len(views),
                           usage=True)
    volume = view_volume(scene, options, box)
    check_output_dir(options.out)
    manifest_path = os.path.join(options.out, "manifest.json")
    if os.path.lexists(manifest_path):
        os.remove(manifest_path)  # a set being rewritten never looks complete
    n = options.face_size
    manifest = {
        "format": "calf-capture-set", "version": 2 if options.coverage else 1,
        "scene": scene.name, "generator": "calf_capture (Blender %s)" % bpy.app.version_string,
        "frame_count": last - first + 1, "fps": scene_fps(scene), "face_size": n,
        "file_pattern": FILE_PATTERN,
        **({"coverage": True} if options.coverage else {}),
        "view_volume": {"min": list(volume[0]), "max": list(volume[1])},
        "viewpoints": [{"name": name, "position": list(p)} for name, p in views],
    }
    renderer = _Renderer(scene, options.samples, options.seed, options.clip_start,
                         options.clip_end, options.threads, options.adaptive_threshold)
    progress = Progress(len(views) * (last - first + 1), log)
    try:
        for frame in range(first, last + 1):
            scene.frame_set(frame)
            for v, (name, position) in enumerate(views):
                rgb_faces, depth_faces = [], []
                cover = ([], [], [])
                for forward, up in convention.FACE_CAMERAS:
                    m = _matrix(position, forward, up)
                    rgb, planar = renderer.render(m, math.pi / 2, n, n)
                    rgb_faces += convention.texels_from_upright(rgb, n, 3)
                    depth = convention.texels_from_upright(
                        convention.radial_from_planar(planar, n), n)
                    depth_faces += depth
                    if options.coverage:
                        fn = convention.COVERAGE_CELLS * n
                        fine = convention.texels_from_upright(convention.radial_from_planar(
                            renderer.depth(m, math.pi / 2, fn, fn), fn), fn)
                        for c, values in enumerate(convention.coverage_from_fine(depth, fine, n)):
                            cover[c].extend(values)
                path = os.path.join(options.out, FILE_PATTERN.format(view=v, frame=frame - first))
                channels = {"R": ("HALF", rgb_faces[0::3]), "G": ("HALF", rgb_faces[1::3]),
                            "B": ("HALF", rgb_faces[2::3]), "Z": ("FLOAT", depth_faces)}
                if options.coverage:
                    channels.update({"coverage.near": ("HALF", cover[0]),
                                     "coverage.far": ("HALF", cover[1]),
                                     "coverage.mask": ("FLOAT", cover[2])})
                try:
                    exr.write_exr(path, n, 6 * n, channels)
                except OSError as e:
                    raise CaptureError("CALF-E004", "%s: cannot write: %s" %
                                       (path, e.strerror or e))
                progress.step("view %d/%d (%s) frame %d/%d" %
                              (v + 1, len(views), name, frame - first + 1, last - first + 1))
    finally:
        renderer.close()
    write_json_atomically(manifest_path, manifest)
    return manifest


def _pose_frame(pose):
    """(forward, up) of an eye-path pose, in calf coordinates."""
    if "orientation" in pose:
        q = mathutils.Quaternion(pose["orientation"])
        return tuple(q @ mathutils.Vector((0, 0, -1))), tuple(q @ mathutils.Vector((0, 1, 0)))
    p = pose["position"]
    if "forward" in pose:
        f = pose["forward"]
    else:
        f = [pose["look_at"][k] - p[k] for k in range(3)]
    return tuple(f), tuple(pose.get("up", (0, 1, 0)))


def read_eye_path(path):
    try:
        with open(path, encoding="utf-8") as f:
            path_json = json.load(f)
    except OSError as e:
        raise CaptureError("CALF-E002", "%s: %s" % (path, e.strerror or e))
    except ValueError as e:
        raise CaptureError("CALF-E130", "%s: not JSON: %s" % (path, e))
    if path_json.get("format") != "calf-eye-path" or not path_json.get("poses"):
        raise CaptureError("CALF-E142", "%s: not a calf eye path with poses" % path)
    return path_json


def eye_path_from_camera(scene, camera_name, width, height, first, last):
    """A calf eye path of the named camera's animation over scene frames first..last, one pose a
    frame at time (frame - first) / fps."""
    cam = bpy.data.objects.get(camera_name)
    if cam is None or cam.type != "CAMERA" or cam.data.type != "PERSP":
        raise CaptureError("CALF-E006", "--camera: no perspective camera named '%s'" %
                           camera_name, usage=True)
    d = cam.data
    fit = d.sensor_fit
    if fit == "AUTO":
        fit = "HORIZONTAL" if width >= height else "VERTICAL"
        sensor = d.sensor_width
    else:
        sensor = d.sensor_width if fit == "HORIZONTAL" else d.sensor_height
    half = sensor / (2.0 * d.lens)
    half_h = half * height / width if fit == "HORIZONTAL" else half
    fov_y = math.degrees(2.0 * math.atan(half_h))
    poses = []
    for frame in range(first, last + 1):
        scene.frame_set(frame)
        m = cam.matrix_world
        rot = m.to_3x3().normalized()
        forward = convention.calf_from_blender(tuple(rot @ mathutils.Vector((0, 0, -1))))
        up = convention.calf_from_blender(tuple(rot @ mathutils.Vector((0, 1, 0))))
        poses.append({"time": (frame - first) / scene_fps(scene),
                      "position": list(convention.calf_from_blender(tuple(m.translation))),
                      "forward": list(forward), "up": list(up)})
    return {"format": "calf-eye-path", "version": 1, "width": width, "height": height,
            "fov_y_degrees": fov_y, "poses": poses}


def _render_path(scene, renderer, eye_path, out_dir, first, seed_offset, progress, label):
    width, height = eye_path["width"], eye_path["height"]
    fps = scene_fps(scene)
    for p, pose in enumerate(eye_path["poses"]):
        fov_y = math.radians(pose.get("fov_y_degrees", eye_path.get("fov_y_degrees", 60.0)))
        forward, up = _pose_frame(pose)
        _set_time(scene, first + pose["time"] * fps)
        rgb, planar = renderer.render(_matrix(pose["position"], forward, up), fov_y, width,
                                      height, seed_offset)
        h = math.tan(fov_y / 2)
        radial = [0.0] * (width * height)
        for j in range(height):
            b = (1 - 2 * (j + 0.5) / height) * h
            for i in range(width):
                a = (2 * (i + 0.5) / width - 1) * h * width / height
                z = planar[j * width + i]
                radial[j * width + i] = z * math.sqrt(1 + a * a + b * b) \
                    if z < convention.SKY_DEPTH else math.inf
        path = os.path.join(out_dir, GT_PATTERN.format(pose=p))
        try:
            exr.write_exr(path, width, height, {"R": ("HALF", rgb[0::3]), "G": ("HALF", rgb[1::3]),
                                                "B": ("HALF", rgb[2::3]), "Z": ("FLOAT", radial)})
        except OSError as e:
            raise CaptureError("CALF-E004", "%s: cannot write: %s" % (path, e.strerror or e))
        progress.step("%s pose %d/%d" % (label, p + 1, len(eye_path["poses"])))


def ground_truth(scene, eye_path, out, samples, seed, first, noise_floor=True, clip_start=0.01,
                 clip_end=1e5, threads=0, log=print,
                 adaptive_threshold=GT_ADAPTIVE_THRESHOLD):
    """Renders `eye_path` (a calf eye-path dict; its width and height are the image size) into
    `out` as calf-play --compare reads it: gt_NNNNN.exr, and eye_path.json last; with
    `noise_floor`, first the same poses at seed + 1 into out/noise-floor/. Scene time t is scene
    frame first + t * fps. `adaptive_threshold` is Cycles' noise threshold, 0 = adaptive sampling
    off (every pixel gets `samples`)."""
    check_cycles(scene)
    check_size("ground-truth width", eye_path["width"], MAX_IMAGE_SIDE)
    check_size("ground-truth height", eye_path["height"], MAX_IMAGE_SIDE)
    if samples < 1:
        raise CaptureError("CALF-E006", "--samples must be >= 1", usage=True)
    check_adaptive_threshold(adaptive_threshold)
    check_output_dir(out)
    main_json = os.path.join(out, "eye_path.json")
    if os.path.lexists(main_json):
        os.remove(main_json)
    written = dict(eye_path)
    written["image_pattern"] = GT_PATTERN
    renderer = _Renderer(scene, samples, seed, clip_start, clip_end, threads, adaptive_threshold)
    passes = [(os.path.join(out, NOISE_FLOOR_DIR), 1, "noise floor")] if noise_floor else []
    passes.append((out, 0, "ground truth"))
    progress = Progress(len(passes) * len(eye_path["poses"]), log)
    try:
        for directory, seed_offset, label in passes:
            check_output_dir(directory)
            _render_path(scene, renderer, eye_path, directory, first, seed_offset, progress, label)
            write_json_atomically(os.path.join(directory, "eye_path.json"), written)
    finally:
        renderer.close()
    return written
