"""Builds the small test scene of the Blender tests in the open (empty) Blender file:
a floor with a procedural checker texture, a red cube that moves and turns over frames 1-3, a
mirror-like glossy sphere, a textured back wall, a sun and a blue-grey world; three viewpoint
empties in the collection "calf_viewpoints", a box object "calf_volume" (not rendered) as the view
volume, and a camera "Eye" that moves inside the volume over the frame range.

    blender -b --factory-startup -P tests/blender/make_scene.py [-- OUT.blend]

Positions in Blender's frame (Z up). With a path after "--" the file is saved there; either way a
script named by a later -P sees the scene.
"""

import math
import sys

import bpy

for obj in list(bpy.data.objects):
    bpy.data.objects.remove(obj)
scene = bpy.context.scene
scene.frame_start, scene.frame_end = 1, 3
scene.render.fps, scene.render.fps_base = 24, 1.0


def material(name, colour, metallic=0.0, roughness=0.5, checker=None):
    m = bpy.data.materials.new(name)
    m.use_nodes = True
    bsdf = m.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = colour
    bsdf.inputs["Metallic"].default_value = metallic
    bsdf.inputs["Roughness"].default_value = roughness
    if checker:
        tex = m.node_tree.nodes.new("ShaderNodeTexChecker")
        tex.inputs["Scale"].default_value = checker
        tex.inputs["Color1"].default_value = colour
        tex.inputs["Color2"].default_value = (0.9, 0.85, 0.6, 1.0)
        m.node_tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
    return m


def add(op, name, mat, **kw):
    op(**kw)
    obj = bpy.context.active_object
    obj.name = name
    if mat:
        obj.data.materials.append(mat)
    return obj


add(bpy.ops.mesh.primitive_plane_add, "Floor", material("floor", (0.1, 0.3, 0.1, 1), checker=12),
    size=12, location=(0, 0, 0))
add(bpy.ops.mesh.primitive_plane_add, "Wall", material("wall", (0.4, 0.1, 0.4, 1), checker=6),
    size=6, location=(0, 4, 3), rotation=(math.pi / 2, 0, 0))
cube = add(bpy.ops.mesh.primitive_cube_add, "Cube", material("red", (0.8, 0.1, 0.05, 1)),
           size=0.8, location=(-1.2, 1.8, 0.4))
for frame, x, turn in ((1, -1.2, 0.0), (2, -0.9, 0.3), (3, -0.6, 0.6)):
    cube.location.x = x
    cube.rotation_euler.z = turn
    cube.keyframe_insert("location", frame=frame)
    cube.keyframe_insert("rotation_euler", frame=frame)
add(bpy.ops.mesh.primitive_uv_sphere_add, "Glossy", material("glossy", (0.9, 0.9, 0.9, 1), 1.0,
    0.08), radius=0.6, location=(1.2, 2.0, 0.6), segments=48, ring_count=24)
bpy.ops.object.shade_smooth()

sun = bpy.data.lights.new("Sun", "SUN")
sun.energy = 3.0
sun_obj = bpy.data.objects.new("Sun", sun)
sun_obj.rotation_euler = (0.6, 0.2, 0.8)
scene.collection.objects.link(sun_obj)
world = scene.world or bpy.data.worlds.new("World")
scene.world = world
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.35, 0.45, 0.6, 1)
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0

views = bpy.data.collections.new("calf_viewpoints")
scene.collection.children.link(views)
for name, p in (("a", (-0.3, -0.2, 1.0)), ("b", (0.3, -0.2, 1.2)), ("c", (0.0, 0.3, 1.1))):
    e = bpy.data.objects.new(name, None)
    e.location = p
    views.objects.link(e)
box = add(bpy.ops.mesh.primitive_cube_add, "calf_volume", None, size=1.0, location=(0, 0.05, 1.1))
box.scale = (0.6, 0.5, 0.2)
box.hide_render = True

cam = bpy.data.cameras.new("Eye")
cam.lens_unit = "FOV"
cam.sensor_fit = "VERTICAL"
cam.angle_y = math.radians(60)
eye = bpy.data.objects.new("Eye", cam)
scene.collection.objects.link(eye)
for frame, x in ((1, -0.2), (2, 0.0), (3, 0.2)):
    eye.location = (x, -0.1, 1.1)
    eye.rotation_euler = (math.radians(82), 0, math.radians(-8 * x))
    eye.keyframe_insert("location", frame=frame)
    eye.keyframe_insert("rotation_euler", frame=frame)
scene.camera = eye
scene.frame_set(1)

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
if argv and argv[0].endswith(".blend"):
    bpy.ops.wm.save_as_mainfile(filepath=argv[0])
