// SPDX-License-Identifier: Apache-2.0
//
// The touch page's heartbeat (touch.js), in a worker of its own: its own WebSocket at /ws/touch (touch messages only,
// no frames), and a timer the page's drawing cannot hold up. A frame that takes long to draw (software rendering, a
// slow GPU, a garbage collection) stalls the page's thread; a heartbeat sent from there would stall with it and the
// hand would let go mid-push (it lets go of a page silent for 40 ms). The page still decides: it posts its target and
// a sign of life, and a page silent for PAGE_SILENT_MS (frozen) is no longer heartbeaten for: the hand lets go.
//
// From the page: {kind: "connect", token}, {kind: "take"}, {kind: "release"}, {kind: "target", target_m}, {kind:
// "alive"}. To the page: the viewer's touch replies (view_protocol.h §4) and {type: "socket", open: bool}.

const SEND_MS = 10;            // the heartbeat: four within the hand's 40 ms
const PAGE_SILENT_MS = 500;    // a page thread silent this long is frozen
const RECONNECT_MS = 1000;

let socket = null;
let token = null;
let holding = false;
let target = null;
let lastPage = 0;

function send(message) {
  if (!socket || socket.readyState !== WebSocket.OPEN) return false;
  socket.send(JSON.stringify(message));
  return true;
}

function connect() {
  socket = new WebSocket(`${self.location.protocol === 'https:' ? 'wss' : 'ws'}://${self.location.host}/ws/touch`);
  const ws = socket;
  ws.onopen = () => postMessage({ type: 'socket', open: true });
  ws.onmessage = (event) => {
    if (typeof event.data !== 'string') return;
    try {
      const message = JSON.parse(event.data);
      if (message && message.type === 'touch') {
        holding = message.state === 'holding';
        postMessage(message);
      }
    } catch {
      // not a reply this worker understands: ignored
    }
  };
  ws.onclose = () => {
    if (socket !== ws) return;
    socket = null;
    holding = false;
    postMessage({ type: 'socket', open: false });
    setTimeout(connect, RECONNECT_MS);
  };
}

onmessage = (event) => {
  const m = event.data;
  lastPage = performance.now();
  switch (m.kind) {
    case 'connect':
      token = m.token;
      if (!socket) connect();
      break;
    case 'take':
      send({ touch: 'take', token });
      break;
    case 'release':
      if (holding) send({ touch: 'release' });
      holding = false;
      target = null;
      break;
    case 'target':
      target = m.target_m;
      break;
    default:
      break;   // 'alive': the time above is all it carries
  }
};

setInterval(() => {
  if (!holding || !target || performance.now() - lastPage > PAGE_SILENT_MS) return;
  if (send({ touch: 'target', target_m: target })) postMessage({ type: 'sent' });
}, SEND_MS);
