// `make bench-dqs`: three-dqs's speed beside three.js's own linear skinning, in headless
// Chromium (software WebGL unless the browser finds a GPU): N = 1, 10 and 100 of dqhand's
// built-in hand (8,668 vertices, 25 bones) drawn with their bones moving every frame, the two
// kinds of frame alternating in blocks of 5 in one run; each frame's time to the GPU's end.
// Prints the medians, 95th percentiles and the ratio, and the CPU cost per bone of the
// dual quaternion split. `--json` prints one JSON object; `--frames N` frames of each (default 30).

import { execFileSync } from 'node:child_process';
import { copyFileSync, mkdtempSync, readFileSync } from 'node:fs';
import { cpus, tmpdir } from 'node:os';
import path from 'node:path';
import { dqhandBin, launchBrowser, newPage, root, serveStatic } from './harness.mjs';

const args = process.argv.slice(2);
const json = args.includes('--json');
const at = args.indexOf('--frames');
const frames = at >= 0 ? Number(args[at + 1]) : 30;
if (!(Number.isInteger(frames) && frames >= 5)) throw new Error(`--frames ${args[at + 1]}: give a whole number of frames, 5 or more`);
const work = mkdtempSync(path.join(process.env.TMPDIR ?? tmpdir(), 'three-dqs-bench-'));
const pkg = path.join(root, 'packages/three-dqs');
const page = path.join(work, 'page');
execFileSync(path.join(pkg, 'node_modules/.bin/vite'), ['build', '--config', 'test/vite.config.js', '--outDir', page, '--logLevel', 'warn'], { cwd: pkg, stdio: 'inherit' });
execFileSync(dqhandBin(), ['export-skinning', '--out', path.join(work, 'rig'), '--frames', '10'], { stdio: json ? 'ignore' : 'inherit' });
for (const file of ['rig.json', 'rig.bin']) copyFileSync(path.join(work, 'rig', file), path.join(page, file));
const server = await serveStatic(page);
const browser = await launchBrowser();
try {
  const p = await newPage(browser, { width: 640, height: 400 });
  await p.goto(`${server.url}?bench`);
  await p.waitForFunction(() => document.title === 'ready', null, { timeout: 60_000 });
  const result = await p.evaluate(({ frames }) => window.bench([1, 10, 100], frames), { frames });
  const cpu = readFileSync('/proc/cpuinfo', 'utf8').match(/model name\s*:\s*(.*)/)?.[1] ?? cpus()[0]?.model;
  const report = { machine: `${cpu}, ${cpus().length} cores`, browser: browser.version(), ...result };
  if (json) {
    console.log(JSON.stringify(report));
  } else {
    console.log(`${report.machine}; Chromium ${report.browser}; WebGL renderer: ${report.renderer}`);
    console.log(`${report.vertices} vertices, ${report.bones} bones a hand; frames of each kind: ${result.results[0].frames}\n`);
    console.log('hands   LBS median ms   LBS p95 ms   DQS median ms   DQS p95 ms   DQS / LBS');
    for (const r of result.results) {
      const f = (x) => x.toFixed(2).padStart(12);
      console.log(`${String(r.hands).padStart(5)}   ${f(r.lbs.median)}  ${f(r.lbs.p95)}   ${f(r.dqs.median)}  ${f(r.dqs.p95)}   ${r.ratio.toFixed(2).padStart(9)}`);
    }
    console.log(`\nCPU: the dual quaternion split, ${report.perBoneMicroseconds.toFixed(2)} µs a bone a frame (${(report.perBoneMicroseconds * report.bones).toFixed(1)} µs a hand)`);
  }
} finally {
  await browser.close();
  await server.stop();
}
