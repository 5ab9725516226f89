// The engine in WebAssembly (crates/dqhand-wasm, built by `make wasm` for Node) against the
// native `dqhand skin` on the same poses: every method, positions and normals, angles inside
// and past the anatomical limits (both clamp); and its gesture loop against `dqhand replay` on
// the same recordings: the same events. Run by `make test` after the Rust tests (which
// build target/debug/dqhand).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const require = createRequire(import.meta.url);
const { GestureLoop, GraspLoop, Hand, wasmMemory } = require(path.join(root, 'target', 'wasm', 'node', 'dqhand_wasm.js'));
const dqhand = process.env.DQHAND_BIN ?? path.join(root, 'target', 'debug', 'dqhand');
const out = mkdtempSync(path.join(tmpdir(), 'dqhand-wasm-'));

/** The native command's posed mesh: `dqhand skin` writes every float in full (shortest round trip). */
function native(anglesDeg, method) {
  const pose = path.join(out, 'pose.json');
  const mesh = path.join(out, `${method}.obj`);
  writeFileSync(pose, JSON.stringify({ model: 'full', angles_deg: anglesDeg }));
  execFileSync(dqhand, ['skin', '--pose', pose, '--method', method, '--out', mesh], { stdio: ['ignore', 'ignore', 'ignore'] });
  const v = [];
  const vn = [];
  for (const line of readFileSync(mesh, 'utf8').split('\n')) {
    const [kind, ...xyz] = line.split(' ');
    if (kind === 'v') v.push(...xyz.map(Number));
    if (kind === 'vn') vn.push(...xyz.map(Number));
  }
  return { positions: Float32Array.from(v), normals: Float32Array.from(vn) };
}

/** Seeded angles in radians, some past any joint's limits (−1 to 2 rad). */
function angles(count, seed) {
  let s = seed;
  return Float32Array.from({ length: count }, () => {
    s = (s * 1103515245 + 12345) % 2147483648;
    return -1 + 3 * (s / 2147483648);
  });
}

function largestGap(a, b) {
  assert.equal(a.length, b.length);
  let worst = 0;
  for (let i = 0; i < a.length; i++) worst = Math.max(worst, Math.abs(a[i] - b[i]));
  return worst;
}

const hand = Hand.builtin(0.19, 0.085, 'right', 'full');
const names = hand.dofNames();

test('the WASM hand is the native built-in hand: its joint model, vertices and triangles', () => {
  assert.equal(hand.dofCount, 23);
  assert.equal(names.length, 23);
  assert.ok(names.includes('index-finger-phalanx-proximal.flex'), names.join(', '));
  const rest = native({}, 'dqb');
  assert.equal(hand.vertexCount * 3, rest.positions.length);
  assert.equal(hand.indices().length % 3, 0);
});

for (const method of ['lb', 'qb', 'dqb']) {
  test(`${method}: positions and normals agree with the native engine's to 1e-5 over seeded poses`, () => {
    hand.setMethod(method);
    for (const seed of [1, 2, 3]) {
      const a = angles(hand.dofCount, seed * 7919 + method.length);
      hand.step(a);
      // Views into the module's memory, no copy (taken after the step, which never grows it).
      const n = 3 * hand.vertexCount;
      const positions = new Float32Array(wasmMemory().buffer, hand.positionsPtr(), n);
      const normals = new Float32Array(wasmMemory().buffer, hand.normalsPtr(), n);
      const deg = Object.fromEntries(names.map((name, i) => [name, (a[i] * 180) / Math.PI]));
      const reference = native(deg, method);
      const moved = largestGap(positions, native({}, method).positions);
      assert.ok(moved > 0.01, `the pose moves the skin (${moved} m): the comparison is not of rest poses`);
      assert.ok(largestGap(positions, reference.positions) < 1e-5, `${method} seed ${seed}: positions ${largestGap(positions, reference.positions)} m apart`);
      assert.ok(largestGap(normals, reference.normals) < 1e-4, `${method} seed ${seed}: normals ${largestGap(normals, reference.normals)} apart`);
    }
  });
}

test('bad input is a one-line Error naming it, and the hand keeps its last pose', () => {
  hand.setMethod('dqb');
  const a = angles(hand.dofCount, 5);
  hand.step(a);
  const before = new Float32Array(wasmMemory().buffer, hand.positionsPtr(), 3 * hand.vertexCount).slice();
  assert.throws(() => hand.step(new Float32Array(5)), /^Error: angles: 5 given, the full joint model has 23$/);
  const nan = a.slice();
  nan[4] = NaN;
  assert.throws(() => hand.step(nan), /^Error: angles\[4\] \(NaN\): not a finite number$/);
  assert.throws(() => hand.setMethod('cor'), (e) => e instanceof Error && e.message.includes('cor') && !e.message.includes('\n'));
  assert.throws(() => Hand.builtin(0.19, 0.085, 'middle', 'full'), /side "middle"/);
  assert.throws(() => Hand.builtin(-1, 0.085, 'left', 'full'), (e) => e instanceof Error && !e.message.includes('\n'));
  const after = new Float32Array(wasmMemory().buffer, hand.positionsPtr(), 3 * hand.vertexCount);
  assert.equal(largestGap(before, after), 0);
});

for (const name of ['gestures-joints.jsonl', 'gestures-landmarks.jsonl']) {
  test(`the WASM gesture loop gives dqhand replay's events on ${name}, and goes on past a bad line`, () => {
    const recording = path.join(root, 'crates', 'dqhand', 'data', 'recordings', name);
    const expected = execFileSync(dqhand, ['replay', '--gestures', '--input', recording], { encoding: 'utf8', stdio: ['ignore', 'pipe', 'ignore'] });
    const lines = readFileSync(recording, 'utf8').split('\n').filter((l) => l.trim() !== '');
    const loop = new GestureLoop('right');
    let events = '';
    let refused = 0;
    lines.forEach((line, i) => {
      events += loop.push(line);
      // A broken line after every 500th: refused with one line, and the loop goes on.
      if (i % 500 === 499) {
        assert.throws(() => loop.push(line.slice(0, 40)), (e) => e instanceof Error && !e.message.includes('\n'));
        refused += 1;
      }
    });
    assert.ok(refused >= 3);
    assert.ok(expected.split('\n').length > 10, `the recording names gestures (${expected.length} bytes of events)`);
    assert.equal(events, expected);
  });
}

test('a gesture loop for a side that is none is refused', () => {
  assert.throws(() => new GestureLoop('up'), /side "up"/);
});

/** Frames of `recording` through `loop` as `dqhand grasp` makes them: every record up to a
 * frame's time goes in before the frame; frames at `rate` per second of the records' clock,
 * from the first record's time, until the records run out. */
function graspFrames(loop, recording, rate = 60) {
  const records = readFileSync(recording, 'utf8').split('\n').filter((l) => l.trim() !== '');
  const frames = [];
  let now = JSON.parse(records[0]).t;
  let next = 0;
  for (;;) {
    while (next < records.length && JSON.parse(records[next]).t <= now) loop.push(records[next++]);
    frames.push(JSON.parse(loop.step(now)));
    if (next >= records.length) return frames;
    now += 1 / rate;
  }
}

/** The largest difference between two arrays of numbers. */
const apart = (a, b) => a.reduce((m, x, i) => Math.max(m, Math.abs(x - b[i])), 0);

// The native and the WASM engine compute the same bits: the physics' arithmetic is libm's with
// no SIMD in its math (rapier's and parry's `enhanced-determinism`), and so are the engine's
// own transcendental functions (the `libm` crate, not each platform's), so every frame holds
// the same objects with the same contacts at the same places, in both WASM builds (measured:
// no difference at all over the 650 frames).
for (const dir of ['node', 'node-simd']) {
  test(`the WASM grasp loop (${dir}) gives dqhand grasp's frames on the grasp recording: holds, contacts and object poses`, () => {
    const { GraspLoop: Loop } = require(path.join(root, 'target', 'wasm', dir, 'dqhand_wasm.js'));
    const recording = path.join(root, 'crates', 'dqhand', 'data', 'recordings', 'grasp-joints.jsonl');
    const trace = path.join(out, 'grasp.jsonl');
    execFileSync(dqhand, ['grasp', '--scene', 'grasp', '--input', recording, '--trace', trace], { stdio: 'ignore' });
    const expected = readFileSync(trace, 'utf8').trim().split('\n').map((l) => JSON.parse(l));
    const frames = graspFrames(new Loop('grasp', false), recording);
    assert.equal(frames.length, expected.length);
    const held = new Set(expected.map((f) => f.held).filter((h) => h !== null));
    assert.deepEqual([...held].sort(), ['ball', 'teapot'], 'the recording grasps the ball and the teapot');
    let [contacts, worst] = [0, 0];
    frames.forEach((f, i) => {
      const e = expected[i];
      const at = `frame ${i} (t ${e.t})`;
      assert.equal(f.t, e.t, at);
      assert.equal(f.held, e.held, at);
      assert.equal(f.tracking, e.tracking, at);
      assert.deepEqual(f.contacts.map((c) => `${c.bone} ${c.object}`), e.contacts.map((c) => `${c.bone} ${c.object}`), at);
      f.contacts.forEach((c, k) => {
        worst = Math.max(worst, apart(c.p, e.contacts[k].p), apart(c.n, e.contacts[k].n));
        contacts += 1;
      });
      for (const [name, pose] of Object.entries(e.objects)) {
        worst = Math.max(worst, apart(f.objects[name].p, pose.p), apart(f.objects[name].q, pose.q));
      }
    });
    assert.ok(contacts > 1000, `${contacts} contacts compared`);
    assert.ok(worst < 1e-6, `contacts and poses ${worst} apart`);
  });
}

test('a grasp loop in a scene that is not built in is refused, and a broken record is one line', () => {
  assert.throws(() => new GraspLoop('kitchen', false), (e) => e instanceof Error && e.message.includes('kitchen') && !e.message.includes('\n'));
  const loop = new GraspLoop('objects', true);
  assert.throws(() => loop.push('{"t": 0, "joints": '), (e) => e instanceof Error && !e.message.includes('\n'));
  assert.equal(JSON.parse(loop.step(0)).held.left, null);
});
