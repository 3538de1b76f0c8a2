// Frames the browser tests compare: calf-play's PNG frames read back, and PSNR between two.
import { readFileSync } from 'node:fs';
import { inflateSync } from 'node:zlib';

// An 8-bit RGB PNG (what calf-play writes) as rows of RGB bytes.
export function readPng(file) {
  const b = readFileSync(file);
  let at = 8, width = 0, height = 0;
  const idat = [];
  while (at < b.length) {
    const n = b.readUInt32BE(at), type = b.toString('latin1', at + 4, at + 8), data = b.subarray(at + 8, at + 8 + n);
    if (type === 'IHDR') {
      width = data.readUInt32BE(0); height = data.readUInt32BE(4);
      if (data[8] !== 8 || data[9] !== 2 || data[12] !== 0) throw new Error(`${file}: not an 8-bit RGB PNG`);
    } else if (type === 'IDAT') idat.push(data);
    at += 12 + n;
  }
  const raw = inflateSync(Buffer.concat(idat)), stride = 3 * width, out = new Uint8Array(stride * height);
  for (let y = 0; y < height; ++y) {
    const filter = raw[y * (stride + 1)], row = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let x = 0; x < stride; ++x) {
      const a = x >= 3 ? out[y * stride + x - 3] : 0, up = y > 0 ? out[(y - 1) * stride + x] : 0;
      const c = x >= 3 && y > 0 ? out[(y - 1) * stride + x - 3] : 0;
      let p = 0;
      if (filter === 1) p = a; else if (filter === 2) p = up; else if (filter === 3) p = (a + up) >> 1;
      else if (filter === 4) {
        const e = a + up - c, pa = Math.abs(e - a), pb = Math.abs(e - up), pc = Math.abs(e - c);
        p = pa <= pb && pa <= pc ? a : pb <= pc ? up : c;
      }
      out[y * stride + x] = (row[x] + p) & 255;
    }
  }
  return { width, height, rgb: out };
}

export function psnr(a, b) {
  let se = 0;
  for (let i = 0; i < a.length; ++i) se += (a[i] - b[i]) ** 2;
  return se === 0 ? Infinity : 10 * Math.log10((255 * 255) / (se / a.length));
}
