// The page with no dqhand process at all: viewer/dist on a plain static file server (as any
// web host), the engine running in the page in WebAssembly. What the page offers with a server
// works here too: the split view LB / QB / DQB / CoR, the heat map, gestures and sliders, the
// timeline, WebXR under IWER (a Meta Quest 3 tracking hands) driving the page's engine, a scene
// of two hands, and Record, which saves a file the browser downloads and `dqhand replay` reads.

import { execFileSync } from 'node:child_process';
import { cpSync, mkdtempSync, readFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { afterAll, beforeAll, describe, expect, test } from 'vitest';
import type { Browser, Page } from 'playwright-core';
import type { XRDevice } from 'iwer';
import { countColour, dqhandBin, emulatedPage, launchBrowser, root, serveStatic, settle, waitState } from '../scripts/harness.mjs';

type Emulated = { iwer: XRDevice };
/** The skin's colours, lit and shaded (the viewer's SKIN, 0xe0a98f). */
const SKIN = { r: [120, 255], g: [70, 210], b: [70, 190] };

interface State {
  engine: string;
  connected: boolean;
  framesReceived: number;
  errors: string[];
  dofs: string[];
  visible: string[];
  input: { tracking: string; accepted: number; rejected: number; gesture: string | null } | null;
  scene: { drawn: number; held: string | null } | null;
  secondHand: { side: string; wrist: number[] | null } | null;
  xr: { active: boolean; sent: number; side: string | null };
  recordings: { on: boolean; path: string | null; records: number }[];
  frame: { methods: string[]; anglesDeg: number[]; wrist: number[]; playing: boolean; time: number; distortion: boolean } | null;
}

let server: Awaited<ReturnType<typeof serveStatic>>;
let browser: Browser;
const state = (page: Page): Promise<State> => page.evaluate(() => (window as unknown as { dqhand: { state(): State } }).dqhand.state());

beforeAll(async () => {
  server = await serveStatic(path.join(root, 'viewer/dist'));
  browser = await launchBrowser();
});

afterAll(async () => {
  await browser?.close();
  await server?.stop();
});

describe('the page on a static host, its engine in WebAssembly', () => {
  let page: Page;

  beforeAll(async () => {
    page = await emulatedPage(browser);
    await page.goto(server.url);
    await waitState(page, 's.connected && s.framesReceived > 3');
  });

  test('the engine runs in the page and draws the hand, the gesture sequence playing', async () => {
    const s = await state(page);
    expect(s.engine).toBe('page');
    expect(s.errors).toEqual([]);
    expect(s.dofs.length).toBe(23);
    expect(await page.locator('#status').textContent()).toBe('engine in this page');
    // The hand came from the file written beside the page (make viewer), not generated.
    expect(await page.locator('#model-line').textContent()).toMatch(/^anatomical right hand, .*\(glTF file right\.glb\)/);
    await settle(page);
    expect(await countColour(page, SKIN)).toBeGreaterThan(3000);
    await waitState(page, `s.frame.playing && s.frame.time > ${s.frame!.time + 0.2}`);
  });

  test('the split view draws LB, QB, DQB and CoR, and the heat map is on their frames', async () => {
    await page.check('#split');
    await waitState(page, 's.visible.length === 4 && s.frame.methods.length === 4');
    await page.check('#heatmap');
    await waitState(page, 's.frame.distortion');
    await page.uncheck('#heatmap');
    await page.uncheck('#split');
    await waitState(page, 's.visible.length === 1 && !s.frame.distortion');
  });

  test('a gesture button and a slider pose the hand', async () => {
    const s = await state(page);
    const index = s.dofs.indexOf('index-finger-phalanx-proximal.flex');
    await page.click('#play'); // pause the sequence
    await waitState(page, '!s.frame.playing');
    await page.click('button:text-is("fist")');
    await waitState(page, `s.frame.anglesDeg[${index}] > 60`);
    await page.locator(`input[data-dof="index-finger-phalanx-proximal.flex"]`).fill('10');
    await waitState(page, `Math.abs(s.frame.anglesDeg[${index}] - 10) < 0.5`);
  });

  test('in VR, the emulated right hand drives the page\'s engine; Record saves a file dqhand replay reads', async () => {
    await page.click('#enter-vr');
    await waitState(page, 's.xr.active && s.input && s.input.tracking === "tracking" && s.input.accepted > 10');
    const s = await state(page);
    expect(s.input!.rejected).toBe(0);
    // IWER's right hand is at (0.25, 1.5, −0.4), 'local-floor' metres.
    const [x, y, z] = s.frame!.wrist;
    expect(Math.hypot(x - 0.25, y - 1.5, z + 0.4)).toBeLessThan(0.15);
    // Record a stretch of the tracked hand pointing, then stop: the browser downloads it.
    await page.evaluate(() => (window as unknown as { dqhand: { send(c: object): void } }).dqhand.send({ type: 'record', on: true }));
    await waitState(page, 's.recordings.length > 0 && s.recordings.at(-1).on');
    await page.evaluate(() => ((window as unknown as Emulated).iwer.hands.right!.poseId = 'point'));
    await waitState(page, 's.input.gesture === "point"');
    const taken = (await state(page)).input!.accepted;
    await waitState(page, `s.input.accepted > ${taken + 20}`);
    const download = page.waitForEvent('download');
    await page.evaluate(() => (window as unknown as { dqhand: { send(c: object): void } }).dqhand.send({ type: 'record', on: false }));
    const file = path.join(mkdtempSync(path.join(process.env.TMPDIR ?? tmpdir(), 'dqhand-recorded-')), 'recorded.jsonl');
    await (await download).saveAs(file);
    const last = (await state(page)).recordings.at(-1)!;
    expect(last.on).toBe(false);
    const lines = readFileSync(file, 'utf8').trim().split('\n');
    expect(lines.length).toBe(last.records);
    expect(lines.length).toBeGreaterThan(10);
    const events = execFileSync(dqhandBin(), ['replay', '--gestures', '--input', file], { encoding: 'utf8' });
    expect(events).toMatch(/"event":"start","gesture":"point"/);
    await page.evaluate(() => (window as unknown as Emulated).iwer.activeSession!.end());
    await waitState(page, '!s.xr.active');
  });
});

describe('a scene of two hands in the page', () => {
  test('both emulated hands drive the page\'s two hands among the scene\'s objects', async () => {
    const page = await emulatedPage(browser);
    await page.goto(`${server.url}?scene=two-hands&hands=2`);
    await waitState(page, 's.connected && s.scene && s.secondHand && s.secondHand.side === "left"');
    await page.click('#enter-vr');
    // The objects are placed by the first scene message, which the input's first record brings.
    await waitState(page, 's.xr.active && s.input && s.input.tracking === "tracking" && s.scene.drawn.join() === "box,baton"');
    // The first hand at IWER's right one, the second at its left one (±0.25, 1.5, −0.4).
    await waitState(page, 'Math.abs(s.frame.wrist[0] - 0.25) < 0.15 && s.secondHand.wrist && Math.abs(s.secondHand.wrist[0] + 0.25) < 0.15');
    expect((await state(page)).errors).toEqual([]);
    expect(await page.locator('#model-line').textContent()).toMatch(/left hand, .*\(glTF file left\.glb\)/);
    await page.close();
  });
});

describe('a static copy without the hand files', () => {
  test('the page generates the same hand itself', async () => {
    const copy = mkdtempSync(path.join(process.env.TMPDIR ?? tmpdir(), 'dqhand-dist-'));
    cpSync(path.join(root, 'viewer/dist'), copy, { recursive: true, filter: (f) => !f.endsWith(`${path.sep}hands`) });
    const bare = await serveStatic(copy);
    try {
      const page = await emulatedPage(browser);
      await page.goto(bare.url);
      await waitState(page, 's.connected && s.framesReceived > 3');
      expect(await page.locator('#model-line').textContent()).toMatch(/^anatomical right hand, length 0\.19 m, breadth 0\.085 m, 8668 vertices, /);
      expect((await state(page)).errors).toEqual([]);
      await page.close();
    } finally {
      await bare.stop();
    }
  });
});
