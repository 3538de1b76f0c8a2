"""calf's conventions as the add-on needs them (format/CAPTURE.md), in plain Python.

- Axes: calf's scene is Y-up and right-handed; Blender's is Z-up. The add-on uses the mapping of
  Blender's glTF exporter, so that a scene exported as glTF and captured by calf-capture lands in
  the same frame: calf (x, y, z) = Blender (x, z, -y). Rig strings, view volumes and eye paths
  are in calf's frame; one Blender unit is one scene unit.
- Faces: calf's order +X, -X, +Y, -Y, +Z, -Z; each is rendered by an upright, unmirrored 90 degree
  camera (forward, up as in CAPTURE.md's table), and pixel (i, j) of that camera's N x N image is
  calf's texel (N - 1 - i, j).
- Depth: Cycles' depth pass is planar (the distance along the camera's forward axis); calf's is
  radial (along the texel's ray). Sky (Cycles writes 1e10, or anything beyond the far clip) is
  +inf.
"""

import math

# Upright camera per calf face: (forward, up), calf coordinates (CAPTURE.md's table).
FACE_CAMERAS = (
    ((1, 0, 0), (0, 1, 0)),    # +X
    ((-1, 0, 0), (0, 1, 0)),   # -X
    ((0, 1, 0), (0, 0, -1)),   # +Y
    ((0, -1, 0), (0, 0, 1)),   # -Y
    ((0, 0, 1), (0, 1, 0)),    # +Z
    ((0, 0, -1), (0, 1, 0)),   # -Z
)
FACE_NAMES = ("+X", "-X", "+Y", "-Y", "+Z", "-Z")

# Cycles' depth for "no surface" is 1e10; anything at or beyond this is sky.
SKY_DEPTH = 1e9


def calf_from_blender(p):
    return (p[0], p[2], -p[1])


def blender_from_calf(p):
    return (p[0], -p[2], p[1])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def normalize(v):
    n = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
    return (v[0] / n, v[1] / n, v[2] / n)


def camera_rotation(forward, up):
    """The 3x3 rotation (rows) of a Blender camera looking along `forward` with `up` above, both in
    calf coordinates: its columns are the camera's +X (right), +Y (up) and +Z (backwards) axes in
    Blender's frame. right = forward x up (calf's camera model); up is re-orthogonalised."""
    f = normalize(forward)
    r = normalize(cross(f, up))
    u = cross(r, f)
    cols = [blender_from_calf(r), blender_from_calf(u), blender_from_calf((-f[0], -f[1], -f[2]))]
    return [[cols[c][row] for c in range(3)] for row in range(3)]


def radial_from_planar(planar, n):
    """An upright N x N 90 degree face's planar depths (row-major, row 0 at the top) as radial
    depths, +inf for sky: the ray through pixel (i, j) is forward + a right + b up with
    a = 2 (i + 0.5) / N - 1, b = 1 - 2 (j + 0.5) / N, so radial = planar * sqrt(1 + a^2 + b^2)."""
    scale = [math.sqrt(1.0 + (2.0 * (i + 0.5) / n - 1.0) ** 2) for i in range(n)]
    out = [0.0] * (n * n)
    for j in range(n):
        b2 = (1.0 - 2.0 * (j + 0.5) / n) ** 2
        for i in range(n):
            z = planar[j * n + i]
            if not z < SKY_DEPTH:
                out[j * n + i] = math.inf
            else:
                out[j * n + i] = z * math.sqrt(scale[i] * scale[i] + b2)
    return out


def texels_from_upright(values, n, channels=1):
    """An upright face image (row-major, `channels` values per pixel) in calf's texel order: the
    same rows, the columns reversed (texel (x, y) = upright pixel (N - 1 - x, y))."""
    out = []
    for j in range(n):
        row = values[j * n * channels:(j + 1) * n * channels]
        for i in range(n - 1, -1, -1):
            out.extend(row[i * channels:(i + 1) * channels])
    return out


def _numbers(text):
    try:
        values = [float(t) for t in text.split(",")]
    except ValueError:
        return None
    return values if all(math.isfinite(v) for v in values) else None


def parse_rig(text):
    """Parses a calf rig string (calf-capture --rig: box, ring, sphere, grid, list), in calf
    coordinates, into ([(name, position)], (min, max)). Raises ValueError naming what is wrong."""
    kind, colon, args = text.partition(":")
    if not colon:
        raise ValueError("rig '%s': missing ':' (box:, ring:, sphere:, grid: or list:)" % text)
    views = []
    if kind == "list":
        for i, item in enumerate(args.split("/")):
            v = _numbers(item)
            if v is None or len(v) != 3:
                raise ValueError("rig '%s': position '%s' is not X,Y,Z" % (text, item))
            views.append(("view%d" % i, tuple(v)))
        lo = tuple(min(p[k] for _, p in views) for k in range(3))
        hi = tuple(max(p[k] for _, p in views) for k in range(3))
        return views, (lo, hi)
    v = _numbers(args)
    if v is None:
        raise ValueError("rig '%s': expected comma-separated numbers" % text)
    if kind == "box":
        if len(v) != 6 or not all(h > 0 for h in v[3:]):
            raise ValueError("rig '%s': box takes CX,CY,CZ,HX,HY,HZ with half-sizes > 0" % text)
        c, h = v[:3], v[3:]
        views.append(("centre", tuple(c)))
        for i in range(8):
            s = (1 if i & 1 else -1, 1 if i & 2 else -1, 1 if i & 4 else -1)
            name = "corner" + "".join(("+" if s[k] > 0 else "-") + "xyz"[k] for k in range(3))
            views.append((name, tuple(c[k] + s[k] * h[k] for k in range(3))))
        return views, (tuple(c[k] - h[k] for k in range(3)), tuple(c[k] + h[k] for k in range(3)))
    if kind in ("ring", "sphere"):
        if len(v) != 5 or v[0] != int(v[0]) or not 1 <= v[0] <= 4096 or not v[1] > 0:
            raise ValueError("rig '%s': %s takes N,R,CX,CY,CZ (N in 1..4096, R > 0)" % (text, kind))
        n, r, c = int(v[0]), v[1], v[2:]
        golden = math.pi * (3 - math.sqrt(5.0))
        for i in range(n):
            if kind == "ring":
                a = 2 * math.pi * i / n
                d = (r * math.cos(a), 0.0, r * math.sin(a))
            else:
                y = 1 - (2 * i + 1.0) / n
                ring = math.sqrt(max(0.0, 1 - y * y))
                d = (r * ring * math.cos(golden * i), r * y, r * ring * math.sin(golden * i))
            views.append(("%s%d" % (kind, i), tuple(c[k] + d[k] for k in range(3))))
        h = (r, r / 4, r) if kind == "ring" else (r, r, r)
        return views, (tuple(c[k] - h[k] for k in range(3)), tuple(c[k] + h[k] for k in range(3)))
    if kind == "grid":
        if len(v) != 9 or not all(x == int(x) and x >= 1 for x in v[:3]):
            raise ValueError("rig '%s': grid takes NX,NY,NZ,X0,Y0,Z0,X1,Y1,Z1" % text)
        n, lo, hi = [int(x) for x in v[:3]], v[3:6], v[6:9]
        if n[0] * n[1] * n[2] > 4096:
            raise ValueError("rig '%s': more than 4096 viewpoints" % text)

        def at(i, count, a, b):
            return (a + b) / 2 if count == 1 else a + (b - a) * i / (count - 1)

        for z in range(n[2]):
            for y in range(n[1]):
                for x in range(n[0]):
                    p = (at(x, n[0], lo[0], hi[0]), at(y, n[1], lo[1], hi[1]),
                         at(z, n[2], lo[2], hi[2]))
                    views.append(("grid%d_%d_%d" % (x, y, z), p))
        return views, (tuple(min(lo[k], hi[k]) for k in range(3)),
                       tuple(max(lo[k], hi[k]) for k in range(3)))
    raise ValueError("rig '%s': unknown rig kind '%s' (box, ring, sphere, grid, list)" % (text, kind))


COVERAGE_CELLS = 4  # a texel's square split into 4 x 4 cells (CAPTURE.md, "Coverage")


def coverage_from_fine(depth, fine, n):
    """CAPTURE.md's coverage of one face: `depth` the face's N x N radial depths in texel order,
    `fine` the radial depths of the same face rendered 4N x 4N (texel order too; cell (i, j) of
    texel (x, y) is fine pixel (4x + i, 4y + j)). Returns (near, far, mask) lists: the shares of
    cells nearer and farther than the texel's own surface, and the 16-bit mask of the cells that
    show it (|ln(z / d)| <= min(4 / N, 0.05); both sky counts as the same surface)."""
    k = COVERAGE_CELLS
    tol = min(4.0 / n, 0.05)
    near, far, mask = [0.0] * (n * n), [0.0] * (n * n), [0.0] * (n * n)
    fn = k * n
    for y in range(n):
        for x in range(n):
            d = depth[y * n + x]
            nn = ff = m = 0
            for j in range(k):
                row = (k * y + j) * fn + k * x
                for i in range(k):
                    z = fine[row + i]
                    if d == math.inf:
                        if z == math.inf:
                            m |= 1 << (k * j + i)
                        else:
                            nn += 1
                    elif z == math.inf:
                        ff += 1
                    elif abs(math.log(z / d)) > tol:
                        if z < d:
                            nn += 1
                        else:
                            ff += 1
                    else:
                        m |= 1 << (k * j + i)
            near[y * n + x] = nn / (k * k)
            far[y * n + x] = ff / (k * k)
            mask[y * n + x] = float(m)
    return near, far, mask
