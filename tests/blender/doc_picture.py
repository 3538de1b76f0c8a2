"""Makes docs/images/blender_capture.png: the six faces of one capture image laid side by side
(calf's order +X, -X, +Y, -Y, +Z, -Z, as stored, sRGB) above the first row of a calf-play contact
sheet (Cycles' ground truth | calf | error heat map).

    blender -b --factory-startup -P tests/blender/doc_picture.py -- CAPTURE.exr SHEET.png OUT.png
"""

import os
import sys

import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "blender"))
from calf_capture import exr  # noqa: E402

capture, sheet_path, out = sys.argv[sys.argv.index("--") + 1:][:3]
n, h6, ch = exr.read_exr(capture)


def srgb(v):
    v = min(max(v, 0.0), 1.0)
    return 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055


sheet = bpy.data.images.load(sheet_path)
sw, sh = sheet.size
row_h = sh // 3  # the sheet's first row (of three)
gap = 4
width = max(6 * n + 5 * gap, sw)
height = n + gap + row_h
pixels = [1.0] * (4 * width * height)  # white; Blender's rows run bottom to top


def put(x, y, rgb):  # y from the top
    k = 4 * ((height - 1 - y) * width + x)
    pixels[k:k + 3] = rgb


for f in range(6):
    for y in range(n):
        for x in range(n):
            i = (f * n + y) * n + x
            put(f * (n + gap) + x, y, [srgb(ch[c][i]) for c in "RGB"])
src = list(sheet.pixels)
for y in range(row_h):
    for x in range(sw):
        k = 4 * ((sh - 1 - y) * sw + x)
        put(x, n + gap + y, src[k:k + 3])
img = bpy.data.images.new("picture", width, height)
img.pixels = pixels
img.filepath_raw = out
img.file_format = "PNG"
img.save()
