#!/usr/bin/python3
"""Bytes against PSNR of AV1 colour layouts beside x265, on a capture set's 8-bit sRGB faces.

The measurement behind docs/ENCODER.md "AV1 colour" ("Which remedy"): the faces of every view and
frame of a calf capture set (EXR, as calf-blender writes) as the bench's peer sees them (linear ->
8-bit sRGB, HDR values clipped to 1), coded

  x265            every view's six faces in a row, all views in one picture a frame (384 x 576 for
                  9 views of 64^2), libx265 preset medium, yuv444p (the bench's x265 peer);
  face-svt420     one stream per face, SVT-AV1 preset 5, 4:2:0 (calf's --av1-chroma 420);
  face-aom444     one stream per face, libaom cpu-used 5, 4:4:4 (calf's --av1-chroma 444);
  view-svt420     one stream per view, its faces in a 3 x 2 atlas, SVT-AV1 4:2:0;
  view-aom444     the same atlas, libaom 4:4:4;

each AV1 layout with --hdr coding calf's av1hdr codes (format/SPEC.md 11.1.12: 10-bit codes of
half-float bits on a per-cell curve, BT.709 full range, 4:2:0 chroma as the mean of 2 x 2) as
calf-encode does for HDR captures, without: 8-bit sRGB. Prints one line per CRF: bytes (AV1: the
OBUs, IVF framing left out) and the mean per-frame PSNR of the decoded faces against the sRGB
faces; `--ratio LOG...` then prints each line's bytes over x265's at the same PSNR (x265's
curve interpolated in log bytes). Needs ffmpeg with libx265, libsvtav1 and libaom-av1, numpy.

  tools/av1_layout_study.py CAPTURE MODE CRF[,CRF...] [--hdr]   > log
  tools/av1_layout_study.py --ratio log...
"""
import json
import math
import os
import re
import subprocess
import sys
import tempfile
from collections import defaultdict

KR, KB = 0.2126, 0.0722
KG = 1 - KR - KB


def ratios(logs):
    rows = defaultdict(list)
    for fn in logs:
        for line in open(fn):
            m = re.match(r'(\S+) (\S+) crf (\d+) bytes (\d+) psnr ([\d.]+)', line)
            if m:
                rows[(m[1], m[2])].append((int(m[3]), int(m[4]), float(m[5])))

    def x265_at(cap, p):
        pts = sorted(rows[(cap, 'x265')], key=lambda r: r[2])
        for a, b in zip(pts, pts[1:]):
            if a[2] <= p <= b[2]:
                f = (p - a[2]) / (b[2] - a[2])
                return math.exp(math.log(a[1]) + f * (math.log(b[1]) - math.log(a[1])))
        return None
    for (cap, mode), rs in sorted(rows.items()):
        if mode == 'x265':
            continue
        cells = []
        for crf, n, p in rs:
            x = x265_at(cap, p)
            cells.append(f'CRF {crf}: {n} B, {p:.2f} dB, ' + (f'{n / x:.2f}x' if x else 'n/a'))
        print(f'{cap} {mode}: ' + ' | '.join(cells))


def main():
    if sys.argv[1] == '--ratio':
        return ratios(sys.argv[2:])
    import numpy as np
    cap, mode, crfs = sys.argv[1], sys.argv[2], [int(c) for c in sys.argv[3].split(',')]
    hdr = '--hdr' in sys.argv[4:]
    m = json.load(open(os.path.join(cap, 'manifest.json')))
    F, V, S = m['frame_count'], len(m['viewpoints']), m['face_size']

    def load(v, f):  # an EXR's 6 faces (a strip 6S high) as linear RGB, 6 x S x S x 3
        p = os.path.join(cap, m['file_pattern'].format(view=v, frame=f))
        raw = subprocess.run(['ffmpeg', '-v', 'error', '-i', p, '-f', 'rawvideo', '-pix_fmt',
                              'gbrpf32le', '-'], capture_output=True, check=True).stdout
        a = np.frombuffer(raw, np.float32).reshape(3, 6 * S, S)
        return np.stack([a[2], a[0], a[1]], -1).reshape(6, S, S, 3)
    lin = np.stack([np.stack([load(v, f) for v in range(V)]) for f in range(F)])

    def srgb8(x):
        x = np.clip(x, 0, 1)
        s = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
        return np.round(s * 255).astype(np.uint8)

    def grid(fc):  # F x V x 6 x S x S x 3 -> F x (V S) x (6 S) x 3
        return fc.transpose(0, 1, 3, 2, 4, 5).reshape(F, V * S, 6 * S, 3)
    G = grid(srgb8(lin))

    def psnr(a, b):
        out = []
        for f in range(F):
            mse = np.mean((a[f].astype(np.float64) - b[f].astype(np.float64)) ** 2)
            out.append(100 if mse == 0 else min(100, 10 * np.log10(255 * 255 / mse)))
        return float(np.mean(out))
    tmp = tempfile.mkdtemp()

    def run(args):
        subprocess.run(args, check=True, stderr=subprocess.DEVNULL)

    def x265(frames, crf):
        h, w = frames.shape[1:3]
        inp, out = os.path.join(tmp, 'in.rgb'), os.path.join(tmp, 'out.hevc')
        frames.tofile(inp)
        run(['ffmpeg', '-v', 'error', '-y', '-f', 'rawvideo', '-pix_fmt', 'rgb24', '-s', f'{w}x{h}',
             '-r', '24', '-i', inp, '-c:v', 'libx265', '-preset', 'medium', '-crf', str(crf),
             '-pix_fmt', 'yuv444p', '-x265-params', 'log-level=error', '-f', 'hevc', out])
        dec = subprocess.run(['ffmpeg', '-v', 'error', '-i', out, '-f', 'rawvideo', '-pix_fmt',
                              'rgb24', '-'], capture_output=True, check=True).stdout
        return os.path.getsize(out), np.frombuffer(dec, np.uint8).reshape(F, h, w, 3)

    def av1(rgb, bits, enc, crf):  # rgb: F x h x w x 3 codes of `bits` -> bytes, decoded codes
        h, w = rgb.shape[1:3]
        top = (1 << bits) - 1
        half = (top + 1) / 2
        x = rgb.astype(np.float64)
        Y = KR * x[..., 0] + KG * x[..., 1] + KB * x[..., 2]
        Cb = half + (x[..., 2] - Y) / (2 * (1 - KB))
        Cr = half + (x[..., 0] - Y) / (2 * (1 - KR))
        sub = enc == 'svt420'
        if sub:
            Cb = Cb.reshape(F, h // 2, 2, w // 2, 2).mean((2, 4))
            Cr = Cr.reshape(F, h // 2, 2, w // 2, 2).mean((2, 4))
        dtype = np.uint8 if bits == 8 else np.uint16
        pf = ('yuv420p' if sub else 'yuv444p') + ('' if bits == 8 else '10le')

        def q(a):
            return np.clip(np.round(a), 0, top).astype(dtype).reshape(F, -1)
        inp, out = os.path.join(tmp, 'in.yuv'), os.path.join(tmp, 'out.ivf')
        np.concatenate([q(Y), q(Cb), q(Cr)], 1).tofile(inp)
        head = ['ffmpeg', '-v', 'error', '-y', '-f', 'rawvideo', '-pix_fmt', pf, '-s', f'{w}x{h}',
                '-r', '24', '-i', inp]
        if sub:
            codec = ['-c:v', 'libsvtav1', '-preset', '5', '-crf', str(crf), '-g', '999',
                     '-svtav1-params', 'lp=1']
        else:
            codec = ['-c:v', 'libaom-av1', '-cpu-used', '5', '-crf', str(crf), '-b:v', '0', '-g',
                     '999', '-threads', '1']
        run(head + codec + ['-f', 'ivf', out])
        n = os.path.getsize(out) - 32 - 12 * F
        dec = subprocess.run(['ffmpeg', '-v', 'error', '-i', out, '-f', 'rawvideo', '-pix_fmt', pf,
                              '-'], capture_output=True, check=True).stdout
        d = np.frombuffer(dec, dtype).reshape(F, -1).astype(np.int64)
        c = (h // 2) * (w // 2) if sub else h * w
        Yd = d[:, :h * w].reshape(F, h, w)

        def plane(k):
            p = d[:, h * w + k * c:h * w + (k + 1) * c]
            if sub:
                return p.reshape(F, h // 2, w // 2).repeat(2, 1).repeat(2, 2) - int(half)
            return p.reshape(F, h, w) - int(half)
        u, v = plane(0), plane(1)
        R = Yd + ((103206 * v + 32768) >> 16)
        Gc = Yd - ((12276 * u + 30679 * v + 32768) >> 16)
        B = Yd + ((121609 * u + 32768) >> 16)
        return n, np.clip(np.stack([R, Gc, B], -1), 0, top)

    def halfbits(x):
        return np.minimum(np.clip(x, 0, 65504).astype(np.float16).view(np.uint16).astype(np.int64),
                          0x7BFF)
    name = os.path.basename(os.path.normpath(cap))
    label = ('hdr-' if hdr else '') + mode
    for crf in crfs:
        if mode == 'x265':
            n, d = x265(G, crf)
            print(f'{name} x265 crf {crf} bytes {n} psnr {psnr(G, d):.3f}', flush=True)
            continue
        kind, enc = mode.split('-')
        n, rec = 0, np.zeros_like(lin)
        for v in range(V):
            for cell in ([[i] for i in range(6)] if kind == 'face' else [list(range(6))]):
                sel = lin[:, v, cell]
                if hdr:  # calf's av1hdr curve over the cell (encoder/src/colour_av1.cc hdr_curve)
                    hb = halfbits(sel)
                    base, sh = max(int(hb.min()), 0x400), 0
                    while sh < 5 and base + (1023 << sh) < int(hb.max()):
                        sh += 1
                    codes = np.minimum(np.where(hb <= base, 0, (hb - base + ((1 << sh) >> 1)) >> sh),
                                       1023)
                else:
                    codes = srgb8(sel).astype(np.int64)
                if kind == 'face':
                    pic = codes[:, 0]
                else:
                    pic = codes.reshape(F, 2, 3, S, S, 3).transpose(0, 1, 3, 2, 4, 5).reshape(
                        F, 2 * S, 3 * S, 3)
                k, d = av1(pic, 10 if hdr else 8, enc, crf)
                n += k
                if hdr:
                    back = np.minimum(base + (d << sh), 0x7BFF).astype(np.uint16).view(
                        np.float16).astype(np.float32)
                else:  # sRGB codes back to linear for one path: decode through srgb8 below
                    c = d / 255.0
                    back = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)
                if kind == 'face':
                    rec[:, v, cell[0]] = back
                else:
                    rec[:, v] = back.reshape(F, 2, S, 3, S, 3).transpose(0, 1, 3, 2, 4, 5).reshape(
                        F, 6, S, S, 3)
        print(f'{name} {label} crf {crf} bytes {n} psnr {psnr(G, grid(srgb8(rec))):.3f}',
              flush=True)


if __name__ == '__main__':
    main()
