// `make bench-web`: the engine in WebAssembly, timed in headless Chromium on this machine, and
// the native kernels in the same run. One table: the deformers of both builds (scalar and
// simd128; LB, QB, DQB; positions only and with normals) in µs per frame with their ratio to
// the native AVX2 kernel; the page's whole interaction frame (a record in, retargeting,
// gestures, skinning; and with a scene, the manipulation loop), as the npm package's
// Interaction and as the viewer's LocalStream, at the median and p99; and the
// time from loading the viewer, on a static server, to its first drawn hand.

import { execFileSync } from 'node:child_process';
import { cpSync, mkdtempSync, mkdirSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { launchBrowser, newPage, root, serveStatic, waitState } from './harness.mjs';

const FRAMES = Number(process.env.BENCH_FRAMES ?? 400);
const dir = mkdtempSync(path.join(process.env.TMPDIR ?? tmpdir(), 'dqhand-bench-web-'));
for (const build of ['web', 'web-simd']) cpSync(path.join(root, 'target/wasm', build), path.join(dir, build), { recursive: true });
mkdirSync(path.join(dir, 'recordings'));
for (const name of ['gestures-joints.jsonl', 'grasp-joints.jsonl']) cpSync(path.join(root, 'crates/dqhand/data/recordings', name), path.join(dir, 'recordings', name));
writeFileSync(path.join(dir, 'index.html'), '<!doctype html><meta charset="utf-8"><script type="module" src="./bench.js"></script>');
// The page's part: runs in Chromium, one build after the other, and leaves its results in window.results.
writeFileSync(path.join(dir, 'bench.js'), `
const FRAMES = ${FRAMES};
const BATCH = 10; // deforms per timed sample (performance.now() is to 5 µs in this isolated page)
const quantiles = (xs) => { const s = [...xs].sort((a, b) => a - b); const q = (p) => s[Math.min(s.length - 1, Math.floor(p * s.length))]; return { median: q(0.5), p90: q(0.9), p99: q(0.99) }; };
/** Seeded rigid transforms, 12 floats per joint (rotations up to 90° about random axes). */
function transforms(joints, seed) {
  let s = seed;
  const r = () => ((s = (s * 1103515245 + 12345) % 2147483648) / 2147483648);
  const out = new Float32Array(12 * joints);
  for (let j = 0; j < joints; j++) {
    let [x, y, z] = [r() - 0.5, r() - 0.5, r() - 0.5];
    const n = Math.hypot(x, y, z) || 1; [x, y, z] = [x / n, y / n, z / n];
    const a = (r() * Math.PI) / 2, c = Math.cos(a), sn = Math.sin(a), t = 1 - c;
    out.set([t*x*x + c, t*x*y - sn*z, t*x*z + sn*y, 0.01 * r(), t*x*y + sn*z, t*y*y + c, t*y*z - sn*x, 0.01 * r(), t*x*z - sn*y, t*y*z + sn*x, t*z*z + c, 0.01 * r()], 12 * j);
  }
  return out;
}
async function lines(name) { return (await (await fetch('./recordings/' + name)).text()).split('\\n').filter((l) => l.trim()); }
const results = { deformers: [], interaction: [] };
for (const build of ['web', 'web-simd']) {
  const wasm = await import('./' + build + '/dqhand_wasm.js');
  await wasm.default({ module_or_path: new URL('./' + build + '/dqhand_wasm_bg.wasm', import.meta.url) });
  const skinner = wasm.Skinner.builtin(0.19, 0.085, 'right');
  const poses = Array.from({ length: 16 }, (_, i) => transforms(skinner.jointCount, i + 1));
  for (const kernel of wasm.Skinner.kernels()) for (const normals of [false, true]) for (const method of ['lb', 'qb', 'dqb']) {
    skinner.setMethod(method, kernel);
    skinner.setNormals(normals);
    for (let i = 0; i < 50; i++) skinner.deform(poses[i % 16]); // warm
    const samples = [];
    for (let i = 0; i < FRAMES / BATCH; i++) {
      const t0 = performance.now();
      for (let k = 0; k < BATCH; k++) skinner.deform(poses[(i * BATCH + k) % 16]);
      samples.push((1000 * (performance.now() - t0)) / BATCH);
    }
    results.deformers.push({ build, kernel, method, normals, ...quantiles(samples) });
  }
  // The page's interaction frame: one record in, then the frame (and the skin).
  // Each over the whole recording twice, timed the second time: during the first, the engine's
  // optimising tier compiles the hot functions (a page that has run for a few seconds).
  for (const [scene, recording] of [['', 'gestures-joints.jsonl'], ['grasp', 'grasp-joints.jsonl']]) {
    const records = await lines(recording);
    const interaction = () => {
      const it = new wasm.Interaction('right', scene);
      const samples = records.map((line) => {
        const t = JSON.parse(line).t;
        const t0 = performance.now();
        it.pushLine(line);
        if (it.step(t) > 0) it.takeEvents();
        return 1000 * (performance.now() - t0);
      });
      it.free();
      return samples;
    };
    interaction();
    results.interaction.push({ build, engine: 'Interaction (npm)', scene: scene || 'none', records: records.length, ...quantiles(interaction()) });
    // The viewer's engine (its session: the frame of the methods in view, encoded for the page).
    const viewer = () => {
      const stream = new wasm.LocalStream(scene, false);
      const samples = records.map((line) => {
        const t0 = performance.now();
        stream.push(line);
        stream.step(1 / 60);
        stream.takeTexts();
        return 1000 * (performance.now() - t0);
      });
      stream.free();
      return samples;
    };
    viewer();
    results.interaction.push({ build, engine: 'LocalStream (viewer)', scene: scene || 'none', records: records.length, ...quantiles(viewer()) });
  }
}
results.resolution = crossOriginIsolated ? '5 µs' : '100 µs';
window.results = results;
`);

const native = JSON.parse(execFileSync(path.join(root, 'target/release/dqhand'), ['bench', '--json', '--frames', String(FRAMES), '--threads', '1'], { encoding: 'utf8' }));
const avx2 = (method, normals) => native.variants.find((v) => v.kernel === 'avx2' && v.method === method && v.normals === normals && v.threads === 1)?.us_per_frame;

const server = await serveStatic(dir, { isolated: true });
const viewer = await serveStatic(path.join(root, 'viewer/dist'));
const browser = await launchBrowser();
try {
  const page = await newPage(browser);
  await page.goto(server.url);
  await page.waitForFunction(() => window.results, null, { timeout: 600_000, polling: 500 });
  const { deformers, interaction, resolution } = await page.evaluate(() => window.results);
  // The viewer on a static server: navigation to its first drawn hand, three loads.
  const firstHand = [];
  for (let i = 0; i < 3; i++) {
    const p = await newPage(browser);
    await p.goto(viewer.url);
    await waitState(p, 's.firstFrameMs !== null', 120_000);
    firstHand.push((await p.evaluate(() => window.dqhand.state())).firstFrameMs);
    await p.close();
  }
  const cpu = execFileSync('sh', ['-c', "grep -m1 'model name' /proc/cpuinfo | cut -d: -f2"], { encoding: 'utf8' }).trim();
  const version = await page.evaluate(() => navigator.userAgent.match(/(?:Headless)?Chrome\/[\d.]+/)?.[0]);
  console.log(`machine: ${cpu}, ${native.cores} cores (native kernels: ${native.kernels.join(', ')}); ${version}; ${FRAMES} frames a variant; the page's clock to ${resolution}\n`);
  console.log('| build | kernel | normals | method | median µs | p90 µs | native AVX2 µs | ratio |');
  console.log('|---|---|---|---|---|---|---|---|');
  for (const d of deformers) {
    const n = avx2(d.method, d.normals);
    console.log(`| ${d.build} | ${d.kernel} | ${d.normals ? 'yes' : 'no'} | ${d.method.toUpperCase()} | ${d.median.toFixed(1)} | ${d.p90.toFixed(1)} | ${n?.toFixed(1) ?? '—'} | ${n ? (d.median / n).toFixed(2) + '×' : '—'} |`);
  }
  console.log('\n| build | engine | scene | records | median µs | p90 µs | p99 µs |');
  console.log('|---|---|---|---|---|---|---|');
  for (const r of interaction) console.log(`| ${r.build} | ${r.engine} | ${r.scene} | ${r.records} | ${r.median.toFixed(0)} | ${r.p90.toFixed(0)} | ${r.p99.toFixed(0)} |`);
  const sorted = [...firstHand].sort((a, b) => a - b);
  console.log(`\nviewer on a static server, page load to the first drawn hand: ${sorted.map((ms) => (ms / 1000).toFixed(2)).join(', ')} s (median ${(sorted[1] / 1000).toFixed(2)} s)`);
} finally {
  await browser.close();
  await server.stop();
  await viewer.stop();
}
