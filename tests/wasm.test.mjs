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
const { GestureLoop, Hand, wasmMemory } = require(path.join(root, 'target', 'wasm', 'node', 'dqhand_wasm.js'));
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
