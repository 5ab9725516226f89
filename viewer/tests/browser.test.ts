// The real page in headless Chromium against a real `dqhand demo`: it loads and draws, the
// controls reach the engine and come back as the right change on screen, and it survives a
// server restart.

import { afterAll, beforeAll, describe, expect, onTestFinished, test } from 'vitest';
import type { Browser, Page } from 'playwright-core';
import { canvasStats, countColour, launchBrowser, settle, startServer, thumbDifference, waitState } from '../scripts/harness.mjs';

type Server = Awaited<ReturnType<typeof startServer>>;
let server: Server;
let browser: Browser;
let page: Page;

interface State {
  connected: boolean;
  framesReceived: number;
  dofs: string[];
  joints: string[];
  visible: string[];
  /** Geometries the renderer holds on the GPU. */
  geometries: number;
  /** `wrist`: translation xyz (m), rotation xyzw, as the engine reports it. */
  frame: { methods: string[]; anglesDeg: number[]; joints: number[]; wrist: number[]; playing: boolean } | null;
}
const state = (): Promise<State> => page.evaluate(() => (window as unknown as { dqhand: { state(): State } }).dqhand.state());
const send = (command: object) => page.evaluate((c) => (window as unknown as { dqhand: { send(c: object): void } }).dqhand.send(c), command);

/** Index of a DOF in the frame's angles. */
const dof = (s: State, name: string) => s.dofs.indexOf(name);
const tip = (s: State, finger: string) => {
  const j = s.joints.indexOf(`${finger}-tip`);
  return s.frame!.joints.slice(3 * j, 3 * j + 3);
};
const distance = (a: number[], b: number[]) => Math.hypot(a[0] - b[0], a[1] - b[1], a[2] - b[2]);
const wristSlider = (i: number) => page.locator(`input[data-wrist="${i}"]`);
const wristSliders = () => page.locator('input[data-wrist]').evaluateAll((inputs) => inputs.map((i) => (i as HTMLInputElement).value));
/** Predicate: the engine reports the rest wrist (the built-in hand's: at the origin, unrotated). */
const REST_WRIST = 's.frame.wrist.every((v, i) => Math.abs(v - (i === 6 ? 1 : 0)) < 1e-6)';
/** Puts the wrist back at rest after the current test, passed or failed (the later tests' pixels expect it). */
const restWristAfterTest = () =>
  onTestFinished(async () => {
    await send({ type: 'rest' });
    await waitState(page, REST_WRIST);
  });

/** Stops the server, runs `whileDown` once the page has noticed, restarts it on the same port and waits for the new session's frames. */
async function restartServer(whileDown = async () => {}) {
  const port = server.port;
  await server.stop();
  await waitState(page, '!s.connected');
  await whileDown();
  server = await startServer({ port });
  const before = (await state()).framesReceived;
  await waitState(page, `s.connected && s.framesReceived > ${before + 3} && s.frame.methods.length === 3`, 90_000);
}

beforeAll(async () => {
  server = await startServer();
  browser = await launchBrowser();
  page = await browser.newPage({ viewport: { width: 900, height: 520 } });
  page.on('pageerror', (e) => console.error('page error:', e.message));
  await page.goto(server.url);
  await waitState(page, 's.connected && s.framesReceived > 3 && s.visible.length === 1');
});

afterAll(async () => {
  await browser?.close();
  await server?.stop();
});

describe('the viewer page', () => {
  test('loads, plays the gesture sequence and draws a hand on the canvas', async () => {
    const s = await state();
    expect(s.frame!.playing).toBe(true);
    expect(s.dofs).toHaveLength(23);
    await settle(page);
    const stats = await canvasStats(page);
    const covered = stats.strips[0] / (stats.width * stats.height);
    expect(covered).toBeGreaterThan(0.02);
    expect(covered).toBeLessThan(0.9);
    expect(await page.locator('#stats').textContent()).toMatch(/engine \d+ fps/);
  });

  test('a gesture button reaches its pose', async () => {
    await page.click('button[data-gesture="fist"]');
    const s = await state();
    const pip = dof(s, 'index-finger-phalanx-intermediate.flex');
    const mcp = dof(s, 'index-finger-phalanx-proximal.flex');
    await waitState(page, `Math.abs(s.frame.anglesDeg[${pip}] - 100) < 0.01 && Math.abs(s.frame.anglesDeg[${mcp}] - 85) < 0.01 && !s.frame.playing`);
  });

  test('a slider moves the right finger and only that finger', async () => {
    await send({ type: 'rest' });
    await waitState(page, 's.frame.anglesDeg.every((a) => Math.abs(a) < 1e-3)');
    const before = await state();
    const name = 'index-finger-phalanx-intermediate.flex';
    await page.locator(`input[data-dof="${name}"]`).fill('90');
    const i = dof(before, name);
    await waitState(page, `Math.abs(s.frame.anglesDeg[${i}] - 90) < 0.01`);
    const after = await state();
    expect(distance(tip(before, 'index-finger'), tip(after, 'index-finger'))).toBeGreaterThan(0.02);
    for (const f of ['thumb', 'middle-finger', 'ring-finger', 'pinky-finger']) {
      expect(distance(tip(before, f), tip(after, f))).toBeLessThan(1e-5);
    }
  });

  test('the wrist sliders show the engine\'s wrist, in its Euler convention', async () => {
    restWristAfterTest();
    await send({ type: 'wrist', translation: [0.02, -0.035, 0.1], rotation_deg: [20, -30, 40] });
    await waitState(page, 'Math.abs(s.frame.wrist[2] - 0.1) < 1e-4');
    await settle(page); // the page moves its sliders on its next animation frame
    expect(await wristSliders()).toEqual(['2', '-3.5', '10', '20', '-30', '40']);
  });

  test('after Rest, touching a wrist slider does not bring the old wrist back', async () => {
    restWristAfterTest();
    await wristSlider(0).fill('5');
    await waitState(page, 'Math.abs(s.frame.wrist[0] - 0.05) < 1e-4');
    await settle(page);
    await wristSlider(5).fill('40');
    await waitState(page, 'Math.abs(s.frame.wrist[5]) > 0.3');
    await page.click('#rest');
    await waitState(page, REST_WRIST);
    await settle(page);
    await wristSlider(1).fill('3');
    await waitState(page, 'Math.abs(s.frame.wrist[1] - 0.03) < 1e-4');
    const rest = [0, 0.03, 0, 0, 0, 0, 1]; // the rest wrist, moved by the touched slider only
    expect((await state()).frame!.wrist).toEqual(rest.map((v) => expect.closeTo(v, 5)));
    await settle(page);
    expect(await wristSliders()).toEqual(['0', '3', '0', '0', '0', '0']);
  });

  test('switching the method changes the rendered hand', async () => {
    await page.click('button[data-gesture="fist"]');
    await waitState(page, '!s.frame.playing && s.frame.methods[0] === "dqb"');
    await page.waitForTimeout(1000); // the move to the gesture takes 0.6 s
    await settle(page);
    const dqb = await canvasStats(page);
    await page.check('#method-qb');
    await waitState(page, 's.visible.length === 1 && s.visible[0] === "qb"');
    await settle(page);
    const qb = await canvasStats(page);
    await page.check('#method-dqb');
    await waitState(page, 's.visible[0] === "dqb"');
    await settle(page);
    const again = await canvasStats(page);
    expect(thumbDifference(dqb, again)).toBeLessThan(0.5); // the same method draws the same hand
    expect(thumbDifference(dqb, qb)).toBeGreaterThan(2 * thumbDifference(dqb, again) + 0.5);
  });

  test('the split view shows three hands, LB, QB and DQB', async () => {
    await page.check('#split');
    await waitState(page, 's.visible.join() === "lb,qb,dqb" && s.frame.methods.length === 3');
    await settle(page);
    const stats = await canvasStats(page, 3);
    const strip = (stats.width / 3) * stats.height;
    for (const covered of stats.strips) expect(covered / strip).toBeGreaterThan(0.01);
    expect(await page.locator('#labels span').allTextContents()).toEqual(['LB', 'QB', 'DQB']);
  });

  test('the heat map colours the distortion', async () => {
    await page.check('#heatmap');
    await waitState(page, 's.frame && s.frame.methods.length === 3');
    await page.waitForFunction(() => (window as unknown as { dqhand: { state(): { frame: { distortion: boolean } } } }).dqhand.state().frame.distortion);
    await settle(page);
    const reds = await countColour(page, { r: [181, 255], g: [0, 109], b: [0, 89] });
    expect(reds).toBeGreaterThan(50); // a fist stretches the skin over the knuckles
    await page.uncheck('#heatmap');
  });

  test('wireframe and skeleton overlays change what is drawn', async () => {
    await page.uncheck('#split'); // one hand: software WebGL draws wireframes slowly
    await waitState(page, 's.visible.length === 1');
    await settle(page);
    const plain = await canvasStats(page);
    await page.check('#wireframe');
    await settle(page);
    const wire = await canvasStats(page);
    expect(thumbDifference(plain, wire)).toBeGreaterThan(1);
    await page.uncheck('#wireframe');
    await page.check('#skeleton');
    await settle(page);
    const blue = await countColour(page, { r: [0, 89], b: [151, 255] });
    expect(blue).toBeGreaterThan(100); // the bones, drawn over the skin
    await page.uncheck('#skeleton');
    await page.check('#split');
    await waitState(page, 's.visible.length === 3');
  });

  test('the page reconnects after the server restarts, with its settings', async () => {
    await restartServer(async () => expect(await page.locator('#status').textContent()).toMatch(/reconnecting/));
  });

  test('reconnecting frees the previous session\'s hand geometries', async () => {
    await page.check('#skeleton'); // bones and joint dots reach the GPU only once drawn
    await settle(page);
    const before = (await state()).geometries;
    for (let k = 0; k < 3; k++) await restartServer();
    await settle(page);
    expect((await state()).geometries).toBe(before);
    await page.uncheck('#skeleton');
  });
});
