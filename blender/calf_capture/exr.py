"""Minimal OpenEXR scanline reader and writer in plain Python (no numpy, no OpenEXR module).

Blender's bundled or system Python has neither numpy nor an OpenEXR binding everywhere, so the
add-on reads the uncompressed multilayer EXR that Cycles writes for each face and writes calf's
capture images itself. Only what the add-on needs: single-part scanline files, compression NONE,
HALF and FLOAT channels, increasing line order. Values are lists of floats, row 0 at the top.
"""

import os
import struct

_MAGIC = b"\x76\x2f\x31\x01"
_HALF, _FLOAT = 1, 2
_COMPRESSION_NONE = 0


class ExrError(Exception):
    """An EXR file this module cannot read or write (the message names the file)."""


def _attribute(name, kind, payload):
    return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(payload)) + payload


def write_exr(path, width, height, channels):
    """Writes `channels` ({name: (type, values)}, type "HALF" or "FLOAT", values a row-major list of
    width * height floats, row 0 at the top) as an uncompressed scanline EXR, whole: to
    `path + ".tmp"`, then renamed to `path`."""
    names = sorted(channels)  # EXR stores channels in alphabetical order
    chlist = b""
    for name in names:
        kind = _HALF if channels[name][0] == "HALF" else _FLOAT
        chlist += name.encode() + b"\0" + struct.pack("<iB3xii", kind, 0, 1, 1)
    chlist += b"\0"
    box = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    header = _MAGIC + struct.pack("<i", 2)
    header += _attribute("channels", "chlist", chlist)
    header += _attribute("compression", "compression", bytes([_COMPRESSION_NONE]))
    header += _attribute("dataWindow", "box2i", box)
    header += _attribute("displayWindow", "box2i", box)
    header += _attribute("lineOrder", "lineOrder", bytes([0]))
    header += _attribute("pixelAspectRatio", "float", struct.pack("<f", 1.0))
    header += _attribute("screenWindowCenter", "v2f", struct.pack("<ff", 0.0, 0.0))
    header += _attribute("screenWindowWidth", "float", struct.pack("<f", 1.0))
    header += b"\0"
    line_bytes = sum(width * (2 if channels[n][0] == "HALF" else 4) for n in names)
    table_end = len(header) + 8 * height
    offsets = b"".join(struct.pack("<Q", table_end + y * (8 + line_bytes)) for y in range(height))
    formats = {n: "<%d%s" % (width, "e" if channels[n][0] == "HALF" else "f") for n in names}
    tmp = path + ".tmp"
    try:
        with open(tmp, "wb") as f:
            f.write(header)
            f.write(offsets)
            for y in range(height):
                row = [struct.pack("<ii", y, line_bytes)]
                for n in names:
                    values = channels[n][1][y * width:(y + 1) * width]
                    row.append(struct.pack(formats[n], *values))
                f.write(b"".join(row))
        os.replace(tmp, path)
    except BaseException:
        try:
            os.remove(tmp)
        except OSError:
            pass
        raise


def read_exr(path):
    """Reads an uncompressed single-part scanline EXR: (width, height, {name: list of floats}),
    row-major, row 0 at the top of the data window."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != _MAGIC:
        raise ExrError("%s: not an OpenEXR file" % path)
    if struct.unpack_from("<i", data, 4)[0] & 0x1A00:  # tiled, deep or multi-part (0x400, long names, is fine)
        raise ExrError("%s: tiled, deep or multi-part EXR (want single-part scanline)" % path)
    at = 8
    channels, compression, window = [], None, None
    while data[at] != 0:
        end = data.index(b"\0", at)
        name = data[at:end].decode()
        end2 = data.index(b"\0", end + 1)
        kind = data[end + 1:end2].decode()
        size = struct.unpack_from("<i", data, end2 + 1)[0]
        value = data[end2 + 5:end2 + 5 + size]
        at = end2 + 5 + size
        if name == "channels" and kind == "chlist":
            c = 0
            while value[c] != 0:
                e = value.index(b"\0", c)
                pixel_type = struct.unpack_from("<i", value, e + 1)[0]
                channels.append((value[c:e].decode(), pixel_type))
                c = e + 17
        elif name == "compression":
            compression = value[0]
        elif name == "dataWindow":
            window = struct.unpack("<iiii", value)
    at += 1
    if compression != _COMPRESSION_NONE:
        raise ExrError("%s: compression %s (this reader takes NONE only)" % (path, compression))
    if window is None or not channels:
        raise ExrError("%s: no dataWindow or channels" % path)
    width, height = window[2] - window[0] + 1, window[3] - window[1] + 1
    sizes = {_HALF: 2, _FLOAT: 4}
    for name, pixel_type in channels:
        if pixel_type not in sizes:
            raise ExrError("%s: channel %s is not HALF or FLOAT" % (path, name))
    out = {name: [0.0] * (width * height) for name, _ in channels}
    offsets = struct.unpack_from("<%dQ" % height, data, at)
    for offset in offsets:
        y = struct.unpack_from("<i", data, offset)[0] - window[1]
        p = offset + 8
        for name, pixel_type in channels:
            fmt = "<%d%s" % (width, "e" if pixel_type == _HALF else "f")
            out[name][y * width:(y + 1) * width] = struct.unpack_from(fmt, data, p)
            p += width * sizes[pixel_type]
    return width, height, out
