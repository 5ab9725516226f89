// The three-dqs package (packages/three-dqs) on the GPU, in headless Chromium's software WebGL
// and WebGPU (SwiftShader): its conformance page (packages/three-dqs/test) reads back what the
// package's shader chunks (WebGLRenderer) and TSL nodes (WebGPURenderer, on WebGPU and on its
// WebGL 2 fallback) compute for every vertex of the built-in hand, from a float render target, and compares it
// with dqhand's native DQB of the same frame (`dqhand export-skinning`) and, over random poses
// (the whole hand turned up to 180°) and poses whose bones scale and shear, with a reference the
// page writes from the definitions. The same page shows that a shader without the sign
// alignment fails the comparison. A hand made elsewhere, the WebXR generic hand (glTF), is held
// to the same reference in three random poses. Then the package as a user meets it: its example app,
// installed from the tarball `make dqs-package` packed, built with Vite, draws a skinned glTF
// made elsewhere (the WebXR generic hand) with its fingers bent.

import { execFileSync } from 'node:child_process';
import { copyFileSync, cpSync, mkdirSync, mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { afterAll, beforeAll, describe, expect, test } from 'vitest';
import type { Browser } from 'playwright-core';
import { canvasStats, countColour, dqhandBin, launchBrowser, newPage, root, serveStatic, thumbDifference } from '../scripts/harness.mjs';

interface Conformance {
  size: number;
  vertices: number;
  exported: { three: number; lbs: number; dqs: number; dqsNormals: number; cpu: number; blend: number };
  native: { name: string; dqs: number; dqsNormals: number; cpu: number }[];
  random: { seed: number; dqs: number; dqsNormals: number; cpu: number; unaligned: number }[];
  scaled: { seed: number; dqs: number; dqsNormals: number; cpu: number }[];
  limb: { size: number; vertices: number; poses: { seed: number; dqs: number; dqsNormals: number; cpu: number }[] };
  outside: { size: number; vertices: number; poses: { seed: number; dqs: number; dqsNormals: number; cpu: number }[] };
  /** WebGPURenderer only: which backend drew, the shadow pictures (pixels) of two random poses, and two meshes sharing a build. */
  backend?: string;
  shadows?: { seed: number; shadowed: number; dqs: number; three: number }[];
  sharedBuild?: { size: number; builds: number; worst: number[] };
}

/** The WebXR generic hand: a skinned glTF from the WebXR input profiles (third_party/). */
const GENERIC_HAND = path.join(root, 'third_party/node_modules/@webxr-input-profiles/assets/dist/profiles/generic-hand/right.glb');

const PACKAGE = path.join(root, 'packages/three-dqs');

/** The random poses dqhand exports for the page (their seeds in their names). */
const NATIVE = ['pose-1', 'pose-2', 'pose-3'];

/**
 * A random pose file of seed `seed` for `dqhand export-skinning --pose`: the wrist turned 90–180°
 * about a random axis, every finger joint flexed −20–100° and spread ±20° (beyond the hand's
 * ranges: the export runs without limits).
 */
function randomPose(seed: number) {
  let state = seed * 2654435761;
  const random = () => ((state = (Math.imul(state, 1664525) + 1013904223) >>> 0) / 2 ** 32);
  const axis = [random() - 0.5, random() - 0.5, random() - 0.5];
  const length = Math.hypot(...axis);
  const half = (Math.PI * (0.5 + 0.5 * random())) / 2;
  const rotation = [...axis.map((a) => (a / length) * Math.sin(half)), Math.cos(half)];
  // Every DOF of the full joint model: flexion everywhere, spread at the thumb and the knuckles.
  const fingers = ['index', 'middle', 'ring', 'pinky'];
  const flex = ['thumb-metacarpal', 'thumb-phalanx-proximal', 'thumb-phalanx-distal', 'ring-finger-metacarpal', 'pinky-finger-metacarpal'].concat(
    ...fingers.map((f) => ['proximal', 'intermediate', 'distal'].map((p) => `${f}-finger-phalanx-${p}`)),
  );
  const spread = ['thumb-metacarpal', 'thumb-phalanx-proximal', ...fingers.map((f) => `${f}-finger-phalanx-proximal`)];
  const angles: Record<string, number> = {};
  for (const bone of flex) angles[`${bone}.flex`] = -20 + 120 * random();
  for (const bone of spread) angles[`${bone}.abd`] = -20 + 40 * random();
  return { model: 'full', wrist: { translation: [0.1, 1.1, -0.2], rotation }, angles_deg: angles };
}
let browser: Browser;
let server: Awaited<ReturnType<typeof serveStatic>>;
/** The conformance page's results through each renderer (WebGLRenderer; WebGPURenderer on WebGPU, and on its WebGL 2 fallback). */
const results: Record<string, Conformance> = {};
/** The page's query for each renderer. */
const RENDERERS = { WebGLRenderer: '', 'WebGPURenderer on WebGPU': '?webgpu', 'WebGPURenderer on WebGL 2': '?webgpu&webgl' };

beforeAll(async () => {
  const work = mkdtempSync(path.join(process.env.TMPDIR ?? tmpdir(), 'three-dqs-'));
  const page = path.join(work, 'page');
  execFileSync(path.join(PACKAGE, 'node_modules/.bin/vite'), ['build', '--config', 'test/vite.config.js', '--outDir', page, '--logLevel', 'warn'], { cwd: PACKAGE, stdio: 'inherit' });
  execFileSync(dqhandBin(), ['export-skinning', '--out', path.join(work, 'rig'), '--frames', '10'], { stdio: 'inherit' });
  for (const file of ['rig.json', 'rig.bin']) copyFileSync(path.join(work, 'rig', file), path.join(page, file));
  // Random poses dqhand itself exports too (its native DQB of each is the reference).
  for (const name of NATIVE) {
    const pose = path.join(work, `${name}.json`);
    writeFileSync(pose, JSON.stringify(randomPose(Number(name.slice(5)))));
    execFileSync(dqhandBin(), ['export-skinning', '--out', path.join(work, name), '--pose', pose, '--no-limits', '--frames', '10'], { stdio: 'inherit' });
    for (const ext of ['json', 'bin']) copyFileSync(path.join(work, name, `rig.${ext}`), path.join(page, `${name}.${ext}`));
  }
  copyFileSync(GENERIC_HAND, path.join(page, 'hand.glb'));
  server = await serveStatic(page);
  browser = await launchBrowser(['--enable-unsafe-webgpu']);
  for (const [name, query] of Object.entries(RENDERERS)) {
    const p = await newPage(browser);
    await p.goto(server.url + query);
    await p.waitForFunction(() => document.title === 'ready', null, { timeout: 60_000 });
    results[name] = await p.evaluate((names) => (window as unknown as { conformance(n: string[]): Promise<Conformance> }).conformance(names), NATIVE);
    // What was measured, for the docs (the worst of each set).
    const r = results[name];
    const most = (set: { dqs: number; dqsNormals: number; cpu: number }[]) => ['dqs', 'dqsNormals', 'cpu'].map((k) => Math.max(...set.map((x) => x[k as 'dqs'])).toPrecision(2)).join(' / ');
    console.log(`three-dqs through ${name} (worst m / rad / m of GPU positions / normals / CPU positions): exported ${most([r.exported])}, dqhand's poses ${most(r.native)}, random ${most(r.random)}, scaled ${most(r.scaled)}, limb ${most(r.limb.poses)}, generic hand ${most(r.outside.poses)}; unaligned ${r.random.map((x) => x.unaligned.toFixed(2)).join(' ')}${r.shadows ? `; shadow pixels differing (dqs, three) of shadowed ${r.shadows.map((x) => `${x.dqs}, ${x.three} of ${x.shadowed}`).join('; ')}; shared build ${JSON.stringify(r.sharedBuild)}` : ''}`);
    await p.close();
  }
}, 240_000);

afterAll(async () => {
  await browser?.close();
  await server?.stop();
});

describe.each(Object.keys(RENDERERS))('three-dqs through %s against dqhand and a reference from the definitions', (renderer) => {
  const result = {} as Conformance;
  beforeAll(() => void Object.assign(result, results[renderer]));
  /** Positions within 1e-4 of the mesh's size; normals within 1e-3 rad. */
  const positions = () => 1e-4 * result.size;
  const normals = 1e-3;
  /** Each pose's GPU positions and normals, and CPU positions, within the bounds (positions: `bound`, by default the built-in hand's). */
  const expectMatches = (poses: { seed?: number; name?: string; dqs: number; dqsNormals: number; cpu: number }[], bound = positions()) => {
    for (const r of poses) {
      const label = r.name ?? `seed ${r.seed}`;
      expect(r.dqs, label).toBeLessThan(bound);
      expect(r.dqsNormals, label).toBeLessThan(normals);
      expect(r.cpu, label).toBeLessThan(bound);
    }
  };

  test('the read-back itself reproduces three.js\'s own linear skinning and dqhand\'s LB', () => {
    expect(result.vertices).toBeGreaterThan(8000);
    expect(result.exported.three).toBeLessThan(positions());
    expect(result.exported.lbs).toBeLessThan(positions());
  });

  test('the dual quaternion skin matches dqhand\'s native DQB of the exported frame, positions and normals, on the GPU and the CPU path', () => {
    expect(result.exported.dqs).toBeLessThan(positions());
    expect(result.exported.dqsNormals).toBeLessThan(normals);
    expect(result.exported.cpu).toBeLessThan(positions());
  });

  test('three random poses dqhand exports itself (wrist turned 90–180°, fingers beyond their ranges) match its native DQB', () => {
    expect(result.native.length).toBe(NATIVE.length);
    expectMatches(result.native);
  });

  test('mode blend follows its vertex attribute: linear where it is 0, dual quaternion where it is 1', () => {
    expect(result.exported.blend).toBeLessThan(positions());
  });

  test('random poses turned up to 180° match the reference, GPU and CPU', () => {
    expect(result.random.length).toBe(6);
    expectMatches(result.random);
  });

  test('bones that scale and shear match the reference (scale blended before the rigid part)', () => {
    expect(result.scaled.length).toBe(3);
    expectMatches(result.scaled);
  });

  test('a cylinder twisted 90–180° at its joint, turned up to 180° as a whole, its bones scaled and sheared, matches the reference in three poses', () => {
    expect(result.limb.vertices).toBeGreaterThan(4000);
    expect(result.limb.poses.length).toBe(3);
    expectMatches(result.limb.poses, 1e-4 * result.limb.size);
  });

  test('a hand made elsewhere (the WebXR generic hand glTF, through its own bind matrix) matches the reference in three poses', () => {
    expect(result.outside.vertices).toBeGreaterThan(1000);
    expect(result.outside.poses.length).toBe(3);
    expectMatches(result.outside.poses, 1e-4 * result.outside.size);
  });

  test('without the sign alignment the same comparison fails: the test can tell', () => {
    const failing = result.random.filter((r) => r.unaligned > 100 * positions());
    expect(failing.length, JSON.stringify(result.random.map((r) => r.unaligned))).toBeGreaterThanOrEqual(3);
  });

  if (renderer !== 'WebGLRenderer') {
    test('it ran where it says (WebGPU, or the WebGL 2 fallback)', () => {
      expect(result.backend).toBe(renderer.endsWith('WebGPU') ? 'webgpu' : 'webgl2');
    });

    test('two meshes of one material, each with its own skeleton and pose, share one build and each is skinned by its own bones', () => {
      expect(result.sharedBuild?.builds).toBe(1);
      expect(result.sharedBuild?.worst.length).toBe(2);
      for (const w of result.sharedBuild?.worst ?? []) expect(w).toBeLessThan(1e-4 * result.sharedBuild!.size);
    });

    test('shadow maps draw the dual quaternion skin: its shadow is the reference\'s to the pixel, three.js\'s linear skin\'s is not', () => {
      expect(result.shadows?.length).toBe(2);
      for (const r of result.shadows ?? []) {
        expect(r.shadowed, `seed ${r.seed}`).toBeGreaterThan(1000);
        expect(r.dqs, `seed ${r.seed}`).toBeLessThanOrEqual(0.01 * r.shadowed);
        expect(r.three, `seed ${r.seed}`).toBeGreaterThan(0.05 * r.shadowed);
      }
    });
  }
});

interface Example {
  mode: string;
  renderer: string;
  meshes: number;
  bones: number;
  programs: string[];
  box: [number, number, number];
}

describe('the three-dqs example app installed from the package tarball', () => {
  const version = JSON.parse(readFileSync(path.join(PACKAGE, 'package.json'), 'utf8')).version as string;
  let app: string;
  let site: Awaited<ReturnType<typeof serveStatic>>;
  const open = async (mode: string, renderer = 'webgl', within = browser) => {
    const p = await newPage(within);
    const errors: string[] = [];
    p.on('pageerror', (e) => errors.push(e.message));
    // (WebGPU reports a pipeline that fails to compile on the console.)
    p.on('console', (m) => void (m.type() === 'error' && !m.text().includes('404') && errors.push(m.text())));
    await p.goto(`${site.url}?mode=${mode}&renderer=${renderer}`);
    await p.waitForFunction(() => document.title === 'drawn', null, { timeout: 60_000 });
    const state = await p.evaluate(() => (window as unknown as { example: Example }).example);
    return { p, state, errors };
  };

  beforeAll(async () => {
    app = mkdtempSync(path.join(process.env.TMPDIR ?? tmpdir(), 'three-dqs-example-'));
    cpSync(path.join(PACKAGE, 'example'), app, { recursive: true });
    execFileSync('npm', ['install', '--no-audit', '--no-fund', path.join(root, 'target/npm', `three-dqs-${version}.tgz`)], { cwd: app, stdio: 'inherit' });
    mkdirSync(path.join(app, 'public'));
    copyFileSync(GENERIC_HAND, path.join(app, 'public/hand.glb'));
    execFileSync(path.join(app, 'node_modules/.bin/vite'), ['build', '--logLevel', 'warn'], { cwd: app, stdio: 'inherit' });
    site = await serveStatic(path.join(app, 'dist'));
  }, 300_000);

  afterAll(async () => {
    await site?.stop();
  });

  test('the installed package needs nothing but three', () => {
    const installed = JSON.parse(readFileSync(path.join(app, 'node_modules/three-dqs/package.json'), 'utf8'));
    expect(Object.keys(installed.peerDependencies ?? {})).toEqual(['three']);
    expect(installed.dependencies ?? {}).toEqual({});
  });

  test('a glTF hand made elsewhere is drawn with dual quaternions, its shadow too, and differently from linear skinning where its fingers bend', async () => {
    const dqs = await open('dqs');
    const lbs = await open('lbs');
    try {
      expect(dqs.errors).toEqual([]);
      expect(dqs.state.meshes).toBe(1);
      expect(dqs.state.bones).toBeGreaterThanOrEqual(25);
      // The skin's material and the shadow's depth material both skin with dual quaternions.
      expect(dqs.state.programs.filter((k) => k.includes('dqs-dqs')).length, dqs.state.programs.join('\n')).toBeGreaterThanOrEqual(2);
      expect(lbs.state.programs.some((k) => k.includes('dqs-')), lbs.state.programs.join('\n')).toBe(false);
      // The skin is drawn (its lit colour covers part of the frame) in both.
      const skin = { r: [120, 255], g: [70, 210], b: [50, 190] };
      const drawn = await countColour(dqs.p, skin);
      expect(drawn).toBeGreaterThan(2000);
      expect(await countColour(lbs.p, skin)).toBeGreaterThan(2000);
      // The CPU path's bounding boxes (each mode's own) agree within a centimetre, and the
      // pictures differ where the knuckles bend.
      for (let k = 0; k < 3; k++) expect(Math.abs(dqs.state.box[k] - lbs.state.box[k])).toBeLessThan(0.01);
      expect(thumbDifference(await canvasStats(dqs.p), await canvasStats(lbs.p))).toBeGreaterThan(0.05);
    } finally {
      await dqs.p.close();
      await lbs.p.close();
    }
  });

  test('with WebGPURenderer (three-dqs/webgpu from the same tarball) the same hand compiles, skin and shadow, and its CPU path gives the WebGL entry\'s box', async () => {
    const webgl = await open('dqs');
    const box = webgl.state.box;
    await webgl.p.close();
    const own = await launchBrowser(['--enable-unsafe-webgpu']);
    try {
      const webgpu = await open('dqs', 'webgpu', own);
      // (WebGPU reports errors asynchronously: give the frame's work time to finish.)
      await webgpu.p.evaluate(() => new Promise((done) => requestAnimationFrame(() => setTimeout(done, 500))));
      // Headless Chromium 156 sometimes drops a page's WebGPU instance after its first frame,
      // with or without this package ("A valid external Instance reference no longer exists",
      // then three.js's error scopes fail): that loss is the browser's, not a shader error.
      const dropped = /Instance dropped in popErrorScope|A valid external Instance reference no longer exists/;
      expect(webgpu.errors.filter((e) => !dropped.test(e))).toEqual([]);
      expect(webgpu.state.renderer).toBe('webgpu');
      expect(webgpu.state.meshes).toBe(1);
      for (let k = 0; k < 3; k++) expect(Math.abs(webgpu.state.box[k] - box[k])).toBeLessThan(1e-6);
    } finally {
      await own.close();
    }
  });
});
