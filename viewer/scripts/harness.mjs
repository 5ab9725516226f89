// Shared by the browser tests and `make figures`: start `dqhand demo` on a free loopback port,
// launch Debian's Chromium headless through playwright-core (no browser download), read the
// rendered canvas back.

import { spawn } from 'node:child_process';
import { createReadStream, existsSync, statSync } from 'node:fs';
import { createServer } from 'node:http';
import { createRequire } from 'node:module';
import path from 'node:path';
import { createInterface } from 'node:readline';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

export const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');

/** The dqhand binary: $DQHAND_BIN, else the release build, else the debug build. */
export function dqhandBin() {
  if (process.env.DQHAND_BIN) return process.env.DQHAND_BIN;
  const release = path.join(root, 'target/release/dqhand');
  return existsSync(release) ? release : path.join(root, 'target/debug/dqhand');
}

/**
 * Starts the viewer server; resolves once it prints its URL.
 * @param {{ port?: number, args?: string[] }} [options] - `args`: more `dqhand demo` arguments (e.g. `--input FILE`)
 */
export function startServer({ port = 0, args = [] } = {}) {
  const child = spawn(dqhandBin(), ['demo', '--no-open', '--port', String(port), '--viewer', path.join(root, 'viewer/dist'), ...args], {
    stdio: ['ignore', 'pipe', 'inherit'],
  });
  return new Promise((resolve, reject) => {
    const lines = createInterface({ input: child.stdout });
    const timer = setTimeout(() => reject(new Error('dqhand demo printed no URL in 120 s')), 120_000);
    child.on('exit', (code) => reject(new Error(`dqhand demo exited with ${code}`)));
    lines.on('line', (line) => {
      const m = /^viewer: (http:\/\/[^/]+\/)/.exec(line);
      if (!m) return;
      clearTimeout(timer);
      const url = m[1];
      resolve({
        url,
        port: Number(new URL(url).port),
        stop: () =>
          new Promise((done) => {
            child.once('exit', () => done());
            child.kill();
          }),
      });
    });
  });
}

/** Content types of what a built page holds (a .wasm must be application/wasm to stream-compile). */
const TYPES = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.css': 'text/css', '.wasm': 'application/wasm', '.json': 'application/json', '.png': 'image/png', '.svg': 'image/svg+xml', '.data': 'application/octet-stream', '.tflite': 'application/octet-stream', '.binarypb': 'application/octet-stream' };

/**
 * A plain static file server of `dir` on a free loopback port, as any web host is: files, their
 * content types, nothing else (no dqhand process). Resolves to its URL and a `stop`. With
 * `isolated`, the pages are cross-origin isolated (COOP and COEP headers), which gives them
 * performance.now() to 5 µs instead of 100 µs.
 * @param {string} dir
 * @param {{ isolated?: boolean }} [options]
 */
export function serveStatic(dir, { isolated = false } = {}) {
  const isolation = isolated ? { 'cross-origin-opener-policy': 'same-origin', 'cross-origin-embedder-policy': 'require-corp' } : {};
  const top = path.resolve(dir);
  const server = createServer((req, res) => {
    const name = decodeURIComponent(new URL(req.url ?? '/', 'http://x').pathname);
    const file = path.resolve(top, `.${name.endsWith('/') ? `${name}index.html` : name}`);
    if (!file.startsWith(top + path.sep) || !existsSync(file) || !statSync(file).isFile()) {
      res.writeHead(404).end();
      return;
    }
    res.writeHead(200, { 'content-type': TYPES[path.extname(file)] ?? 'application/octet-stream', ...isolation });
    createReadStream(file).pipe(res);
  });
  return new Promise((resolve) => {
    server.listen(0, '127.0.0.1', () => {
      const { port } = /** @type {import('node:net').AddressInfo} */ (server.address());
      resolve({ url: `http://127.0.0.1:${port}/`, port, stop: () => new Promise((done) => server.close(() => done())) });
    });
  });
}

/**
 * Headless Chromium with software WebGL (SwiftShader), as on a machine without a GPU.
 * @param {string[]} [args] - more command-line switches (e.g. a fake camera's)
 */
export function launchBrowser(args = []) {
  const executablePath = process.env.CHROMIUM ?? '/usr/bin/chromium';
  if (!existsSync(executablePath)) throw new Error(`${executablePath} not found: install Debian's chromium (make test does)`);
  return chromium.launch({
    executablePath,
    args: ['--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist', '--no-sandbox', ...args],
  });
}

/**
 * A page of the tests' size (or `viewport`) in `browser` that logs its errors.
 * @param {import('playwright-core').Browser} browser
 * @param {{ width: number, height: number }} [viewport]
 */
export async function newPage(browser, viewport = { width: 900, height: 520 }) {
  const p = await browser.newPage({ viewport });
  p.on('pageerror', (e) => console.error('page error:', e.message));
  return p;
}

/** IWER's UMD build: defines `window.IWER`. */
const IWER_BUNDLE = createRequire(import.meta.url).resolve('iwer/build/iwer.min.js');

/**
 * A page of `browser` with a headset emulated by IWER (a Meta Quest 3 tracking hands) injected
 * before the page's own script, so the shipped page holds no emulator; the device is
 * `window.iwer`. Over headless Chromium's own navigator.xr, which offers no immersive session.
 * @param {import('playwright-core').Browser} browser
 */
export async function emulatedPage(browser) {
  const p = await newPage(browser);
  await p.addInitScript({ path: IWER_BUNDLE });
  await p.addInitScript(() => {
    const device = new window.IWER.XRDevice(window.IWER.metaQuest3);
    device.primaryInputMode = 'hand';
    device.installRuntime({ forceInstall: true });
    window.iwer = device;
  });
  return p;
}

/** Waits until the page's state satisfies `predicate` (a function source over `s`). */
export async function waitState(page, predicate, timeout = 60_000) {
  await page.waitForFunction(`(() => { const s = window.dqhand && window.dqhand.state(); return !!s && (${predicate}); })()`, null, { timeout, polling: 100 });
}

/** Lets the page draw a few more frames (so the canvas shows the latest engine frame). */
export async function settle(page, frames = 3) {
  await page.evaluate(
    (n) => new Promise((done) => { let k = 0; const tick = () => (++k >= n ? done() : requestAnimationFrame(tick)); requestAnimationFrame(tick); }),
    frames,
  );
}

/**
 * The canvas, read back: for each of `columns` vertical strips, how many pixels differ from
 * the background; and a coarse 64×40 grey thumbnail to compare two renders.
 */
export async function canvasStats(page, columns = 1) {
  return page.evaluate((columns) => {
    const c = document.getElementById('view');
    const w = c.width, h = c.height;
    const tmp = document.createElement('canvas');
    tmp.width = w;
    tmp.height = h;
    const g = tmp.getContext('2d');
    g.drawImage(c, 0, 0);
    const d = g.getImageData(0, 0, w, h).data;
    const bg = [d[0], d[1], d[2]];
    const strips = new Array(columns).fill(0);
    const thumb = new Array(64 * 40).fill(0);
    const counts = new Array(64 * 40).fill(0);
    for (let y = 0; y < h; y++) {
      for (let x = 0; x < w; x++) {
        const i = 4 * (y * w + x);
        const diff = Math.abs(d[i] - bg[0]) + Math.abs(d[i + 1] - bg[1]) + Math.abs(d[i + 2] - bg[2]);
        if (diff > 40) strips[Math.min(columns - 1, Math.floor((x * columns) / w))]++;
        const t = Math.floor((y * 40) / h) * 64 + Math.floor((x * 64) / w);
        thumb[t] += (d[i] + d[i + 1] + d[i + 2]) / 3;
        counts[t]++;
      }
    }
    return { width: w, height: h, strips, thumb: thumb.map((v, i) => v / counts[i]) };
  }, columns);
}

/** Mean absolute difference of two thumbnails, in grey levels. */
export function thumbDifference(a, b) {
  return a.thumb.reduce((sum, v, i) => sum + Math.abs(v - b.thumb[i]), 0) / a.thumb.length;
}

/** Pixels of the canvas whose red, green and blue lie in the given [min, max] ranges. */
export async function countColour(page, { r = [0, 255], g = [0, 255], b = [0, 255] }) {
  return page.evaluate(({ r, g, b }) => {
    const c = document.getElementById('view');
    const ctx = Object.assign(document.createElement('canvas'), { width: c.width, height: c.height }).getContext('2d');
    ctx.drawImage(c, 0, 0);
    const d = ctx.getImageData(0, 0, c.width, c.height).data;
    const inside = (v, [lo, hi]) => v >= lo && v <= hi;
    let n = 0;
    for (let i = 0; i < d.length; i += 4) if (inside(d[i], r) && inside(d[i + 1], g) && inside(d[i + 2], b)) n++;
    return n;
  }, { r, g, b });
}
