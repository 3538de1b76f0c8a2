// The page's inline (non-XR) viewer: drag with the mouse, or a finger on a touch screen, to look
// around; W A S D (or the arrow keys) to move along the view and sideways while held. `step()`
// moves the eye by one frame's worth of the held keys and returns the camera's axes.
const KEYS = { w: 'forward', arrowup: 'forward', s: 'back', arrowdown: 'back', a: 'left', arrowleft: 'left', d: 'right', arrowright: 'right' };

// target: the element that takes pointer drags (the canvas); eye: [x, y, z], moved in place
// (state.eye: the page sets another when another clip opens).
export function inlineControls(target, eye, { speed = 0.02, turn = 0.005 } = {}) {
  const state = { eye, yaw: 0, pitch: 0, held: new Set(), pointer: null };
  const look = (dx, dy) => {
    state.yaw -= dx * turn;
    state.pitch = Math.max(-1.5, Math.min(1.5, state.pitch - dy * turn));
  };
  target.style.touchAction = 'none';  // a finger's drag looks instead of scrolling the page
  target.addEventListener('pointerdown', (e) => {
    state.pointer = { id: e.pointerId, x: e.clientX, y: e.clientY };
    target.setPointerCapture?.(e.pointerId);
  });
  target.addEventListener('pointermove', (e) => {
    const p = state.pointer;
    if (!p || p.id !== e.pointerId) return;
    look(e.clientX - p.x, e.clientY - p.y);
    p.x = e.clientX;
    p.y = e.clientY;
  });
  const release = (e) => { if (state.pointer?.id === e.pointerId) state.pointer = null; };
  target.addEventListener('pointerup', release);
  target.addEventListener('pointercancel', release);
  addEventListener('keydown', (e) => { if (KEYS[e.key.toLowerCase()]) state.held.add(KEYS[e.key.toLowerCase()]); });
  addEventListener('keyup', (e) => state.held.delete(KEYS[e.key.toLowerCase()]));
  addEventListener('blur', () => state.held.clear());
  // The camera's forward and right axes (yaw about +y, pitch up; yaw 0 looks down -z).
  state.axes = () => {
    const cy = Math.cos(state.yaw), sy = Math.sin(state.yaw), cp = Math.cos(state.pitch), sp = Math.sin(state.pitch);
    return { forward: [-sy * cp, sp, -cy * cp], right: [cy, 0, -sy], up: [0, 1, 0] };
  };
  state.step = () => {
    const axes = state.axes(), h = state.held;
    const move = speed * ((h.has('forward') ? 1 : 0) - (h.has('back') ? 1 : 0));
    const strafe = speed * ((h.has('right') ? 1 : 0) - (h.has('left') ? 1 : 0));
    for (let k = 0; k < 3; ++k) state.eye[k] += move * axes.forward[k] + strafe * axes.right[k];
    return axes;
  };
  return state;
}
