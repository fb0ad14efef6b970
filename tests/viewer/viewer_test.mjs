// SPDX-License-Identifier: Apache-2.0
// The viewer in a real browser (headless Chromium driven by Playwright), against the project's own binaries.
//   node tests/viewer/viewer_test.mjs --build BUILD_DIR
//     --case live|replay|bodies|kill|bad-input|clay|meshes|terrain|tool
//     [--picture FILE]
// --picture (replay only): also saves the page at the tap's hardest push as FILE (the README's picture;
// scripts/make_figures.sh).
// Each case starts what it needs under a shared-memory name of its own, prints what it checks and measures, and exits
// 0 if every check held, 1 otherwise.

import fs from "node:fs";
import net from "node:net";
import path from "node:path";
import { fileURLToPath } from "node:url";
import {
  Failure, angleDeg, changedPixels, check, colourCount, csvPose, decodePng, distance, cpuSeconds, readCsv, runCase,
  sleep, view, waitFor,
} from "./browser.mjs";

const source = path.resolve(path.dirname(fileURLToPath(import.meta.url)), "../..");
const args = process.argv.slice(2);
const option = (name) => { const i = args.indexOf(name); return i >= 0 ? args[i + 1] : undefined; };
const build = path.resolve(option("--build") ?? path.join(source, "build"));
const which = option("--case");
const outDir = path.join(build, "test-output", `viewer-${which}`);
fs.rmSync(outDir, { recursive: true, force: true });
fs.mkdirSync(outDir, { recursive: true });
const shm = `impetus_viewer_${which}_${process.pid}`;
const tapScene = path.join(source, "scenes", "tap.json");

// The page's 3-D view drawn now, decoded (impetusView.capture: faster than a page screenshot in software WebGL), and
// where body `name` is in it.
async function capture(page, name) {
  const { url, at } = await page.evaluate((body) => ({ url: window.impetusView.capture(),
    at: window.impetusView.project(body) }), name);
  if (!at) throw new Failure(`the page drew no body '${name}' in its capture`);
  return { image: decodePng(Buffer.from(url.slice(url.indexOf(",") + 1), "base64")), at };
}

// The last row of a log the world is still writing (it flushes every step).
function lastRow(file) {
  const lines = fs.readFileSync(file, "utf8").split("\n").filter((line) => line.length > 0);
  return { columns: lines[0].split(","), row: lines[lines.length - 1].split(",").map(Number) };
}

async function openPage(browser, url) {
  const page = await browser.newPage({ viewport: { width: 960, height: 640 } });
  page.on("pageerror", (error) => console.log(`  page error: ${error.message}`));
  await page.goto(url);
  return page;
}

// A real-time tap trial watched live: the page renders, shows the world's poses, and moves where the cube moves.
async function live(procs, browser) {
  const world = procs.start("world", "world_manager", ["--scene", tapScene, "--clock", "realtime", "--shm", shm,
    "--log", path.join(outDir, "world.csv")]);
  const viewer = await procs.viewer(["--shm", shm]);
  const viewerStart = { cpu: cpuSeconds(viewer.pid), wall: Date.now() };
  const page = await openPage(browser, viewer.url);
  await waitFor("the page's first frames", async () => (await view(page))?.framesReceived > 5);
  const haptic = procs.start("haptic", "haptic_controller", ["--clock", "realtime", "--shm", shm,
    "--summary", path.join(outDir, "haptic.json")]);
  const device = procs.start("device", "spidar_sim", ["--clock", "realtime", "--shm", shm, "--trajectory", "tap"]);
  // The first screenshot as the cube starts to move (seen in world.csv: the page is not polled, so the browser keeps
  // its CPU), the second a second later, when it has slid ~25 cm further; the camera holds still on the whole slide.
  await page.evaluate(() => window.impetusView.lookAt([0.15, 0, 0.025], 0.2));
  const worldCsv = path.join(outDir, "world.csv");
  await waitFor("the tap in world.csv", () => {
    const { columns, row } = lastRow(worldCsv);
    return row[columns.indexOf("cube.x_m")] > 0.032;  // the cube rests at x = 0.03 m
  }, 15000, 10);
  const first = await capture(page, "cube");
  const samples = [];
  for (const end = Date.now() + 1000; Date.now() < end;) {
    samples.push((await view(page)).latest);
    await sleep(100);
  }
  const second = await capture(page, "cube");
  await page.screenshot({ path: path.join(outDir, "page.png") });
  for (let i = 0; i < 10; ++i) { samples.push((await view(page)).latest); await sleep(100); }
  const state = await view(page);
  const viewerCpu = (cpuSeconds(viewer.pid) - viewerStart.cpu) / ((Date.now() - viewerStart.wall) / 1000);
  await procs.stop(device);
  await procs.stop(haptic);
  await procs.stop(viewer);
  await procs.stop(world);

  const [cubeBefore, cubeAfter] = [first.at, second.at];
  check(colourCount(first.image) > 5, `the canvas is not blank (a cleared one has 1 colour) (${colourCount(first.image)} colours)`);
  const box = (p) => [p.x - 20, p.y - 20, p.x + 20, p.y + 20];
  const changedAtCube = changedPixels(first.image, second.image, box(cubeBefore)) +
    changedPixels(first.image, second.image, box(cubeAfter));
  check(distance([cubeBefore.x, cubeBefore.y, 0], [cubeAfter.x, cubeAfter.y, 0]) > 5,
    `the cube moved on screen between the screenshots (${cubeBefore.x.toFixed(0)},${cubeBefore.y.toFixed(0)} → ` +
    `${cubeAfter.x.toFixed(0)},${cubeAfter.y.toFixed(0)} px)`);
  check(changedAtCube > 400, `the screenshots a second apart differ where the cube was and is (${changedAtCube} of 3200 pixels)`);

  const log = readCsv(path.join(outDir, "world.csv"));
  const time = log.column("time_s");
  let compared = 0, worstMm = 0, worstDeg = 0, moving = 0;
  for (const sample of samples) {
    const row = log.rows.find((r) => Math.abs(r[time] - sample.worldTime_s) < 1e-9);
    if (!row) continue;
    const logged = csvPose(log, row, "cube");
    const shown = sample.bodies.find((b) => b.name === "cube");
    worstMm = Math.max(worstMm, 1000 * distance(logged.position_m, shown.position_m));
    worstDeg = Math.max(worstDeg, angleDeg(logged.orientation_wxyz, shown.orientation_wxyz));
    if (distance(logged.position_m, log.rows[0].slice(1, 4)) > 1e-3) ++moving;
    ++compared;
  }
  check(compared >= 10, `${compared} of ${samples.length} page samples found in world.csv by their world time`);
  check(moving >= 3, `${moving} of them after the cube had moved`);
  check(worstMm <= 1 && worstDeg <= 1,
    `the page's cube matches world.csv at the same frame: worst ${worstMm.toFixed(4)} mm, ${worstDeg.toFixed(4)}°`);
  check(state.rejectedFrames === 0, "no frame rejected by the page");
  const loop = JSON.parse(fs.readFileSync(path.join(outDir, "haptic.json"), "utf8")).haptic;
  console.log(`  measured: haptic lateness with a viewer and a page watching (and a browser rendering on the same ` +
    `2 cores): p50 ${loop.lateness_p50_ns / 1e3} µs, p99 ${loop.lateness_p99_ns / 1e3} µs, ` +
    `max ${loop.lateness_max_ns / 1e3} µs`);
  console.log(`  measured: page ${state.fps.toFixed(1)} fps, ${state.framesReceived} frames received; the viewer ` +
    `used ${(100 * viewerCpu).toFixed(1)} % of a core serving one page`);
}

// Plays a replay at 10 times its speed to its end; the page's last frame.
async function playToEnd(page, scene) {
  await page.evaluate(() => window.impetusView.send({ speed: 10 }));
  const end = scene.replay.end_s;
  return waitFor("the end of the replay", async () => {
    const state = await view(page);
    return state?.latest && Math.abs(state.latest.worldTime_s - end) < 1e-9 ? state.latest : null;
  }, 30000, 100);
}

// A lockstep trial replayed: the replay reaches the trial's final pose.
async function replay(procs, browser) {
  const trial = path.join(outDir, "trial");
  await runTrial(trial, ["--clock", "lockstep"]);
  const summary = JSON.parse(fs.readFileSync(path.join(trial, "summary.json"), "utf8"));
  const viewer = await procs.viewer(["--replay", trial]);
  const page = await openPage(browser, viewer.url);
  const scene = await waitFor("the replay's scene", async () => (await view(page))?.scene);
  check(scene.mode === "replay", "the page is in replay mode");
  const last = await playToEnd(page, scene);
  const cube = last.bodies.find((b) => b.name === "cube");
  const final = summary.objects.cube.position;
  const errorMm = 1000 * distance(cube.position_m, final);
  check(errorMm < 1e-6, `the replay ends at the trial's final cube position (${cube.position_m.map((v) => v.toFixed(4))}` +
    ` m, off by ${errorMm.toExponential(1)} mm)`);
  await page.evaluate((t) => window.impetusView.send({ seek: t }), scene.replay.start_s);
  await waitFor("a seek back to the start", async () => {
    const state = await view(page);
    return state?.latest && state.latest.worldTime_s === scene.replay.start_s;
  });
  check(true, "seeking back to the start shows the first frame");
  if (option("--picture")) await picture(page, trial, option("--picture"));
  await procs.stop(viewer);
}

// The page at the frame where the finger pushes hardest, after playing up to it at half speed (so the strip charts
// have the run-up).
async function picture(page, trial, file) {
  const world = readCsv(path.join(trial, "world.csv"));
  const haptic = readCsv(path.join(trial, "haptic.csv"));
  const [t, fx, fy, fz] = ["time_s", "force_x", "force_y", "force_z"].map((c) => haptic.column(c));
  let hardest = haptic.rows[0];
  for (const row of haptic.rows) {
    if (Math.hypot(row[fx], row[fy], row[fz]) > Math.hypot(hardest[fx], hardest[fy], hardest[fz])) hardest = row;
  }
  // The first world frame at or after the hardest push shows the haptic row at its own time: the one just before.
  const frameTime = world.rows.map((r) => r[world.column("time_s")]).find((time) => time >= hardest[t]);
  await page.evaluate(() => window.impetusView.send({ seek: 0 }));
  await page.evaluate(() => window.impetusView.send({ speed: 0.5 }));
  await page.evaluate(() => window.impetusView.send({ play: true }));
  await waitFor("the hardest push", async () => (await view(page))?.latest?.worldTime_s >= frameTime - 0.1, 30000, 20);
  await page.evaluate(() => window.impetusView.send({ play: false }));
  await page.evaluate((time) => window.impetusView.send({ seek: time }), frameTime);
  await waitFor("the picture's frame", async () => (await view(page))?.latest?.worldTime_s === frameTime);
  await sleep(500);
  await page.screenshot({ path: file });
  console.log(`  wrote ${file} (world time ${frameTime} s)`);
}

async function runTrial(out, extra) {
  const { spawnSync } = await import("node:child_process");
  const result = spawnSync("bash", [path.join(source, "scripts", "run.sh"), "--scene", tapScene, "--trajectory", "tap",
    "--out", out, "--quiet", ...extra], { env: { ...process.env, IMPETUS_BUILD_DIR: build }, encoding: "utf8" });
  if (result.status !== 0) throw new Failure(`run.sh failed: ${result.stderr}`);
}

// 2000 bodies: the page renders them all and reports its frame rate.
async function bodies(procs, browser) {
  const objects = [];
  for (let k = 0; k < 2000; ++k) {
    const i = k % 50, j = Math.floor(k / 50);
    const dynamic = k % 20 === 0;  // 100 spheres fall onto 1900 static boxes and cylinders
    const at = [(i - 25) * 0.03, (j - 20) * 0.03];
    if (dynamic) {
      objects.push({ name: `ball${k}`, shape: "sphere", radius_m: 0.008, dynamic: true, mass_kg: 0.05,
        position_m: [at[0], at[1], 0.06] });
    } else if (k % 2) {
      objects.push({ name: `box${k}`, shape: "box", size_m: [0.02, 0.02, 0.02], dynamic: false,
        position_m: [at[0], at[1], 0.01] });
    } else {
      objects.push({ name: `cyl${k}`, shape: "cylinder", radius_m: 0.01, length_m: 0.02, dynamic: false,
        position_m: [at[0], at[1], 0.01] });
    }
  }
  const scene = path.join(outDir, "bodies2000.json");
  fs.writeFileSync(scene, JSON.stringify({ description: "2000 bodies for the viewer's frame rate", objects }));
  const world = procs.start("world", "world_manager", ["--scene", scene, "--clock", "realtime", "--shm", shm]);
  const viewer = await procs.viewer(["--shm", shm]);
  const page = await openPage(browser, viewer.url);
  await waitFor("2000 bodies on the page", async () => (await view(page))?.latest?.bodies?.length === 2000, 30000);
  const cpuBefore = cpuSeconds(viewer.pid);
  await sleep(3000);
  const viewerCpu = (cpuSeconds(viewer.pid) - cpuBefore) / 3;
  const state = await view(page);
  const image = decodePng(await page.screenshot({ path: path.join(outDir, "bodies2000.png") }));
  await procs.stop(viewer);
  await procs.stop(world);
  check(state.renderedFrames > 0 && colourCount(image) > 20, `2000 bodies render (${colourCount(image)} colours)`);
  console.log(`  measured: ${state.fps.toFixed(1)} fps with 2000 bodies in headless Chromium (software WebGL), ` +
    `${state.framesReceived} world frames received; the viewer used ${(100 * viewerCpu).toFixed(1)} % of a core ` +
    `serving 112 kB frames at 20 Hz`);
}

// A viewer killed with kill -9 mid-trial leaves a lockstep trial's outcome bitwise unchanged.
async function kill(procs, browser) {
  // ~10 s of lockstep (600 s simulated): time for a page to attach and watch mid-trial however slowly a loaded machine
  // brings it its first frames (at 200 s it once saw them only at 194 s).
  const holdS = 600;
  const trajectory = `press:hold=${holdS}`;
  const runLockstep = async (name, watch) => {
    const dir = path.join(outDir, name);
    fs.mkdirSync(dir);
    const world = procs.start(`${name}-world`, "world_manager", ["--scene", tapScene, "--clock", "lockstep", "--shm",
      `${shm}_${name}`, "--log", path.join(dir, "world.csv"), "--summary", path.join(dir, "world.json")]);
    // The page attaches before the finger starts (a lockstep world waits for its first turn), so however loaded the
    // machine, it watches the trial from the beginning and is killed mid-trial.
    let viewer = null;
    let page = null;
    if (watch) {
      viewer = await procs.viewer(["--shm", `${shm}_${name}`]);
      page = await openPage(browser, viewer.url);
      await waitFor("the scene on the page", async () => (await view(page))?.scene);
    }
    const haptic = procs.start(`${name}-haptic`, "haptic_controller", ["--clock", "lockstep", "--shm", `${shm}_${name}`,
      "--summary", path.join(dir, "haptic.json")]);
    const device = procs.start(`${name}-device`, "spidar_sim", ["--clock", "lockstep", "--shm", `${shm}_${name}`,
      "--trajectory", trajectory]);
    let killed = null;
    if (watch) {
      await waitFor("frames on the page", async () => (await view(page))?.framesReceived > 10, 30000);
      viewer.kill("SIGKILL");
      killed = { signal: (await viewer.exited).signal, at_s: (await view(page)).latest.worldTime_s };
      await page.close();
    }
    const deviceExit = await device.exited;
    await procs.stop(haptic);
    await procs.stop(world);
    if (deviceExit.code !== 0) throw new Failure(`${name}: spidar_sim exited ${deviceExit.code}`);
    return { dir, killed };
  };
  const plain = await runLockstep("alone", false);
  const watched = await runLockstep("watched", true);
  check(watched.killed.signal === "SIGKILL" && watched.killed.at_s < 0.95 * holdS,
    `the viewer was killed mid-trial (${watched.killed.signal} at world time ${watched.killed.at_s.toFixed(2)} s of ` +
    `${holdS})`);
  const a = fs.readFileSync(path.join(plain.dir, "world.csv"));
  const b = fs.readFileSync(path.join(watched.dir, "world.csv"));
  check(a.equals(b), `world.csv is bitwise the same with and without the killed viewer (${a.length} bytes)`);
  // The outcome: final state and the impulse totals (summaries also hold wall-clock figures, which differ).
  const outcome = (dir) => JSON.stringify(JSON.parse(fs.readFileSync(path.join(dir, "world.json"), "utf8")).objects);
  check(outcome(plain.dir) === outcome(watched.dir), "the objects' final state and impulses are the same");
  const ticks = (dir) => JSON.parse(fs.readFileSync(path.join(dir, "haptic.json"), "utf8")).haptic.ticks;
  check(ticks(plain.dir) === ticks(watched.dir), `the haptic controller ran the same ${ticks(plain.dir)} ticks`);
}

// Bad requests: errors, never a crash.
async function badInput(procs, browser) {
  const world = procs.start("world", "world_manager", ["--scene", tapScene, "--clock", "realtime", "--shm", shm]);
  const viewer = await procs.viewer(["--shm", shm]);
  const status = async (target, init) => (await fetch(viewer.url.replace(/\/$/, "") + target, init)).status;
  check(await status("/no/such/page") === 404, "an unknown path is 404");
  check(await status("/three/build/../../package.json") === 404, "a path out of the page's folder is 404");
  check(await status("/", { method: "POST", body: "x".repeat(100000) }) === 413, "a 100 kB request body is 413");
  check(await status("/", { method: "DELETE" }) === 405, "DELETE is 405");

  // Another site's page: by DNS rebinding (its own name in Host) or by opening a WebSocket to the viewer (its own
  // Origin). Both are refused before anything is served.
  const port = Number(new URL(viewer.url).port);
  const statusLine = (request) => new Promise((resolve) => {
    const socket = net.connect(port, "127.0.0.1");
    let data = "";
    const done = () => { socket.destroy(); resolve(data.split("\r\n")[0]); };
    socket.on("data", (chunk) => { data += chunk; });
    socket.on("end", done);
    socket.on("error", done);
    setTimeout(done, 5000);
    socket.write(request);
  });
  const upgrade = "Upgrade: websocket\r\nConnection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n" +
    "Sec-WebSocket-Version: 13\r\n";
  const rebound = await statusLine(`GET / HTTP/1.1\r\nHost: evil.example:${port}\r\n\r\n`);
  check(rebound.includes(" 403 "), `a request naming another host (DNS rebinding) is refused (${rebound})`);
  const reboundWs = await statusLine(`GET /ws HTTP/1.1\r\nHost: evil.example:${port}\r\n${upgrade}\r\n`);
  check(reboundWs.includes(" 403 "), `so is its WebSocket (${reboundWs})`);
  const crossSite = await statusLine(`GET /ws HTTP/1.1\r\nHost: 127.0.0.1:${port}\r\n${upgrade}` +
    "Origin: http://evil.example\r\n\r\n");
  check(crossSite.includes(" 403 "), `a WebSocket with another site's Origin is refused (${crossSite})`);
  const own = await statusLine(`GET /ws HTTP/1.1\r\nHost: 127.0.0.1:${port}\r\n${upgrade}` +
    `Origin: http://127.0.0.1:${port}\r\n\r\n`);
  check(own.includes(" 101 "), `one with the viewer's own Origin is accepted (${own})`);
  const evil = await browser.newPage();
  await evil.route("http://evil.example/", (route) => route.fulfill({ contentType: "text/html", body: "<p>elsewhere</p>" }));
  await evil.goto("http://evil.example/");
  const fromEvil = await evil.evaluate((url) => new Promise((resolve) => {
    const socket = new WebSocket(url);
    socket.onmessage = () => resolve("read the world");
    socket.onerror = () => resolve("refused");
    socket.onclose = () => resolve("refused");
    setTimeout(() => resolve("no answer"), 5000);
  }), `ws://127.0.0.1:${port}/ws`);
  check(fromEvil === "refused", `a page of another site opening the viewer's WebSocket in the browser is refused (${fromEvil})`);
  await evil.close();

  const page = await openPage(browser, viewer.url);
  await waitFor("frames on the page", async () => (await view(page))?.framesReceived > 0);
  const closed = await page.evaluate(() => new Promise((resolve) => {
    const socket = new WebSocket(`ws://${location.host}/ws`);
    socket.onopen = () => socket.send("x".repeat(1 << 20));
    socket.onclose = (event) => resolve(event.code);
    setTimeout(() => resolve("still open"), 10000);
  }));
  check(closed !== "still open", `a 1 MB WebSocket message closes that connection (close code ${closed})`);
  const badControl = await page.evaluate(() => new Promise((resolve) => {
    const socket = new WebSocket(`ws://${location.host}/ws`);
    socket.onopen = () => socket.send("{not json");
    socket.onclose = (event) => resolve(event.code);
    setTimeout(() => resolve("still open"), 10000);
  }));
  check(badControl !== "still open", `a malformed control message closes that connection (close code ${badControl})`);

  // A flood: 300 connections held open at once, some sending garbage.
  const sockets = [];
  for (let i = 0; i < 300; ++i) {
    const socket = net.connect(Number(new URL(viewer.url).port), "127.0.0.1");
    socket.on("error", () => {});
    if (i % 3 === 0) socket.write("GARBAGE \x00\x01\x02\r\n\r\n");
    sockets.push(socket);
  }
  await sleep(1000);
  for (const socket of sockets) socket.destroy();
  await sleep(200);
  check(await status("/") === 200, "after a flood of 300 connections the page is still served");
  const before = (await view(page)).framesReceived;
  await sleep(500);
  check((await view(page)).framesReceived > before, "and the open page still receives frames");
  check(viewer.exitCode === null, "the viewer is still running");
  const result = await procs.stop(viewer);
  check(result.code === 0, "it exits 0 on SIGTERM");
  console.log(`  ${procs.log(viewer.name).trim().split("\n").pop()}`);
  await procs.stop(world);
}

// A real-time press into the clay watched live: the page draws the dent the world made, as deep as world.csv says,
// and the face changes on screen where it was pressed.
async function clay(procs, browser) {
  const scene = path.join(source, "scenes", "clay.json");
  const worldCsv = path.join(outDir, "world.csv");
  const world = procs.start("world", "world_manager", ["--scene", scene, "--clock", "realtime", "--shm", shm,
    "--log", worldCsv]);
  const viewer = await procs.viewer(["--shm", shm]);
  const page = await openPage(browser, viewer.url);
  await waitFor("the page's first frames", async () => (await view(page))?.framesReceived > 5);
  // Looking down on the pressed point from above and to the side, close enough to see a few millimetres of dent.
  await page.evaluate(() => window.impetusView.lookAt([0, 0, 0.03], 0.03));
  await sleep(500);
  const before = await capture(page, "clay");
  const haptic = procs.start("haptic", "haptic_controller", ["--clock", "realtime", "--shm", shm]);
  const device = procs.start("device", "spidar_sim", ["--clock", "realtime", "--shm", shm, "--trajectory",
    "press:x=0,y=0,surface_z=0.03,depth=0.008,hold=1.0,speed=0.1"]);
  // Until the press is over: the device ends its trajectory and exits.
  await waitFor("the press to end", () => device.exitCode !== null, 20000, 50);
  await procs.stop(haptic);
  // The world's next step may still apply the last report the controller sent: compare with world.csv's newest row
  // each time, and only once that row has held for 200 ms (four world steps at 20 Hz), so the dent is final.
  let dentM = 0;
  let seen = null;
  let dentSince = Date.now();
  const newestDent = () => {
    const { columns, row } = lastRow(worldCsv);
    return row[columns.indexOf("clay.dent_m")];
  };
  try {
    await waitFor("the page's dent", async () => {
      const newest = newestDent();
      if (newest !== dentM) {
        dentM = newest;
        dentSince = Date.now();
      }
      seen = await view(page);
      const shown = seen?.dent;
      return Date.now() - dentSince >= 200 && shown && Math.abs(shown.deepest_m - dentM) <= 1e-6 * dentM;
    }, 5000, 50);
  } catch (error) {
    throw new Failure(`${error.message}: world.csv has ${dentM} m, the page ${JSON.stringify(seen?.dent)} ` +
                      `(${seen?.framesReceived} frames, ${seen?.rejectedFrames} rejected)`);
  }
  await sleep(300);
  const after = await capture(page, "clay");
  await page.screenshot({ path: path.join(outDir, "clay.png") });
  const state = await view(page);
  state.pressedAt = await page.evaluate(() => window.impetusView.projectPoint([0, 0, 0.027]));
  await procs.stop(viewer);
  await procs.stop(world);
  dentM = newestDent();

  check(dentM > 0.002, `the press dented the clay (${(1e3 * dentM).toFixed(2)} mm in world.csv)`);
  check(state.dent.body === 0 && Math.abs(state.dent.deepest_m - dentM) <= 1e-6 * dentM,
    `the page's dent is the world's: ${(1e3 * state.dent.deepest_m).toFixed(4)} mm deep on ` +
    `${state.dent.columns} × ${state.dent.rows} points`);
  // Where the press went in, the dent's walls face the light at other angles than the face: their pixels changed.
  // Counted beside the finger's marker (drawn only after), left and right of it: the dent is 12 mm across, 50 px here.
  const { x, y } = state.pressedAt;
  const changed = changedPixels(before.image, after.image, [x - 40, y - 20, x - 8, y + 20]) +
                  changedPixels(before.image, after.image, [x + 8, y - 20, x + 40, y + 20]);
  // Undented, none of them would change (the marker is left out); dented, about 150 do.
  check(changed > 50, `the face changed on screen where it was pressed, beside the finger (${changed} of 2560 pixels)`);
  check(state.rejectedFrames === 0, "no frame rejected by the page");
}

// The meshes scene live, the viewer given its file: every mesh is drawn as its own triangles (as many as the world's
// files have, which world_manager prints), not as a ball; without the file the page says so and draws the bound.
async function meshes(procs, browser) {
  const scene = path.join(source, "scenes", "meshes.json");
  const world = procs.start("world", "world_manager", ["--scene", scene, "--clock", "realtime", "--shm", shm]);
  const viewer = await procs.viewer(["--shm", shm, "--meshes-from", scene]);
  const page = await openPage(browser, viewer.url);
  await waitFor("the page's first frames", async () => (await view(page))?.framesReceived > 5);
  await page.evaluate(() => window.impetusView.lookAt([0.12, -0.05, 0.02], 0.16));
  await sleep(500);
  await capture(page, "bowl");  // throws if the page drew no bowl
  await page.screenshot({ path: path.join(outDir, "meshes.png") });
  const withFiles = await view(page);
  const bare = await procs.viewer(["--shm", shm]);
  const barePage = await openPage(browser, bare.url);
  await waitFor("the second page's first frames", async () => (await view(barePage))?.framesReceived > 5);
  const withoutFiles = await view(barePage);
  await procs.stop(bare);
  await procs.stop(viewer);
  await procs.stop(world);

  // The triangle counts of scenes/meshes/*.obj (scripts/make_meshes.py); the cube's 12 are the fewest a cube has.
  const counts = Object.fromEntries(withFiles.meshes.map((m) => [m.name, m]));
  for (const name of ["cube", "pebble", "bowl", "shell"]) {
    check(counts[name]?.drawn === "triangles" && counts[name].triangles >= 12,
      `${name} drawn as its ${counts[name]?.triangles} triangles`);
  }
  check(counts.pebble.triangles === 1280,
    `the pebble has the 1280 triangles its scene says (${counts.pebble.triangles})`);
  check(withoutFiles.meshes.length === 4 && withoutFiles.meshes.every((m) => m.drawn === "bound"),
    "a viewer not given the scene draws each mesh as a ball that holds it");
  check(withFiles.rejectedMessages === 0 && withFiles.rejectedFrames === 0,
    `no message rejected by the page (${withFiles.rejectedMessages} text, ${withFiles.rejectedFrames} frames)`);
}

// The terrain of 10^6 triangles (scripts/make_meshes.py --terrain writes it; not run by CTest, which does not make it):
// more triangles than a page is sent, so the page gets it coarsened, and draws it as triangles, not as its bound.
async function terrain(procs, browser) {
  const scene = path.join(source, "scenes", "terrain.json");
  const file = path.join(source, "out", "meshes", "terrain.stl");
  if (!fs.existsSync(file)) throw new Failure(`${file} is missing: /usr/bin/python3 scripts/make_meshes.py --terrain`);
  const world = procs.start("world", "world_manager", ["--scene", scene, "--clock", "realtime", "--shm", shm]);
  const started = Date.now();
  const viewer = await procs.viewer(["--shm", shm, "--meshes-from", scene]);
  const page = await openPage(browser, viewer.url);
  await waitFor("the page's first frames", async () => (await view(page))?.framesReceived > 5, 60000);
  const waited = ((Date.now() - started) / 1000).toFixed(1);
  console.log(`  the page drew its first frames ${waited} s after the viewer started`);
  await page.evaluate(() => window.impetusView.lookAt([0.0, 0.0, 0.0], 0.5));
  await sleep(500);
  await page.screenshot({ path: path.join(outDir, "terrain.png") });
  const drawn = await view(page);
  await procs.stop(viewer);
  await procs.stop(world);
  const ground = drawn.meshes.find((m) => m.name === "terrain");
  check(ground?.drawn === "triangles" && ground.triangles > 10000 && ground.triangles <= 100000,
    `the terrain drawn as ${ground?.triangles} triangles (${ground?.drawn}), coarsened from 10^6 to fit a page`);
  check(drawn.rejectedMessages === 0 && drawn.rejectedFrames === 0, "no message rejected by the page");
}

// A tool in the hand replayed (impetus.ToolSimulation's out_dir): the page draws the tool's shape, solid at the
// proxy's pose and as a ghost at the grip's, turned as its log has it, and the torque on the grip.
async function tool(procs, browser) {
  const { spawnSync } = await import("node:child_process");
  const trial = path.join(outDir, "trial");
  // The peg down its hole, then turned 0.3 rad about y with the hand: the walls hold it, so the grip and the proxy
  // turn by different angles and the hand feels a torque.
  const script = `
import impetus, math, sys
half = 0.15
with impetus.ToolSimulation(impetus.shipped_scene("peg_in_hole"), start_m=[0, 0, 0.1], out_dir=sys.argv[1]) as sim:
    sim.step(targets=[[0, 0, 0.1 - 0.04 * k / 399] for k in range(400)])
    sim.step(targets=[[0, 0, 0.06, math.cos(half), 0, math.sin(half), 0]] * 300)
`;
  const result = spawnSync("/usr/bin/python3", ["-c", script, trial],
    { env: { ...process.env, PYTHONPATH: path.join(build, "python") }, encoding: "utf8" });
  if (result.status !== 0) throw new Failure(`the tool run failed: ${result.stderr}`);
  const log = readCsv(path.join(trial, "haptic.tool.csv"));
  const viewer = await procs.viewer(["--replay", trial]);
  const page = await openPage(browser, viewer.url);
  const scene = await waitFor("the replay's scene", async () => (await view(page))?.scene);
  check(scene.tool?.shape === "box" && scene.tool.size_m.join() === "0.01,0.01,0.04",
    `the scene message carries the tool: a ${scene.tool?.shape} of ${scene.tool?.size_m?.join(" × ")} m`);
  check(Math.abs(scene.tool.placement.position_m[2] + 0.03) < 1e-12, "placed 3 cm below the grip, as the scene has it");
  const last = await playToEnd(page, scene);
  const shown = last.tool;
  check(shown?.valid && shown.drawn, "the tool is drawn at the end of the replay");
  // The frame shows a row of the tool's log: its proxy and grip poses together, as logged.
  const pose = (row, name) => ["x_m", "y_m", "z_m", "qw", "qx", "qy", "qz"].map((c) => row[log.column(`${name}_${c}`)]);
  const same = (a, b) => a.every((v, i) => Math.abs(v - b[i]) < 1e-12);
  const proxy = [...shown.proxy.position_m, ...shown.proxy.orientation_wxyz];
  const grip = [...shown.grip.position_m, ...shown.grip.orientation_wxyz];
  const row = log.rows.find((r) => same(pose(r, "proxy"), proxy) && same(pose(r, "grip"), grip));
  check(row !== undefined,
    `the page's proxy and grip poses are one row of haptic.tool.csv (tick ${row?.[log.column("tick")]})`);
  const turn = (q) => 2 * Math.asin(Math.min(1, Math.abs(q[2])));
  const gripTurn = turn(shown.grip.orientation_wxyz);
  const proxyTurn = turn(shown.proxy.orientation_wxyz);
  check(gripTurn > proxyTurn + 0.002, `the grip turned ${gripTurn.toFixed(3)} rad about y, the proxy held by the ` +
    `walls to ${proxyTurn.toFixed(3)} rad`);
  check(shown.torque_Nm[1] < -0.01, "the torque on the grip pushes the turn back: " +
    `${shown.torque_Nm[1].toFixed(3)} N·m about y`);
  // Drawn where the frame puts it: the tool's pixels move when the replay seeks back to the peg above the hole.
  await page.evaluate(() => window.impetusView.lookAt([0, 0, 0.06], 0.05));
  await sleep(300);
  const at = (url) => decodePng(Buffer.from(url.slice(url.indexOf(",") + 1), "base64"));
  const deep = at(await page.evaluate(() => window.impetusView.capture()));
  await page.screenshot({ path: path.join(outDir, "tool.png") });
  await page.evaluate((t) => window.impetusView.send({ seek: t }), scene.replay.start_s);
  const start = scene.replay.start_s;
  await waitFor("a seek back to the start", async () => (await view(page))?.latest?.worldTime_s === start);
  const high = at(await page.evaluate(() => window.impetusView.capture()));
  const changed = changedPixels(deep, high);
  check(changed > 500, `${changed} pixels change between the peg in its hole and above it`);
  check((await view(page)).rejectedFrames === 0, "no frame rejected by the page");
  await procs.stop(viewer);
}

const cases = { live, replay, bodies, kill, "bad-input": badInput, clay, meshes, terrain, tool };
await runCase("viewer_test", cases, which, build, outDir, shm);
