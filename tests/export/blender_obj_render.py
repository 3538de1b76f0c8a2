# The tiles OBJ in Blender (run by tests/export/blender_compare.sh):
#   blender -b --factory-startup -noaudio -P blender_obj_render.py -- MODEL.obj EYE_PATH.json \
#       FRAMES_DIR OUT_DIR
# imports MODEL.obj (+ its .mtl and atlas) with Blender's OBJ importer (wm.obj_import, the default
# axes: OBJ's +Y up becomes Blender's +Z), shows every imported material unlit: an Emission shader
# of what the importer connected to the Principled BSDF's Base Color, mixed with a Transparent
# shader by what it connected to Alpha (so the file's map_d is what makes the tiles transparent;
# without it they come out opaque), renders each pose of EYE_PATH.json with Cycles (1 sample at the
# pixel centre: a pixel filter of 0.01 px, no denoising, no dither, the Standard view transform,
# black world) at the eye path's size into OUT_DIR/blender_NNNNN.png and prints
#   pose P: PSNR X dB
# against FRAMES_DIR/frame_NNNNN.png (calf-play's frames), over 8-bit RGB.
import json
import math
import os
import sys

import bpy
from bpy_extras.io_utils import axis_conversion
from mathutils import Matrix, Vector

model, eye_path_file, frames_dir, out_dir = sys.argv[sys.argv.index('--') + 1:]

bpy.ops.wm.read_factory_settings(use_empty=True)
scene = bpy.context.scene
bpy.ops.wm.obj_import(filepath=model)

for material in bpy.data.materials:
    if not material.use_nodes:
        continue
    nodes, links = material.node_tree.nodes, material.node_tree.links
    bsdf = next((n for n in nodes if n.type == 'BSDF_PRINCIPLED'), None)
    output = next((n for n in nodes if n.type == 'OUTPUT_MATERIAL'), None)
    if bsdf is None or output is None:
        continue
    emission = nodes.new('ShaderNodeEmission')
    emission.inputs['Strength'].default_value = 1.0
    base = bsdf.inputs['Base Color']
    if base.is_linked:
        links.new(base.links[0].from_socket, emission.inputs['Color'])
    else:
        emission.inputs['Color'].default_value = base.default_value
    transparent = nodes.new('ShaderNodeBsdfTransparent')
    mix = nodes.new('ShaderNodeMixShader')
    alpha = bsdf.inputs['Alpha']
    if alpha.is_linked:
        links.new(alpha.links[0].from_socket, mix.inputs['Fac'])
    else:
        mix.inputs['Fac'].default_value = alpha.default_value
    links.new(transparent.outputs['BSDF'], mix.inputs[1])
    links.new(emission.outputs['Emission'], mix.inputs[2])
    links.new(mix.outputs['Shader'], output.inputs['Surface'])

eye_path = json.load(open(eye_path_file))
width, height = eye_path['width'], eye_path['height']
render = scene.render
render.engine = 'CYCLES'
render.resolution_x, render.resolution_y, render.resolution_percentage = width, height, 100
render.dither_intensity = 0.0
render.image_settings.file_format = 'PNG'
render.image_settings.color_mode = 'RGB'
render.image_settings.color_depth = '8'
scene.cycles.device = 'CPU'
scene.cycles.samples = 1
scene.cycles.use_denoising = False
scene.cycles.filter_width = 0.01
scene.cycles.max_bounces = 0
scene.cycles.transparent_max_bounces = 1024
scene.view_settings.view_transform = 'Standard'
scene.view_settings.look = 'None'
world = bpy.data.worlds.new('black')
world.use_nodes = False
world.color = (0.0, 0.0, 0.0)
scene.world = world

camera_data = bpy.data.cameras.new('eye')
camera_data.sensor_fit = 'VERTICAL'
camera_data.clip_start = 0.01
camera_data.clip_end = 1e4
camera = bpy.data.objects.new('eye', camera_data)
scene.collection.objects.link(camera)
scene.camera = camera
# calf's (and OBJ's) axes to Blender's, as the importer converts them.
to_blender = axis_conversion(from_forward='-Z', from_up='Y').to_4x4()


def pixels_of(path):
    image = bpy.data.images.load(path)
    values = [round(v * 255) for i, v in enumerate(image.pixels) if i % 4 != 3]
    size = tuple(image.size)
    bpy.data.images.remove(image)
    return size, values


for p, pose in enumerate(eye_path['poses']):
    fov = pose.get('fov_y_degrees', eye_path.get('fov_y_degrees', 60))
    camera_data.angle_y = math.radians(fov)
    position = Vector(pose['position'])
    up = Vector(pose.get('up', [0, 1, 0]))
    forward = (Vector(pose['look_at']) - position) if 'look_at' in pose else Vector(pose['forward'])
    forward.normalize()
    right = forward.cross(up).normalized()
    true_up = right.cross(forward)
    # A Blender camera looks along its -Z with +Y up.
    frame = Matrix((right, true_up, -forward)).transposed().to_4x4()
    frame.translation = position
    camera.matrix_world = to_blender @ frame
    out = os.path.join(out_dir, 'blender_%05d.png' % p)
    render.filepath = out
    bpy.ops.render.render(write_still=True)
    got_size, got = pixels_of(out)
    want_size, want = pixels_of(os.path.join(frames_dir, 'frame_%05d.png' % p))
    if got_size != want_size:
        print('pose %d: size %s differs from calf-play\'s %s' % (p, got_size, want_size))
        sys.exit(1)
    mse = sum((a - b) ** 2 for a, b in zip(got, want)) / len(got)
    psnr = 99.0 if mse == 0 else 10 * math.log10(255 * 255 / mse)
    print('pose %d: PSNR %.2f dB' % (p, psnr), flush=True)
