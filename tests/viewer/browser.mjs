// SPDX-License-Identifier: Apache-2.0
// What the viewer's browser tests share: starting the project's binaries, Debian's Chromium through Playwright,
// reading the logs and the page's state, and decoding screenshots.

import { spawn } from "node:child_process";
import fs from "node:fs";
import path from "node:path";
import zlib from "node:zlib";
import { createRequire } from "node:module";

const require = createRequire(import.meta.url);

export const CHROMIUM = "/usr/bin/chromium";
// Headless Chromium as root on a machine without a GPU or a network: no sandbox (root), software WebGL, and none of the
// background connections a closed network refuses.
export const CHROMIUM_ARGS = ["--no-sandbox", "--headless=new", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
  "--ignore-gpu-blocklist", "--disable-background-networking", "--disable-component-update", "--disable-sync",
  "--no-first-run", "--disable-quic"];

export class Failure extends Error {}

export function check(condition, message) {
  if (!condition) throw new Failure(message);
  console.log(`  ok: ${message}`);
}

export function sleep(ms) { return new Promise((resolve) => setTimeout(resolve, ms)); }

export async function waitFor(what, probe, timeoutMs = 15000, everyMs = 50) {
  const end = Date.now() + timeoutMs;
  for (;;) {
    const value = await probe();
    if (value) return value;
    if (Date.now() > end) throw new Failure(`timed out after ${timeoutMs} ms waiting for ${what}`);
    await sleep(everyMs);
  }
}

// Playwright from tests/viewer/node_modules (scripts/deps.sh --browser installs it and Chromium).
export async function launchBrowser() {
  let playwright;
  try {
    playwright = require("playwright-core");
  } catch {
    throw new Failure("playwright-core is not installed in tests/viewer (run scripts/deps.sh --browser)");
  }
  if (!fs.existsSync(CHROMIUM)) throw new Failure(`${CHROMIUM} is missing (run scripts/deps.sh --browser)`);
  return playwright.chromium.launch({ executablePath: CHROMIUM, args: CHROMIUM_ARGS, headless: true });
}

export class Processes {
  constructor(build, outDir) {
    this.build = build;
    this.outDir = outDir;
    this.children = [];
  }

  start(name, binary, args) {
    const log = fs.openSync(path.join(this.outDir, `${name}.log`), "w");
    const child = spawn(path.join(this.build, binary, binary), args, { stdio: ["ignore", "pipe", log] });
    child.name = name;
    child.stdoutText = "";
    child.stdout.on("data", (chunk) => { child.stdoutText += chunk; });
    child.exited = new Promise((resolve) => child.on("exit", (code, signal) => resolve({ code, signal })));
    this.children.push(child);
    return child;
  }

  async viewer(args) {
    const child = this.start(`viewer${this.children.length}`, "viewer", ["--listen", "127.0.0.1:0", ...args]);
    const url = await waitFor("the viewer's address", () => {
      const match = /serving (http:\/\/\S+)/.exec(child.stdoutText);
      return match ? match[1] : null;
    }, 10000);
    child.url = url;
    return child;
  }

  log(name) { return fs.readFileSync(path.join(this.outDir, `${name}.log`), "utf8"); }

  async stop(child, signal = "SIGTERM", timeoutMs = 10000) {
    if (child.exitCode === null && child.signalCode === null) child.kill(signal);
    const timer = sleep(timeoutMs).then(() => null);
    const result = await Promise.race([child.exited, timer]);
    if (result === null) {
      child.kill("SIGKILL");
      throw new Failure(`${child.name} did not exit within ${timeoutMs} ms of ${signal}`);
    }
    return result;
  }

  killAll() {
    for (const child of this.children) {
      if (child.exitCode === null && child.signalCode === null) child.kill("SIGKILL");
    }
  }
}

// CPU seconds a process has used (user + system), from /proc; its clock ticks are 100 per second on Linux.
export function cpuSeconds(pid) {
  const stat = fs.readFileSync(`/proc/${pid}/stat`, "utf8");
  const fields = stat.slice(stat.lastIndexOf(")") + 2).split(" ");
  return (Number(fields[11]) + Number(fields[12])) / 100;  // utime, stime: fields 14 and 15 of stat
}

export function readCsv(file) {
  const lines = fs.readFileSync(file, "utf8").split("\n").filter((line) => line.length > 0);
  const columns = lines[0].split(",");
  const rows = lines.slice(1).map((line) => line.split(",").map(Number));
  return { columns, rows, column: (name) => columns.indexOf(name) };
}

// A body's pose in a world.csv row.
export function csvPose(table, row, name) {
  const at = (suffix) => row[table.column(`${name}.${suffix}`)];
  return { position_m: [at("x_m"), at("y_m"), at("z_m")], orientation_wxyz: [at("qw"), at("qx"), at("qy"), at("qz")] };
}

export function distance(a, b) { return Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]); }

// Angle between two orientations (unit quaternions), degrees.
export function angleDeg(p, q) {
  const dot = Math.abs(p[0] * q[0] + p[1] * q[1] + p[2] * q[2] + p[3] * q[3]);
  return (2 * Math.acos(Math.min(1, dot)) * 180) / Math.PI;
}

// Decodes an 8-bit RGB or RGBA PNG (what Chromium's screenshots are) into RGBA pixels.
export function decodePng(buffer) {
  let offset = 8;
  let width = 0, height = 0, colorType = 0;
  const idat = [];
  while (offset < buffer.length) {
    const length = buffer.readUInt32BE(offset);
    const type = buffer.toString("ascii", offset + 4, offset + 8);
    const data = buffer.subarray(offset + 8, offset + 8 + length);
    if (type === "IHDR") {
      width = data.readUInt32BE(0);
      height = data.readUInt32BE(4);
      if (data[8] !== 8 || data[12] !== 0) throw new Failure("unsupported PNG (bit depth or interlace)");
      colorType = data[9];
    } else if (type === "IDAT") {
      idat.push(data);
    }
    offset += 12 + length;
  }
  const channels = colorType === 6 ? 4 : colorType === 2 ? 3 : 0;
  if (!channels) throw new Failure(`unsupported PNG colour type ${colorType}`);
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const pixels = Buffer.alloc(width * height * 4);
  const previous = Buffer.alloc(stride);
  const current = Buffer.alloc(stride);
  for (let y = 0; y < height; ++y) {
    const filter = raw[y * (stride + 1)];
    const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let x = 0; x < stride; ++x) {
      const a = x >= channels ? current[x - channels] : 0;
      const b = previous[x];
      const c = x >= channels ? previous[x - channels] : 0;
      let predictor = 0;
      if (filter === 1) predictor = a;
      else if (filter === 2) predictor = b;
      else if (filter === 3) predictor = (a + b) >> 1;
      else if (filter === 4) {
        const p = a + b - c, pa = Math.abs(p - a), pb = Math.abs(p - b), pc = Math.abs(p - c);
        predictor = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      current[x] = (line[x] + predictor) & 0xff;
    }
    for (let x = 0; x < width; ++x) {
      for (let k = 0; k < 4; ++k) pixels[(y * width + x) * 4 + k] = k < channels ? current[x * channels + k] : 255;
    }
    current.copy(previous);
  }
  return { width, height, pixels };
}

// How many distinct colours (quantised to 4 bits per channel) an image has: a blank canvas has one or two.
export function colourCount(image) {
  const seen = new Set();
  for (let i = 0; i < image.pixels.length; i += 4) {
    seen.add(((image.pixels[i] >> 4) << 8) | ((image.pixels[i + 1] >> 4) << 4) | (image.pixels[i + 2] >> 4));
  }
  return seen.size;
}

// Pixels that differ by more than 24 levels in any channel, inside the box [x0, x1) × [y0, y1).
export function changedPixels(a, b, box = [0, 0, a.width, a.height]) {
  let changed = 0;
  const [x0, y0, x1, y1] = box.map(Math.round);
  for (let y = Math.max(0, y0); y < Math.min(a.height, y1); ++y) {
    for (let x = Math.max(0, x0); x < Math.min(a.width, x1); ++x) {
      const i = (y * a.width + x) * 4;
      if (Math.abs(a.pixels[i] - b.pixels[i]) > 24 || Math.abs(a.pixels[i + 1] - b.pixels[i + 1]) > 24 ||
          Math.abs(a.pixels[i + 2] - b.pixels[i + 2]) > 24) ++changed;
    }
  }
  return changed;
}

export async function view(page) { return page.evaluate(() => window.impetusView ? JSON.parse(JSON.stringify({
  scene: window.impetusView.scene, connected: window.impetusView.connected,
  framesReceived: window.impetusView.framesReceived, latest: window.impetusView.latest,
  fps: window.impetusView.fps, renderedFrames: window.impetusView.renderedFrames,
  rejectedFrames: window.impetusView.rejectedFrames, rejectedMessages: window.impetusView.rejectedMessages,
  dent: window.impetusView.dent,
  meshes: window.impetusView.meshes })) : null); }

// Runs case `which` of `cases` (each an async function of the processes and the browser) as a test program: prints
// what it checks, and on a failure the reason and each process's last stderr; kills what it started and removes the
// shared-memory segments named `shm`*; exits 0 if every check held, 1 if not, 2 for an unknown case.
export async function runCase(program, cases, which, build, outDir, shm) {
  if (!cases[which]) {
    console.error(`${program}: --case must be one of ${Object.keys(cases).join(", ")}`);
    process.exit(2);
  }
  const procs = new Processes(build, outDir);
  let browser;
  let status = 0;
  try {
    browser = await launchBrowser();
    console.log(`${program.replace("_", " ")} '${which}':`);
    await cases[which](procs, browser);
    console.log("passed");
  } catch (error) {
    console.log(`FAILED: ${error instanceof Failure ? error.message : error.stack}`);
    for (const child of procs.children) {
      const file = path.join(outDir, `${child.name}.log`);
      if (fs.existsSync(file)) console.log(`--- ${child.name} stderr:\n${fs.readFileSync(file, "utf8").slice(-2000)}`);
    }
    status = 1;
  } finally {
    procs.killAll();
    if (browser) await browser.close();
    for (const name of fs.readdirSync("/dev/shm").filter((n) => n.startsWith(shm))) {
      fs.rmSync(path.join("/dev/shm", name), { force: true });
    }
  }
  process.exit(status);
}
