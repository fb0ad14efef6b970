// SPDX-License-Identifier: Apache-2.0
//
// The viewer's page. It speaks the protocol of viewer/view_protocol.h over the WebSocket at /ws:
//   - a text message, the scene, names the bodies and their shapes; every scene rebuilds the 3-D view;
//   - each binary message is one world frame (little-endian float64): header, body poses, endpoints with their
//     active planes; body k of a frame is bodies[k] of the scene;
//   - in replay, the page sends {"play": b}, {"speed": x}, {"seek": t} back;
//   - with ?touch=TOKEN in its address, touch.js steers the web hand over a socket of its own (/ws/touch).
// Poses are drawn one world period behind the newest frame, interpolated between the last two frames, so motion is
// smooth at the display's rate whatever the world's rate. The socket reconnects every second when it closes, since
// the viewer or the world behind it may restart.
//
// All bodies are one mesh (and their outlines one set of lines), built once per scene with each body's shape in its
// own frame and a body index per vertex; the vertex shader places each body from its pose in a float texture that
// the render loop rewrites, so thousands of bodies are two draw calls and 32 bytes a body per frame. (Instancing
// would be the obvious alternative; software WebGL, e.g. SwiftShader in headless browsers, pays per instance.)
// Drawing the 3-D view allocates nothing per frame; the charts and the HUD make a few strings when their data change.
//
// window.impetusView exposes the page's state for automated browser tests (see `view` below).

import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { createTouch } from './touch.js';
import { createTool, TOOL_VALUES } from './tool.js';

// ---- Protocol (viewer/view_protocol.h) ------------------------------------------------------------------------------

const FRAME_KIND = 1;
const HEADER_VALUES = 16;
const BODY_VALUES = 7;
const ENDPOINT_VALUES = 12;
const PLANE_VALUES = 6;
const DENT_VALUES = 8;

// Header offsets.
const H_KIND = 0;
const H_INDEX = 1;
const H_TIME = 2;
const H_PERIOD = 3;
const H_BODIES = 4;
const H_ENDPOINTS = 5;
const H_LATENESS_P99 = 6;
const H_FAULTS = 7;
const H_WORLD_SKIPPED = 8;
const H_HAPTIC_SKIPPED = 9;
const H_PLAYING = 10;
const H_SPEED = 11;
const H_DENT = 12;
const H_TOOL = 13;

// Endpoint offsets, from the endpoint's first value.
const E_ID = 0;
const E_FINGER_VALID = 1;
const E_FINGER = 2;
const E_PROXY = 5;
const E_FORCE = 8;
const E_PLANE_COUNT = 11;

// ---- Display choices ------------------------------------------------------------------------------------------------

const FINGER_RADIUS_M = 0.004;
const PROXY_RADIUS_M = 0.0025;
const FORCE_M_PER_N = 0.01;          // force arrow: 1 cm per newton
const FORCE_MIN_N = 1e-3;            // below this the arrow is hidden
const PLANE_SIDE_M = 0.03;
const PLANE_NORMAL_M = 0.01;
const CHART_SPAN_S = 10;
const RECONNECT_MS = 1000;
const HUD_INTERVAL_MS = 250;         // the HUD is text in the DOM: refreshing it every frame would be waste
const HUGE_STATIC_RADIUS_M = 0.5;    // static bodies larger than this (a table, a ground slab) do not frame the camera
const TELEPORT_PERIODS = 5;          // a jump forward of more than this many periods (a seek) is not interpolated
const MANY_BODIES = 300;             // above this many bodies, coarser tessellation; above 3 times this, coarsest

const BACKGROUND = 0x1c2027;
const STATIC_COLOUR = new THREE.Color(0x8d949e);
const EDGE_COLOUR = new THREE.Color(0x0b0d10);

const hostIsLittleEndian = new Uint8Array(new Uint16Array([1]).buffer)[0] === 1;

// ---- The page's state, as the tests see it --------------------------------------------------------------------------

let scene = null;            // the parsed scene message
let prev = null;             // the frame before the latest, or null after a reset: {data, recv, endpoints}
let latest = null;           // the latest accepted frame
let shownCount = 0;          // bodies in shownPoses
let shownPoses = new Float64Array(0);  // per body the pose drawn in the last animation frame: x y z w x y z

const view = {
  scene: null,
  connected: false,
  framesReceived: 0,         // binary messages accepted as frames
  rejectedFrames: 0,         // binary messages ignored as malformed (or arriving before any scene)
  rejectedMessages: 0,       // text messages ignored (not JSON, not a scene, or a malformed scene)
  dent: null,                // the dent drawn: {body, version, columns, rows, deepest_m}, or null
  fps: 0,
  renderedFrames: 0,
  get latest() { return latest ? describeFrame(latest) : null; },
  get touch() { return touch.state; },   // the web hand as this page sees it (touch.js)
  get shown() { return { bodies: describePoses(shownPoses, shownCount) }; },
  send(message) { return sendControl(message); },
  project(name) { return projectBody(name); },   // where body `name` was drawn: {x, y} page pixels, or null
  projectPoint(point) { return projectPoint(point); },  // where world point [x, y, z] (m) is drawn: {x, y} page pixels
  meshes: [],                // each mesh body of the scene: {name, drawn: 'triangles' | 'bound', triangles}
  // Points the camera at a sphere (centre [x, y, z] m, radius m) and stops it following the bodies, as a user's
  // own camera move does.
  lookAt(center, radius) {
    cameraTouched = true;
    aimCamera(new THREE.Vector3(center[0], center[1], center[2]), radius);
  },
  // The 3-D view as a PNG data URL, drawn now with the bodies placed now: a screenshot of the canvas alone that does
  // not wait for the next animation frame (software WebGL under load can take seconds to deliver one, the first
  // after a scene longer still while shaders compile). `project` afterwards gives positions in this picture.
  capture() {
    placeAll(performance.now());
    renderer.render(world, camera);
    return renderer.domElement.toDataURL('image/png');
  },
};
window.impetusView = view;

// ---- three.js set-up ------------------------------------------------------------------------------------------------

// Whether WebGL runs on the CPU (SwiftShader, llvmpipe: headless browsers, machines without a GPU driver). There
// multisampling costs more than it gives, so the renderer goes without.
function softwareRenderer() {
  try {
    const gl = document.createElement('canvas').getContext('webgl2');
    if (!gl) return false;
    const info = gl.getExtension('WEBGL_debug_renderer_info');
    const name = String(gl.getParameter(info ? info.UNMASKED_RENDERER_WEBGL : gl.RENDERER));
    const lose = gl.getExtension('WEBGL_lose_context');
    if (lose) lose.loseContext();
    return /swiftshader|llvmpipe|softpipe|software/i.test(name);
  } catch {
    return false;
  }
}

const viewElement = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ antialias: !softwareRenderer(), powerPreference: 'high-performance' });
renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
viewElement.prepend(renderer.domElement);

const world = new THREE.Scene();
world.background = new THREE.Color(BACKGROUND);

// Lighting for a z-up world: sky above, a warm key light from the front right, a cool fill from behind.
const hemisphere = new THREE.HemisphereLight(0xe8eef7, 0x3a3630, 1.3);
hemisphere.position.set(0, 0, 1);
world.add(hemisphere);
const keyLight = new THREE.DirectionalLight(0xfff3e6, 2.2);
keyLight.position.set(0.6, -0.9, 1.4);
world.add(keyLight);
const fillLight = new THREE.DirectionalLight(0xcfe0ff, 0.7);
fillLight.position.set(-0.8, 0.7, 0.5);
world.add(fillLight);

const camera = new THREE.PerspectiveCamera(45, 1, 0.001, 100);
camera.up.set(0, 0, 1);                  // before OrbitControls, which orbits about camera.up
camera.position.set(0.1, -0.18, 0.12);
const controls = new OrbitControls(camera, renderer.domElement);
controls.enableDamping = true;
controls.dampingFactor = 0.12;

// Everything a scene message creates lives under sceneRoot and is disposed of with it.
const sceneRoot = new THREE.Group();
world.add(sceneRoot);
const endpointRoot = new THREE.Group();
world.add(endpointRoot);
const toolRoot = new THREE.Group();
world.add(toolRoot);
const toolVisual = createTool({ root: toolRoot, geometryOf: (shape) => solidGeometry(shape, 2), shapeOf });

// A small frame at the world origin (x red, y green, z blue); buildFloor scales it with the grid.
const axes = new THREE.AxesHelper(0.01);
world.add(axes);

// Fog the colour of the background, ahead of the floor's far edge and behind the bodies: the floor fades out instead
// of ending at a horizon line. Its range follows the camera's distance to what it orbits (see animate).
world.fog = new THREE.Fog(BACKGROUND, 1, 10);

// Each body's pose, two RGBA float texels a body: position (x, y, z, unused), then orientation (x, y, z, w). The
// uniform object is shared by both materials below and keeps its identity when a scene brings a texture of
// another size.
const POSE_TEXTURE_WIDTH = 2048;         // texels a row: 1024 bodies
const poseUniform = { value: null };

// GLSL that places a vertex of body `bodyIndex`; main() starts by fetching the pose.
const POSE_DECLARATIONS = /* glsl */ `
  uniform highp sampler2D bodyPoses;
  attribute float bodyIndex;
  vec3 rotateByQuaternion(vec4 q, vec3 v) { return v + 2.0 * cross(q.xyz, cross(q.xyz, v) + q.w * v); }
`;
const POSE_FETCH = /* glsl */ `
  int poseTexel = int(bodyIndex + 0.5) * 2;
  ivec2 poseAt = ivec2(poseTexel % ${POSE_TEXTURE_WIDTH}, poseTexel / ${POSE_TEXTURE_WIDTH});
  vec3 bodyPosition = texelFetch(bodyPoses, poseAt, 0).xyz;
  vec4 bodyRotation = texelFetch(bodyPoses, poseAt + ivec2(1, 0), 0);
`;

// Bodies: the standard material with colours per vertex (one colour a body) and the pose applied before
// three.js's own transforms; pushed back in depth so that their outlines win.
const bodyMaterial = new THREE.MeshStandardMaterial({
  color: 0xffffff, vertexColors: true, roughness: 0.55, metalness: 0.05,
  polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
});
bodyMaterial.onBeforeCompile = (shader) => {
  shader.uniforms.bodyPoses = poseUniform;
  shader.vertexShader = POSE_DECLARATIONS + shader.vertexShader
    .replace('void main() {', `void main() {${POSE_FETCH}`)
    .replace('#include <beginnormal_vertex>',
             '#include <beginnormal_vertex>\n  objectNormal = rotateByQuaternion(bodyRotation, objectNormal);')
    .replace('#include <begin_vertex>',
             '#include <begin_vertex>\n  transformed = rotateByQuaternion(bodyRotation, transformed) + bodyPosition;');
};
bodyMaterial.customProgramCacheKey = () => 'impetus-bodies';

// Body outlines, placed the same way.
const edgeMaterial = new THREE.ShaderMaterial({
  uniforms: { color: { value: EDGE_COLOUR }, bodyPoses: poseUniform },
  vertexShader: POSE_DECLARATIONS + /* glsl */ `
    void main() {${POSE_FETCH}
      vec3 p = rotateByQuaternion(bodyRotation, position) + bodyPosition;
      gl_Position = projectionMatrix * modelViewMatrix * vec4(p, 1.0);
    }`,
  fragmentShader: /* glsl */ `
    uniform vec3 color;
    void main() {
      gl_FragColor = vec4(color, 1.0);
      #include <colorspace_fragment>
    }`,
});

// ---- Shapes ---------------------------------------------------------------------------------------------------------

// A body's shape, with the key of its geometry (bodies of one shape and size share the template geometry while a
// scene is built) and the radius of a sphere about its origin that holds it.
function shapeOf(body) {
  const positive = (v) => typeof v === 'number' && Number.isFinite(v) && v > 0;
  const nonNegative = (v) => typeof v === 'number' && Number.isFinite(v) && v >= 0;
  const r = positive(body.radius_m) ? body.radius_m : 0.005;
  switch (body.shape) {
    case 'sphere':
      return { key: `sphere:${r}`, kind: 'sphere', radius: r, boundingRadius: r };
    case 'cylinder': {
      const l = positive(body.length_m) ? body.length_m : 0.01;
      return { key: `cylinder:${r}:${l}`, kind: 'cylinder', radius: r, length: l,
               boundingRadius: Math.hypot(r, l / 2) };
    }
    case 'capsule': {
      const l = nonNegative(body.length_m) ? body.length_m : 0;
      return { key: `capsule:${r}:${l}`, kind: 'capsule', radius: r, length: l, boundingRadius: r + l / 2 };
    }
    case 'mesh': {
      // Its triangles when the viewer sent them (view_protocol.h §1); else a coarse ball about its centre of mass
      // that holds it (radius_m), so the page shows where it is and how it turns, not its form.
      const form = body.mesh;
      if (form && form.drawn === 'triangles' && validTriangles(form.vertices_m, form.triangles)) {
        return { key: `triangles:${body.mesh_hash}`, kind: 'triangles', vertices: form.vertices_m,
                 triangles: form.triangles, boundingRadius: r };
      }
      if (form && form.why) console.info(`impetus viewer: ${body.name} is drawn as its bound: ${form.why}`);
      return { key: `mesh:${r}`, kind: 'mesh', radius: r, boundingRadius: r };
    }
    default: {
      if (body.shape !== 'box') {
        console.warn(`impetus viewer: unknown shape ${body.shape} of ${body.name}, drawn as a box`);
      }
      const s = Array.isArray(body.size_m) && body.size_m.length === 3 && body.size_m.every(positive)
        ? body.size_m : [0.01, 0.01, 0.01];
      return { key: `box:${s.join(':')}`, kind: 'box', size: s, boundingRadius: Math.hypot(s[0], s[1], s[2]) / 2 };
    }
  }
}

// Whether a mesh's arrays are whole: finite coordinates in threes, vertex indices in threes and in range.
function validTriangles(vertices, triangles) {
  if (!Array.isArray(vertices) || !Array.isArray(triangles)) return false;
  if (vertices.length % 3 !== 0 || triangles.length % 3 !== 0 || triangles.length === 0) return false;
  const count = vertices.length / 3;
  return vertices.every(Number.isFinite) && triangles.every((i) => Number.isInteger(i) && i >= 0 && i < count);
}

// Corners whose triangles meet at less than this angle share a normal (a scan or a sphere looks smooth); a sharper
// crease (a box's edge, a bowl's rim) stays sharp.
const CREASE_COS = Math.cos(35 * Math.PI / 180);

// A user's mesh in its body frame: each triangle's corners get the mean normal of the triangles around that vertex
// within the crease angle of its own.
function triangleGeometry(vertices, triangles) {
  const vertexCount = vertices.length / 3;
  const triangleCount = triangles.length / 3;
  const faceNormals = new Float32Array(triangles.length);
  const a = new THREE.Vector3();
  const b = new THREE.Vector3();
  const c = new THREE.Vector3();
  for (let f = 0; f < triangleCount; f++) {
    a.fromArray(vertices, 3 * triangles[3 * f]);
    b.fromArray(vertices, 3 * triangles[3 * f + 1]).sub(a);
    c.fromArray(vertices, 3 * triangles[3 * f + 2]).sub(a);
    b.cross(c).normalize().toArray(faceNormals, 3 * f);   // a zero-area triangle's stays zero
  }
  // The triangles around each vertex, as one list in vertex order (start[v] .. start[v + 1]).
  const start = new Uint32Array(vertexCount + 1);
  for (const v of triangles) start[v + 1]++;
  for (let v = 0; v < vertexCount; v++) start[v + 1] += start[v];
  const around = new Uint32Array(triangles.length);
  const filled = start.slice(0, vertexCount);
  triangles.forEach((v, n) => { around[filled[v]++] = Math.floor(n / 3); });

  const position = new Float32Array(triangles.length * 3);
  const normal = new Float32Array(triangles.length * 3);
  const sum = new THREE.Vector3();
  const own = new THREE.Vector3();
  const other = new THREE.Vector3();
  for (let n = 0; n < triangles.length; n++) {
    const v = triangles[n];
    const f = Math.floor(n / 3);
    position.set(vertices.slice(3 * v, 3 * v + 3), 3 * n);
    own.fromArray(faceNormals, 3 * f);
    sum.set(0, 0, 0);
    for (let k = start[v]; k < start[v + 1]; k++) {
      other.fromArray(faceNormals, 3 * around[k]);
      if (other.dot(own) >= CREASE_COS) sum.add(other);
    }
    (sum.lengthSq() > 0 ? sum.normalize() : own).toArray(normal, 3 * n);
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(position, 3));
  geometry.setAttribute('normal', new THREE.BufferAttribute(normal, 3));
  const index = new Uint32Array(triangles.length);
  for (let n = 0; n < index.length; n++) index[n] = n;
  geometry.setIndex(new THREE.BufferAttribute(index, 1));
  return geometry;
}

// The solid of a shape in the body's frame, axis along z for capsule and cylinder (three.js builds them along y).
// Detail 2 is smooth; 1 and 0 (hundreds, thousands of bodies) have few triangles a body, since a software renderer
// (headless browsers) spends its time per triangle, and bodies that many are small on screen.
function solidGeometry(shape, detail) {
  const radial = [6, 12, 32][detail];
  switch (shape.kind) {
    case 'sphere': return new THREE.SphereGeometry(shape.radius, radial, [4, 8, 20][detail]);
    case 'mesh': return new THREE.SphereGeometry(shape.radius, 8, 6);  // coarse: a bound, not the form
    case 'triangles': return triangleGeometry(shape.vertices, shape.triangles);
    case 'cylinder':
      return new THREE.CylinderGeometry(shape.radius, shape.radius, shape.length, radial).rotateX(Math.PI / 2);
    case 'capsule':
      return new THREE.CapsuleGeometry(shape.radius, shape.length, [1, 3, 6][detail], radial).rotateX(Math.PI / 2);
    default: return shape.dent ? dentedBoxGeometry(shape) : new THREE.BoxGeometry(...shape.size);
  }
}

// A box whose top face is dented (shape.dent, from a frame: depths below the face on a grid of the body frame,
// bilinear between its points, none beyond them): the box's bottom and sides, and a top face through every grid line.
function dentedBoxGeometry(shape) {
  const [hx, hy, hz] = shape.size.map((v) => v / 2);
  const dent = shape.dent;
  const lines = (first, step, count, half) => {
    const out = [-half];
    for (let k = 0; k < count; k++) {
      const at = first + k * step;
      if (at > -half && at < half) out.push(at);
    }
    out.push(half);
    return out;
  };
  const xs = lines(dent.x0, dent.dx, dent.columns, hx);
  const ys = lines(dent.y0, dent.dy, dent.rows, hy);
  const depthAt = (x, y) => {
    const u = (x - dent.x0) / dent.dx;
    const v = (y - dent.y0) / dent.dy;
    if (!(u >= 0 && v >= 0 && u <= dent.columns - 1 && v <= dent.rows - 1)) return 0;
    const c = Math.min(Math.floor(u), dent.columns - 2);
    const r = Math.min(Math.floor(v), dent.rows - 2);
    const tu = u - c;
    const tv = v - r;
    const at = (i, j) => dent.depths[j * dent.columns + i];
    return (1 - tv) * ((1 - tu) * at(c, r) + tu * at(c + 1, r)) +
           tv * ((1 - tu) * at(c, r + 1) + tu * at(c + 1, r + 1));
  };
  const top = new THREE.BufferGeometry();
  const position = new Float32Array(xs.length * ys.length * 3);
  ys.forEach((y, j) => xs.forEach((x, i) => position.set([x, y, hz - depthAt(x, y)], (j * xs.length + i) * 3)));
  const index = [];
  for (let j = 0; j + 1 < ys.length; j++) {
    for (let i = 0; i + 1 < xs.length; i++) {
      const a = j * xs.length + i;  // counter-clockwise seen from above
      index.push(a, a + 1, a + 1 + xs.length, a, a + 1 + xs.length, a + xs.length);
    }
  }
  top.setAttribute('position', new THREE.BufferAttribute(position, 3));
  top.setIndex(index);
  top.computeVertexNormals();
  // BoxGeometry's faces in order +x, −x, +y, −y, +z, −z, six indices each: all but +z.
  const box = new THREE.BoxGeometry(2 * hx, 2 * hy, 2 * hz);
  const boxIndex = Array.from(box.index.array).filter((_, n) => n < 24 || n >= 30);
  const boxCount = box.attributes.position.count;
  const out = new THREE.BufferGeometry();
  const merged = (a, b) => { const m = new Float32Array(a.length + b.length); m.set(a); m.set(b, a.length); return m; };
  out.setAttribute('position', new THREE.BufferAttribute(merged(box.attributes.position.array, position), 3));
  out.setAttribute('normal', new THREE.BufferAttribute(merged(box.attributes.normal.array,
                                                               top.attributes.normal.array), 3));
  out.setIndex([...boxIndex, ...index.map((n) => n + boxCount)]);
  box.dispose();
  top.dispose();
  return out;
}

// The tessellation detail for a scene of `count` bodies.
function detailFor(count) {
  return count > MANY_BODIES * 3 ? 0 : count > MANY_BODIES ? 1 : 2;
}

// Appends an arc as line segments: centre c, in-plane unit axes u and v, radius r, from angle a0 to a1.
function pushArc(out, c, u, v, r, a0, a1, segments) {
  for (let i = 0; i < segments; i++) {
    for (const a of [a0 + (a1 - a0) * i / segments, a0 + (a1 - a0) * (i + 1) / segments]) {
      const cos = Math.cos(a) * r;
      const sin = Math.sin(a) * r;
      out.push(c[0] + u[0] * cos + v[0] * sin, c[1] + u[1] * cos + v[1] * sin, c[2] + u[2] * cos + v[2] * sin);
    }
  }
}

// The outline of a shape in the body's frame, as line segments: a box's 12 edges; for round shapes the rims and a
// few lines along the surface that make their rotation visible. Below full detail (many bodies): boxes only, whose
// flat faces need it most; shading tells round shapes apart.
function outlinePositions(shape, detail) {
  if (detail < 2 && shape.kind !== 'box') return [];
  if (shape.kind === 'triangles') return [];   // its creases show in its shading
  const n = 48;
  const X = [1, 0, 0];
  const Y = [0, 1, 0];
  const Z = [0, 0, 1];
  const O = [0, 0, 0];
  const out = [];
  switch (shape.kind) {
    case 'sphere':
    case 'mesh': {
      const r = shape.radius * 1.002;    // just outside the tessellated surface
      pushArc(out, O, X, Y, r, 0, 2 * Math.PI, n);
      pushArc(out, O, Y, Z, r, 0, 2 * Math.PI, n);
      pushArc(out, O, Z, X, r, 0, 2 * Math.PI, n);
      break;
    }
    case 'cylinder': {
      const r = shape.radius;
      const h = shape.length / 2;
      pushArc(out, [0, 0, -h], X, Y, r, 0, 2 * Math.PI, n);
      pushArc(out, [0, 0, h], X, Y, r, 0, 2 * Math.PI, n);
      for (let k = 0; k < 4; k++) {
        const a = k * Math.PI / 2;
        out.push(r * Math.cos(a), r * Math.sin(a), -h, r * Math.cos(a), r * Math.sin(a), h);
      }
      break;
    }
    case 'capsule': {
      const r = shape.radius * 1.002;
      const h = shape.length / 2;
      pushArc(out, [0, 0, -h], X, Y, r, 0, 2 * Math.PI, n);
      pushArc(out, [0, 0, h], X, Y, r, 0, 2 * Math.PI, n);
      // Its silhouette in the xz and yz planes: two straight sides and the two caps' half circles.
      for (const u of [X, Y]) {
        out.push(u[0] * r, u[1] * r, -h, u[0] * r, u[1] * r, h, -u[0] * r, -u[1] * r, -h, -u[0] * r, -u[1] * r, h);
        pushArc(out, [0, 0, h], u, Z, r, 0, Math.PI, n / 2);
        pushArc(out, [0, 0, -h], u, Z, r, Math.PI, 2 * Math.PI, n / 2);
      }
      break;
    }
    default: {
      const [x, y, z] = shape.size.map((v) => v / 2);
      for (const a of [-1, 1]) {
        for (const b of [-1, 1]) {
          out.push(-x, a * y, b * z, x, a * y, b * z);
          out.push(a * x, -y, b * z, a * x, y, b * z);
          out.push(a * x, b * y, -z, a * x, b * y, z);
        }
      }
    }
  }
  return out;
}

// ---- Scene ----------------------------------------------------------------------------------------------------------

let bodiesMesh = null;                   // all bodies, one mesh; hidden until the scene's first frame
let bodiesOutline = null;                // their outlines
let bodiesPlaced = false;                // whether the pose texture holds the poses of a frame of this scene
let poseTexture = null;
let bodyRadii = new Float64Array(0);     // per body, radius of a sphere about its origin that holds it
let sceneSignature = '';
let needsFraming = true;                 // frame the camera on the next frame (a scene of other bodies arrived)
let floor = null;                        // {group, height}
let floorCell = 0.01;                    // grid cell, m: set when the camera is framed, kept across like scenes

// Disposes of what a scene created under root: geometries, and materials that are not shared.
function disposeTree(root) {
  root.traverse((object) => {
    if (object.geometry) object.geometry.dispose();
    if (object.material && object.material !== bodyMaterial && object.material !== edgeMaterial) {
      object.material.dispose();
    }
  });
  root.clear();
}

// Golden-ratio hues: neighbouring dynamic bodies get clearly different colours, however many there are.
function dynamicColour(i, out) {
  return out.setHSL((0.07 + i * 0.618034) % 1, 0.62, 0.56);
}

// One geometry of all bodies: each body's solid (or outline) in its own frame, its colour, and its index.
function mergeBodies(bodies, shapes, detail) {
  const solids = new Map();              // template geometries by shape key, for this build only
  const outlines = new Map();
  let vertices = 0;
  let indices = 0;
  let lineVertices = 0;
  for (const shape of shapes) {
    if (!solids.has(shape.key)) {
      solids.set(shape.key, solidGeometry(shape, detail));
      outlines.set(shape.key, outlinePositions(shape, detail));
    }
    const solid = solids.get(shape.key);
    vertices += solid.attributes.position.count;
    indices += solid.index.count;
    lineVertices += outlines.get(shape.key).length / 3;
  }

  const position = new Float32Array(vertices * 3);
  const normal = new Float32Array(vertices * 3);
  const colour = new Float32Array(vertices * 3);
  const bodyIndex = new Float32Array(vertices);
  const index = vertices > 65535 ? new Uint32Array(indices) : new Uint16Array(indices);
  const linePosition = new Float32Array(lineVertices * 3);
  const lineBodyIndex = new Float32Array(lineVertices);
  const c = new THREE.Color();
  let dynamicCount = 0;
  let v = 0;
  let i = 0;
  let lv = 0;
  shapes.forEach((shape, k) => {
    const solid = solids.get(shape.key);
    const count = solid.attributes.position.count;
    position.set(solid.attributes.position.array, v * 3);
    normal.set(solid.attributes.normal.array, v * 3);
    if (bodies[k].dynamic) dynamicColour(dynamicCount++, c); else c.copy(STATIC_COLOUR);
    for (let n = 0; n < count; n++) c.toArray(colour, (v + n) * 3);
    bodyIndex.fill(k, v, v + count);
    const from = solid.index.array;
    for (let n = 0; n < from.length; n++) index[i + n] = from[n] + v;
    v += count;
    i += from.length;

    const outline = outlines.get(shape.key);
    linePosition.set(outline, lv * 3);
    lineBodyIndex.fill(k, lv, lv + outline.length / 3);
    lv += outline.length / 3;
  });
  for (const solid of solids.values()) solid.dispose();

  const mesh = new THREE.BufferGeometry();
  mesh.setAttribute('position', new THREE.BufferAttribute(position, 3));
  mesh.setAttribute('normal', new THREE.BufferAttribute(normal, 3));
  mesh.setAttribute('color', new THREE.BufferAttribute(colour, 3));
  mesh.setAttribute('bodyIndex', new THREE.BufferAttribute(bodyIndex, 1));
  mesh.setIndex(new THREE.BufferAttribute(index, 1));
  const lines = new THREE.BufferGeometry();
  lines.setAttribute('position', new THREE.BufferAttribute(linePosition, 3));
  lines.setAttribute('bodyIndex', new THREE.BufferAttribute(lineBodyIndex, 1));
  return { mesh, lines };
}

// What the bodies' mesh was built from, so a dent can rebuild it (showDent).
let sceneShapes = [];
let sceneDetail = 2;
let dentBuiltAt = -Infinity;
const DENT_REDRAW_MS = 200;  // clay being pressed changes every world step: its face is rebuilt 5 times a second

function buildScene(message) {
  disposeTree(sceneRoot);
  if (poseTexture) poseTexture.dispose();
  const bodies = message.bodies;
  const count = bodies.length;
  const shapes = bodies.map(shapeOf);
  sceneShapes = shapes;
  view.meshes = bodies.flatMap((body, k) => body.shape !== 'mesh' ? [] : [{
    name: body.name,
    drawn: shapes[k].kind === 'triangles' ? 'triangles' : 'bound',
    triangles: shapes[k].kind === 'triangles' ? shapes[k].triangles.length / 3 : 0,
  }]);
  sceneDetail = detailFor(count);
  view.dent = null;
  dentBuiltAt = -Infinity;
  bodyRadii = Float64Array.from(shapes, (shape) => shape.boundingRadius);
  shownPoses = new Float64Array(count * BODY_VALUES);
  shownCount = 0;

  const rows = Math.max(1, Math.ceil(count * 2 / POSE_TEXTURE_WIDTH));
  poseTexture = new THREE.DataTexture(new Float32Array(POSE_TEXTURE_WIDTH * rows * 4), POSE_TEXTURE_WIDTH, rows,
                                      THREE.RGBAFormat, THREE.FloatType);
  poseTexture.needsUpdate = true;
  poseUniform.value = poseTexture;

  bodiesMesh = null;
  bodiesOutline = null;
  bodiesPlaced = false;
  drawnFrame = null;
  if (count > 0) {
    const merged = mergeBodies(bodies, shapes, sceneDetail);
    bodiesMesh = new THREE.Mesh(merged.mesh, bodyMaterial);
    bodiesOutline = new THREE.LineSegments(merged.lines, edgeMaterial);
    for (const object of [bodiesMesh, bodiesOutline]) {
      object.frustumCulled = false;      // its bounds are those of the bodies at their origins, not where they are
      object.visible = false;
      sceneRoot.add(object);
    }
  }

  floor = null;
  if (message.floor && message.floor.present) {
    const height = Number.isFinite(message.floor.height_m) ? message.floor.height_m : 0;
    floor = { group: new THREE.Group(), height };
    sceneRoot.add(floor.group);
    buildFloor(floorCell);
  }

  const signature = JSON.stringify([message.bodies, message.floor]);
  if (signature !== sceneSignature) needsFraming = true;
  sceneSignature = signature;

  prev = null;
  latest = null;
  resetEndpoints();
  toolVisual.build(message.tool);
  rebuildBodySelect(bodies);
  forceChart.reset(chartCapacity(message));
  positionChart.reset(chartCapacity(message));
  showReplayBar(message);
}

// The floor: a plane at its height 200 cells of `cell` metres across, with a major grid of ten cells over all of it
// and the fine grid over the middle 60 cells (farther out, fine lines are below a pixel apart and only cost time).
function buildFloor(cell) {
  floorCell = cell;
  if (!floor) return;
  disposeTree(floor.group);
  const size = cell * 200;
  // Unlit: a flat plane under directional light is one colour anyway, and the floor covers most of the view, so
  // its per-pixel cost is what a software renderer feels most.
  const plane = new THREE.Mesh(
    new THREE.PlaneGeometry(size, size),
    new THREE.MeshBasicMaterial({ color: 0x272c33,
                                  polygonOffset: true, polygonOffsetFactor: 2, polygonOffsetUnits: 2 }));
  floor.group.add(plane);
  const minor = new THREE.GridHelper(cell * 60, 60, 0x363d47, 0x333944);
  const major = new THREE.GridHelper(size, 20, 0x55606c, 0x444d58);
  for (const grid of [minor, major]) {
    grid.rotation.x = Math.PI / 2;       // GridHelper lies in xz; the floor is the xy plane
    floor.group.add(grid);
  }
  floor.group.position.z = floor.height;
  axes.scale.setScalar(cell / 0.01);
}

// Points the camera at the bodies of the frame (bar huge static ones, such as a ground slab) and any valid finger.
// Frames the bodies and fingers of `frame`; with `widen`, also everything framed before (the view only grows, so a
// body that slid out of view is brought back without losing the others).
function frameCamera(frame, widen = false) {
  const d = frame.data;
  const box = new THREE.Box3();
  const sphere = new THREE.Sphere();
  const point = new THREE.Vector3();
  const addBodies = (skipHuge) => {
    for (let k = 0; k < scene.bodies.length; k++) {
      if (skipHuge && !scene.bodies[k].dynamic && bodyRadii[k] > HUGE_STATIC_RADIUS_M) continue;
      const o = HEADER_VALUES + k * BODY_VALUES;
      const r = bodyRadii[k];
      point.set(d[o], d[o + 1], d[o + 2]);
      if (!Number.isFinite(point.x + point.y + point.z)) continue;
      box.expandByPoint(point.addScalar(r)).expandByPoint(point.addScalar(-2 * r));
    }
  };
  addBodies(true);
  if (box.isEmpty()) addBodies(false);
  for (const o of frame.endpoints) {
    if (d[o + E_FINGER_VALID] !== 1) continue;
    point.set(d[o + E_FINGER], d[o + E_FINGER + 1], d[o + E_FINGER + 2]);
    if (Number.isFinite(point.x + point.y + point.z)) box.expandByPoint(point);
  }
  if (box.isEmpty()) box.setFromCenterAndSize(new THREE.Vector3(), new THREE.Vector3().setScalar(0.1));
  if (widen && framedBox) box.union(framedBox);
  framedBox = box.clone();
  box.getBoundingSphere(sphere);
  // Room around the bodies for them to move in: half their extent again, and 2 cm at least.
  aimCamera(sphere.center, Math.max(sphere.radius * 1.5 + 0.02, 0.04));
}

// Looks at a sphere of `radius` m about `center` from the front right, above: the view of a person at a desk.
function aimCamera(center, radius) {
  // The bounding sphere overstates what is there, hence a distance somewhat short of fitting all of it in view.
  const halfFov = THREE.MathUtils.degToRad(camera.fov / 2);
  const fit = Math.min(halfFov, Math.atan(Math.tan(halfFov) * camera.aspect));
  const distance = radius / Math.sin(fit) * 0.85;
  const direction = new THREE.Vector3(0.55, -1, 0.62).normalize();
  camera.position.copy(center).addScaledVector(direction, distance);
  camera.near = distance / 500;
  camera.far = distance * 200;
  camera.updateProjectionMatrix();
  controls.target.copy(center);
  controls.update();

  // A grid of a power of ten, a third of the radius or less: centimetres for a few bodies on a desk.
  buildFloor(Math.pow(10, Math.floor(Math.log10(radius / 3))));
}

// ---- Frames ---------------------------------------------------------------------------------------------------------

function float64s(buffer) {
  if (hostIsLittleEndian) return new Float64Array(buffer);
  const values = new Float64Array(buffer.byteLength / 8);
  const dv = new DataView(buffer);
  for (let i = 0; i < values.length; i++) values[i] = dv.getFloat64(i * 8, true);
  return values;
}

// A frame checked against the protocol and the scene, or null. The check is structural: kind, counts, and a length
// that is exactly the header, the scene's bodies and the endpoints with their planes.
function parseFrame(buffer) {
  if (!scene || !(buffer instanceof ArrayBuffer)) return null;
  if (buffer.byteLength % 8 !== 0 || buffer.byteLength < HEADER_VALUES * 8) return null;
  const d = float64s(buffer);
  if (d[H_KIND] !== FRAME_KIND) return null;
  if (!Number.isInteger(d[H_INDEX]) || d[H_INDEX] < 0) return null;
  if (d[H_BODIES] !== scene.bodies.length) return null;
  const endpointCount = d[H_ENDPOINTS];
  let offset = HEADER_VALUES + scene.bodies.length * BODY_VALUES;
  if (!Number.isInteger(endpointCount) || endpointCount < 0) return null;
  if (offset + endpointCount * ENDPOINT_VALUES > d.length) return null;
  const endpoints = new Int32Array(endpointCount);
  for (let e = 0; e < endpointCount; e++) {
    if (offset + ENDPOINT_VALUES > d.length) return null;
    const planes = d[offset + E_PLANE_COUNT];
    if (!Number.isInteger(planes) || planes < 0) return null;
    endpoints[e] = offset;
    offset += ENDPOINT_VALUES + planes * PLANE_VALUES;
  }
  let dent = null;
  if (d[H_DENT] === 1) {
    if (offset + DENT_VALUES > d.length) return null;
    const [body, version, columns, rows] = d.subarray(offset, offset + 4);
    if (!Number.isInteger(body) || body < 0 || body >= scene.bodies.length) return null;
    if (!Number.isInteger(columns) || !Number.isInteger(rows) || columns < 2 || rows < 2) return null;
    dent = { offset, body, version, columns, rows };
    offset += DENT_VALUES + columns * rows;
  }
  let tool = -1;
  if (d[H_TOOL] === 1) {
    if (!scene.tool) return null;
    tool = offset;
    offset += TOOL_VALUES;
  }
  if (offset !== d.length) return null;
  return { data: d, recv: performance.now(), endpoints, dent, tool };
}

// Until the user moves the camera, it follows the bodies: when a dynamic body leaves the view (a tapped cube sliding
// 30 cm), the view widens to take it in. Checked twice a second on the poses last drawn.
let framedBox = null;
let cameraTouched = false;
let lastFollowCheck = 0;
const FOLLOW_CHECK_MS = 500;
const FOLLOW_MARGIN = 0.9;  // normalised device coordinates: a body this close to the edge counts as leaving
const followPoint = new THREE.Vector3();

function followBodies(now) {
  if (cameraTouched || !latest || !scene || now - lastFollowCheck < FOLLOW_CHECK_MS) return;
  lastFollowCheck = now;
  for (let k = 0; k < shownCount && k < scene.bodies.length; k++) {
    if (!scene.bodies[k].dynamic) continue;
    const s = k * BODY_VALUES;
    followPoint.set(shownPoses[s], shownPoses[s + 1], shownPoses[s + 2]).project(camera);
    if (Math.abs(followPoint.x) > FOLLOW_MARGIN || Math.abs(followPoint.y) > FOLLOW_MARGIN || followPoint.z > 1) {
      frameCamera(latest, true);
      return;
    }
  }
}

function onFrame(frame) {
  const d = frame.data;
  // History restarts on a step back (another run, a seek back) and on a jump forward of several periods (a seek):
  // interpolating across either would slide bodies through poses they never had.
  if (latest) {
    const l = latest.data;
    const jump = d[H_TIME] - l[H_TIME];
    const backwards = d[H_INDEX] <= l[H_INDEX];
    prev = backwards || jump > TELEPORT_PERIODS * worldPeriod(latest) ? null : latest;
  }
  latest = frame;
  view.framesReceived++;
  if (needsFraming) {
    frameCamera(frame);
    needsFraming = false;
  }
  recordCharts(frame);
  hudDirty = true;
  syncReplayBar(frame);
  showDent(frame);
}

// A frame's dent, drawn into its box's top face: the bodies' mesh rebuilt with that box's face through the dent's
// points, when the dent changed (at most every DENT_REDRAW_MS; a later frame brings the newest).
function showDent(frame) {
  const dent = frame.dent;
  if (!dent || !bodiesMesh || sceneShapes[dent.body].kind !== 'box') return;
  if (view.dent && view.dent.body === dent.body && view.dent.version === dent.version) return;
  const now = performance.now();
  if (now - dentBuiltAt < DENT_REDRAW_MS) return;
  dentBuiltAt = now;
  const d = frame.data;
  const o = dent.offset;
  const depths = d.slice(o + DENT_VALUES, o + DENT_VALUES + dent.columns * dent.rows);
  const shapes = sceneShapes.slice();
  shapes[dent.body] = { ...sceneShapes[dent.body], key: `dent:${dent.body}:${dent.version}`,
                        dent: { x0: d[o + 4], y0: d[o + 5], dx: d[o + 6], dy: d[o + 7], columns: dent.columns,
                                rows: dent.rows, depths } };
  const merged = mergeBodies(scene.bodies, shapes, sceneDetail);
  bodiesMesh.geometry.dispose();
  bodiesMesh.geometry = merged.mesh;
  bodiesOutline.geometry.dispose();
  bodiesOutline.geometry = merged.lines;
  view.dent = { body: dent.body, version: dent.version, columns: dent.columns, rows: dent.rows,
                deepest_m: depths.reduce((a, b) => Math.max(a, b), 0) };
}

function worldPeriod(frame) {
  const period = frame.data[H_PERIOD];
  if (Number.isFinite(period) && period > 0) return period;
  const rate = scene && scene.world_rate_hz;
  return Number.isFinite(rate) && rate > 0 ? 1 / rate : 0.05;
}

// Wall-clock seconds from the previous frame to the latest: the world time between them (one period, or more when
// the world skipped periods or a replay sends every n-th frame), shortened by the replay speed.
function frameInterval() {
  const speed = latest.data[H_SPEED];
  const step = latest.data[H_TIME] - prev.data[H_TIME];
  const worldStep = Number.isFinite(step) && step > 0 ? step : worldPeriod(latest);
  return worldStep / (Number.isFinite(speed) && speed > 0 ? speed : 1);
}

function describePoses(values, count, offset = 0) {
  const bodies = new Array(count);
  for (let k = 0; k < count; k++) {
    const o = offset + k * BODY_VALUES;
    bodies[k] = {
      name: scene ? scene.bodies[k].name : String(k),
      position_m: [values[o], values[o + 1], values[o + 2]],
      orientation_wxyz: [values[o + 3], values[o + 4], values[o + 5], values[o + 6]],
    };
  }
  return bodies;
}

function describeFrame(frame) {
  const d = frame.data;
  return {
    frameIndex: d[H_INDEX],
    worldTime_s: d[H_TIME],
    bodies: describePoses(d, d[H_BODIES], HEADER_VALUES),
    endpoints: Array.from(frame.endpoints, (o) => ({
      id: d[o + E_ID],
      fingerValid: d[o + E_FINGER_VALID] === 1,
      finger_m: [d[o + E_FINGER], d[o + E_FINGER + 1], d[o + E_FINGER + 2]],
      proxy_m: [d[o + E_PROXY], d[o + E_PROXY + 1], d[o + E_PROXY + 2]],
      force_N: [d[o + E_FORCE], d[o + E_FORCE + 1], d[o + E_FORCE + 2]],
      planeCount: d[o + E_PLANE_COUNT],
    })),
    tool: toolVisual.describe(d, frame.tool),
  };
}

// ---- Drawing poses --------------------------------------------------------------------------------------------------

const qa = new THREE.Quaternion();
const qb = new THREE.Quaternion();
let drawnFrame = null;                   // the latest frame and alpha of the poses in the pose texture
let drawnAlpha = 0;

// How far from prev to latest to draw, now: one frame interval behind the newest frame, so that the latest pose is
// reached about when the next frame arrives; exactly the latest frame when there is no previous one or the replay is
// paused.
function interpolationAlpha(now) {
  if (!prev || latest.data[H_PLAYING] === 0) return 1;
  return Math.min(Math.max((now - latest.recv) / (frameInterval() * 1000), 0), 1);
}

// Interpolates the poses into shownPoses and writes them to the pose texture (quaternion normalised there: the
// shader rotates with it as it is).
function drawBodies(alpha) {
  if (alpha >= 1 && drawnFrame === latest && drawnAlpha >= 1) return;   // already on screen: nothing to upload
  drawnFrame = latest;
  drawnAlpha = alpha;
  const l = latest.data;
  const p = prev ? prev.data : null;
  const count = l[H_BODIES];
  const texels = poseTexture.image.data;
  for (let k = 0; k < count; k++) {
    const o = HEADER_VALUES + k * BODY_VALUES;
    const s = k * BODY_VALUES;
    if (alpha >= 1) {
      for (let i = 0; i < BODY_VALUES; i++) shownPoses[s + i] = l[o + i];
    } else {
      for (let i = 0; i < 3; i++) shownPoses[s + i] = p[o + i] + (l[o + i] - p[o + i]) * alpha;
      qa.set(p[o + 4], p[o + 5], p[o + 6], p[o + 3]);
      qb.set(l[o + 4], l[o + 5], l[o + 6], l[o + 3]);
      qa.slerp(qb, alpha);
      shownPoses[s + 3] = qa.w; shownPoses[s + 4] = qa.x; shownPoses[s + 5] = qa.y; shownPoses[s + 6] = qa.z;
    }
    let qw = shownPoses[s + 3];
    let qx = shownPoses[s + 4];
    let qy = shownPoses[s + 5];
    let qz = shownPoses[s + 6];
    const n2 = qw * qw + qx * qx + qy * qy + qz * qz;
    if (n2 > 0 && Number.isFinite(n2)) {
      const n = 1 / Math.sqrt(n2);
      qw *= n; qx *= n; qy *= n; qz *= n;
    } else {
      qw = 1; qx = 0; qy = 0; qz = 0;
    }
    const t = k * 8;
    texels[t] = shownPoses[s];
    texels[t + 1] = shownPoses[s + 1];
    texels[t + 2] = shownPoses[s + 2];
    texels[t + 4] = qx;
    texels[t + 5] = qy;
    texels[t + 6] = qz;
    texels[t + 7] = qw;
  }
  shownCount = count;
  poseTexture.needsUpdate = true;
  if (bodiesMesh && !bodiesPlaced) bodiesMesh.visible = bodiesOutline.visible = true;
  bodiesPlaced = true;
}

// Where the origin of body `name`, as drawn in the last animation frame, is on the page: {x, y} in CSS pixels from
// the page's top left (a screenshot's pixels at a device pixel ratio of 1), or null if there is no such body drawn.
function projectBody(name) {
  const k = scene ? scene.bodies.findIndex((body) => body.name === name) : -1;
  if (k < 0 || k >= shownCount) return null;
  const s = k * BODY_VALUES;
  return projectPoint([shownPoses[s], shownPoses[s + 1], shownPoses[s + 2]]);
}

// Page pixels of world point [x, y, z] (m) with the camera as drawn now.
function projectPoint(point) {
  camera.updateMatrixWorld();
  const p = new THREE.Vector3(point[0], point[1], point[2]).project(camera);
  const rect = renderer.domElement.getBoundingClientRect();
  return { x: rect.left + (p.x + 1) / 2 * rect.width, y: rect.top + (1 - p.y) / 2 * rect.height };
}

// ---- Endpoints ------------------------------------------------------------------------------------------------------

const fingerGeometry = new THREE.SphereGeometry(FINGER_RADIUS_M, 24, 16);
const proxyGeometry = new THREE.SphereGeometry(PROXY_RADIUS_M, 20, 14);
// The finger is usually inside a body (it is what pushes); drawn without depth test it shows through as a ghost.
const fingerMaterial = new THREE.MeshBasicMaterial({ color: 0x5fd3f3, transparent: true, opacity: 0.45,
                                                     depthTest: false, depthWrite: false });
const proxyMaterial = new THREE.MeshStandardMaterial({ color: 0xf5f7fa, roughness: 0.3, emissive: 0x303840 });
const planeGeometry = new THREE.PlaneGeometry(PLANE_SIDE_M, PLANE_SIDE_M);
const planeOutlineGeometry = new THREE.EdgesGeometry(planeGeometry);
const planeMaterial = new THREE.MeshBasicMaterial({ color: 0xffd54a, transparent: true, opacity: 0.22,
                                                    side: THREE.DoubleSide, depthWrite: false });
const planeOutlineMaterial = new THREE.LineBasicMaterial({ color: 0xffd54a, transparent: true, opacity: 0.8 });
const planesToggle = document.getElementById('show-planes');

const UP = new THREE.Vector3(0, 0, 1);
const direction = new THREE.Vector3();
let endpointVisuals = [];                // by endpoint index in the frame; grows, never shrinks within a scene

function makeEndpointVisual() {
  const visual = {
    finger: new THREE.Mesh(fingerGeometry, fingerMaterial),
    proxy: new THREE.Mesh(proxyGeometry, proxyMaterial),
    force: new THREE.ArrowHelper(UP, new THREE.Vector3(), 0.01, 0xff5a4e),
    planes: new THREE.Group(),
    planeVisuals: [],
  };
  visual.finger.renderOrder = 10;
  visual.force.line.material.depthTest = false;
  visual.force.cone.material.depthTest = false;
  visual.force.renderOrder = 11;
  endpointRoot.add(visual.finger, visual.proxy, visual.force, visual.planes);
  return visual;
}

function makePlaneVisual(parent) {
  const mesh = new THREE.Mesh(planeGeometry, planeMaterial);
  mesh.add(new THREE.LineSegments(planeOutlineGeometry, planeOutlineMaterial));
  // The normal arrow lies along the square's own z, its normal.
  mesh.add(new THREE.ArrowHelper(UP, new THREE.Vector3(), PLANE_NORMAL_M, 0xffd54a, PLANE_NORMAL_M * 0.3,
                                 PLANE_NORMAL_M * 0.18));
  mesh.renderOrder = 2;
  parent.add(mesh);
  return mesh;
}

function resetEndpoints() {
  for (const visual of endpointVisuals) {
    visual.force.dispose();
    visual.planeVisuals.forEach((mesh) => mesh.children[1].dispose());
  }
  endpointRoot.clear();
  endpointVisuals = [];
}

// The endpoint value i drawn now: interpolated from the previous frame's endpoint (epPrev at epPrevOffset) to the
// latest's (at epOffset) when there is one, else the latest's. Module state rather than a closure: no allocation.
let epLatest = null;
let epOffset = 0;
let epPrev = null;
let epPrevOffset = 0;
let epAlpha = 1;
function endpointValue(i) {
  const l = epLatest[epOffset + i];
  return epPrev ? epPrev[epPrevOffset + i] + (l - epPrev[epPrevOffset + i]) * epAlpha : l;
}

function drawEndpoints(alpha) {
  const l = latest.data;
  const count = latest.endpoints.length;
  while (endpointVisuals.length < count) endpointVisuals.push(makeEndpointVisual());
  for (let e = 0; e < endpointVisuals.length; e++) {
    const visual = endpointVisuals[e];
    const present = e < count;
    visual.finger.visible = visual.proxy.visible = visual.force.visible = visual.planes.visible = present;
    if (!present) continue;
    const lo = latest.endpoints[e];
    // Interpolated like the bodies when the previous frame has the same endpoint at the same place.
    epLatest = l;
    epOffset = lo;
    epAlpha = alpha;
    epPrev = null;
    if (alpha < 1 && prev && e < prev.endpoints.length && prev.data[prev.endpoints[e] + E_ID] === l[lo + E_ID]) {
      epPrev = prev.data;
      epPrevOffset = prev.endpoints[e];
    }
    const at = endpointValue;

    // Without a finger (no device yet, or it stopped) there is no contact to show either.
    visual.finger.visible = visual.proxy.visible = l[lo + E_FINGER_VALID] === 1;
    visual.finger.position.set(at(E_FINGER), at(E_FINGER + 1), at(E_FINGER + 2));
    visual.proxy.position.set(at(E_PROXY), at(E_PROXY + 1), at(E_PROXY + 2));

    direction.set(at(E_FORCE), at(E_FORCE + 1), at(E_FORCE + 2));
    const magnitude = direction.length();
    visual.force.visible = magnitude >= FORCE_MIN_N;
    if (visual.force.visible) {
      const length = magnitude * FORCE_M_PER_N;
      const head = Math.min(length * 0.35, 0.005);
      visual.force.position.copy(visual.proxy.position);
      visual.force.setDirection(direction.divideScalar(magnitude));
      visual.force.setLength(length, head, head * 0.6);
    }

    // Planes: exactly as in the latest frame (they switch, they do not move).
    const planeCount = l[lo + E_PLANE_COUNT];
    while (visual.planeVisuals.length < planeCount) visual.planeVisuals.push(makePlaneVisual(visual.planes));
    visual.planes.visible = planesToggle.checked;
    for (let j = 0; j < visual.planeVisuals.length; j++) {
      const mesh = visual.planeVisuals[j];
      mesh.visible = j < planeCount;
      if (!mesh.visible) continue;
      const o = lo + ENDPOINT_VALUES + j * PLANE_VALUES;
      direction.set(l[o + 3], l[o + 4], l[o + 5]);
      const n = direction.length();
      mesh.visible = n > 0 && Number.isFinite(n);
      if (!mesh.visible) continue;
      mesh.position.set(l[o], l[o + 1], l[o + 2]);
      mesh.quaternion.setFromUnitVectors(UP, direction.divideScalar(n));
    }
  }
}

// ---- Strip charts ---------------------------------------------------------------------------------------------------

// A strip chart of a few series over the last CHART_SPAN_S seconds of world time, in a ring buffer.
class StripChart {
  constructor(canvas, series, minSpan, unit) {
    this.canvas = canvas;
    this.context = canvas.getContext('2d');
    this.series = series;                // [{label, colour}]
    this.minSpan = minSpan;              // smallest vertical span drawn, so noise is not blown up to full height
    this.unit = unit;
    this.reset(1024);
  }

  reset(capacity) {
    this.capacity = capacity;
    this.times = new Float64Array(capacity);
    this.values = new Float64Array(capacity * this.series.length);
    this.start = 0;
    this.size = 0;
    this.dirty = true;
  }

  clear() {
    this.start = 0;
    this.size = 0;
    this.dirty = true;
  }

  // Appends a sample; a sample earlier than the last one (a rewind, another run) starts the chart afresh.
  push(t, a, b, c, d) {
    if (this.size > 0) {
      const last = this.times[(this.start + this.size - 1) % this.capacity];
      if (t < last || t - last > CHART_SPAN_S) this.clear();
    }
    const slot = (this.start + this.size) % this.capacity;
    if (this.size < this.capacity) this.size++; else this.start = (this.start + 1) % this.capacity;
    this.times[slot] = t;
    const n = this.series.length;
    const v = this.values;
    v[slot * n] = a;
    if (n > 1) v[slot * n + 1] = b;
    if (n > 2) v[slot * n + 2] = c;
    if (n > 3) v[slot * n + 3] = d;
    this.dirty = true;
  }

  draw() {
    const canvas = this.canvas;
    const ratio = Math.min(window.devicePixelRatio || 1, 2);
    const width = Math.max(1, Math.round(canvas.clientWidth * ratio));
    const height = Math.max(1, Math.round(canvas.clientHeight * ratio));
    if (canvas.width !== width || canvas.height !== height) {
      canvas.width = width;
      canvas.height = height;
      this.dirty = true;
    }
    if (!this.dirty) return;
    this.dirty = false;

    const g = this.context;
    g.setTransform(ratio, 0, 0, ratio, 0, 0);
    const w = width / ratio;
    const h = height / ratio;
    g.clearRect(0, 0, w, h);
    g.font = '11px ui-monospace, "DejaVu Sans Mono", monospace';
    g.textBaseline = 'middle';
    const left = 52;
    const right = 8;
    const top = 18;
    const bottom = 16;
    const plotW = Math.max(1, w - left - right);
    const plotH = Math.max(1, h - top - bottom);
    const n = this.series.length;

    const newest = this.size ? this.times[(this.start + this.size - 1) % this.capacity] : 0;
    const t0 = newest - CHART_SPAN_S;
    let lo = Infinity;
    let hi = -Infinity;
    for (let i = 0; i < this.size; i++) {
      const slot = (this.start + i) % this.capacity;
      if (this.times[slot] < t0) continue;
      for (let s = 0; s < n; s++) {
        const v = this.values[slot * n + s];
        if (v < lo) lo = v;
        if (v > hi) hi = v;
      }
    }
    if (!(lo <= hi)) { lo = -this.minSpan / 2; hi = this.minSpan / 2; }
    if (hi - lo < this.minSpan) {
      const mid = (hi + lo) / 2;
      lo = mid - this.minSpan / 2;
      hi = mid + this.minSpan / 2;
    }
    const pad = (hi - lo) * 0.08;
    lo -= pad;
    hi += pad;
    const x = (t) => left + (t - t0) / CHART_SPAN_S * plotW;
    const y = (v) => top + (hi - v) / (hi - lo) * plotH;

    // Axes: a line a second, labelled every two; the top, bottom and zero of the value axis.
    g.lineWidth = 1;
    g.strokeStyle = '#232932';
    g.fillStyle = '#7d8794';
    for (let s = 0; s <= CHART_SPAN_S; s++) {
      const px = Math.round(left + s / CHART_SPAN_S * plotW) + 0.5;
      g.beginPath(); g.moveTo(px, top); g.lineTo(px, top + plotH); g.stroke();
      if (s % 2 !== 0) continue;
      g.textAlign = s === CHART_SPAN_S ? 'right' : 'center';
      g.fillText(s === CHART_SPAN_S ? 'now' : `${s - CHART_SPAN_S} s`, px, h - bottom / 2);
    }
    g.textAlign = 'right';
    for (const v of [lo + pad, hi - pad]) g.fillText(formatValue(v), left - 5, y(v));
    if (lo < 0 && hi > 0) {
      g.strokeStyle = '#3a4350';
      g.beginPath(); g.moveTo(left, Math.round(y(0)) + 0.5); g.lineTo(left + plotW, Math.round(y(0)) + 0.5); g.stroke();
      // Labelled unless a bound's label is there already.
      if (Math.min(Math.abs(y(0) - y(lo + pad)), Math.abs(y(0) - y(hi - pad))) > 12) g.fillText('0', left - 5, y(0));
    }

    // The series.
    g.save();
    g.beginPath(); g.rect(left, top, plotW, plotH); g.clip();
    g.lineWidth = 1.4;
    for (let s = 0; s < n; s++) {
      g.strokeStyle = this.series[s].colour;
      g.beginPath();
      let drawing = false;
      for (let i = 0; i < this.size; i++) {
        const slot = (this.start + i) % this.capacity;
        const t = this.times[slot];
        const v = this.values[slot * n + s];
        if (t < t0 - 1 || !Number.isFinite(v)) { drawing = false; continue; }
        if (drawing) g.lineTo(x(t), y(v)); else g.moveTo(x(t), y(v));
        drawing = true;
      }
      g.stroke();
    }
    g.restore();

    // Legend with the newest values.
    g.textAlign = 'left';
    let lx = left;
    for (let s = 0; s < n; s++) {
      const v = this.size ? this.values[((this.start + this.size - 1) % this.capacity) * n + s] : NaN;
      const text = `${this.series[s].label} ${Number.isFinite(v) ? formatValue(v) : '—'}`;
      g.fillStyle = this.series[s].colour;
      g.fillRect(lx, top / 2 - 1, 8, 2);
      g.fillStyle = '#b9c2cd';
      g.fillText(text, lx + 11, top / 2);
      lx += g.measureText(text).width + 24;
    }
    g.textAlign = 'right';
    g.fillStyle = '#7d8794';
    g.fillText(this.unit, w - right, top / 2);
  }
}

function formatValue(v) {
  const a = Math.abs(v);
  if (a === 0) return '0';
  if (a !== 0 && (a < 1e-3 || a >= 1e4)) return v.toExponential(1);
  return v.toFixed(a < 0.01 ? 4 : a < 1 ? 3 : a < 100 ? 2 : 0);
}

const forceChart = new StripChart(document.getElementById('chart-force'), [
  { label: '|f|', colour: '#f2f4f7' },
  { label: 'x', colour: '#ff6b5e' },
  { label: 'y', colour: '#6fdc7a' },
  { label: 'z', colour: '#5fa8ff' },
], 0.1, 'N');
const positionChart = new StripChart(document.getElementById('chart-position'), [
  { label: 'x', colour: '#ff6b5e' },
  { label: 'y', colour: '#6fdc7a' },
  { label: 'z', colour: '#5fa8ff' },
], 0.002, 'm');

const bodySelect = document.getElementById('body-select');
let chartBody = -1;                      // the body whose position is charted, or -1
let chartBodyName = null;                // its name, to chart it again when a new scene has it

function chartCapacity(message) {
  const rate = Number.isFinite(message.world_rate_hz) && message.world_rate_hz > 0 ? message.world_rate_hz : 100;
  return Math.min(Math.max(Math.ceil(rate * CHART_SPAN_S * 2) + 64, 1024), 200000);
}

function rebuildBodySelect(bodies) {
  const previous = chartBodyName;
  bodySelect.replaceChildren();
  // The body charted before, if the new scene has it; else the first dynamic body.
  let first = -1;
  let same = -1;
  bodies.forEach((body, k) => {
    if (!body.dynamic) return;
    bodySelect.append(new Option(body.name || `body ${k}`, String(k)));
    if (first < 0) first = k;
    if (same < 0 && previous !== null && body.name === previous) same = k;
  });
  chartBody = same >= 0 ? same : first;
  chartBodyName = chartBody >= 0 ? bodies[chartBody].name : null;
  if (chartBody >= 0) bodySelect.value = String(chartBody);
  bodySelect.disabled = chartBody < 0;
}

bodySelect.addEventListener('change', () => {
  chartBody = Number(bodySelect.value);
  chartBodyName = scene.bodies[chartBody].name;
  positionChart.clear();
});

function recordCharts(frame) {
  const d = frame.data;
  const t = d[H_TIME];
  if (frame.endpoints.length > 0) {
    const o = frame.endpoints[0] + E_FORCE;
    forceChart.push(t, Math.hypot(d[o], d[o + 1], d[o + 2]), d[o], d[o + 1], d[o + 2]);
  }
  if (chartBody >= 0 && chartBody < d[H_BODIES]) {
    const o = HEADER_VALUES + chartBody * BODY_VALUES;
    positionChart.push(t, d[o], d[o + 1], d[o + 2]);
  }
}

// ---- Replay bar -----------------------------------------------------------------------------------------------------

const replayBar = document.getElementById('replay');
const playButton = document.getElementById('replay-play');
const timeSlider = document.getElementById('replay-time');
const speedSelect = document.getElementById('replay-speed');
const timeLabel = document.getElementById('replay-label');
let replayPlaying = false;
let sliderHeld = false;                  // while the user drags, frames do not move the slider under the pointer
let seekTimer = 0;
let pendingSeek = null;

function showReplayBar(message) {
  const replay = message.mode === 'replay' && message.replay ? message.replay : null;
  replayBar.classList.toggle('shown', Boolean(replay));
  if (!replay) return;
  const start = Number.isFinite(replay.start_s) ? replay.start_s : 0;
  const end = Number.isFinite(replay.end_s) && replay.end_s > start ? replay.end_s : start + 1;
  timeSlider.min = String(start);
  timeSlider.max = String(end);
  timeSlider.value = String(start);
  timeLabel.textContent = `${start.toFixed(3)} / ${end.toFixed(3)} s`;
}

function syncReplayBar(frame) {
  if (!scene || scene.mode !== 'replay') return;
  const d = frame.data;
  replayPlaying = d[H_PLAYING] === 1;
  playButton.textContent = replayPlaying ? 'pause' : 'play';
  if (!sliderHeld) timeSlider.value = String(d[H_TIME]);
  timeLabel.textContent = `${d[H_TIME].toFixed(3)} / ${Number(timeSlider.max).toFixed(3)} s`;
  if (document.activeElement !== speedSelect) {
    const option = Array.from(speedSelect.options).find((o) => Number(o.value) === d[H_SPEED]);
    if (option) speedSelect.value = option.value;
  }
}

playButton.addEventListener('click', () => {
  replayPlaying = !replayPlaying;        // shown at once; the next frame says what the viewer really does
  playButton.textContent = replayPlaying ? 'pause' : 'play';
  sendControl({ play: replayPlaying });
});

speedSelect.addEventListener('change', () => sendControl({ speed: Number(speedSelect.value) }));

// Seeks follow the slider at most every 50 ms, and the last position is always sent.
timeSlider.addEventListener('input', () => {
  pendingSeek = Number(timeSlider.value);
  timeLabel.textContent = `${pendingSeek.toFixed(3)} / ${Number(timeSlider.max).toFixed(3)} s`;
  if (seekTimer) return;
  const flush = () => {
    if (pendingSeek === null) { seekTimer = 0; return; }
    sendControl({ seek: pendingSeek });
    pendingSeek = null;
    seekTimer = setTimeout(flush, 50);
  };
  flush();
});
timeSlider.addEventListener('pointerdown', () => { sliderHeld = true; });
window.addEventListener('pointerup', () => { sliderHeld = false; });

// ---- HUD ------------------------------------------------------------------------------------------------------------

const hud = document.getElementById('hud');
const hudText = document.createElement('span');
const hudState = document.createElement('span');
hud.replaceChildren(hudText, hudState);
let hudDirty = true;
let hudLast = 0;
let connectionState = 'connecting';

function setConnectionState(state) {
  connectionState = state;
  hudDirty = true;
  updateHud();
}

function updateHud() {
  hudDirty = false;
  const d = latest ? latest.data : null;
  const number = (v, digits = 0) => (d && Number.isFinite(v) ? v.toFixed(digits) : '—');
  const lateness = d ? d[H_LATENESS_P99] : NaN;
  const rows = [
    ['mode', scene ? scene.mode : '—'],
    ['source', scene ? scene.source : '—'],
    ['coupling', scene ? scene.coupling : '—'],
    ['world rate', scene && Number.isFinite(scene.world_rate_hz) ? `${scene.world_rate_hz} Hz` : '—'],
    ['frame', d ? number(d[H_INDEX]) : '—'],
    ['world time', d ? `${number(d[H_TIME], 3)} s` : '—'],
    ['late p99', Number.isFinite(lateness) ? `${(lateness * 1e6).toFixed(0)} µs` : '—'],
    ['faults', d ? number(d[H_FAULTS]) : '—'],
    ['skipped', d ? `world ${number(d[H_WORLD_SKIPPED])}, haptic ${number(d[H_HAPTIC_SKIPPED])}` : '—'],
    ['fps', view.fps.toFixed(0)],
  ];
  hudText.textContent = rows.map(([k, v]) => `${k.padEnd(11)}${v ?? '—'}`).join('\n') + '\nconnection ';
  hudState.textContent = connectionState === 'disconnected' ? 'disconnected, retrying' : connectionState;
  hudState.className = `state-${connectionState}`;
}

// ---- Connection -----------------------------------------------------------------------------------------------------

let socket = null;

function connect() {
  setConnectionState('connecting');
  try {
    socket = new WebSocket(`ws://${location.host}/ws`);
  } catch (error) {
    console.warn('impetus viewer: cannot open the socket', error);
    setTimeout(connect, RECONNECT_MS);
    return;
  }
  const ws = socket;
  ws.binaryType = 'arraybuffer';
  ws.onopen = () => {
    view.connected = true;
    setConnectionState('live');
  };
  ws.onmessage = (event) => onMessage(event.data);
  ws.onclose = () => {
    if (socket !== ws) return;
    view.connected = false;
    socket = null;
    setConnectionState('disconnected');
    setTimeout(connect, RECONNECT_MS);
  };
}

// Never throws: a message that cannot be used is counted and dropped.
function onMessage(data) {
  if (typeof data === 'string') {
    try {
      const message = JSON.parse(data);
      if (!message || message.type !== 'scene' || !Array.isArray(message.bodies)
          || !message.bodies.every((b) => b && typeof b === 'object')) {
        view.rejectedMessages++;
        return;
      }
      scene = message;
      view.scene = message;
      buildScene(message);
      hudDirty = true;
    } catch (error) {
      view.rejectedMessages++;
      console.warn('impetus viewer: bad text message', error);
    }
    return;
  }
  try {
    const frame = parseFrame(data);
    if (frame) onFrame(frame); else view.rejectedFrames++;
  } catch (error) {
    view.rejectedFrames++;
    console.warn('impetus viewer: bad frame', error);
  }
}

function sendControl(message) {
  if (!socket || socket.readyState !== WebSocket.OPEN) return false;
  socket.send(JSON.stringify(message));
  return true;
}

// ---- Render loop ----------------------------------------------------------------------------------------------------

let fpsWindowStart = performance.now();
let fpsWindowFrames = 0;

function resize() {
  const width = Math.max(1, viewElement.clientWidth);
  const height = Math.max(1, viewElement.clientHeight);
  renderer.setSize(width, height, false);
  camera.aspect = width / height;
  camera.updateProjectionMatrix();
  forceChart.dirty = true;
  positionChart.dirty = true;
}
new ResizeObserver(resize).observe(viewElement);

// Places bodies and endpoints where they are at page time `now` (ms), interpolated between the last two frames.
function placeAll(now) {
  if (!latest) return;
  const alpha = interpolationAlpha(now);
  drawBodies(alpha);
  drawEndpoints(alpha);
  toolVisual.draw(latest.data, latest.tool, prev ? prev.data : null, prev ? prev.tool : -1, alpha);
}

function animate() {
  requestAnimationFrame(animate);
  const now = performance.now();

  controls.update();
  const orbit = camera.position.distanceTo(controls.target);
  world.fog.near = orbit * 1.5;
  world.fog.far = orbit * 4;
  placeAll(now);
  followBodies(now);
  renderer.render(world, camera);
  forceChart.draw();
  positionChart.draw();
  touch.update(now);

  view.renderedFrames++;
  fpsWindowFrames++;
  if (now - fpsWindowStart >= 1000) {
    view.fps = fpsWindowFrames * 1000 / (now - fpsWindowStart);
    fpsWindowStart = now;
    fpsWindowFrames = 0;
    hudDirty = true;
  }
  if (hudDirty && now - hudLast >= HUD_INTERVAL_MS) {
    hudLast = now;
    updateHud();
  }
}

document.getElementById('reframe').addEventListener('click', () => {
  cameraTouched = false;
  if (latest) frameCamera(latest);
});
controls.addEventListener('start', () => { cameraTouched = true; });
planesToggle.addEventListener('change', () => {
  for (const visual of endpointVisuals) visual.planes.visible = planesToggle.checked;
});

// Endpoint 0's finger and force in the latest frame, for the touch panel (null without one).
function firstEndpointVector(offset) {
  if (!latest || latest.endpoints.length === 0) return null;
  const o = latest.endpoints[0] + offset;
  const d = latest.data;
  return [d[o], d[o + 1], d[o + 2]];
}
const touch = createTouch({
  camera,
  controls,
  canvas: renderer.domElement,
  finger: () => (latest && latest.endpoints.length && latest.data[latest.endpoints[0] + E_FINGER_VALID] === 1
    ? firstEndpointVector(E_FINGER) : null),
  force: () => firstEndpointVector(E_FORCE),
});

resize();
connect();
requestAnimationFrame(animate);
