// The cells a frame needs (docs/DECODER.md, "One frame", step 1): per active view and face, the
// cells whose frustum (apex at the viewpoint, through the cell's corners, from the view's z_near
// to a far cap past the viewer's far plane) meets the viewer's frustum, united with the sky set
// (the cell frustum placed at the eye). The exact separating-axis test of
// format/src/geometry.cc over every cell (the native decoder's brute-force search, which gives
// the same sets as its hierarchical one); the same for depth regions on their own grid.
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const len = (a) => Math.sqrt(dot(a, a));
const normalize = (a) => scale(a, 1 / len(a));

// direction_from_face_coord (format/src/cube.cc; SPEC §11.1.1's face table).
function faceDirection(face, s, t) {
  const sc = 2 * s - 1, tc = 2 * t - 1;
  const v = [[1, -tc, -sc], [-1, -tc, sc], [sc, 1, tc], [sc, -1, -tc], [sc, -tc, 1], [-sc, -tc, -1]][face];
  return normalize(v);
}

// A convex frustum from 4 near and 4 far corners (Frustum's constructor).
function frustum(n, f) {
  const corners = [...n, ...f], normals = [], edges = [], offsets = [];
  for (let i = 0; i < 4; ++i) {
    const j = (i + 1) % 4;
    normals[i] = cross(sub(n[j], n[i]), sub(f[i], n[i]));
    edges[i] = sub(f[i], n[i]);
  }
  normals[4] = cross(sub(n[1], n[0]), sub(n[3], n[0]));
  normals[5] = cross(sub(f[1], f[0]), sub(f[3], f[0]));
  edges[4] = sub(n[1], n[0]);
  edges[5] = sub(n[3], n[0]);
  let centroid = [0, 0, 0];
  for (const c of corners) centroid = add(centroid, scale(c, 1 / 8));
  const onFace = [n[0], n[1], n[2], n[3], n[0], f[0]];
  for (let i = 0; i < 6; ++i) {
    if (dot(normals[i], sub(centroid, onFace[i])) < 0) normals[i] = scale(normals[i], -1);
    offsets[i] = dot(normals[i], onFace[i]);
  }
  return { corners, normals, edges, offsets };
}

function contains(fr, p) {
  for (let i = 0; i < 6; ++i) if (dot(fr.normals[i], p) < fr.offsets[i]) return false;
  return true;
}

function separatedOn(axis, a, b) {
  let aMin = Infinity, aMax = -Infinity, bMin = Infinity, bMax = -Infinity;
  for (const p of a.corners) { const d = dot(axis, p); aMin = Math.min(aMin, d); aMax = Math.max(aMax, d); }
  for (const p of b.corners) { const d = dot(axis, p); bMin = Math.min(bMin, d); bMax = Math.max(bMax, d); }
  const tolerance = 1e-12 * Math.max(Math.abs(aMin), Math.abs(aMax), Math.abs(bMin), Math.abs(bMax));
  return aMax < bMin - tolerance || bMax < aMin - tolerance;
}

// frusta_intersect (format/src/geometry.cc).
export function frustaIntersect(a, b) {
  for (const axis of a.normals) if (separatedOn(axis, a, b)) return false;
  for (const axis of b.normals) if (separatedOn(axis, a, b)) return false;
  for (const p of a.corners) if (contains(b, p)) return true;
  for (const p of b.corners) if (contains(a, p)) return true;
  for (const ea of a.edges) {
    for (const eb of b.edges) {
      const axis = cross(ea, eb);
      if (dot(axis, axis) <= 1e-24 * dot(ea, ea) * dot(eb, eb)) continue;
      if (separatedOn(axis, a, b)) return false;
    }
  }
  return true;
}

// eye_frustum: camera { position, forward, up, fovY, width, height } from near to far.
export function eyeFrustum(camera, near, far) {
  const f = normalize(camera.forward), r = normalize(cross(f, camera.up)), u = cross(r, f);
  const ty = Math.tan(camera.fovY / 2), tx = ty * (camera.width / camera.height);
  const sx = [-1, 1, 1, -1], sy = [-1, -1, 1, 1], n = [], fa = [];
  for (let i = 0; i < 4; ++i) {
    const dir = add(f, add(scale(r, sx[i] * tx), scale(u, sy[i] * ty)));
    n.push(add(camera.position, scale(dir, near)));
    fa.push(add(camera.position, scale(dir, far)));
  }
  return frustum(n, fa);
}

// kRenderReachTexels (calf/decoder/culling.h): each cell's rect is tested grown by this much, so
// that every texel a visible point's colour reads (bilinear and sharpened taps) is decoded.
export const RENDER_REACH_TEXELS = 2;

// cell_directions + cell_frustum_corners for one rect of a face, grown by RENDER_REACH_TEXELS.
function cellFrustum(apex, face, faceSize, rect, zNear, zFar) {
  const g = RENDER_REACH_TEXELS;
  const u0 = rect.x - g, v0 = rect.y - g, u1 = rect.x + rect.w + g, v1 = rect.y + rect.h + g;
  const us = [u0, u1, u1, u0], vs = [v0, v0, v1, v1];
  const axis = faceDirection(face, 0.5, 0.5);
  const dirs = [], cos = [];
  let minCos = Infinity;
  for (let i = 0; i < 4; ++i) {
    dirs[i] = faceDirection(face, us[i] / faceSize, vs[i] / faceSize);
    cos[i] = dot(dirs[i], axis);
    minCos = Math.min(minCos, cos[i]);
  }
  const half = faceSize / 2;
  const cu = Math.min(Math.max(half, u0), u1), cv = Math.min(Math.max(half, v0), v1);
  const maxCos = dot(faceDirection(face, cu / faceSize, cv / faceSize), axis);
  const nearAxial = zNear * minCos, farAxial = zFar * maxCos, n = [], f = [];
  for (let i = 0; i < 4; ++i) {
    n.push(add(apex, scale(dirs[i], nearAxial / cos[i])));
    f.push(add(apex, scale(dirs[i], farAxial / cos[i])));
  }
  return frustum(n, f);
}

// The cells of `grid` (faceGrid) on `face` seen from `apex` whose frustum meets `eye`.
function visible(apex, face, grid, faceSize, zNear, zFar, eye) {
  const out = new Set();
  for (let r = 0; r < grid.count; ++r) {
    if (frustaIntersect(eye, cellFrustum(apex, face, faceSize, grid.rect(r), zNear, zFar))) out.add(r);
  }
  return out;
}

// For one eye (camera with the march range's near and far): per active view, per face, the
// colour cells and depth regions the frame needs: { cells: [Set × 6], tiles: [Set × 6] } by view.
export function visibleSets(lf, camera, near, far, active) {
  const N = lf.header.face_size, eye = eyeFrustum(camera, near, far), out = new Map();
  const sky = { cells: [], tiles: [] };
  for (let f = 0; f < 6; ++f) {
    sky.cells[f] = visible(camera.position, f, lf.cells, N, near, 2 * far, eye);
    sky.tiles[f] = visible(camera.position, f, lf.tiles, N, near, 2 * far, eye);
  }
  for (const v of active) {
    const info = lf.views[v];
    const zFar = Math.max(info.zFar, len(sub(camera.position, info.position)) + far);
    const sets = { cells: [], tiles: [] };
    for (let f = 0; f < 6; ++f) {
      sets.cells[f] = new Set([...visible(info.position, f, lf.cells, N, info.zNear, zFar, eye), ...sky.cells[f]]);
      sets.tiles[f] = new Set([...visible(info.position, f, lf.tiles, N, info.zNear, zFar, eye), ...sky.tiles[f]]);
    }
    out.set(v, sets);
  }
  return out;
}
