"""Makes docs/images/blender_gltf.png: ground-truth images of one size side by side (sRGB, each
pixel repeated SCALE x SCALE), here Cycles' ground truth of the test scene and calf's of its glTF
export at the same pose. Prints each image's mean linear RGB.

    blender -b --factory-startup -P tests/blender/compare_picture.py -- OUT.png SCALE A.exr B.exr...
"""

import sys

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
out, scale, paths = argv[0], int(argv[1]), argv[2:]
images = []
for p in paths:  # Blender reads any EXR compression; pixels are linear, bottom row first
    im = bpy.data.images.load(p)
    images.append((im.size[0], im.size[1], list(im.pixels)))
    n = len(images[-1][2]) // 4
    print("compare_picture: %s mean linear RGB %.3f %.3f %.3f" %
          ((p,) + tuple(sum(images[-1][2][c::4]) / n for c in range(3))))
w, h = images[0][0], images[0][1]
gap = 4


def srgb(v):
    v = min(max(v, 0.0), 1.0)
    return 12.92 * v if v <= 0.0031308 else 1.055 * v ** (1 / 2.4) - 0.055


width = len(images) * w * scale + (len(images) - 1) * gap
height = h * scale
pixels = [1.0] * (4 * width * height)  # white; Blender's rows run bottom to top
for n, (iw, ih, ch) in enumerate(images):
    if (iw, ih) != (w, h):
        print("compare_picture: %s is %dx%d, not %dx%d" % (paths[n], iw, ih, w, h))
        sys.exit(1)
    for y in range(h):  # from the top
        for x in range(w):
            k = 4 * ((h - 1 - y) * w + x)
            rgb = [srgb(v) for v in ch[k:k + 3]]
            for dy in range(scale):
                for dx in range(scale):
                    px = n * (w * scale + gap) + x * scale + dx
                    k = 4 * ((height - 1 - (y * scale + dy)) * width + px)
                    pixels[k:k + 3] = rgb
img = bpy.data.images.new("picture", width, height)
img.pixels = pixels
img.filepath_raw = out
img.file_format = "PNG"
img.save()
