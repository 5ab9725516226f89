// The page on `dqhand demo`, its engine in WebAssembly following the live input the server
// relays (crates/dqhand-cli/src/server/relay_socket.rs): what a browser cannot reach itself
// drives the page's engine: a glove recording the server plays (read with the server's glove
// table), another device's records on `/input`, a scene's scripted grasps of both hands; the
// page's Record writes the server's input to its disk, and `dqhand replay` reads it back. A
// scene file (its meshes are the server's files) falls back to the server's stream.

import { execFileSync, spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { afterAll, beforeAll, describe, expect, test } from 'vitest';
import type { Browser, Page } from 'playwright-core';
import { dqhandBin, launchBrowser, newPage, root, startServer, waitState } from '../scripts/harness.mjs';

type Server = Awaited<ReturnType<typeof startServer>>;

interface State {
  engine: string;
  relay: { open: boolean; received: number } | null;
  connected: boolean;
  framesReceived: number;
  errors: string[];
  input: { source: string; gestures: string[]; tracking: string; gesture: string | null; accepted: number; rejected: number; log: string[] } | null;
  scene: { held: string | null } | null;
  secondHand: { side: string; wrist: number[] | null } | null;
  recordings: { on: boolean; path: string | null; records: number; failed: boolean }[];
  frame: { anglesDeg: number[] } | null;
}
const stateOf = (p: Page): Promise<State> => p.evaluate(() => (window as unknown as { dqhand: { state(): State } }).dqhand.state());

let browser: Browser;
let dir = '';

beforeAll(async () => {
  browser = await launchBrowser();
  dir = mkdtempSync(path.join(tmpdir(), 'dqhand-relay-'));
});

afterAll(async () => {
  await browser?.close();
  if (dir) rmSync(dir, { recursive: true, force: true });
});

/** A `dqhand demo` with `args` and a page on it, for one describe block. */
function demoPage(args: () => string[], opened: (p: Page, s: Server) => void, query = ''): void {
  let server: Server | null = null;
  let page: Page | null = null;
  beforeAll(async () => {
    server = await startServer({ args: args() });
    page = await newPage(browser);
    opened(page, server);
    await page.goto(server.url + query);
  });
  afterAll(async () => {
    await page?.close();
    await server?.stop();
  });
}

describe('a glove recording the server plays', () => {
  let p: Page;
  let labels: string[] = [];
  demoPage(
    () => {
      // A labelled glove recording (5DT 14-sensor CSV): values only the server's glove table names.
      const csv = path.join(dir, 'glove.csv');
      execFileSync(dqhandBin(), ['synthesize', '--format', 'glove', '--seed', '5', '--out', csv]);
      labels = (JSON.parse(readFileSync(csv.replace(/\.csv$/, '.labels.json'), 'utf8')) as { holds: { gesture: string }[] }).holds.map((h) => h.gesture);
      return ['--input', csv];
    },
    (page) => (p = page),
  );

  test('drives the engine in the page, which names the recording\'s gestures', async () => {
    await waitState(p, 's.relay !== null && s.relay.open && s.framesReceived > 3 && s.input !== null', 90_000);
    const s = await stateOf(p);
    expect(s.engine).toBe('page');
    expect(await p.locator('#input-source').textContent()).toMatch(/glove\.csv, relayed by dqhand demo$/);
    expect(await p.locator('#status').textContent()).toBe('engine in this page, following dqhand demo');
    // Three gestures started by the page's engine, every one of them held in the recording.
    await waitState(p, 'new Set(s.input.log.filter((l) => l.includes(" start ")).map((l) => l.split(" ").at(-1))).size >= 3', 60_000);
    const after = await stateOf(p);
    const started = new Set(after.input!.log.filter((l) => l.includes(' start ')).map((l) => l.split(' ').at(-1)!));
    for (const g of started) expect(labels).toContain(g);
    expect(after.relay!.received).toBeGreaterThan(100);
    expect(after.input!.accepted).toBeGreaterThan(100);
    expect(after.frame!.anglesDeg.some((a) => Math.abs(a) > 10)).toBe(true);
    expect(after.errors).toEqual([]);
  });
});

describe('another device on /input, and Record', () => {
  let p: Page;
  const recordings = () => path.join(dir, 'recordings');
  demoPage(() => ['--recordings', recordings(), '--config', writeConfig()], (page) => (p = page));

  /** Generous grace and latency: a stalled thread on a loaded machine is not a dropout here. */
  function writeConfig(): string {
    const file = path.join(dir, 'config.json');
    writeFileSync(file, JSON.stringify({ grace_s: 5.0, max_latency_s: 5.0 }));
    return file;
  }

  test('the device\'s records drive the page\'s engine, and Record writes them to the server\'s disk for replay', async () => {
    await waitState(p, 's.relay !== null && s.relay.open && s.framesReceived > 3', 90_000);
    expect((await stateOf(p)).input).toBeNull(); // no input until a record comes
    await p.click('#record');
    await waitState(p, 's.recordings.some((r) => r.on)');
    // The device: a WebSocket on /input (here opened in another page) sending a recording of joints.
    const lines = readFileSync(path.join(root, 'crates/dqhand/data/recordings/gestures-joints.jsonl'), 'utf8').split('\n').filter(Boolean).slice(0, 600);
    const device = await newPage(browser);
    await device.goto(new URL('/engine.json', p.url()).href);
    await device.evaluate(
      async (lines) => {
        const ws = new WebSocket(`ws://${location.host}/input`);
        await new Promise((r) => (ws.onopen = r));
        for (const line of lines) {
          ws.send(line);
          await new Promise((r) => setTimeout(r, 4));
        }
        ws.close();
      },
      lines,
    );
    await device.close();
    await waitState(p, `s.input !== null && s.input.accepted === ${lines.length} && s.relay.received === ${lines.length}`, 60_000);
    const s = await stateOf(p);
    expect(s.input!.source).toMatch(/relayed by dqhand demo$/);
    expect(s.input!.log.some((l) => l.includes(' start '))).toBe(true);
    await p.click('#record');
    await waitState(p, 's.recordings.length >= 2 && !s.recordings.at(-1).on');
    const saved = (await stateOf(p)).recordings.at(-1)!;
    expect(saved.records).toBe(lines.length);
    expect(path.dirname(saved.path!)).toBe(recordings());
    expect(readFileSync(saved.path!, 'utf8').split('\n').filter(Boolean)).toHaveLength(lines.length);
    // Replayed under the live input's config: a replay judges lateness by the recorded arrivals.
    const replay = spawnSync(dqhandBin(), ['replay', '--input', saved.path!, '--config', path.join(dir, 'config.json')], { encoding: 'utf8' });
    expect(replay.status).toBe(0);
    expect(replay.stderr).toContain(`${lines.length} records, ${lines.length} taken`);
    expect(s.errors).toEqual([]);
  });
});

describe('a scene of two hands', () => {
  let p: Page;
  // No input: the demo plays its scripted carry of the box by both hands and its hand-over.
  demoPage(() => ['--scene', 'two-hands'], (page) => (p = page));

  test('the page\'s engine drives both hands among the objects and grasps', async () => {
    await waitState(p, 's.relay !== null && s.relay.open && s.secondHand !== null && s.scene !== null', 120_000);
    expect((await stateOf(p)).secondHand!.side).toBe('left');
    await waitState(p, 's.scene.held !== null && s.secondHand.wrist !== null', 120_000);
    const s = await stateOf(p);
    expect(s.engine).toBe('page');
    expect(s.errors).toEqual([]);
  });
});

describe('a scene file', () => {
  let p: Page;
  demoPage(
    () => {
      const scene = path.join(dir, 'scene.json');
      writeFileSync(scene, JSON.stringify({ objects: [{ name: 'ball', shape: 'sphere', radius: 0.04, position: [0, 0.05, -0.3], mass: 0.15 }] }));
      return ['--scene', scene];
    },
    (page) => (p = page),
  );

  test('is the server\'s to run: the page shows its stream', async () => {
    await waitState(p, 's.connected && s.framesReceived > 3 && s.scene !== null', 90_000);
    const s = await stateOf(p);
    expect([s.engine, s.relay]).toEqual(['server', null]);
  });
});
