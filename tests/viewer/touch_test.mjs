// SPDX-License-Identifier: Apache-2.0
// The viewer's page as an input device (docs/touch.md): a person's pointer steers the web hand
// (haptic_controller --device web) through `viewer --touch`, in headless Chromium driven by Playwright.
//   node tests/viewer/touch_test.mjs --build BUILD_DIR --case drag|letgo|control [--picture FILE]
// --picture (drag only): also saves the page mid-push as FILE (the README's picture; scripts/make_figures.sh).
// Each case runs a real-time tap scene (world_manager, haptic_controller --device web, viewer --touch) under a
// shared-memory name of its own, prints what it checks and measures, and exits 0 if every check held, 1 otherwise.

import fs from "node:fs";
import http from "node:http";
import net from "node:net";
import path from "node:path";
import crypto from "node:crypto";
import { fileURLToPath } from "node:url";
import { Failure, check, readCsv, runCase, sleep, waitFor } from "./browser.mjs";

const source = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "../..");
const args = process.argv.slice(2);
const option = (name) => { const i = args.indexOf(name); return i >= 0 ? args[i + 1] : undefined; };
const build = path.resolve(option("--build") ?? path.join(source, "build"));
const which = option("--case");
const picture = option("--picture");
const outDir = path.join(build, "test-output", `touch-${which}`);
fs.rmSync(outDir, { recursive: true, force: true });
fs.mkdirSync(outDir, { recursive: true });
const shm = `impetus_touch_${which}_${process.pid}`;
const tapScene = path.join(source, "scenes", "tap.json");
const monotonicNs = () => process.hrtime.bigint();  // CLOCK_MONOTONIC on Linux, the clock the hand stamps

// The world (local coupling, as scripts/demo.sh --interactive runs it), the web hand and a viewer that takes input;
// returns the viewer's touch address.
async function startTrial(procs) {
  procs.start("world", "world_manager", ["--scene", tapScene, "--clock", "realtime", "--coupling", "local", "--shm", shm,
    "--log", path.join(outDir, "world.csv")]);
  const haptic = procs.start("haptic", "haptic_controller", ["--clock", "realtime", "--shm", shm, "--device", "web",
    "--log", path.join(outDir, "haptic.csv"), "--summary", path.join(outDir, "haptic.json")]);
  const viewer = await procs.viewer(["--shm", shm, "--touch"]);
  const touchUrl = await waitFor("the viewer's touch address", () => {
    const match = /touch the world: (http:\/\/\S+)/.exec(viewer.stdoutText);
    return match ? match[1] : null;
  }, 10000);
  return { haptic, viewer, touchUrl };
}

async function openPage(browser, url) {
  // Small, but for the README's picture: software WebGL draws every frame on the two cores the trial runs on.
  const page = await browser.newPage({ viewport: picture ? { width: 960, height: 640 } : { width: 640, height: 420 } });
  page.on("pageerror", (error) => console.log(`  page error: ${error.message}`));
  await page.goto(url);
  return page;
}

const touchState = (page) => page.evaluate(() => JSON.parse(JSON.stringify(window.impetusView.touch)));

// Waits until the page holds the hand and has drawn the world (its camera framed the scene: a camera set before the
// first frame would be framed over).
async function holding(page) {
  await waitFor("the page to hold the hand", async () => (await touchState(page)).state === "holding", 15000);
  return waitFor("the page's first frames", () => page.evaluate(() => window.impetusView.framesReceived > 5), 15000);
}

// Page pixels of a world point, with the camera as drawn now.
const project = (page, point) => page.evaluate((p) => window.impetusView.projectPoint(p), point);

// Drags the pointer so that the hand's target, moving in the upright x–z plane through it, goes from `from` to each
// point of `path` in turn (world metres), `msPerStep` between pointer moves of at most 2 mm.
async function dragTarget(page, from, path, msPerStep = 8) {
  await page.selectOption("#touch-plane", "xz");
  let at = await project(page, from);
  await page.mouse.move(at.x, at.y);
  await page.mouse.down();
  let current = from;
  for (const point of path) {
    const steps = Math.max(1, Math.ceil(Math.hypot(point[0] - current[0], point[2] - current[2]) / 0.002));
    for (let s = 1; s <= steps; ++s) {
      const p = current.map((c, k) => c + (point[k] - c) * (s / steps));
      at = await project(page, p);
      await page.mouse.move(at.x, at.y);
      await sleep(msPerStep);
    }
    current = point;
  }
}

function summary() { return JSON.parse(fs.readFileSync(path.join(outDir, "haptic.json"), "utf8")).haptic; }

// Presses the finger on the floor beside the cube, from above, until the page's gauge shows more than 1 N. A page the
// machine starves for 40 ms mid-press loses the hand and takes it again with its next message; the finger, resting
// where it was, resumes the press (haptic_controller/god_object.h), so one press is enough.
async function pressFloor(page) {
  const state = await touchState(page);
  const from = state.target_m ?? state.hand.finger_m;  // the target the page sends now: the drag moves it
  await dragTarget(page, from, [[-0.04, 0, 0.02], [-0.04, 0, -0.01]]);
  await waitFor("a force on the finger", async () =>
    Number.parseFloat(await page.textContent("#touch-gauge-label")) > 1.0, 5000);
}

// A person drags the finger down beside the cube and pushes it along +x: the cube slides in world.csv.
async function drag(procs, browser) {
  const { haptic, viewer, touchUrl } = await startTrial(procs);
  const page = await openPage(browser, touchUrl);
  await holding(page);
  check(true, "the page opened from the printed address holds the hand");
  // A side view along +y: the drag plane x–z faces the camera.
  await page.evaluate(() => window.impetusView.lookAt([0.06, 0, 0.03], 0.12));
  await sleep(300);
  const rest = (await touchState(page)).hand.finger_m;
  check(Math.abs(rest[0]) < 1e-9 && Math.abs(rest[2] - 0.05) < 1e-9,
    `the hand rests at the workspace centre before the first drag (${rest.map((v) => v.toFixed(3))})`);
  // Down beside the cube's −x face (at x = 0.005 m), then through where the cube is: 8 cm along +x at ~0.25 m/s.
  await dragTarget(page, rest, [[-0.02, 0, 0.025], [-0.02, 0, 0.025], [0.08, 0, 0.025]]);
  const mid = await touchState(page);
  if (picture) await page.screenshot({ path: picture });
  await page.screenshot({ path: path.join(outDir, "page.png") });
  await page.mouse.up();
  await sleep(1500);
  const gauge = await page.textContent("#touch-gauge-label");
  await page.close();
  await procs.stop(haptic);
  await procs.stop(viewer);
  console.log(`  ${procs.log(viewer.name).trim().split("\n").pop()}`);
  const world = readCsv(path.join(outDir, "world.csv"));
  const x = world.column("cube.x_m");
  const start = world.rows[0][x];
  const end = world.rows[world.rows.length - 1][x];
  check(Math.abs(start - 0.03) < 1e-6, `the cube starts at x = ${start.toFixed(4)} m`);
  check(end > start + 0.03, `the finger pushed it along +x: it ends at x = ${end.toFixed(4)} m`);
  const log = readCsv(path.join(outDir, "haptic.csv"));
  const fx = log.column("force_x_N");
  const pushing = log.rows.filter((row) => row[fx] < -0.3).length;
  check(pushing > 50, `the finger felt the cube: ${pushing} ticks with a force of more than 0.3 N along −x`);
  const s = summary();
  // A page the machine starves for 40 ms (this test shares two cores with software WebGL) loses the hand and takes
  // it again with its next message: every hold after the first follows such a silence, and nothing else let go.
  check(s.device.kind === "web" && s.device.holds >= 1 && s.device.holds <= 1 + s.device.timeouts &&
    s.device.releases <= 1, `the web hand was taken ${s.device.holds} time(s): once, and again only after ` +
    `silences of the starved page (${s.device.timeouts}); let go ${s.device.releases} time(s) when told`);
  check(mid.sent > 50, `the page sent ${mid.sent} targets while it dragged`);
  console.log(`  gauge after the push: ${gauge}; max force ${s.max_force_N.toFixed(2)} N, lateness p99 ` +
    `${(s.lateness_p99_ns / 1e3).toFixed(0)} µs, skipped periods ${s.skipped_periods}`);
}

// The hand lets go when the page hides, takes it again when shown, and lets go within 50 ms of the page closing
// while the finger presses into the floor (the force is off from that tick on).
async function letgo(procs, browser) {
  const { haptic, touchUrl } = await startTrial(procs);
  const page = await openPage(browser, touchUrl);
  await holding(page);
  await page.evaluate(() => window.impetusView.lookAt([0, 0, 0.03], 0.12));
  await sleep(300);
  // Down into the floor (z = 0) beside the cube: the hand's spring presses the finger on it.
  await pressFloor(page);

  await page.evaluate(() => {
    Object.defineProperty(document, "hidden", { configurable: true, get: () => true });
    document.dispatchEvent(new Event("visibilitychange"));
  });
  check((await touchState(page)).state === "released", "a hidden page lets go of the hand");
  await sleep(600);  // hidden this long: longer than any silence a starved page has here (the longest seen, 0.2 s)
  await page.evaluate(() => {
    delete document.hidden;  // the browser's own again: visible
    document.dispatchEvent(new Event("visibilitychange"));
  });
  await holding(page);
  check(true, "and takes it again when shown");
  await pressFloor(page);

  // The page is gone somewhere between the call to close it and that call's return: a starved browser takes its time
  // to tear a page down (over 100 ms here under load), and heartbeats go on until it does.
  const closeCalled = monotonicNs();
  await page.close();
  const closeReturned = monotonicNs();
  await sleep(300);
  await procs.stop(haptic);
  const s = summary();
  const release = BigInt(s.device.last_release_ns);
  const afterCallMs = Number(release - closeCalled) / 1e6;
  const afterGoneMs = Number(release - closeReturned) / 1e6;
  console.log(`  web hand: taken ${s.device.holds} times, let go ${s.device.releases} times when told and ` +
    `${s.device.timeouts} on silence (a page starved of CPU here); the browser took ` +
    `${(Number(closeReturned - closeCalled) / 1e6).toFixed(1)} ms to close the page`);
  // Negative: a silence let go before the close did (the force was off already).
  check(afterGoneMs <= 50, `closing the page mid-press took the force off ${afterCallMs.toFixed(1)} ms after the ` +
    `close was asked for, ${afterGoneMs.toFixed(1)} ms after the page was gone`);
  check(s.device.max_release_delay_s <= 0.05, `every let-go came within 50 ms of the page's last word or silence ` +
    `(the longest ${(s.device.max_release_delay_s * 1e3).toFixed(1)} ms)`);
  const log = readCsv(path.join(outDir, "haptic.csv"));
  const fz = log.column("force_z_N"), flags = log.column("flags");
  const present = log.rows.map((row) => (row[flags] & 1) === 1);
  let last = present.lastIndexOf(true);  // the last tick with a finger: the page's last
  const before = log.rows.slice(Math.max(0, last - 20), last + 1);
  const after = log.rows.slice(last + 1);
  check(last > 0 && before.every((row) => row[fz] > 1.0),
    `the finger pressed on the floor up to its last tick (${before.length} ticks, over 1 N each)`);
  check(after.length > 100 && after.every((row) => row[fz] === 0),
    `and the ${after.length} ticks after it (to the end of the trial) have no finger and no force`);
  // While the page was hidden: a run of ticks without a finger between two holds, as long as it was hidden.
  let longestGap = 0;
  for (let i = present.indexOf(true), run = 0; i >= 0 && i <= last; ++i) {
    run = present[i] ? 0 : run + 1;
    longestGap = Math.max(longestGap, run);
  }
  check(longestGap >= 500, `while it was hidden the hand had no finger and rendered nothing (${longestGap} ticks)`);
}

// One page holds the hand at a time; a page from another site, or a client that is not a page, never takes it.
async function control(procs, browser) {
  const { haptic, viewer, touchUrl } = await startTrial(procs);
  const first = await openPage(browser, touchUrl);
  await holding(first);
  const second = await openPage(browser, touchUrl);
  await waitFor("the second page's answer", async () => (await touchState(second)).state === "watching", 10000);
  check(/another page/.test((await touchState(second)).reason), "a second page with the token watches: " +
    (await touchState(second)).reason);
  await second.click("#touch-take");
  await sleep(300);
  check((await touchState(second)).state === "watching", "and cannot take the hand while the first holds it");
  check((await touchState(first)).state === "holding", "the first page still holds it");
  const wrong = await openPage(browser, touchUrl.replace(/touch=[0-9a-f]+/, "touch=0123456789abcdef0123456789abcdef"));
  await waitFor("the wrong token's answer", async () => (await touchState(wrong)).state === "refused", 10000);
  check(true, `a page with a wrong token is refused: ${(await touchState(wrong)).reason}`);
  await wrong.close();

  // Another site's page, opened in the same browser, tries the viewer's WebSocket with the right token.
  const port = Number(new URL(touchUrl).port);
  const token = new URL(touchUrl).searchParams.get("touch");
  const site = http.createServer((request, response) => {
    response.writeHead(200, { "content-type": "text/html" });
    response.end(`<script>
      window.outcome = "pending";
      const ws = new WebSocket("ws://127.0.0.1:${port}/ws/touch");
      ws.onopen = () => { ws.send(JSON.stringify({ touch: "take", token: "${token}" })); window.outcome = "open"; };
      ws.onmessage = (e) => { if (typeof e.data === "string" && e.data.includes('"touch"')) window.outcome = e.data; };
      ws.onerror = () => { window.outcome = "refused"; };
    </script>`);
  });
  await new Promise((resolve) => site.listen(0, "127.0.0.1", resolve));
  const foreign = await browser.newPage();
  await foreign.goto(`http://127.0.0.1:${site.address().port}/`);
  const outcome = await waitFor("the other site's socket", async () => {
    const value = await foreign.evaluate(() => window.outcome);
    return value !== "pending" ? value : null;
  }, 10000);
  check(outcome === "refused", `another site's page cannot open the viewer's socket (${outcome})`);
  await foreign.close();
  site.close();

  // A client that is not a browser page (no Origin header) sends the right token.
  const reply = await rawTouchTake(port, token);
  check(/"state":"refused"/.test(reply) && /only a page/.test(reply), `a client that is no page is refused: ${reply}`);

  await first.close();
  await second.click("#touch-take");
  await holding(second);
  check(true, "once the first page closes, the second takes the hand");
  await second.close();
  await sleep(200);
  await procs.stop(haptic);
  await procs.stop(viewer);
  const s = summary();
  console.log(`  web hand: taken ${s.device.holds} times, let go ${s.device.releases} times when told and ` +
    `${s.device.timeouts} on silence (pages starved of CPU here take it again with their next message)`);
  console.log(`  ${procs.log(viewer.name).trim().split("\n").pop()}`);
  check(/2 takes refused|[3-9] takes refused/.test(procs.log(viewer.name)),
    "the viewer counted the refused takes (the second page's, the wrong token's, the client without a page)");
}

// A WebSocket opened by hand without an Origin header; sends {"touch": "take"} with `token` and returns the first text
// message the viewer answers with.
function rawTouchTake(port, token) {
  return new Promise((resolve, reject) => {
    const socket = net.connect(port, "127.0.0.1");
    const key = crypto.randomBytes(16).toString("base64");
    let buffer = Buffer.alloc(0);
    let upgraded = false;
    const timer = setTimeout(() => { socket.destroy(); reject(new Failure("no answer from the viewer")); }, 5000);
    socket.on("error", reject);
    socket.write(`GET /ws/touch HTTP/1.1\r\nHost: 127.0.0.1:${port}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n` +
      `Sec-WebSocket-Key: ${key}\r\nSec-WebSocket-Version: 13\r\n\r\n`);
    socket.on("data", (chunk) => {
      buffer = Buffer.concat([buffer, chunk]);
      if (!upgraded) {
        const end = buffer.indexOf("\r\n\r\n");
        if (end < 0) return;
        if (!buffer.subarray(0, end).toString().includes(" 101 ")) {
          clearTimeout(timer);
          socket.destroy();
          resolve(buffer.subarray(0, end).toString().split("\r\n")[0]);
          return;
        }
        upgraded = true;
        buffer = buffer.subarray(end + 4);
        const payload = Buffer.from(JSON.stringify({ touch: "take", token }));
        const mask = crypto.randomBytes(4);
        const frame = Buffer.concat([Buffer.from([0x81, 0x80 | payload.length]), mask,
          Buffer.from(payload.map((b, i) => b ^ mask[i % 4]))]);
        socket.write(frame);
      }
      // Frames from the server are unmasked; text frames (opcode 1) under 126 bytes of length field or 16-bit.
      while (buffer.length >= 2) {
        const opcode = buffer[0] & 0x0f;
        let length = buffer[1] & 0x7f, offset = 2;
        if (length === 126) { if (buffer.length < 4) return; length = buffer.readUInt16BE(2); offset = 4; }
        else if (length === 127) { if (buffer.length < 10) return; length = Number(buffer.readBigUInt64BE(2)); offset = 10; }
        if (buffer.length < offset + length) return;
        const data = buffer.subarray(offset, offset + length);
        buffer = buffer.subarray(offset + length);
        if (opcode === 1 && data.toString().includes('"touch"')) {
          clearTimeout(timer);
          socket.destroy();
          resolve(data.toString());
          return;
        }
      }
    });
  });
}

const cases = { drag, letgo, control };
await runCase("touch_test", cases, which, build, outDir, shm);
