// The WebXR input in headless Chromium against a real `dqhand demo`, the headset emulated by
// IWER (a Meta Quest 3 tracking hands; the test injects it before the page's own script, so
// the shipped page holds no emulator): the Enter VR / AR buttons, the tracked hand's joint
// records reaching the engine, its hand following the emulated one and drawn where that is,
// and the desktop view back after the session.

import { afterAll, beforeAll, describe, expect, test } from 'vitest';
import type { Browser, Page } from 'playwright-core';
import type { XRDevice } from 'iwer';
import { canvasStats, countColour, emulatedPage as emulatedPageOf, launchBrowser, newPage, settle, startServer, thumbDifference, waitState } from '../scripts/harness.mjs';

/** The skin's colours, lit and shaded (the viewer's SKIN, 0xe0a98f). */
const SKIN = { r: [120, 255], g: [70, 210], b: [70, 190] };
/** The page's globals with the emulator: its module and the device, as the init script makes it. */
type Emulated = { IWER: typeof import('iwer'); iwer: XRDevice };

interface State {
  connected: boolean;
  framesReceived: number;
  errors: string[];
  dofs: string[];
  visible: string[];
  input: { tracking: string; accepted: number; rejected: number } | null;
  /** `wrist`: translation xyz (m), rotation xyzw. */
  frame: { methods: string[]; anglesDeg: number[]; wrist: number[] } | null;
  xr: { supported: { vr: boolean; ar: boolean }; active: boolean; mode: string | null; sent: number; side: string | null };
}

let server: Awaited<ReturnType<typeof startServer>>;
let browser: Browser;
let page: Page;
const state = (p = page): Promise<State> => p.evaluate(() => (window as unknown as { dqhand: { state(): State } }).dqhand.state());
/** Index of a DOF in the frame's angles. */
const dof = (s: State, name: string) => s.dofs.indexOf(name);
/** The share of each half of the canvas (left, right) that is not background. */
const halves = async () => {
  const { strips, width, height } = await canvasStats(page, 2);
  return strips.map((n: number) => n / ((width * height) / 2));
};
/** Predicate: the engine's hand at rest (every angle 0, the wrist at the origin, unrotated). */
const AT_REST = 's.frame.anglesDeg.every((a) => Math.abs(a) < 1e-3) && s.frame.wrist.every((v, i) => Math.abs(v - (i === 6 ? 1 : 0)) < 1e-6)';
/** The canvas's size in pixels and its parent's id. */
const canvasPlace = () => page.evaluate(() => {
  const c = document.getElementById('view') as HTMLCanvasElement;
  return { width: c.width, height: c.height, parent: c.parentElement?.id };
});


/** A page of the tests' browser with the emulated headset. */
const emulatedPage = () => emulatedPageOf(browser);

beforeAll(async () => {
  server = await startServer();
  browser = await launchBrowser();
  page = await emulatedPage();
  await page.goto(server.url);
  await waitState(page, 's.connected && s.framesReceived > 3');
});

afterAll(async () => {
  await browser?.close();
  await server?.stop();
});

describe('the WebXR input, with an emulated headset tracking hands', () => {
  /** The desktop canvas before the session, and what it drew of the hand at rest. */
  let desktop: Awaited<ReturnType<typeof canvasPlace>>;
  let restView: Awaited<ReturnType<typeof canvasStats>>;

  test('the Enter VR and Enter AR buttons show only where the browser offers the modes', async () => {
    await waitState(page, 's.xr.supported.vr && s.xr.supported.ar');
    expect(await page.locator('#enter-vr').isVisible()).toBe(true);
    expect(await page.locator('#enter-ar').isVisible()).toBe(true);
    const plain = await newPage(browser);
    try {
      await plain.goto(server.url);
      await waitState(plain, 's.connected');
      // Chromium's own answer, once the page has had it too.
      expect(await plain.evaluate(() => navigator.xr?.isSessionSupported('immersive-vr') ?? false)).toBe(false);
      expect((await state(plain)).xr.supported).toEqual({ vr: false, ar: false });
      expect(await plain.locator('#enter-vr').isVisible()).toBe(false);
      expect(await plain.locator('#enter-ar').isVisible()).toBe(false);
    } finally {
      await plain.close();
    }
  });

  test('Enter VR streams the right hand\'s joints to the engine, whose hand is drawn at it', async () => {
    await page.click('#rest');
    await waitState(page, AT_REST);
    await settle(page);
    desktop = await canvasPlace();
    restView = await canvasStats(page);
    await page.check('#split'); // four hands on the desktop; in the world, one
    await waitState(page, 's.visible.length === 4');
    await page.click('#enter-vr');
    await waitState(page, 's.xr.active && s.xr.mode === "immersive-vr" && s.xr.side === "right" && s.visible.join() === "dqb"');
    await waitState(page, 's.input && s.input.tracking === "tracking" && s.input.accepted > 10');
    const s = await state();
    expect(s.xr.sent).toBeGreaterThanOrEqual(s.input!.accepted);
    expect(s.input!.rejected).toBe(0);
    expect(s.errors).toEqual([]);
    // The engine's wrist is the emulated one's, in 'local-floor' metres (IWER's right hand is
    // at (0.25, 1.5, -0.4) with the headset at 1.6 m).
    const [x, y, z] = s.frame!.wrist;
    expect(Math.hypot(x - 0.25, y - 1.5, z + 0.4)).toBeLessThan(0.15);
    await waitState(page, `s.framesReceived > ${s.framesReceived + 10}`); // the stream goes on
    // Drawn where the hand is: to the right in the headset's view, nothing on the left.
    await settle(page);
    const [left, right] = await halves();
    expect(right).toBeGreaterThan(0.01);
    expect(left).toBeLessThan(0.05 * right);
  });

  test('the engine\'s hand follows the emulated hand moving 10 cm, then pointing', async () => {
    const before = await state();
    const [x, y, z] = before.frame!.wrist;
    await page.evaluate(() => ((window as unknown as Emulated).iwer.hands.right!.position.x += 0.1));
    await waitState(page, `Math.abs(s.frame.wrist[0] - ${x + 0.1}) < 0.003 && Math.abs(s.frame.wrist[1] - ${y}) < 0.003 && Math.abs(s.frame.wrist[2] - ${z}) < 0.003`);
    // IWER's 'point': middle, ring and pinky curled, the index straight.
    await page.evaluate(() => ((window as unknown as Emulated).iwer.hands.right!.poseId = 'point'));
    const curled = ['middle', 'ring', 'pinky'].map((f) => dof(before, `${f}-finger-phalanx-proximal.flex`));
    const index = dof(before, 'index-finger-phalanx-proximal.flex');
    const flex = (i: number) => before.frame!.anglesDeg[i];
    await waitState(page, `${JSON.stringify(curled)}.every((i, k) => s.frame.anglesDeg[i] > ${JSON.stringify(curled.map(flex))}[k] + 40)`);
    expect(Math.abs((await state()).frame!.anglesDeg[index] - flex(index))).toBeLessThan(15);
  });

  test('a left hand alone is sent, and drawn mirrored back where it is', async () => {
    await page.evaluate(() => ((window as unknown as Emulated).iwer.hands.right!.connected = false));
    await waitState(page, 's.xr.side === "left" && s.input.tracking === "tracking"');
    // The engine mirrors it onto its right hand (x → −x); IWER's left hand is at x = −0.25.
    await waitState(page, 's.frame.wrist[0] > 0.15');
    await settle(page);
    await expect.poll(async () => {
      const [left, right] = await halves();
      return left > 0.01 && right < 0.05 * left;
    }, { timeout: 10_000 }).toBe(true);
    await page.evaluate(() => ((window as unknown as Emulated).iwer.hands.right!.connected = true));
    await waitState(page, 's.xr.side === "right"');
  });

  test('leaving the session gives the desktop view back', async () => {
    // One hand, as when the rest view was taken (the emulator's view covers the page's controls).
    await page.evaluate(() => (window as unknown as { dqhand: { setting(c: object): void } }).dqhand.setting({ type: 'view', methods: ['dqb'] }));
    await waitState(page, 's.frame.methods.length === 1');
    await page.evaluate(() => (window as unknown as Emulated).iwer.activeSession!.end());
    await waitState(page, '!s.xr.active && s.xr.mode === null && s.xr.side === null');
    expect(await canvasPlace()).toEqual(desktop);
    const sent = (await state()).xr.sent;
    await waitState(page, 's.input.tracking === "lost"'); // the records stopped
    expect((await state()).xr.sent).toBe(sent);
    // Turned for viewing again, under the desktop camera (untouched by the headset's): at rest, drawn as before.
    await page.click('#rest');
    await waitState(page, AT_REST);
    await settle(page);
    expect(thumbDifference(restView, await canvasStats(page))).toBeLessThan(0.5);
    expect((await state()).errors).toEqual([]);
  });

  test('Enter AR starts an AR session streaming the hand the same way', async () => {
    const before = await state();
    await page.click('#enter-ar');
    await waitState(page, `s.xr.active && s.xr.mode === "immersive-ar" && s.input.tracking === "tracking" && s.input.accepted > ${before.input!.accepted + 10}`);
    await page.evaluate(() => (window as unknown as Emulated).iwer.activeSession!.end());
    await waitState(page, '!s.xr.active');
  });

  // Done with this page: the next describe's page draws alone (both share one software GPU).
  afterAll(async () => {
    await page?.close();
  });
});

describe('the WebXR input to a server driving two hands', () => {
  let twoServer: Awaited<ReturnType<typeof startServer>> | null = null;
  let p: Page;
  type TwoState = State & {
    input: { tracking: string; hands: { side: string; tracking: string }[] | null } | null;
    xr: State['xr'] & { both: boolean };
    secondHand: { side: string; wrist: number[] | null; sequence: number | null } | null;
  };
  const twoState = (): Promise<TwoState> => p.evaluate(() => (window as unknown as { dqhand: { state(): TwoState } }).dqhand.state());

  beforeAll(async () => {
    // Two hands in the built-in two-hands scene; --udp so that no scripted recording plays
    // (the headset is the only input). Drawn in software, the emulated headset may give a
    // record only every 0.3-0.8 s (seen with the other describe's page still drawing): the
    // engine's grace then follows the stream's rate, and the hands follow (interaction.md).
    twoServer = await startServer({ args: ['--hands', '2', '--udp', '0'] });
    p = await emulatedPage();
    await p.goto(twoServer.url);
    await waitState(p, 's.connected && s.framesReceived > 3 && s.secondHand !== null && s.secondHand.sequence !== null', 90_000);
  }, 180_000);

  afterAll(async () => {
    await p?.close();
    await twoServer?.stop();
  });

  test('both hands are sent, and each engine hand follows the user\'s hand of its side', async () => {
    expect((await twoState()).secondHand!.side).toBe('left');
    await p.click('#enter-vr');
    await waitState(p, 's.xr.active && s.xr.both && s.input && s.input.hands && s.input.hands.every((h) => h.tracking === "tracking")', 60_000);
    // IWER's hands are at (±0.25, 1.5, -0.4): the first engine hand at the right one, the second at the left.
    await waitState(p, 'Math.hypot(s.frame.wrist[0] - 0.25, s.frame.wrist[1] - 1.5, s.frame.wrist[2] + 0.4) < 0.15 && Math.hypot(s.secondHand.wrist[0] + 0.25, s.secondHand.wrist[1] - 1.5, s.secondHand.wrist[2] + 0.4) < 0.15', 60_000);
    expect((await twoState()).input!.hands!.map((h) => h.side)).toEqual(['right', 'left']);
    // Moving the left hand moves the second engine hand, not the first.
    const before = await twoState();
    await p.evaluate(() => ((window as unknown as Emulated).iwer.hands.left!.position.x -= 0.1));
    await waitState(p, `Math.abs(s.secondHand.wrist[0] - ${before.secondHand!.wrist![0] - 0.1}) < 0.01`, 60_000);
    expect(Math.abs((await twoState()).frame!.wrist[0] - before.frame!.wrist[0])).toBeLessThan(0.01);
    // Both drawn: the skin's pixels about double with the second hand in the picture.
    const skin = async (on: boolean) => {
      await p.evaluate((v) => (window as unknown as { dqhand: { showSecondHand(on: boolean): void } }).dqhand.showSecondHand(v), on);
      await settle(p);
      return countColour(p, SKIN);
    };
    const [one, both] = [await skin(false), await skin(true)];
    expect(one).toBeGreaterThan(500);
    expect(both).toBeGreaterThan(1.5 * one);
    expect((await twoState()).errors).toEqual([]);
    await p.evaluate(() => (window as unknown as Emulated).iwer.activeSession!.end());
    await waitState(p, '!s.xr.active');
  }, 240_000);
});
