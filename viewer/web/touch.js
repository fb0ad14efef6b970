// SPDX-License-Identifier: Apache-2.0
//
// The page as an input device (viewer/view_protocol.h §4): when the page's address carries the run's token
// (?touch=TOKEN, printed by `viewer --touch`), it asks for the web hand and, while it holds it, steers the hand's
// target with the pointer.
//   - Drag (left button, or one finger on a touch screen): the target moves in the chosen plane through it, by as much
//     as the pointer moves over that plane (grab anywhere; the finger does not jump to the pointer).
//   - Wheel, W/S or PageUp/PageDown: the target moves along the plane's normal, away from or toward the camera.
//   - Right drag (two fingers on a touch screen) turns the camera; the wheel no longer zooms while the page holds.
// A worker (touch_worker.js) holds the page's touch socket and sends the target every 10 ms while the page holds the
// hand: that is its heartbeat, and the hand lets go of a page silent for 40 ms (common/runtime/staleness.h); the page
// tells the worker its target and that it is alive. A hidden page lets go at once and takes the hand again when shown.
// The panel shows who holds the hand and a gauge of the force on the finger; a gamepad that can rumble does so with
// the force.

import * as THREE from 'three';

const ALIVE_MS = 100;                // the page tells its worker it is alive (touch_worker.js: PAGE_SILENT_MS)
const DEPTH_STEP_M = 0.002;         // per wheel notch or key press
const GAUGE_RUMBLE_MIN = 0.05;      // of the device's force limit: below it a gamepad is quiet
const RUMBLE_MS = 60;

export function createTouch({ camera, controls, canvas, finger, force }) {
  const token = new URLSearchParams(location.search).get('touch');
  const panel = document.getElementById('touch');
  const state = {
    enabled: Boolean(token),
    state: token ? 'connecting' : 'off',   // off, connecting, holding, watching, released, refused, unavailable
    reason: '',
    target_m: null,                        // the target the page sends while it holds, [x, y, z]
    hand: null,                            // the device's reply: finger_m, workspace_min_m/max_m, max_force_N
    sent: 0,
    plane: 'camera',
    dragging: false,
  };
  if (!state.enabled) return { state, update() {} };
  panel.classList.add('shown');
  let worker = null;
  function startWorker() {
    worker = new Worker('/touch_worker.js');
    worker.onmessage = (event) => onMessage(event.data);
    worker.postMessage({ kind: 'connect', token });
  }
  const stateLabel = document.getElementById('touch-state');
  const planeSelect = document.getElementById('touch-plane');
  const takeButton = document.getElementById('touch-take');
  const gaugeBar = document.getElementById('touch-gauge-bar');
  const gaugeLabel = document.getElementById('touch-gauge-label');
  let wantHold = true;                     // the person wants the hand (taken on load, again when the page shows)

  const raycaster = new THREE.Raycaster();
  const pointer = new THREE.Vector2();
  const plane = new THREE.Plane();
  const normal = new THREE.Vector3();
  const hit = new THREE.Vector3();
  const grabbed = new THREE.Vector3();     // where the pointer met the plane at the last move
  const target = new THREE.Vector3();

  function show() {
    const words = {
      connecting: 'connecting…',
      holding: 'you hold the hand: drag to move the finger',
      watching: 'watching',
      released: 'released',
      refused: 'refused',
      unavailable: 'unavailable',
    };
    stateLabel.textContent = words[state.state] + (state.reason ? ` — ${state.reason}` : '');
    stateLabel.className = `touch-${state.state}`;
    takeButton.textContent = state.state === 'holding' ? 'let go' : 'take the hand';
    // While the page holds the hand the left button and one finger steer it; the camera turns with the right button
    // or two fingers.
    const holding = state.state === 'holding';
    controls.mouseButtons.LEFT = holding ? -1 : THREE.MOUSE.ROTATE;
    controls.mouseButtons.RIGHT = holding ? THREE.MOUSE.ROTATE : THREE.MOUSE.PAN;
    controls.touches.ONE = holding ? -1 : THREE.TOUCH.ROTATE;
    controls.enableZoom = !holding;
    canvas.style.cursor = holding ? 'grab' : '';
  }

  function take() {
    wantHold = true;
    worker.postMessage({ kind: 'take' });
  }
  function release() {
    worker.postMessage({ kind: 'release' });
    state.state = 'released';
    state.target_m = null;
    show();
  }

  function planeNormal() {
    switch (state.plane) {
      case 'xy': return normal.set(0, 0, 1);
      case 'xz': return normal.set(0, 1, 0);
      case 'yz': return normal.set(1, 0, 0);
      default: return camera.getWorldDirection(normal);
    }
  }

  // Where the pointer's ray meets the drag plane through the target, into `out`; false if it does not.
  function pointerOnPlane(event, out) {
    const rect = canvas.getBoundingClientRect();
    pointer.set(((event.clientX - rect.left) / rect.width) * 2 - 1, -((event.clientY - rect.top) / rect.height) * 2 + 1);
    raycaster.setFromCamera(pointer, camera);
    plane.setFromNormalAndCoplanarPoint(planeNormal(), target);
    return raycaster.ray.intersectPlane(plane, out) !== null;
  }

  function clampToWorkspace() {
    const h = state.hand;
    if (!h || !h.workspace_min_m || !h.workspace_max_m) return;
    target.x = Math.min(Math.max(target.x, h.workspace_min_m[0]), h.workspace_max_m[0]);
    target.y = Math.min(Math.max(target.y, h.workspace_min_m[1]), h.workspace_max_m[1]);
    target.z = Math.min(Math.max(target.z, h.workspace_min_m[2]), h.workspace_max_m[2]);
  }

  function setTarget() {
    clampToWorkspace();
    state.target_m = [target.x, target.y, target.z];
    worker.postMessage({ kind: 'target', target_m: state.target_m });
  }

  canvas.style.touchAction = 'none';       // the page, not the browser, scrolls and zooms on a touch screen
  canvas.addEventListener('pointerdown', (event) => {
    if (state.state !== 'holding' || !event.isPrimary || event.button !== 0) return;
    if (!pointerOnPlane(event, grabbed)) return;
    state.dragging = true;
    canvas.setPointerCapture(event.pointerId);
    canvas.style.cursor = 'grabbing';
  });
  canvas.addEventListener('pointermove', (event) => {
    if (!state.dragging || state.state !== 'holding') return;
    if (!pointerOnPlane(event, hit)) return;
    target.x += hit.x - grabbed.x;
    target.y += hit.y - grabbed.y;
    target.z += hit.z - grabbed.z;
    grabbed.copy(hit);
    setTarget();
  });
  const endDrag = () => {
    state.dragging = false;
    if (state.state === 'holding') canvas.style.cursor = 'grab';
  };
  canvas.addEventListener('pointerup', endDrag);
  canvas.addEventListener('pointercancel', endDrag);

  // Depth: along the plane's normal, a wheel turn away from the person pushes the finger in.
  function moveDepth(steps) {
    if (state.state !== 'holding') return;
    const n = planeNormal();
    if (state.plane !== 'camera' && n.dot(camera.getWorldDirection(hit)) < 0) n.negate();
    target.addScaledVector(n, steps * DEPTH_STEP_M);
    setTarget();
  }
  canvas.addEventListener('wheel', (event) => {
    if (state.state !== 'holding') return;
    event.preventDefault();
    moveDepth(event.deltaY < 0 ? 1 : -1);
  }, { passive: false });
  window.addEventListener('keydown', (event) => {
    if (event.target instanceof HTMLInputElement || event.target instanceof HTMLSelectElement) return;
    if (event.key === 'w' || event.key === 'W' || event.key === 'PageUp') moveDepth(1);
    else if (event.key === 's' || event.key === 'S' || event.key === 'PageDown') moveDepth(-1);
  });

  planeSelect.addEventListener('change', () => { state.plane = planeSelect.value; });
  takeButton.addEventListener('click', () => {
    if (state.state === 'holding') { wantHold = false; release(); } else take();
  });

  // A hidden page cannot be watched by the person steering it: it lets go at once, and takes the hand again when shown.
  document.addEventListener('visibilitychange', () => {
    if (document.hidden) {
      const held = state.state === 'holding';
      release();
      wantHold = held || wantHold;
    } else if (wantHold) {
      take();
    }
  });

  // A page being closed or navigated away lets go at once: its worker ends, and with it the touch socket, which the
  // viewer takes as the page's end (the page's own teardown, or its silence, would say so only later). A page that
  // comes back from the browser's cache starts a new worker.
  window.addEventListener('pagehide', () => {
    release();
    worker.terminate();
  });
  window.addEventListener('pageshow', (event) => {
    if (!event.persisted) return;
    startWorker();
  });

  // The page is alive while this timer runs; a hidden page has let go, and says nothing.
  setInterval(() => {
    if (!document.hidden) worker.postMessage({ kind: 'alive' });
  }, ALIVE_MS);

  let lastRumble = 0;
  function update(now) {
    const f = force();
    const limit = state.hand && state.hand.max_force_N > 0 ? state.hand.max_force_N : 10;
    const magnitude = f ? Math.hypot(f[0], f[1], f[2]) : 0;
    const share = Math.min(magnitude / limit, 1);
    gaugeBar.style.width = `${(share * 100).toFixed(1)}%`;
    gaugeBar.classList.toggle('high', share > 0.8);
    gaugeLabel.textContent = `${magnitude.toFixed(2)} N of ${limit.toFixed(0)} N`;
    if (state.state === 'holding' && share > GAUGE_RUMBLE_MIN && now - lastRumble >= RUMBLE_MS
        && navigator.getGamepads) {
      lastRumble = now;
      for (const pad of navigator.getGamepads()) {
        const actuator = pad && pad.vibrationActuator;
        if (actuator && actuator.playEffect) {
          actuator.playEffect('dual-rumble', { duration: RUMBLE_MS, strongMagnitude: share, weakMagnitude: share })
            .catch(() => {});
        }
      }
    }
  }

  function onMessage(message) {
    if (message.type === 'sent') {
      state.sent++;
      return;
    }
    if (message.type === 'socket') {
      if (message.open && wantHold && !document.hidden) take();
      if (!message.open) {
        state.state = 'connecting';
        state.target_m = null;
        show();
      }
      return;
    }
    state.state = typeof message.state === 'string' ? message.state : 'unavailable';
    state.reason = typeof message.reason === 'string' ? message.reason : '';
    if (message.hand && typeof message.hand === 'object') state.hand = message.hand;
    if (state.state === 'holding' && !state.target_m) {
      // The hand takes the fingertip where it rests: the target starts there.
      const start = (state.hand && state.hand.finger_m) || finger();
      if (start) {
        target.set(start[0], start[1], start[2]);
        setTarget();
      }
    }
    if (state.state !== 'holding') {
      state.target_m = null;
      state.dragging = false;
    }
    show();
  }

  startWorker();
  show();
  return { state, update };
}
