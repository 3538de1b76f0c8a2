#!/usr/bin/env python3
"""An independent reader of calf's tiles, surfels and mesh tracks.

Written from format/SPEC.md (§1 – §10 the container, §11.2 tiles, §11.3 surfels, §11.4 mesh,
§11.1.10 the BC7 block) and tests/conformance/README.md alone, without calf's source. It prints,
for each clip named on the command line, the lines `calf-verify --decode -q` prints for its tiles,
surfels and mesh tracks (SPEC §11.2.6, §11.3.6, §11.4.7).

  calf_clean_room.py CLIP.calf...            print the hash lines
  calf_clean_room.py --check CLIP.calf...    compare each with CLIP.hashes beside it; exit 1 on a
                                             difference

Needs Python 3 with zstandard and xxhash (Debian: python3-zstandard, python3-xxhash). When they
are missing it exits 77 (the ctest skip code), unless the environment variable CI is "true".
"""

import lzma
import math
import os
import struct
import sys

try:
    import xxhash
    import zstandard
except ImportError as e:  # pragma: no cover
    print(f"calf_clean_room: {e} (install python3-zstandard and python3-xxhash)", file=sys.stderr)
    sys.exit(1 if os.environ.get("CI") == "true" else 77)


class Error(Exception):
    pass


def xxh3(data):
    return xxhash.xxh3_64_intdigest(bytes(data))


# ---------------------------------------------------------------------------------------------
# The container (SPEC §2 – §7).

IDENTIFIER = bytes([0xAB, 0x43, 0x41, 0x4C, 0x46, 0x20, 0x31, 0xBB, 0x0D, 0x0A, 0x1A, 0x0A])


class Chunk:
    __slots__ = ("offset", "stored_size", "raw_size", "hash", "compression", "flags", "track",
                 "stream", "view", "face", "region", "layer", "first_frame", "frame_count")


class Container:
    def __init__(self, path):
        with open(path, "rb") as f:
            self.data = f.read()
        d = self.data
        if d[:12] != IDENTIFIER:
            raise Error("not a calf file")
        (_, major, _minor, required, _optional, file_size, dir_offset, dir_size, chunk_count,
         track_count, checksum) = struct.unpack_from("<12sHHIIQQQIIQ", d, 0)
        if xxh3(d[:56]) != checksum or major != 1 or file_size != len(d):
            raise Error("bad header")
        directory = d[dir_offset:dir_offset + dir_size]
        if xxh3(directory[:-8]) != struct.unpack_from("<Q", directory, dir_size - 8)[0]:
            raise Error("bad directory checksum")
        if required & 1:  # §4.1 compressed directory
            (body_size,) = struct.unpack_from("<Q", directory, 0)
            body = zstandard.ZstdDecompressor().decompress(bytes(directory[8:-8]),
                                                            max_output_size=body_size)
            if len(body) != body_size:
                raise Error("bad compressed directory")
        else:
            body = directory[:-8]
        pos = 0

        def u32():
            nonlocal pos
            (v,) = struct.unpack_from("<I", body, pos)
            pos += 4
            return v

        def string():
            nonlocal pos
            n = u32()
            s = body[pos:pos + n]
            pos += n
            return s

        self.metadata = []
        for _ in range(u32()):
            self.metadata.append((string(), string()))
        self.tracks = []
        for _ in range(track_count):
            kind, flags = struct.unpack_from("<HH", body, pos)
            pos += 4
            self.tracks.append((kind, flags, bytes(string())))
        self.chunks = []
        for _ in range(chunk_count):
            c = Chunk()
            (c.offset, c.stored_size, c.raw_size, c.hash, c.compression, c.flags, c.track,
             c.stream, c.view, c.face, c.region, c.layer, c.first_frame,
             c.frame_count) = struct.unpack_from("<QQQQHHHHIIIIII", body, pos)
            pos += 64
            self.chunks.append(c)
        if pos != len(body):
            raise Error("directory bytes left over")

    def read(self, c):
        stored = self.data[c.offset:c.offset + c.stored_size]
        if xxh3(stored) != c.hash:
            raise Error("chunk hash mismatch")
        if c.compression == 0:
            raw = stored
        elif c.compression == 1:
            raw = zstandard.ZstdDecompressor().decompress(bytes(stored),
                                                          max_output_size=c.raw_size)
        elif c.compression == 2:
            p = stored[0]
            dict_size = 0xFFFFFFFF if p == 40 else (2 | (p & 1)) << (p // 2 + 11)
            dec = lzma.LZMADecompressor(
                format=lzma.FORMAT_RAW, filters=[{"id": lzma.FILTER_LZMA2, "dict_size": dict_size}])
            raw = dec.decompress(bytes(stored[1:]))
            if not dec.eof:
                raise Error("LZMA2 stream without its end marker")
        else:
            raise Error("unknown compression")
        if len(raw) != c.raw_size:
            raise Error("raw size mismatch")
        return bytes(raw)

    def track_chunks(self, t):
        return [c for c in self.chunks if c.track == t]


# ---------------------------------------------------------------------------------------------
# Shared codings.

def f32(x):
    """x rounded to binary32 (as a Python float)."""
    return struct.unpack("<f", struct.pack("<f", x))[0]


def f32_bits(x):
    return struct.unpack("<I", struct.pack("<f", x))[0]


def bits_f32(u):
    return struct.unpack("<f", struct.pack("<I", u))[0]


def byte_planes32(b, n, off=0):
    """n 32-bit words stored as four byte planes (SPEC §11.2.3 step 3, §11.4.1)."""
    p0, p1, p2, p3 = (b[off + k * n:off + (k + 1) * n] for k in range(4))
    return [p0[i] | p1[i] << 8 | p2[i] << 16 | p3[i] << 24 for i in range(n)]


def byte_planes16(b, n, off=0):
    lo = b[off:off + n]
    hi = b[off + n:off + 2 * n]
    return [lo[i] | hi[i] << 8 for i in range(n)]


def words_le(words):
    return struct.pack(f"<{len(words)}I", *words)


M32 = 0xFFFFFFFF


# ---------------------------------------------------------------------------------------------
# BC7 (SPEC §11.1.10; the partition and anchor tables of the BPTC specification).

# Subset of each texel (texel 4j + i is column i, row j), per partition.
P2 = [
    "0011001100110011", "0001000100010001", "0111011101110111", "0001001100110111",
    "0000000100010011", "0011011101111111", "0001001101111111", "0000000100110111",
    "0000000000010011", "0011011111111111", "0000000101111111", "0000000000010111",
    "0001011111111111", "0000000011111111", "0000111111111111", "0000000000001111",
    "0000100011101111", "0111000100000000", "0000000010001110", "0111001100010000",
    "0011000100000000", "0000100011001110", "0000000010001100", "0111001100110001",
    "0011000100010000", "0000100010001100", "0110011001100110", "0011011001101100",
    "0001011111101000", "0000111111110000", "0111000110001110", "0011100110011100",
    "0101010101010101", "0000111100001111", "0101101001011010", "0011001111001100",
    "0011110000111100", "0101010110101010", "0110100101101001", "0101101010100101",
    "0111001111001110", "0001001111001000", "0011001001001100", "0011101111011100",
    "0110100110010110", "0011110011000011", "0110011010011001", "0000011001100000",
    "0100111001000000", "0010011100100000", "0000001001110010", "0000010011100100",
    "0110110010010011", "0011011011001001", "0110001110011100", "0011100111000110",
    "0110110011001001", "0110001100111001", "0111111010000001", "0001100011100111",
    "0000111100110011", "0011001111110000", "0010001011101110", "0100010001110111",
]
P3 = [
    "0011001102212222", "0001001122112221", "0000200122112211", "0222002200110111",
    "0000000011221122", "0011001100220022", "0022002211111111", "0011001122112211",
    "0000000011112222", "0000111111112222", "0000111122222222", "0012001200120012",
    "0112011201120112", "0122012201220122", "0011011211221222", "0011200122002220",
    "0001001101121122", "0111001120012200", "0000112211221122", "0022002200221111",
    "0111011102220222", "0001000122212221", "0000001101220122", "0000110022102210",
    "0122012200110000", "0012001211222222", "0110122112210110", "0000011012211221",
    "0022110211020022", "0110011020022222", "0011012201220011", "0000200022112221",
    "0000000211221222", "0222002200120011", "0011001200220222", "0120012001200120",
    "0000111122220000", "0120120120120120", "0120201212010120", "0011220011220011",
    "0011112222000011", "0101010122222222", "0000000021212121", "0022112200221122",
    "0022001100220011", "0220122102201221", "0101222222220101", "0000212121212121",
    "0101010101012222", "0222011102220111", "0002111200021112", "0000211221122112",
    "0222011101110222", "0002111211120002", "0110011001102222", "0000000021122112",
    "0110011022222222", "0022001100110022", "0022112211220022", "0000000000002112",
    "0002000100020001", "0222122202221222", "0101222222222222", "0111201122012220",
]
ANCHOR2 = [
    15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15,
    15, 2, 8, 2, 2, 8, 8, 15, 2, 8, 2, 2, 8, 8, 2, 2,
    15, 15, 6, 8, 2, 8, 15, 15, 2, 8, 2, 2, 2, 15, 15, 6,
    6, 2, 6, 8, 15, 15, 2, 2, 15, 15, 15, 15, 15, 2, 2, 15,
]
ANCHOR3A = [
    3, 3, 15, 15, 8, 3, 15, 15, 8, 8, 6, 6, 6, 5, 3, 3,
    3, 3, 8, 15, 3, 3, 6, 10, 5, 8, 8, 6, 8, 5, 15, 15,
    8, 15, 3, 5, 6, 10, 8, 15, 15, 3, 15, 5, 15, 15, 15, 15,
    3, 15, 5, 5, 5, 8, 5, 10, 5, 10, 8, 13, 15, 12, 3, 3,
]
ANCHOR3B = [
    15, 8, 8, 3, 15, 15, 3, 8, 15, 15, 15, 15, 15, 15, 15, 8,
    15, 8, 15, 3, 15, 8, 15, 8, 3, 15, 6, 10, 15, 15, 10, 8,
    15, 3, 15, 10, 10, 8, 9, 10, 6, 15, 8, 15, 3, 6, 6, 8,
    15, 3, 15, 15, 15, 15, 15, 15, 15, 15, 15, 15, 3, 15, 15, 8,
]
WEIGHTS = {
    2: [0, 21, 43, 64],
    3: [0, 9, 18, 27, 37, 46, 55, 64],
    4: [0, 4, 9, 13, 17, 21, 26, 30, 34, 38, 43, 47, 51, 55, 60, 64],
}
# mode: subsets, P, rotation bits, index selection bits, CB, AB, p-bits (0 none, 1 per subset,
# 2 per endpoint), IB, IB2
BC7_MODES = [
    (3, 4, 0, 0, 4, 0, 2, 3, 0),
    (2, 6, 0, 0, 6, 0, 1, 3, 0),
    (3, 6, 0, 0, 5, 0, 0, 2, 0),
    (2, 6, 0, 0, 7, 0, 2, 2, 0),
    (1, 0, 2, 1, 5, 6, 0, 2, 3),
    (1, 0, 2, 0, 7, 8, 0, 2, 2),
    (1, 0, 0, 0, 7, 7, 2, 4, 0),
    (2, 6, 0, 0, 5, 5, 2, 2, 0),
]


def bc7_block(b):
    """16 texels of (R, G, B, A) bytes."""
    v = int.from_bytes(b, "little")
    if b[0] == 0:
        return [(0, 0, 0, 0)] * 16
    m = 0
    while not (v >> m) & 1:
        m += 1
    pos = m + 1

    def take(n):
        nonlocal pos
        r = (v >> pos) & ((1 << n) - 1)
        pos += n
        return r

    ns, pb, rb, isb, cb, ab, pmode, ib, ib2 = BC7_MODES[m]
    part = take(pb)
    rot = take(rb)
    isel = take(isb)
    ne = 2 * ns
    ends = [[0, 0, 0, 0] for _ in range(ne)]
    for ch in range(3):
        for e in range(ne):
            ends[e][ch] = take(cb)
    if ab:
        for e in range(ne):
            ends[e][3] = take(ab)
    if pmode == 2:
        pbits = [take(1) for _ in range(ne)]
    elif pmode == 1:
        shared = [take(1) for _ in range(ns)]
        pbits = [shared[e // 2] for e in range(ne)]
    else:
        pbits = None

    def expand(x, n):
        x = x << (8 - n)
        return x | (x >> n)

    for e in range(ne):
        for ch in range(4):
            if ch == 3 and not ab:
                ends[e][3] = 255
                continue
            n = cb if ch < 3 else ab
            x = ends[e][ch]
            if pbits is not None:
                x = (x << 1) | pbits[e]
                n += 1
            ends[e][ch] = expand(x, n)
    if ns == 1:
        subset = [0] * 16
        anchors = {0}
    elif ns == 2:
        subset = [int(c) for c in P2[part]]
        anchors = {0, ANCHOR2[part]}
    else:
        subset = [int(c) for c in P3[part]]
        anchors = {0, ANCHOR3A[part], ANCHOR3B[part]}
    idx1 = [take(ib - 1 if k in anchors else ib) for k in range(16)]
    idx2 = [take(ib2 - 1 if k == 0 else ib2) for k in range(16)] if ib2 else None
    out = []
    for k in range(16):
        s = subset[k]
        e0, e1 = ends[2 * s], ends[2 * s + 1]
        if idx2 is None:
            w = WEIGHTS[ib][idx1[k]]
            px = [((64 - w) * e0[c] + w * e1[c] + 32) >> 6 for c in range(4)]
        else:
            if isel:
                wc, wa = WEIGHTS[ib2][idx2[k]], WEIGHTS[ib][idx1[k]]
            else:
                wc, wa = WEIGHTS[ib][idx1[k]], WEIGHTS[ib2][idx2[k]]
            px = [((64 - wc) * e0[c] + wc * e1[c] + 32) >> 6 for c in range(3)]
            px.append(((64 - wa) * e0[3] + wa * e1[3] + 32) >> 6)
        if rot:
            px[3], px[rot - 1] = px[rot - 1], px[3]
        out.append(tuple(px))
    return out


# ---------------------------------------------------------------------------------------------
# Tiles (SPEC §11.2).

def tiles_lines(cont, t, header):
    out = []
    chunks = [c for c in cont.track_chunks(t) if c.stream <= 2]
    index = [c for c in chunks if c.stream == 0]
    if not index:
        return out
    n, aw, ah, fmt, _flags = struct.unpack_from("<IIIHH", header, 12)
    idx = cont.read(index[0])
    version, _flags, *rest = struct.unpack_from("<II6dI", idx, 0)
    if version != 1 or len(idx) != 60:
        raise Error("tiles index")
    band_rows = rest[6]
    view = idx[8:56]
    quads = cont.read([c for c in chunks if c.stream == 2][0])
    res = byte_planes32(quads, 24 * n)
    words = []
    for tile in range(n):
        w = [0] * 24
        for k in range(24):
            r = res[k * n + tile]
            if k < 6:
                pred = words[(tile - 1) * 24 + k] if tile > 0 else 0
            else:
                pred = w[k % 6]
            w[k] = (r + pred) & M32
        words += w
    out.append(f"track {t} tiles quads {xxh3(struct.pack('<I', n) + view + words_le(words)):016x}")
    bands = {c.region: c for c in chunks if c.stream == 1}
    texels = bytearray()
    for b in range((ah + band_rows - 1) // band_rows):
        r0, r1 = b * band_rows, min((b + 1) * band_rows, ah)
        data = cont.read(bands[b])
        if fmt == 1:
            texels += data
        elif fmt == 8:
            bw = (aw + 3) // 4
            rows = r1 - r0
            band = bytearray(4 * aw * rows)
            for by in range((rows + 3) // 4):
                for bx in range(bw):
                    off = 16 * (by * bw + bx)
                    px = bc7_block(data[off:off + 16])
                    for j in range(4):
                        y = by * 4 + j
                        if y >= rows:
                            break
                        for i in range(4):
                            x = bx * 4 + i
                            if x >= aw:
                                break
                            band[4 * (y * aw + x):4 * (y * aw + x) + 4] = bytes(px[4 * j + i])
            texels += band
        else:
            raise Error("atlas format")
    out.append(f"track {t} tiles atlas {xxh3(struct.pack('<II', aw, ah) + texels):016x}")
    return out


# ---------------------------------------------------------------------------------------------
# Surfels (SPEC §11.3).

def srgb_to_linear(c):
    x = c / 255.0
    return f32(x / 12.92 if x <= 0.04045 else math.pow((x + 0.055) / 1.055, 2.4))


def surfels_lines(cont, t):
    out = []
    chunks = [c for c in cont.track_chunks(t) if c.stream <= 1]
    index = [c for c in chunks if c.stream == 0]
    if not index:
        return out
    idx = cont.read(index[0])
    version, _flags, _mesh_track, count = struct.unpack_from("<IIII", idx, 0)
    if version != 1:
        raise Error("surfels index")
    levels = {(c.region, c.layer): c for c in chunks if c.stream == 1}
    colour_lut = [srgb_to_linear(c) for c in range(256)]
    for p in range(count):
        rec = idx[16 + 40 * p:16 + 40 * (p + 1)]
        n_total, flags, prefix_count, _radius = struct.unpack_from("<IIIf", rec, 0)
        box = struct.unpack_from("<6f", rec, 16)
        pos, nrm, col = [], [], []
        k = 0
        while True:
            b = 0 if k == 0 else 1024 << (k - 1)
            e = min(1024 << k, n_total)
            if b >= n_total:
                break
            n = e - b
            data = cont.read(levels[(p, k)])
            q = byte_planes16(data, 3 * n)
            uv = byte_planes16(data, 2 * n, 6 * n)
            cbytes = data[10 * n:13 * n]
            for i in range(n):
                for c in range(3):
                    lo, hi = box[c], box[3 + c]
                    code = q[c * n + i]
                    pos.append(f32(((65535 - code) * lo + code * hi) / 65535))
                a = uv[i] / 65535 * 2 - 1
                bb = uv[n + i] / 65535 * 2 - 1
                z = 1 - abs(a) - abs(bb)
                if z < 0:
                    a, bb = ((1 - abs(bb)) * (1.0 if a >= 0 else -1.0),
                             (1 - abs(a)) * (1.0 if bb >= 0 else -1.0))
                ell = math.sqrt(a * a + bb * bb + z * z)
                nrm += [f32(a / ell), f32(bb / ell), f32(z / ell)]
                col += [colour_lut[cbytes[c * n + i]] for c in range(3)]
            k += 1
        blob = rec[:16] + struct.pack(f"<{len(pos) * 3}f", *(pos + nrm + col))
        out.append(f"track {t} surfels {p} {xxh3(blob):016x}")
    return out


# ---------------------------------------------------------------------------------------------
# Mesh (SPEC §11.4).

def vec3_array(b, v, off, ref=None):
    w = byte_planes32(b, 3 * v, off)
    if ref is not None:  # ref is vertex-major (x, y, z per vertex), as returned
        w = [(w[c * v + i] + ref[3 * i + c]) & M32 for c in range(3) for i in range(v)]
    return [w[c * v + i] for i in range(v) for c in range(3)]


def sequence(b, n, off):
    w = byte_planes32(b, n, off)
    out = []
    prev = 0
    for x in w:
        prev = (x + prev) & M32
        out.append(prev)
    return out


def med(a, b, c):
    if c >= max(a, b):
        return min(a, b)
    if c <= min(a, b):
        return max(a, b)
    return a + b - c


def mesh_lines(cont, t):
    out = []
    chunks = [c for c in cont.track_chunks(t) if c.stream <= 4]
    index = [c for c in chunks if c.stream == 0]
    if not index:
        return out
    idx = cont.read(index[0])
    version, _flags = struct.unpack_from("<II", idx, 0)
    if version not in (1, 2):
        raise Error("mesh index")
    pos = 56
    (m,) = struct.unpack_from("<I", idx, pos)
    pos += 4 + 24 * m
    (p_count,) = struct.unpack_from("<I", idx, pos)
    protos = [struct.unpack_from("<5I", idx, pos + 4 + 20 * p) for p in range(p_count)]
    pos += 4 + 20 * p_count
    (o_count,) = struct.unpack_from("<I", idx, pos)
    objects = [struct.unpack_from("<6I", idx, pos + 4 + 24 * o) for o in range(o_count)]
    pos += 4 + 24 * o_count
    textures = []
    if version == 2:
        (x_count,) = struct.unpack_from("<I", idx, pos)
        textures = [struct.unpack_from("<4I", idx, pos + 4 + 16 * x) for x in range(x_count)]
    by_key = {(c.stream, c.region): c for c in chunks}

    tri_cache = {}

    def triangles(p):
        if p not in tri_cache:
            _v, tcount, flags, _s, _tof = protos[p]
            data = cont.read(by_key[(2, p)])
            ind = sequence(data, 3 * tcount, 0)
            mats = sequence(data, tcount, 12 * tcount) if flags & 4 else []
            tri_cache[p] = (ind, mats)
        return tri_cache[p]

    for p, (v, _tcount, flags, s, tri_of) in enumerate(protos):
        data = cont.read(by_key[(1, p)])
        off = 0
        positions = vec3_array(data, v, off)
        off += 12 * v
        blob = words_le(positions)
        normals = colours = uvs = []
        if flags & 1:
            normals = vec3_array(data, v, off)
            off += 12 * v
        if flags & 2:
            colours = vec3_array(data, v, off)
            off += 12 * v
        if flags & 8:
            w = byte_planes32(data, 2 * v, off)
            uvs = [w[c * v + i] for i in range(v) for c in range(2)]
            off += 8 * v
        times = sequence(data, s, off)
        off += 4 * s
        states = []
        ref = positions
        for _k in range(s):
            st = vec3_array(data, v, off, ref)
            off += 12 * v
            states += st
            ref = st
        ind, mats = triangles(tri_of)
        blob = words_le(positions + normals + colours + ind + mats + times + states + uvs)
        out.append(f"track {t} prototype {p} {xxh3(blob):016x}")

    for o, (_src, proto, material, n, oflags, k) in enumerate(objects):
        data = cont.read(by_key[(3, o)])
        w = byte_planes32(data, 12 * n, 0)
        transforms = []
        prev = [0] * 12
        for f in range(n):
            cur = [(w[e * n + f] + prev[e]) & M32 for e in range(12)]
            transforms += cur
            prev = cur
        subset = []
        if not oflags & 1:
            (r,) = struct.unpack_from("<I", data, 48 * n)
            gaps = byte_planes32(data, r, 48 * n + 4)
            lens = byte_planes32(data, r, 48 * n + 4 + 4 * r)
            start = 0
            for i in range(r):
                start += gaps[i]
                subset += range(start, start + lens[i])
                start += lens[i]
        blob = words_le([proto, material, 1 if oflags & 1 else 0] + transforms + subset)
        out.append(f"track {t} object {o} {xxh3(blob):016x}")

    for x, (tw, th, coding, _flags) in enumerate(textures):
        data = cont.read(by_key[(4, x)])
        if coding == 1:
            texels = data
        else:
            texels = bytearray(4 * tw * th)
            for ch in range(4):
                plane = data[ch * tw * th:(ch + 1) * tw * th]
                val = [0] * (tw * th)
                for y in range(th):
                    for xx in range(tw):
                        i = y * tw + xx
                        if y == 0 and xx == 0:
                            pred = 0
                        elif y == 0:
                            pred = val[i - 1]
                        elif xx == 0:
                            pred = val[i - tw]
                        else:
                            pred = med(val[i - 1], val[i - tw], val[i - tw - 1])
                        val[i] = (plane[i] + pred) & 0xFF
                        texels[4 * i + ch] = val[i]
        out.append(f"track {t} texture {x} {xxh3(struct.pack('<II', tw, th) + texels):016x}")
    return out


# ---------------------------------------------------------------------------------------------

def clip_lines(path):
    cont = Container(path)
    lines = []
    for t, (kind, _flags, header) in enumerate(cont.tracks):
        if kind == 2:
            lines += tiles_lines(cont, t, header)
        elif kind == 3:
            lines += surfels_lines(cont, t)
        elif kind == 4:
            lines += mesh_lines(cont, t)
    return lines


def main(argv):
    check = False
    if argv and argv[0] == "--check":
        check, argv = True, argv[1:]
    if not argv:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    failed = 0
    for path in argv:
        try:
            lines = clip_lines(path)
        except (Error, struct.error, KeyError, IndexError, lzma.LZMAError,
                zstandard.ZstdError) as e:
            print(f"{path}: cannot decode: {e}", file=sys.stderr)
            failed += 1
            continue
        if not check:
            print("\n".join(lines))
            continue
        expected_path = path[:-len(".calf")] + ".hashes" if path.endswith(".calf") else path
        with open(expected_path, encoding="utf-8") as f:
            expected = f.read().splitlines()
        if lines == expected:
            print(f"{path}: {len(lines)} lines match")
        else:
            failed += 1
            print(f"{path}: MISMATCH", file=sys.stderr)
            for i in range(max(len(lines), len(expected))):
                got = lines[i] if i < len(lines) else "(none)"
                want = expected[i] if i < len(expected) else "(none)"
                if got != want:
                    print(f"  line {i + 1}: got {got!r}, want {want!r}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
