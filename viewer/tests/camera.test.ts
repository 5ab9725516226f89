// The camera path end to end: a video of a hand in known gestures played to headless Chromium
// as its webcam; the Camera button runs MediaPipe Hands in the page on it, the landmarks go to
// the engine, and its recognised gestures and retargeted angles are compared with the video's.
// First our own hand (rendered by the real page, scripts/webcam-video.mjs) with a real `dqhand
// demo` as the engine, whose input the Record button records and `dqhand replay` replays to the
// same gesture events; then, on a plain static server with no dqhand process (the engine in the
// page, in WebAssembly), the same video mirrored (a left hand) and a hand that is not ours, the
// WebXR generic hand posed from a synthetic recording (scripts/generic-hand-video.mjs), against
// which MediaPipe's own tracking error is measured.
//
// Every video frame carries its number (scripts/y4m.mjs, MARKER); the page is given a hook that
// reads it off each frame handed to MediaPipe. The frames taken give the video's clock
// (`videoClock`), so every sample of the page's state knows where in the (looping) video it was
// taken; and every recorded record which frame it came from.

import { spawnSync } from 'node:child_process';
import { mkdtempSync, readdirSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import type { Browser, Page } from 'playwright-core';
import { afterAll, beforeAll, describe, expect, test } from 'vitest';
import { dqhandBin, launchBrowser, newPage, root, serveStatic, startServer, waitState } from '../scripts/harness.mjs';
import { MARKER, besideItsMirror } from '../scripts/y4m.mjs';

type Server = Awaited<ReturnType<typeof startServer>>;
let staticServer: Awaited<ReturnType<typeof serveStatic>>;
interface Hold {
  gesture: string;
  from_s: number;
  to_s: number;
}
interface Labels {
  fps: number;
  frames: number;
  size: [number, number];
  side: 'left' | 'right' | 'both';
  gestures: Hold[];
}
interface Sample {
  /** When it was taken (ms, the test's clock). */
  at: number;
  /** Where the video was then (s from its first frame, by `videoClock`); null if the page took no frame. */
  video: number | null;
  gesture: string | null;
  tracking: string;
  side: string | null;
  anglesDeg: number[];
  /** Each engine hand's state (two hands in a scene: the right one first). */
  hands: { side: string; tracking: string; gesture: string | null }[] | null;
}

/**
 * The input configuration of these tests: a grace time of 1.5 s. MediaPipe in software WebGL on
 * a small CI machine gives 2-6 frames a second, not a webcam's 30, with longer stalls now and
 * then; the engine's own grace follows a slow stream's rate (2.5 of its intervals) but these
 * tests' waits were measured with this one, and the XR test's two hands run on the default.
 */
const CONFIG = { grace_s: 1.5 };
/**
 * Largest median error of the retargeted angles against the rendered gesture's (degrees, over
 * the DOFs each gesture bends, per hold, on every sample of the hold). Measured on a 2-core VM:
 * 6–14° (open palm) to 25° (victory: the ring and little fingers curled under the thumb, which
 * MediaPipe sees less curled from one camera); docs/performance.md has the numbers.
 */
const MEDIAN_TOLERANCE_DEG = 30;

/**
 * How long after a hold begins in the video the engine may still show the move into it (s):
 * MediaPipe sees a new frame only when done with the last (2–6 frames a second on a loaded
 * 2-core machine, so a frame may wait up to 0.5 s and take as long), the engine's filters
 * follow, and a gesture must hold `min_hold_s` (0.1 s) before it is recognised. Measured on a
 * 2-core VM (`latencies`: the angles reaching the hold's): 0.1–1.0 s on our hand's video; on
 * the generic hand's 0–3.8 s, half of the holds within 1.2–1.8 s (MediaPipe at 1.3–2.9 frames
 * a second, the machine loaded by builds): some of those holds are judged on the move into
 * them, which the per-hold report shows as the previous gesture.
 */
const LATENCY_S = 1.5;
/**
 * A hold is "named" when its gesture is shown on at least this share of the samples taken in
 * it (from its start plus LATENCY_S to its end): most of the hold, not a glimpse.
 */
const NAMED_SHARE = 0.8;
/** Fewest samples a hold is judged on (the page samples itself less often than every 100 ms when loaded). */
const MIN_HOLD_SAMPLES = 3;

const dir = mkdtempSync(path.join(tmpdir(), 'dqhand-camera-'));
let labels: Labels;
/** Each library gesture's angles (degrees) by DOF name, from `dqhand demo --out` (0 where absent). */
const poses = new Map<string, Record<string, number>>();
let server: Server;
let browser: Browser;
let page: Page;

/** Renders the test's video into `dir` (`--left`: mirrored) and reads its labels. */
function renderVideo(...flags: string[]): Labels {
  const video = spawnSync('node', [path.join(root, 'viewer/scripts/webcam-video.mjs'), dir, ...flags], { encoding: 'utf8', env: { ...process.env, DQHAND_BIN: dqhandBin() } });
  if (video.status !== 0) throw new Error(`webcam-video.mjs ${flags.join(' ')} failed: ${video.stderr}`);
  return JSON.parse(readFileSync(path.join(dir, flags.includes('--left') ? 'hand-left.labels.json' : 'hand.labels.json'), 'utf8'));
}

/**
 * In the page, before its scripts: each frame the page takes from a video (its next frame for
 * MediaPipe, requestVideoFrameCallback) is read for its number (MARKER's blocks), logged in
 * `window.videoFrames` with the page's time.
 */
function watchFrames([marker, size]: [typeof MARKER, [number, number]]): void {
  const log: { at: number; frame: number }[] = [];
  (window as unknown as { videoFrames: typeof log }).videoFrames = log;
  const g = Object.assign(document.createElement('canvas'), { width: marker.bits * marker.block[0], height: marker.block[1] }).getContext('2d', { willReadFrequently: true })!;
  const requestFrame = HTMLVideoElement.prototype.requestVideoFrameCallback;
  HTMLVideoElement.prototype.requestVideoFrameCallback = function (callback) {
    return requestFrame.call(this, (now, metadata) => {
      const scale = this.videoWidth / size[0];
      g.drawImage(this, 0, 0, g.canvas.width * scale, g.canvas.height * scale, 0, 0, g.canvas.width, g.canvas.height);
      const row = g.getImageData(0, marker.block[1] / 2, g.canvas.width, 1).data;
      let frame = 0;
      for (let b = 0; b < marker.bits; b++) frame = 2 * frame + (row[4 * (b * marker.block[0] + marker.block[0] / 2)] > 127 ? 1 : 0);
      log.push({ at: performance.now(), frame });
      callback(now, metadata);
    });
  };
}

/**
 * A browser whose camera plays `video` (in `dir`, of `size`), and a page of it, connected: on
 * `dqhand demo` (the demo's engine in the page, the camera's records relayed back by the demo,
 * which records them), or on a plain static server (no dqhand process: the page's own engine,
 * given the tests' input configuration in its URL; Record downloads the file).
 */
async function cameraPage(video: string, size: [number, number], host: 'server' | 'static' = 'server', query = ''): Promise<{ browser: Browser; page: Page }> {
  if (query && host === 'server') throw new Error('a page on dqhand demo takes the demo\'s settings, not a query');
  const b = await launchBrowser(['--use-fake-device-for-media-stream', '--use-fake-ui-for-media-stream', `--use-file-for-fake-video-capture=${path.join(dir, video)}`]);
  const p = await newPage(b, { width: 1100, height: 700 });
  await p.addInitScript(watchFrames, [MARKER, size] as [typeof MARKER, [number, number]]);
  await p.goto(host === 'server' ? server.url : `${staticServer.url}?config=${encodeURIComponent(JSON.stringify(CONFIG))}${query}`);
  await waitState(p, 's.connected && s.frame !== null');
  const s = await read<{ engine: string; relay: object | null }>(p);
  expect([s.engine, s.relay !== null]).toEqual(['page', host === 'server']);
  return { browser: b, page: p };
}

/** Clicks Record off on a page whose engine runs in it, and saves the file the browser downloads; its path. */
async function downloadRecording(p: Page): Promise<string> {
  const download = p.waitForEvent('download');
  await p.click('#record');
  const file = path.join(dir, `downloaded-${Date.now()}.jsonl`);
  await (await download).saveAs(file);
  return file;
}

beforeAll(async () => {
  labels = renderVideo();
  const out = path.join(dir, 'poses');
  const written = spawnSync(dqhandBin(), ['demo', '--out', out], { encoding: 'utf8' });
  if (written.status !== 0) throw new Error(`dqhand demo --out failed: ${written.stderr}`);
  for (const f of readdirSync(out).filter((f) => f.endsWith('.pose.json'))) {
    poses.set(f.replace(/^\d+-/, '').replace('.pose.json', ''), JSON.parse(readFileSync(path.join(out, f), 'utf8')).angles_deg);
  }
  writeFileSync(path.join(dir, 'config.json'), JSON.stringify(CONFIG));
  server = await startServer({ args: ['--config', path.join(dir, 'config.json'), '--recordings', path.join(dir, 'recordings')] });
  staticServer = await serveStatic(path.join(root, 'viewer/dist'));
  ({ browser, page } = await cameraPage('hand.y4m', labels.size));
});

afterAll(async () => {
  await browser?.close();
  await server?.stop();
  await staticServer?.stop();
  rmSync(dir, { recursive: true, force: true });
});

/** The page's state (`window.dqhand.state()`), as the test expects it. */
const read = <T>(p: Page = page): Promise<T> => p.evaluate(() => (window as unknown as { dqhand: { state(): T } }).dqhand.state());

/** The frames the page has taken from its camera for MediaPipe (its time, ms; the frame's number). */
const framesTaken = (p: Page) => p.evaluate(() => (window as unknown as { videoFrames: { at: number; frame: number }[] }).videoFrames);

/** Frames taken this close to a time (ms) set the video's clock there. */
const CLOCK_WINDOW_MS = 2000;

/**
 * The video's clock: where the looping video is (s from its first frame) at a page time (ms),
 * from the frames the page took: the median of their phases (page time less video time)
 * within CLOCK_WINDOW_MS. A frame alone is not trusted (it is read up to a few hundred ms late
 * when the page is busy with MediaPipe), nor one phase for the whole run (Chromium's fake
 * camera falls behind on a loaded machine and does not catch up: 1.0–1.5 s in a minute at load 12).
 * `residuals`: each frame's phase against the clock's there (s); `drift`: the clock's phase at
 * the last frame less at the first (s).
 */
function videoClock(taken: { at: number; frame: number }[], v: Labels): { at(pageMs: number): number | null; residuals: number[]; drift: number } {
  const loop = v.frames / v.fps;
  const wrap = (x: number) => ((x % loop) + loop) % loop;
  /** `x` less `from`, in (−loop/2, loop/2]. */
  const less = (x: number, from: number) => wrap(x - from + loop / 2) - loop / 2;
  const phases = taken.map((f) => wrap(f.at / 1000 - f.frame / v.fps));
  const phaseAt = (pageMs: number): number | null => {
    const near = taken.map((f, i) => [Math.abs(f.at - pageMs), phases[i]]).filter(([d]) => d <= CLOCK_WINDOW_MS).map(([, p]) => p);
    return near.length === 0 ? null : near[0] + median(near.map((p) => less(p, near[0])));
  };
  const at = (pageMs: number) => {
    const phase = phaseAt(pageMs);
    return phase === null ? null : wrap(pageMs / 1000 - phase);
  };
  const residuals = taken.map((f, i) => less(phases[i], phaseAt(f.at)!));
  const drift = taken.length > 0 ? less(phaseAt(taken[taken.length - 1].at)!, phaseAt(taken[0].at)!) : 0;
  return { at, residuals, drift };
}

/**
 * Samples the page's state every 100 ms for `seconds`, each sample placed in the video of `v`.
 * The page samples itself (a round trip from the test per sample takes longer than 100 ms on a
 * loaded machine).
 */
async function sample(p: Page, seconds: number, v: Labels): Promise<Sample[]> {
  const raw = await p.evaluate(
    (seconds) =>
      new Promise<(Omit<Sample, 'video'> & { pageAt: number })[]>((done) => {
        const w = window as unknown as { dqhand: { state(): { input: { gesture: string | null; tracking: string; side: string | null; hands: Sample['hands'] } | null; frame: { anglesDeg: number[] } | null } } };
        const samples: (Omit<Sample, 'video'> & { pageAt: number })[] = [];
        const timer = setInterval(() => {
          const s = w.dqhand.state();
          samples.push({ at: Date.now(), pageAt: performance.now(), gesture: s.input?.gesture ?? null, tracking: s.input?.tracking ?? 'none', side: s.input?.side ?? null, anglesDeg: s.frame?.anglesDeg ?? [], hands: s.input?.hands ?? null });
        }, 100);
        setTimeout(() => {
          clearInterval(timer);
          done(samples);
        }, seconds * 1000);
      }),
    seconds,
  );
  const clock = videoClock(await framesTaken(p), v);
  return raw.map(({ pageAt, ...s }) => ({ ...s, video: clock.at(pageAt) }));
}

/** The samples taken in `hold`: from its start plus LATENCY_S to its end, in any pass of the video. */
const inHold = (samples: Sample[], hold: Hold) => samples.filter((s) => s.video !== null && s.video >= hold.from_s + LATENCY_S && s.video < hold.to_s);

/** How many samples showed each gesture ('none' for none). */
function shown(samples: Sample[]): Record<string, number> {
  const counts: Record<string, number> = {};
  for (const s of samples) counts[s.gesture ?? 'none'] = (counts[s.gesture ?? 'none'] ?? 0) + 1;
  return counts;
}

/**
 * Asserts that each hold of `report` showing one of `gestures` has MIN_HOLD_SAMPLES samples or
 * more, and shows its gesture on NAMED_SHARE of them (`label` names the hand in a failure).
 */
function expectNamed(report: (Hold & { shown: Record<string, number> })[], gestures: string[], label = ''): void {
  for (const { gesture, shown: counts } of report.filter((r) => gestures.includes(r.gesture))) {
    const n = Object.values(counts).reduce((a, b) => a + b, 0);
    expect(n, `${label}${gesture}`).toBeGreaterThanOrEqual(MIN_HOLD_SAMPLES);
    expect((counts[gesture] ?? 0) / n, `${label}${gesture}: ${JSON.stringify(counts)}`).toBeGreaterThanOrEqual(NAMED_SHARE);
  }
}

/** Mean difference of two poses' angles (degrees) under which a pose has reached the other. */
const REACHED_DEG = 10;

/**
 * How long after a hold's start the retargeted angles reached the hold's (s): the first sample
 * within REACHED_DEG of the median angles of the hold's last second, in each pass of the video
 * whose hold start the sampling saw (a sample in the second before it). The pipeline's
 * latency, whatever the recogniser makes of the pose: LATENCY_S's measure.
 */
function latencies(samples: Sample[], v: Labels): number[] {
  const out: number[] = [];
  for (const hold of v.gestures) {
    for (let i = 1; i < samples.length; i++) {
      const [a, b] = [samples[i - 1].video, samples[i].video];
      if (a === null || b === null || !(a < hold.from_s && b >= hold.from_s && hold.from_s - a < 1)) continue;
      const end = samples.findIndex((s, k) => k >= i && (s.video! < hold.from_s || s.video! >= hold.to_s));
      const pass = samples.slice(i, end < 0 ? samples.length : end).filter((s) => s.anglesDeg.length > 0);
      const last = pass.filter((s) => s.video! >= hold.to_s - 1);
      if (last.length === 0) continue;
      const reached = last[0].anglesDeg.map((_, d) => median(last.map((s) => s.anglesDeg[d])));
      const first = pass.find((s) => s.anglesDeg.reduce((e, x, d) => e + Math.abs(x - reached[d]), 0) / reached.length < REACHED_DEG);
      if (first) out.push(first.video! - hold.from_s);
    }
  }
  return out.sort((x, y) => x - y);
}

const median = (v: number[]) => [...v].sort((a, b) => a - b)[Math.floor(v.length / 2)];
const quantile = (v: number[], q: number) => [...v].sort((a, b) => a - b)[Math.floor(q * (v.length - 1))];

/** The gestures recognised in turn, each with how long it lasted (s, from its first sample to the next run's). */
function runs(samples: Sample[]): { gesture: string; seconds: number }[] {
  const out: { gesture: string | null; from: number; to: number }[] = [];
  for (const { at, gesture } of samples) {
    const last = out[out.length - 1];
    if (last) last.to = at;
    if (!last || last.gesture !== gesture) out.push({ gesture, from: at, to: at });
  }
  return out.filter((r) => r.gesture !== null).map((r) => ({ gesture: r.gesture!, seconds: (r.to - r.from) / 1000 }));
}

/**
 * A move between two gestures may pass through another (closing the hand brings the thumb
 * onto the curling index: a pinch, 0.8–1.1 s here, the filters and MediaPipe's few frames a
 * second on a loaded machine stretching the video's 0.3 s move): runs up to this long (s) are
 * moves, not gestures shown. Each gesture is shown for 4 s (3 s left too few samples past LATENCY_S
 * when MediaPipe ran at 2 frames a second).
 */
const PASSING_S = 1.5;

/** Gathers the lines of the page's log (it keeps the latest 30) every 200 ms, until stopped. */
function gatherLog(p: Page): { lines: Set<string>; stop(): Promise<void> } {
  const lines = new Set<string>();
  let running = true;
  const gather = async () => {
    for (const line of (await p.evaluate(() => (window as unknown as { dqhand: { state(): { input: { log: string[] } | null } } }).dqhand.state().input?.log ?? []))) lines.add(line);
  };
  const done = (async () => {
    while (running) {
      await gather();
      await new Promise((r) => setTimeout(r, 200));
    }
    await gather();
  })();
  return {
    lines,
    stop: async () => {
      running = false;
      await done;
    },
  };
}

describe('the Camera button on a video of our own hand', () => {
  /** The engine's log while the camera input is recorded (from before its first record). */
  let log: ReturnType<typeof gatherLog>;

  test('Record, then Camera: MediaPipe finds the right hand, the engine recognises the rendered gestures, and the angles follow', async () => {
    // Recording from before the first record: the engine starts as fresh as a replay does.
    await page.click('#record');
    await waitState(page, 's.recordings.length === 1 && s.recordings[0].on');
    expect(await page.locator('#record').textContent()).toBe('Stop recording');
    log = gatherLog(page);
    await page.click('#camera');
    await waitState(page, '(s.camera.detected > 3) && s.input !== null && s.input.accepted > 3', 90_000);
    const state = await read<{ camera: { hands: string[]; status: string }; input: { source: string } }>();
    expect(state.camera.status).toBe('running');
    // The video shows a right hand's palm: MediaPipe calls it "Left" (its labels assume a mirrored image).
    expect(state.camera.hands[0]).toBe(labels.side);
    expect(state.input.source).toBe('WebSocket /input, relayed by dqhand demo');
    expect(await page.locator('#camera-preview').isVisible()).toBe(true);

    const loop = labels.frames / labels.fps;
    const samples = await sample(page, 1.4 * loop, labels);
    const tracked = samples.filter((s) => s.tracking === 'tracking');
    expect(tracked.length / samples.length).toBeGreaterThan(0.8);
    expect(new Set(samples.map((s) => s.side).filter(Boolean))).toEqual(new Set([labels.side]));

    // Every rendered gesture is recognised, nothing else is but in passing, and in the video's
    // (looping) order.
    const rendered = labels.gestures.map((g) => g.gesture);
    const all = runs(samples);
    const seen = all.filter((r) => r.seconds > PASSING_S).map((r) => r.gesture).filter((g, i, a) => g !== a[i - 1]);
    expect(new Set(seen), JSON.stringify(all)).toEqual(new Set(rendered));
    for (const r of all) if (!rendered.includes(r.gesture)) expect(r.seconds, `${r.gesture} in ${JSON.stringify(all)}`).toBeLessThanOrEqual(PASSING_S);
    // Each next gesture is the video's next one, or the one after when a short hold was
    // missed (MediaPipe at a few frames a second on a loaded machine).
    const follows = (a: string, b: string) => rendered.some((g, i) => g === a && [1, 2].some((d) => rendered[(i + d) % rendered.length] === b));
    for (let i = 1; i < seen.length; i++) expect(follows(seen[i - 1], seen[i]), `${seen[i - 1]} → ${seen[i]} in ${JSON.stringify(all)}`).toBe(true);

    // The retargeted angles on every sample of each hold (recognised or not), against the
    // rendered gesture's, over the DOFs it bends (all for the open palm).
    const { dofs } = await read<{ dofs: string[] }>();
    const errors: Record<string, { samples: number; recognised: number; median: number; p90: number; worst: string }> = {};
    const everySample: number[] = [];
    labels.gestures.forEach((hold, h) => {
      const pose = poses.get(hold.gesture)!;
      const bent = dofs.map((d, i) => [d, i] as const).filter(([d]) => Math.abs(pose[d] ?? 0) >= 20 || hold.gesture === 'open_palm');
      const held = inHold(samples, hold).filter((s) => s.anglesDeg.length === dofs.length);
      const perDof = bent.map(([d, i]) => ({ d, e: held.map((s) => Math.abs(s.anglesDeg[i] - (pose[d] ?? 0))) }));
      const all = perDof.flatMap((x) => x.e);
      everySample.push(...all);
      const worst = perDof.map(({ d, e }) => `${d} ${median(e).toFixed(0)}`).sort((a, b) => Number(b.split(' ')[1]) - Number(a.split(' ')[1]));
      errors[`${h} ${hold.gesture}`] = { samples: held.length, recognised: held.filter((s) => s.gesture === hold.gesture).length, median: median(all), p90: quantile(all, 0.9), worst: worst.slice(0, 3).join(', ') };
    });
    console.log(`camera: retargeted angle error against the rendered gestures on every sample of each hold (degrees): ${JSON.stringify(errors, null, 1)}; latency (s, the angles reaching a hold's) ${latencies(samples, labels).map((l) => l.toFixed(1)).join(' ')}`);
    // Over every sample of every hold: a single hold's median is at the mercy of MediaPipe's
    // frame rate (a point judged on its move from the open palm read 58–64° in 2 of 3 runs on a
    // loaded 2-core VM, 15° in the third).
    for (const [name, e] of Object.entries(errors)) expect(e.samples, name).toBeGreaterThanOrEqual(MIN_HOLD_SAMPLES);
    expect(median(everySample), JSON.stringify(errors)).toBeLessThan(MEDIAN_TOLERANCE_DEG);
    const speed = await read<{ camera: { detectMs: number; fps: number; frames: number; detected: number }; pageFps: number; frame: { engineUs: number } }>();
    const { detectMs, fps, frames, detected } = speed.camera;
    console.log(`camera: MediaPipe ${detectMs.toFixed(0)} ms/frame, ${fps.toFixed(1)} frames/s, a hand in ${detected}/${frames}; page ${speed.pageFps.toFixed(1)} fps; engine ${speed.frame.engineUs.toFixed(0)} µs/frame`);
  });

  test('Stop recording: the file holds the camera input the engine took, and replay gives exactly the live gesture events', async () => {
    const file = (await read<{ recordings: { path: string }[] }>()).recordings[0].path;
    expect(path.dirname(file)).toBe(path.join(dir, 'recordings'));
    await page.click('#record');
    await waitState(page, 's.recordings.length === 2');
    // The engine may still be judging the last records recorded when the file closes (their
    // events then reach the log a moment later): gather it until the engine has taken two more.
    const taken = (await read<{ input: { accepted: number } }>()).input.accepted;
    await waitState(page, `s.input !== null && s.input.accepted > ${taken + 2}`, 60_000);
    await log.stop();
    const state = await read<{ recordings: { on: boolean; path: string; records: number }[] }>();
    expect(state.recordings[1]).toMatchObject({ on: false, path: file });
    const records = readFileSync(file, 'utf8').split('\n').filter(Boolean).map((l) => JSON.parse(l));
    expect(records.length).toBe(state.recordings[1].records);
    expect(records.length).toBeGreaterThan(10);
    expect(records[0]).toMatchObject({ hand: 'right' });
    expect(records[0].landmarks).toHaveLength(21);
    expect(typeof records[0].arrival).toBe('number');

    // The engine's live events (the page's log lines "t  start fist", gathered) and the
    // replay's, up to the last record recorded (the camera went on after it). The recording
    // began before the first record, so the replay starts from the engine's own start, and
    // with the records' arrival times it judges them on the live clock: exactly equal.
    // Compared as the log prints it (two decimals): an event judged on the last record itself
    // can round up past its unrounded time (CI once lost a t = 51.66 event that way).
    const last = Number(records[records.length - 1].t.toFixed(2));
    const live = [...log.lines]
      .map((line) => /^(\S+) {2}(start|end) (\S+)$/.exec(line))
      .filter((m) => m !== null)
      .map((m) => ({ t: Number(m[1]), event: m[2], gesture: m[3] }))
      .filter((e) => e.t <= last)
      .sort((a, b) => a.t - b.t || (a.event === 'end' ? -1 : 1));
    const replay = spawnSync(dqhandBin(), ['replay', '--gestures', '--input', file, '--config', path.join(dir, 'config.json')], { encoding: 'utf8' });
    expect(replay.status, replay.stderr).toBe(0);
    const replayed = replay.stdout
      .split('\n')
      .filter(Boolean)
      .map((l) => JSON.parse(l) as { t: number; event: string; gesture: string })
      .map(({ t, event, gesture }) => ({ t: Number(t.toFixed(2)), event, gesture }));
    expect(live.length).toBeGreaterThan(4);
    expect(replayed).toEqual(live);
  });

  test('Stop camera: no hand comes, the engine says tracking lost and the hand rests', async () => {
    await page.click('#camera');
    await waitState(page, '!s.camera.on && s.input.tracking === "lost"', 10_000);
    expect(await page.locator('#camera-preview').isVisible()).toBe(false);
    expect(await page.locator('#tracking-lost').isVisible()).toBe(true);
    // The engine blends to rest: every angle back to zero.
    await waitState(page, 's.frame.anglesDeg.every((a) => Math.abs(a) < 0.5)', 10_000);
  });

  // Done with this page: the next describes' pages run MediaPipe and draw alone (software WebGL).
  afterAll(async () => {
    await page?.close();
  });
});

describe('the Camera button on a video of our own hand, mirrored: a left hand', () => {
  let leftLabels: Labels;
  let leftBrowser: Browser;
  let leftPage: Page;

  beforeAll(async () => {
    leftLabels = renderVideo('--left');
    ({ browser: leftBrowser, page: leftPage } = await cameraPage('hand-left.y4m', leftLabels.size, 'static'));
  });

  afterAll(async () => {
    await leftBrowser?.close();
  });

  test('MediaPipe\'s label is swapped to the left hand, the engine mirrors it, and the open palm and the fist are named', async () => {
    await leftPage.click('#camera');
    await waitState(leftPage, 's.camera.detected > 3 && s.input !== null && s.input.side === "left"', 90_000);
    const { dofs } = await read<{ dofs: string[] }>(leftPage);
    const fingers = ['index', 'middle', 'ring'].map((f) => dofs.indexOf(`${f}-finger-phalanx-proximal.flex`));
    // Three passes of the video: enough samples of each hold on a loaded machine.
    const samples = await sample(leftPage, (3 * leftLabels.frames) / leftLabels.fps, leftLabels);
    const { camera, input } = await read<{ camera: { hands: string[] }; input: { side: string; mirrored: boolean } }>(leftPage);
    expect([camera.hands[0], input.side, input.mirrored]).toEqual(['left', 'left', true]);
    expect(new Set(samples.map((s) => s.side).filter(Boolean))).toEqual(new Set(['left']));
    const curled = Math.max(...samples.filter((s) => s.anglesDeg.length === dofs.length).map((s) => Math.min(...fingers.map((i) => s.anglesDeg[i]))));
    expect(curled).toBeGreaterThan(45);
    // The open palm is recognised, and the fist is named (fist on NAMED_SHARE of its samples).
    // MediaPipe reads the mirrored thumb less curled than the original's, and the engine's
    // recogniser then takes the fist for thumbs_up or nothing: this fails until it tells them apart.
    const report = leftLabels.gestures.map((hold) => ({ ...hold, shown: shown(inHold(samples, hold)) }));
    console.log(`camera, left: shown in each hold: ${JSON.stringify(report)}`);
    expect(samples.some((s) => s.gesture === 'open_palm'), JSON.stringify(report)).toBe(true);
    expectNamed(report, ['fist']);
    await leftPage.click('#camera');
  });
});

describe('the Camera button on a video of both hands: each drives the engine hand of its side', () => {
  let bothLabels: Labels;
  let bothBrowser: Browser;
  let bothPage: Page;

  beforeAll(async () => {
    // Our hand's video beside its mirror image: the user's right hand and their left, in the
    // same gestures at once.
    const { y4m, size } = besideItsMirror(readFileSync(path.join(dir, 'hand.y4m')));
    writeFileSync(path.join(dir, 'hands-both.y4m'), y4m);
    bothLabels = { ...labels, size, side: 'both' };
    ({ browser: bothBrowser, page: bothPage } = await cameraPage('hands-both.y4m', size, 'static', '&scene=two-hands&hands=2'));
  });

  afterAll(async () => {
    await bothBrowser?.close();
  });

  test('MediaPipe finds both hands, the engine\'s right hand follows the user\'s right and its left the left, and each names the open palm and the fist', async () => {
    await bothPage.click('#camera');
    await waitState(bothPage, 's.camera.detected > 3 && s.input !== null && s.input.hands !== null && s.input.hands.length === 2 && s.input.hands.every((h) => h.tracking === "tracking")', 90_000);
    const samples = await sample(bothPage, (2 * bothLabels.frames) / bothLabels.fps, bothLabels);
    const s = await read<{ camera: { hands: string[] }; frame: { wrist: number[] } | null; secondHand: { side: string; wrist: number[] | null } | null }>(bothPage);
    expect([...s.camera.hands].sort()).toEqual(['left', 'right']);
    // Each engine hand where the user's hand of its side is: the right one to the right (+x).
    expect(s.secondHand!.side).toBe('left');
    const [right, left] = [s.frame!.wrist[0], s.secondHand!.wrist![0]];
    expect(right - left, `right hand at x ${right}, left at ${left}`).toBeGreaterThan(0.05);
    const bySide = (side: string) =>
      samples.map((x) => {
        const hand = x.hands?.find((h) => h.side === side);
        return { ...x, gesture: hand?.gesture ?? null, tracking: hand?.tracking ?? 'none' };
      });
    const report = Object.fromEntries(['right', 'left'].map((side) => [side, bothLabels.gestures.map((hold) => ({ ...hold, shown: shown(inHold(bySide(side), hold)) }))]));
    console.log(`camera, both hands: shown in each hold: ${JSON.stringify(report)}`);
    for (const side of ['right', 'left']) {
      const tracked = bySide(side).filter((x) => x.tracking === 'tracking');
      expect(tracked.length / samples.length, side).toBeGreaterThan(0.8);
      // The open palm and the fist named on NAMED_SHARE of each of their holds' samples, by each hand.
      expectNamed(report[side], ['fist', 'open_palm'], `${side} `);
    }
    await bothPage.click('#camera');
  });
});

/**
 * The generic hand's recording: `dqhand synthesize` arguments, but for `--out`. A right hand
 * (the page's camera test takes one), every built-in gesture once (13 holds: the 12 and one
 * again), no idle motion after them.
 */
const GENERIC_RECORDING = ['synthesize', '--format', 'joints', '--seed', '3', '--holds', '13', '--idle', '0', '--side', 'right'];
/**
 * The share of holds named the project aims for (issue 27). Not met yet (4 of 13 on a 2-core
 * VM with the learned recogniser, 1–6 before it): most misses show the previous hold's gesture
 * past LATENCY_S (MediaPipe at ~3 frames a second, the fake camera falling behind) and pinch,
 * ok and thumbs up read as other shapes from MediaPipe's landmarks. Reported with every run,
 * not asserted, so that `make test` passes until it is met: docs/testing.md says so.
 */
const NAMED_HOLDS = 0.9;
/** Largest median retargeted angle error over every DOF and sample of the holds (degrees). */
const GENERIC_MEDIAN_TOLERANCE_DEG = 20;
/** MediaPipe's landmarks are compared with frames from this far into a hold (s): MediaPipe tracks from frame to frame, and the pose has settled. */
const SETTLED_S = 0.5;
/** A finger whose 4 landmarks lie this far from the truth on average (m) is "dropped". */
const DROPPED_M = 0.02;
/** The WebXR joint at each of MediaPipe's 21 landmarks (crates/dqhand/src/input/mediapipe.rs, WEBXR_INDEX). */
const WEBXR_INDEX = [0, 1, 2, 3, 4, 6, 7, 8, 9, 11, 12, 13, 14, 16, 17, 18, 19, 21, 22, 23, 24];
/** MediaPipe's landmarks of each finger. */
const FINGERS: Record<string, number[]> = { thumb: [1, 2, 3, 4], index: [5, 6, 7, 8], middle: [9, 10, 11, 12], ring: [13, 14, 15, 16], pinky: [17, 18, 19, 20] };

type Vec = [number, number, number];

/**
 * The similarity (scale, rotation, translation) that best maps `from` onto `to` in the least-
 * squares sense (Umeyama; the rotation by Horn's quaternion method), and each point's residual
 * `to − (s R from + t)`.
 */
function align(from: Vec[], to: Vec[]): { scale: number; residuals: Vec[] } {
  const mean = (p: Vec[]) => [0, 1, 2].map((k) => p.reduce((s, q) => s + q[k], 0) / p.length) as Vec;
  const [mf, mt] = [mean(from), mean(to)];
  const x = from.map((p) => p.map((v, k) => v - mf[k]) as Vec);
  const y = to.map((p) => p.map((v, k) => v - mt[k]) as Vec);
  const S = [0, 1, 2].map((a) => [0, 1, 2].map((b) => x.reduce((s, p, i) => s + p[a] * y[i][b], 0)));
  const [[xx, xy, xz], [yx, yy, yz], [zx, zy, zz]] = S;
  const [w, qx, qy, qz] = topEigenvector([
    [xx + yy + zz, yz - zy, zx - xz, xy - yx],
    [yz - zy, xx - yy - zz, xy + yx, zx + xz],
    [zx - xz, xy + yx, -xx + yy - zz, yz + zy],
    [xy - yx, zx + xz, yz + zy, -xx - yy + zz],
  ]);
  const R = [
    [1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - w * qz), 2 * (qx * qz + w * qy)],
    [2 * (qx * qy + w * qz), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - w * qx)],
    [2 * (qx * qz - w * qy), 2 * (qy * qz + w * qx), 1 - 2 * (qx * qx + qy * qy)],
  ];
  const turned = x.map((p) => R.map((r) => r[0] * p[0] + r[1] * p[1] + r[2] * p[2]) as Vec);
  const scale = turned.reduce((s, p, i) => s + p[0] * y[i][0] + p[1] * y[i][1] + p[2] * y[i][2], 0) / x.reduce((s, p) => s + p[0] ** 2 + p[1] ** 2 + p[2] ** 2, 0);
  return { scale, residuals: y.map((q, i) => q.map((v, k) => v - scale * turned[i][k]) as Vec) };
}

/** The eigenvector of the largest eigenvalue of a symmetric matrix (cyclic Jacobi rotations). */
function topEigenvector(m: number[][]): number[] {
  const n = m.length;
  const a = m.map((r) => [...r]);
  const v = a.map((_, i) => a.map((_, j) => (i === j ? 1 : 0)));
  for (let sweep = 0; sweep < 50; sweep++) {
    let off = 0;
    for (let p = 0; p < n; p++) for (let q = p + 1; q < n; q++) off += a[p][q] ** 2;
    if (off < 1e-24) break;
    for (let p = 0; p < n; p++) {
      for (let q = p + 1; q < n; q++) {
        if (a[p][q] === 0) continue;
        const theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
        const t = (theta >= 0 ? 1 : -1) / (Math.abs(theta) + Math.sqrt(theta * theta + 1));
        const c = 1 / Math.sqrt(t * t + 1);
        const s = t * c;
        for (const r of [a, v]) {
          for (let k = 0; k < n; k++) [r[k][p], r[k][q]] = [c * r[k][p] - s * r[k][q], s * r[k][p] + c * r[k][q]];
        }
        for (let k = 0; k < n; k++) [a[p][k], a[q][k]] = [c * a[p][k] - s * a[q][k], s * a[p][k] + c * a[q][k]];
      }
    }
  }
  const top = a.reduce((best, r, i) => (r[i] > a[best][best] ? i : best), 0);
  return v.map((r) => r[top]);
}

describe('the Camera button on a video of a hand not ours: the WebXR generic hand', () => {
  let generic: Labels;
  /** Each frame's record time and the 25 joints in the camera's frame (MediaPipe's axes, m). */
  let truth: { frames: { t: number; joints: Vec[] }[] };
  /** The recording's true angles: `dqhand replay --out` of it, by record time. */
  const trueAngles = new Map<number, Record<string, number>>();
  let genericBrowser: Browser;
  let genericPage: Page;
  let samples: Sample[];
  let dofs: string[];
  /** The camera input the engine took (the Record button), each record with the frame it came from. */
  let recorded: { landmarks: Vec[]; frame: number }[];
  /** The frames the page took for MediaPipe, with the page's time (ms). */
  let taken: { at: number; frame: number }[];

  beforeAll(async () => {
    const rec = path.join(dir, 'generic.jsonl');
    const synthesized = spawnSync(dqhandBin(), [...GENERIC_RECORDING, '--out', rec], { encoding: 'utf8' });
    if (synthesized.status !== 0) throw new Error(`dqhand ${GENERIC_RECORDING.join(' ')} failed: ${synthesized.stderr}`);
    const video = spawnSync('node', [path.join(root, 'viewer/scripts/generic-hand-video.mjs'), dir, '--input', rec], { encoding: 'utf8' });
    if (video.status !== 0) throw new Error(`generic-hand-video.mjs failed: ${video.stderr}`);
    generic = JSON.parse(readFileSync(path.join(dir, 'generic-hand.labels.json'), 'utf8'));
    truth = JSON.parse(readFileSync(path.join(dir, 'generic-hand.truth.json'), 'utf8'));
    const replayed = spawnSync(dqhandBin(), ['replay', '--input', rec, '--out', path.join(dir, 'generic.poses.jsonl')], { encoding: 'utf8' });
    if (replayed.status !== 0) throw new Error(`dqhand replay failed: ${replayed.stderr}`);
    for (const line of readFileSync(path.join(dir, 'generic.poses.jsonl'), 'utf8').split('\n').filter(Boolean)) {
      const { t, angles_deg } = JSON.parse(line);
      trueAngles.set(t, angles_deg);
    }

    ({ browser: genericBrowser, page: genericPage } = await cameraPage('generic-hand.y4m', generic.size, 'static'));
    const last = 's.recordings[s.recordings.length - 1]';
    await genericPage.click('#record');
    await waitState(genericPage, `s.recordings.length > 0 && ${last}.on`);
    await genericPage.click('#camera');
    await waitState(genericPage, 's.camera.detected > 3 && s.input !== null && s.input.accepted > 3', 90_000);
    ({ dofs } = await read<{ dofs: string[] }>(genericPage));
    // Two passes of the video: every hold sampled twice.
    samples = await sample(genericPage, (2 * generic.frames) / generic.fps, generic);
    const file = await downloadRecording(genericPage);
    await waitState(genericPage, `!${last}.on`);
    taken = await framesTaken(genericPage);
    // A record's time is the page's when MediaPipe gave the hand: its frame is the last one taken before.
    recorded = readFileSync(file, 'utf8')
      .split('\n')
      .filter(Boolean)
      .map((l) => JSON.parse(l) as { t: number; landmarks: Vec[] })
      .map(({ t, landmarks }) => ({ landmarks, frame: taken.filter((f) => f.at <= t * 1000).pop()?.frame ?? -1 }));
    await genericPage.click('#camera');
    const speed = await read<{ camera: { detectMs: number; fps: number; frames: number; detected: number } }>(genericPage);
    console.log(`camera, generic hand: MediaPipe ${speed.camera.detectMs.toFixed(0)} ms/frame, ${speed.camera.fps.toFixed(1)} frames/s, a hand in ${speed.camera.detected}/${speed.camera.frames}; ${samples.length} samples, ${recorded.length} records`);
  }, 300_000);

  afterAll(async () => {
    await genericBrowser?.close();
  });

  test('the video clock holds: the frames MediaPipe takes fit it', () => {
    const { residuals, drift } = videoClock(taken, generic);
    const off = residuals.map(Math.abs);
    console.log(`camera, generic hand: ${taken.length} frames taken; their phase against the clock's: median |Δ| ${median(off).toFixed(2)} s, 90th percentile ${quantile(off, 0.9).toFixed(2)} s; the fake camera fell behind by ${drift.toFixed(2)} s over the run`);
    expect(taken.length).toBeGreaterThan(50);
    // Most frames sit on the clock to a frame or two: the samples' places are as good.
    expect(median(off)).toBeLessThan(0.2);
  });

  test('every hold is judged on every sample of it, tracked, and what the engine named is reported against the 90 % target', () => {
    const report = generic.gestures.map((hold) => {
      const held = inHold(samples, hold);
      const counts = shown(held);
      const tracking = held.filter((s) => s.tracking === 'tracking').length;
      return { gesture: hold.gesture, from_s: hold.from_s, samples: held.length, tracking, named: (counts[hold.gesture] ?? 0) >= NAMED_SHARE * held.length, shown: counts };
    });
    const wrong = report.reduce((n, r) => n + Object.entries(r.shown).filter(([g]) => g !== r.gesture && g !== 'none').reduce((a, [, c]) => a + c, 0), 0);
    const all = report.reduce((n, r) => n + r.samples, 0);
    const share = report.filter((r) => r.named).length / report.length;
    const lat = latencies(samples, generic);
    console.log(`camera, generic hand: shown in each hold (from its start + ${LATENCY_S} s; samples, of them tracking, gestures shown): ${report.map((r) => `\n  ${r.gesture} at ${r.from_s} s: ${r.samples}, ${r.tracking}, ${JSON.stringify(r.shown)}${r.named ? ' named' : ''}`).join('')}\nnamed ${report.filter((r) => r.named).length}/${report.length} holds; a wrong gesture on ${wrong}/${all} samples; latency (s, the angles reaching a hold's) ${lat.map((l) => l.toFixed(1)).join(' ')}`);
    console.log(`camera, generic hand: ${(share * 100).toFixed(0)} % of holds named (target ${NAMED_HOLDS * 100} %: ${share >= NAMED_HOLDS ? 'met' : 'NOT met'})`);
    for (const r of report) expect(r.samples, `${r.gesture} at ${r.from_s} s`).toBeGreaterThanOrEqual(MIN_HOLD_SAMPLES);
    // The engine tracked the hand over the holds (one hold may be lost whole on a loaded
    // machine: records arriving late are refused).
    expect(report.reduce((n, r) => n + r.tracking, 0) / all, JSON.stringify(report.map((r) => [r.gesture, r.tracking, r.samples]))).toBeGreaterThan(0.75);
  });

  test('the retargeted angles follow the recording\'s, on every sample of every hold', () => {
    const perHold = generic.gestures.map((hold) => {
      // The hold shows one record throughout: its middle frame's.
      const angles = trueAngles.get(truth.frames[Math.floor(((hold.from_s + hold.to_s) / 2) * generic.fps)].t)!;
      const held = inHold(samples, hold).filter((s) => s.anglesDeg.length === dofs.length);
      return { gesture: hold.gesture, errors: held.flatMap((s) => dofs.filter((d) => d in angles).map((d) => Math.abs(s.anglesDeg[dofs.indexOf(d)] - angles[d]))) };
    });
    const all = perHold.flatMap((h) => h.errors);
    const summary = (e: number[]) => (e.length ? `${median(e).toFixed(1)} / ${quantile(e, 0.9).toFixed(1)}` : 'no samples');
    console.log(`camera, generic hand: retargeted angle error against the recording's (degrees, median / 90th percentile, every DOF, every sample of each hold): ${perHold.map(({ gesture, errors }) => `${gesture} ${summary(errors)}`).join(', ')}; all ${summary(all)}`);
    expect(all.length).toBeGreaterThan(100);
    expect(median(all)).toBeLessThan(GENERIC_MEDIAN_TOLERANCE_DEG);
  });

  test('MediaPipe\'s tracking error: its landmarks against the true joints, in the camera\'s frame', () => {
    // The records are in the engine's world: the camera's axes turned a half turn about z
    // (packages/dqhand/src/landmarks.ts, placeLandmarks), undone here; the translation goes in the alignment.
    const frames = recorded.filter(({ frame }) => generic.gestures.some((h) => frame >= (h.from_s + SETTLED_S) * generic.fps && frame < h.to_s * generic.fps));
    const joints = truth.frames[0].joints;
    const chain = [0, 10, 11, 12, 13, 14]; // the wrist, the middle finger's joints to its tip
    const size = chain.slice(1).reduce((s, j, i) => s + Math.hypot(...(joints[j].map((v, k) => v - joints[chain[i]][k]) as Vec)), 0);
    const groups: Record<string, number[]> = { wrist: [0], ...FINGERS, all: [...Array(21).keys()] };
    const sums = Object.fromEntries(Object.keys(groups).map((g) => [g, { xy: 0, z: 0, n: 0 }]));
    const dropped = Object.fromEntries(Object.keys(FINGERS).map((f) => [f, 0]));
    const scales: number[] = [];
    for (const { landmarks, frame } of frames) {
      const { scale, residuals } = align(
        landmarks.map(([x, y, z]) => [-x, -y, z] as Vec),
        WEBXR_INDEX.map((j) => truth.frames[frame].joints[j]),
      );
      scales.push(scale);
      for (const [g, idx] of Object.entries(groups)) {
        for (const i of idx) {
          sums[g].xy += residuals[i][0] ** 2 + residuals[i][1] ** 2;
          sums[g].z += residuals[i][2] ** 2;
          sums[g].n++;
        }
      }
      for (const [f, idx] of Object.entries(FINGERS)) if (idx.reduce((s, i) => s + Math.hypot(...residuals[i]), 0) / idx.length > DROPPED_M) dropped[f]++;
    }
    const rms = Object.fromEntries(
      Object.entries(sums).map(([g, { xy, z, n }]) => [g, { xy_mm: Number(((1000 * Math.sqrt(xy / n)) as number).toFixed(1)), z_mm: Number((1000 * Math.sqrt(z / n)).toFixed(1)), xy_share: Number((Math.sqrt(xy / n) / size).toFixed(3)), z_share: Number((Math.sqrt(z / n) / size).toFixed(3)) }]),
    );
    const droppedShare = Object.fromEntries(Object.entries(dropped).map(([f, n]) => [f, Number((n / frames.length).toFixed(3))]));
    console.log(
      `camera, generic hand: MediaPipe's landmarks against the true joints on ${frames.length} frames from ${SETTLED_S} s into a hold, each aligned by the best similarity ` +
        `(hand size: wrist to middle fingertip along the bones, ${(1000 * size).toFixed(0)} mm; MediaPipe's scale fitted ${median(scales).toFixed(2)} median, ${Math.min(...scales).toFixed(2)}–${Math.max(...scales).toFixed(2)}): ` +
        `RMS residual in the image plane (xy, per point) and in depth (z): ${JSON.stringify(rms, null, 1)}; fingers dropped (mean residual > ${DROPPED_M * 100} cm), share of frames: ${JSON.stringify(droppedShare)}`,
    );
    expect(frames.length).toBeGreaterThan(50);
    // A gross bound: landmarks matched to the wrong joints, or in other axes, are off by the hand's size.
    expect(rms.all.xy_share + rms.all.z_share).toBeLessThan(0.3);
  });
});
