"""Exports the open scene as glTF for calf-capture, the way a user hands a Blender scene to
calf's own tracer:

    blender -b scene.blend -P tests/blender/export_gltf.py -- OUT.gltf [--bake-size N]
        [--camera NAME --eye-path FILE --size WxH]

Blender's glTF exporter (io_scene_gltf2, which needs numpy: Debian's python3-numpy) writes image
textures only; a procedural base colour (a Checker node here) would be lost. So every material
whose Principled BSDF takes its Base Color from a node other than an image is first baked with
Cycles into an N x N image on the object's UV map (the colour through an Emission shader, bake
type Emit: the albedo without light; denoising off, since with it on the Debian build, which
has no OpenImageDenoise, bakes black), and that image is wired to Base Color. calf-capture
samples a file's animation at 30 fps from time 0, so the scene is retimed before the export:
its first frame goes to frame 0 and its fps to 30, which puts scene frame FIRST + k at k / 30 s
in the file, capture frame k of calf-capture. Objects not rendered (hide_render) are left out;
lights, the world and cameras are not exported (calf's tracer lights a file with its own sun and
sky).

With --camera, the camera's animation is also written as a calf eye path (the add-on's
--write-eye-path, at WxH) in the file's time: pose k at k / 30 s. Nothing is saved to the .blend
file.
"""

import argparse
import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "blender"))

from calf_capture import capture  # noqa: E402

parser = argparse.ArgumentParser(prog="export_gltf")
parser.add_argument("out")
parser.add_argument("--bake-size", type=int, default=512)
parser.add_argument("--camera", default="")
parser.add_argument("--eye-path", default="")
parser.add_argument("--size", default="128x128")
args = parser.parse_args(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
try:
    import numpy  # noqa: F401
except ImportError:
    print("export_gltf: Blender's glTF exporter needs numpy, which this Blender's Python lacks "
          "(Debian: apt-get install python3-numpy)")
    sys.exit(1)
out = os.path.abspath(args.out)
bake_size = args.bake_size
scene = bpy.context.scene
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 1
scene.cycles.use_denoising = False


def procedural_base_colour(mat):
    """The Principled BSDF of mat when its Base Color comes from a non-image node, else None."""
    if not mat or not mat.use_nodes:
        return None
    for node in mat.node_tree.nodes:
        if node.type == "BSDF_PRINCIPLED":
            links = node.inputs["Base Color"].links
            if links and links[0].from_node.type != "TEX_IMAGE":
                return node
    return None


for mat in bpy.data.materials:
    bsdf = procedural_base_colour(mat)
    if bsdf is None:
        continue
    users = [o for o in scene.objects if o.type == "MESH" and not o.hide_render and
             any(s.material == mat for s in o.material_slots)]
    if not users:
        continue
    image = bpy.data.images.new(mat.name + "_base_colour", bake_size, bake_size)
    node = mat.node_tree.nodes.new("ShaderNodeTexImage")
    node.image = image
    mat.node_tree.nodes.active = node
    bpy.ops.object.select_all(action="DESELECT")
    for o in users:
        o.select_set(True)
    bpy.context.view_layer.objects.active = users[0]
    # The colour into an Emission shader on the material's output for the bake, then back.
    tree = mat.node_tree
    output = next(n for n in tree.nodes if n.type == "OUTPUT_MATERIAL" and n.is_active_output)
    shader_link = output.inputs["Surface"].links[0]
    shader_from = shader_link.from_socket
    emission = tree.nodes.new("ShaderNodeEmission")
    tree.links.new(bsdf.inputs["Base Color"].links[0].from_socket, emission.inputs["Color"])
    tree.links.new(emission.outputs["Emission"], output.inputs["Surface"])
    bake = scene.render.bake
    bake.margin, bake.use_clear, bake.target = 4, True, "IMAGE_TEXTURES"
    bpy.ops.object.bake(type="EMIT")
    tree.links.new(shader_from, output.inputs["Surface"])
    tree.nodes.remove(emission)
    mat.node_tree.links.new(node.outputs["Color"], bsdf.inputs["Base Color"])
    image.filepath_raw = os.path.join(os.path.dirname(out), image.name + ".png")
    image.file_format = "PNG"
    image.save()

# Scene frame FIRST + k at k / 30 s.
first = scene.frame_start
for action in bpy.data.actions:
    for curve in action.fcurves:
        for key in curve.keyframe_points:
            key.co.x -= first
            key.handle_left.x -= first
            key.handle_right.x -= first
scene.frame_end -= first
scene.frame_start = 0
scene.render.fps, scene.render.fps_base = 30, 1.0
scene.frame_set(0)

result = bpy.ops.export_scene.gltf(filepath=out, export_format="GLTF_SEPARATE",
                                   use_renderable=True, export_cameras=False,
                                   export_lights=False, export_apply=True,
                                   export_animations=True)
if result != {"FINISHED"}:
    print("export_gltf: the glTF exporter failed")
    sys.exit(1)
print("export_gltf: wrote %s (frames 0-%d at 30 fps)" % (out, scene.frame_end))
if args.camera:
    w, h = (int(v) for v in args.size.split("x"))
    eye_path = capture.eye_path_from_camera(scene, args.camera, w, h, 0, scene.frame_end)
    capture.write_json_atomically(args.eye_path, eye_path)
    print("export_gltf: wrote %d poses to %s" % (len(eye_path["poses"]), args.eye_path))
