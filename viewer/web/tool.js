// SPDX-License-Identifier: Apache-2.0
//
// A tool in the hand (viewer/view_protocol.h: the scene's "tool", a frame's tool values), drawn twice:
//   - solid where the servo holds it, the proxy's pose: the tool as the world meets it, out of every object;
//   - as a faint ghost where the hand holds the grip: the gap between the two is what the coupling's spring pulls on,
//     the force and torque the hand feels.
// The torque on the grip is drawn as an arrow along its axis from the grip's centre (the force arrow is the
// endpoint's).

import * as THREE from 'three';

export const TOOL_VALUES = 21;
// Offsets from the tool's first value.
const T_VALID = 0;
const T_GRIP = 1;     // x y z qw qx qy qz
const T_PROXY = 8;    // x y z qw qx qy qz
const T_FORCE = 15;
const T_TORQUE = 18;

const TORQUE_M_PER_NM = 0.2;   // torque arrow: 2 cm per 0.1 N·m (a tool's torques are tenths of a newton metre)
const TORQUE_MIN_NM = 1e-4;    // below this the arrow is hidden

const solidMaterial = new THREE.MeshStandardMaterial({ color: 0xe3a857, roughness: 0.45, metalness: 0.15 });
// The grip's ghost shows through the objects the hand has pushed it into.
const ghostMaterial = new THREE.MeshBasicMaterial({ color: 0x5fd3f3, transparent: true, opacity: 0.25,
                                                    depthTest: false, depthWrite: false });
const ghostEdgeMaterial = new THREE.LineBasicMaterial({ color: 0x5fd3f3, transparent: true, opacity: 0.7,
                                                        depthTest: false });
const UP = new THREE.Vector3(0, 0, 1);

// `root`: the group the tool is drawn in. `geometryOf(shape)`: a shape's solid in its own frame (viewer.js
// solidGeometry); `shapeOf(entry)`: the page's shape of a scene entry (viewer.js shapeOf).
export function createTool({ root, geometryOf, shapeOf }) {
  let visual = null;
  const qa = new THREE.Quaternion();
  const qb = new THREE.Quaternion();
  const axis = new THREE.Vector3();

  // A pose (position, quaternion) from values at `o` (x y z qw qx qy qz), moved `alpha` of the way from `p` at `po`
  // when there is a previous one.
  function placeAt(object, l, o, p, po, alpha) {
    if (p) {
      object.position.set(p[po] + (l[o] - p[po]) * alpha, p[po + 1] + (l[o + 1] - p[po + 1]) * alpha,
                          p[po + 2] + (l[o + 2] - p[po + 2]) * alpha);
      qa.set(p[po + 4], p[po + 5], p[po + 6], p[po + 3]).normalize();
      qb.set(l[o + 4], l[o + 5], l[o + 6], l[o + 3]).normalize();
      object.quaternion.copy(qa.slerp(qb, alpha));
    } else {
      object.position.set(l[o], l[o + 1], l[o + 2]);
      object.quaternion.set(l[o + 4], l[o + 5], l[o + 6], l[o + 3]).normalize();
    }
  }

  // The tool's shape placed in a grip frame (a group moved to the grip's pose each frame).
  function shapeInGrip(geometry, material, placement) {
    const grip = new THREE.Group();
    const mesh = new THREE.Mesh(geometry, material);
    const p = placement && Array.isArray(placement.position_m) ? placement.position_m : [0, 0, 0];
    const q = placement && Array.isArray(placement.orientation_wxyz) ? placement.orientation_wxyz : [1, 0, 0, 0];
    mesh.position.set(p[0], p[1], p[2]);
    mesh.quaternion.set(q[1], q[2], q[3], q[0]).normalize();
    grip.add(mesh);
    return { grip, mesh };
  }

  return {
    // A new scene: builds the tool it carries (none: nothing drawn).
    build(sceneTool) {
      if (visual) {
        visual.geometry.dispose();
        visual.edges.dispose();
        visual.torque.dispose();
        root.clear();
        visual = null;
      }
      if (!sceneTool || typeof sceneTool !== 'object') return;
      const geometry = geometryOf(shapeOf(sceneTool));
      const edges = new THREE.EdgesGeometry(geometry, 30);
      const solid = shapeInGrip(geometry, solidMaterial, sceneTool.placement);
      const ghost = shapeInGrip(geometry, ghostMaterial, sceneTool.placement);
      ghost.mesh.add(new THREE.LineSegments(edges, ghostEdgeMaterial));
      ghost.mesh.renderOrder = 9;
      const torque = new THREE.ArrowHelper(UP, new THREE.Vector3(), 0.01, 0xc77dff);
      torque.line.material.depthTest = false;
      torque.cone.material.depthTest = false;
      torque.renderOrder = 11;
      root.add(solid.grip, ghost.grip, torque);
      visual = { geometry, edges, solid: solid.grip, ghost: ghost.grip, torque };
      for (const object of [visual.solid, visual.ghost, visual.torque]) object.visible = false;
    },

    // Places the tool of frame data `l` (its values at `o`, or o < 0: none), `alpha` of the way from frame data `p`
    // (values at `po`; p null: the latest's alone).
    draw(l, o, p, po, alpha) {
      if (!visual) return;
      const valid = o >= 0 && l[o + T_VALID] === 1;
      visual.solid.visible = visual.ghost.visible = valid;
      visual.torque.visible = false;
      if (!valid) return;
      const from = p && po >= 0 && p[po + T_VALID] === 1 && alpha < 1 ? p : null;
      placeAt(visual.solid, l, o + T_PROXY, from, po + T_PROXY, alpha);
      placeAt(visual.ghost, l, o + T_GRIP, from, po + T_GRIP, alpha);
      axis.set(l[o + T_TORQUE], l[o + T_TORQUE + 1], l[o + T_TORQUE + 2]);
      const magnitude = axis.length();
      if (!(magnitude >= TORQUE_MIN_NM) || !Number.isFinite(magnitude)) return;
      const length = magnitude * TORQUE_M_PER_NM;
      const head = Math.min(length * 0.35, 0.005);
      visual.torque.position.copy(visual.ghost.position);
      visual.torque.setDirection(axis.divideScalar(magnitude));
      visual.torque.setLength(length, head, head * 0.6);
      visual.torque.visible = true;
    },

    // The tool of frame data `d` at `o` as the tests read it, or null.
    describe(d, o) {
      if (o < 0) return null;
      const pose = (k) => ({ position_m: [d[k], d[k + 1], d[k + 2]],
                             orientation_wxyz: [d[k + 3], d[k + 4], d[k + 5], d[k + 6]] });
      return {
        valid: d[o + T_VALID] === 1,
        grip: pose(o + T_GRIP),
        proxy: pose(o + T_PROXY),
        force_N: [d[o + T_FORCE], d[o + T_FORCE + 1], d[o + T_FORCE + 2]],
        torque_Nm: [d[o + T_TORQUE], d[o + T_TORQUE + 1], d[o + T_TORQUE + 2]],
        drawn: Boolean(visual && visual.solid.visible),
      };
    },
  };
}
