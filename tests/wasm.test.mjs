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
const { Hand, Interaction, LocalStream, wasmMemory } = require(path.join(root, 'target', 'wasm', 'node', 'dqhand_wasm.js'));
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

for (const method of ['lb', 'qb', 'dqb', 'cor']) {
  test(`${method}: positions and normals agree with the native engine's to 1e-5 over seeded poses`, () => {
    hand.setMethod(method);
    for (const seed of [1, 2, 3]) {
      const a = angles(hand.dofCount, seed * 7919 + method.length);
      // Unrelated poses, as `dqhand skin` deforms each (else a pair of bones that moved less
      // than 60° since the last pose keeps its sign, as frames of one motion do).
      hand.forgetPreviousFrame();
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
  assert.throws(() => hand.setMethod('blend'), (e) => e instanceof Error && e.message.includes('blend') && !e.message.includes('\n'));
  assert.throws(() => Hand.builtin(0.19, 0.085, 'middle', 'full'), /side "middle"/);
  assert.throws(() => Hand.builtin(-1, 0.085, 'left', 'full'), (e) => e instanceof Error && !e.message.includes('\n'));
  const after = new Float32Array(wasmMemory().buffer, hand.positionsPtr(), 3 * hand.vertexCount);
  assert.equal(largestGap(before, after), 0);
});

/** Every non-blank line of the built-in recording `name`. */
const recordingLines = (name) => readFileSync(path.join(root, 'crates', 'dqhand', 'data', 'recordings', name), 'utf8').split('\n').filter((l) => l.trim() !== '');

for (const name of ['gestures-joints.jsonl', 'gestures-landmarks.jsonl']) {
  test(`the WASM interaction gives dqhand replay's gesture events on ${name}, and goes on past a bad line`, () => {
    const recording = path.join(root, 'crates', 'dqhand', 'data', 'recordings', name);
    const expected = execFileSync(dqhand, ['replay', '--gestures', '--input', recording], { encoding: 'utf8', stdio: ['ignore', 'pipe', 'ignore'] });
    const interaction = new Interaction('right', '');
    let events = '';
    let refused = 0;
    recordingLines(name).forEach((line, i) => {
      interaction.pushLine(line);
      if (interaction.step(JSON.parse(line).t) > 0) events += interaction.takeEvents();
      // A broken line after every 500th: refused with one line, and the loop goes on.
      if (i % 500 === 499) {
        assert.throws(() => interaction.pushLine(line.slice(0, 40)), (e) => e instanceof Error && !e.message.includes('\n'));
        refused += 1;
      }
    });
    assert.ok(refused >= 3);
    assert.deepEqual(Array.from(interaction.counts()), [recordingLines(name).length, refused]);
    assert.ok(expected.split('\n').length > 10, `the recording names gestures (${expected.length} bytes of events)`);
    // The same events, each naming its hand.
    const named = expected.trim().split('\n').map((l) => ({ ...JSON.parse(l), hand: 'right' }));
    assert.deepEqual(events.trim().split('\n').map((l) => JSON.parse(l)), named);
  });
}

/** WebXR's hand joints in `XRHand`'s order. */
const FINGERS = ['index-finger', 'middle-finger', 'ring-finger', 'pinky-finger'].flatMap((f) => ['metacarpal', 'phalanx-proximal', 'phalanx-intermediate', 'phalanx-distal', 'tip'].map((b) => `${f}-${b}`));
const XR_JOINTS = ['wrist', 'thumb-metacarpal', 'thumb-phalanx-proximal', 'thumb-phalanx-distal', 'thumb-tip', ...FINGERS];

/** A WebXR joint (`{p, q}`) as the 4 × 4 column-major matrix `XRFrame.fillPoses` writes. */
function jointMatrix({ p, q }, out, at) {
  const [x, y, z, w] = q;
  const m = [
    1 - 2 * (y * y + z * z), 2 * (x * y + z * w), 2 * (x * z - y * w), 0,
    2 * (x * y - z * w), 1 - 2 * (x * x + z * z), 2 * (y * z + x * w), 0,
    2 * (x * z + y * w), 2 * (y * z - x * w), 1 - 2 * (x * x + y * y), 0,
    p[0], p[1], p[2], 1,
  ];
  out.set(m, at);
}

test('joints given as fillPoses matrices drive the hand as the same joints in JSON lines, and the skin is read in place with no memory growth', () => {
  const lines = recordingLines('gestures-joints.jsonl').slice(0, 600);
  const [json, arrays] = [new Interaction('right', ''), new Interaction('right', '')];
  const [matrices, radii] = [new Float32Array(25 * 16), new Float32Array(25)];
  const view = (it) => new Float32Array(wasmMemory().buffer, it.positionsPtr(0), 3 * it.vertexCount(0));
  let [eventsJson, eventsArrays, worst, buffer] = ['', '', 0, null];
  lines.forEach((line, i) => {
    const record = JSON.parse(line);
    const joints = XR_JOINTS.map((name) => record.joints[name]);
    joints.forEach((j, k) => {
      jointMatrix(j, matrices, 16 * k);
      radii[k] = j.r ?? 0;
    });
    json.pushLine(line);
    arrays.pushJoints(record.hand ?? 'right', record.t, matrices, radii);
    if (json.step(record.t) > 0) eventsJson += json.takeEvents();
    if (arrays.step(record.t) > 0) eventsArrays += arrays.takeEvents();
    worst = Math.max(worst, largestGap(view(json), view(arrays)));
    // After the first frames, stepping allocates nothing: the memory (and every view of it) stays.
    if (i === 10) buffer = wasmMemory().buffer;
    if (i > 10) assert.equal(wasmMemory().buffer, buffer, `frame ${i}: the module's memory grew`);
  });
  assert.ok(eventsJson.length > 0, 'the first 600 records name gestures');
  // The same events; their times may differ in the last bit (serde_json reads a decimal to the
  // nearest double or one next to it, the array path takes the page's double as it is).
  const parse = (events) => events.trim().split('\n').map((l) => JSON.parse(l));
  const [a, j] = [parse(eventsArrays), parse(eventsJson)];
  assert.deepEqual(a.map(({ t, ...e }) => e), j.map(({ t, ...e }) => e));
  a.forEach((e, i) => assert.ok(Math.abs(e.t - j[i].t) < 1e-12, `event ${i}: t ${e.t} and ${j[i].t}`));
  // Quaternion to matrix and back rounds in the last bits of float32.
  assert.ok(worst < 1e-5, `skins ${worst} m apart`);
  // The skin is in the world where the tracked hand is: a vertex within 3 cm of its middle fingertip.
  const skin = view(arrays);
  const tip = JSON.parse(lines.at(-1)).joints['middle-finger-tip'].p;
  let nearest = Infinity;
  for (let i = 0; i < skin.length; i += 3) nearest = Math.min(nearest, Math.hypot(skin[i] - tip[0], skin[i + 1] - tip[1], skin[i + 2] - tip[2]));
  assert.ok(nearest < 0.03, `the skin's nearest vertex is ${nearest} m from the tracked middle fingertip`);
});

test('bad typed arrays are refused with one line naming the problem, and the hand goes on', () => {
  const it = new Interaction('left', '');
  assert.equal(it.side(0), 'left');
  assert.throws(() => it.pushJoints('left', 0, new Float32Array(24 * 16), new Float32Array(0)), /joint matrices: 384 floats, 25 joints need 400/);
  assert.throws(() => it.pushLandmarks('left', 0, new Float32Array(63).fill(NaN)), /landmark 0: position/);
  assert.throws(() => it.pushLandmarks('middle', 0, new Float32Array(63)), /side "middle"/);
  assert.deepEqual(Array.from(it.counts()), [0, 2]);
  assert.equal(it.step(0.1), 0);
  assert.equal(it.tracking(0), 'waiting');
  assert.throws(() => new Interaction('three', ''), /hands "three"/);
  assert.throws(() => new Interaction('both', '{"objects": [{"name": "x", "shape": "cone"}]}'), (e) => e instanceof Error && !e.message.includes('\n'));
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
    while (next < records.length && JSON.parse(records[next]).t <= now) loop.pushLine(records[next++]);
    loop.step(now);
    frames.push(JSON.parse(loop.trace(now)));
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
    const { Interaction: Loop } = require(path.join(root, 'target', 'wasm', dir, 'dqhand_wasm.js'));
    const recording = path.join(root, 'crates', 'dqhand', 'data', 'recordings', 'grasp-joints.jsonl');
    const trace = path.join(out, 'grasp.jsonl');
    // Gestures on, as in the page: the scene's gesture commands (an open palm held resets it) act.
    execFileSync(dqhand, ['grasp', '--gestures', '--scene', 'grasp', '--input', recording, '--trace', trace], { stdio: 'ignore' });
    const expected = readFileSync(trace, 'utf8').trim().split('\n').map((l) => JSON.parse(l));
    const frames = graspFrames(new Loop('right', 'grasp'), recording);
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

test('an interaction in a scene that is not built in is refused, and a broken record is one line', () => {
  assert.throws(() => new Interaction('both', 'kitchen'), (e) => e instanceof Error && e.message.includes('kitchen') && !e.message.includes('\n'));
  const loop = new Interaction('both', 'objects');
  assert.deepEqual([loop.handCount, loop.side(0), loop.side(1)], [2, 'left', 'right']);
  assert.throws(() => loop.pushLine('{"t": 0, "joints": '), (e) => e instanceof Error && !e.message.includes('\n'));
  loop.step(0);
  assert.equal(JSON.parse(loop.trace(0)).held.left, null);
  assert.deepEqual([loop.held(0), loop.held(1)], [-1, -1]);
  const scene = JSON.parse(loop.scene());
  assert.equal(scene.objects.length, loop.objectCount);
  const poses = new Float32Array(wasmMemory().buffer, loop.posesPtr(), 7 * loop.objectCount);
  const trace = JSON.parse(loop.trace(0));
  scene.objects.forEach((o, i) => assert.deepEqual(Array.from(poses.slice(7 * i, 7 * i + 3)), trace.objects[o.name].p.map(Math.fround)));
});

/** Every event line of `interaction` over `lines`, and its skin `k` after the last. */
function drive(interaction, lines, k = 0) {
  let events = '';
  for (const line of lines) {
    interaction.pushLine(line);
    if (interaction.step(JSON.parse(line).t) > 0) events += interaction.takeEvents();
  }
  return { events, skin: new Float32Array(wasmMemory().buffer, interaction.positionsPtr(k), 3 * interaction.vertexCount(k)).slice() };
}

/** The skin's vertex nearest to `p`, its distance. */
function nearestVertex(skin, p) {
  let nearest = Infinity;
  for (let i = 0; i < skin.length; i += 3) nearest = Math.min(nearest, Math.hypot(skin[i] - p[0], skin[i + 1] - p[1], skin[i + 2] - p[2]));
  return nearest;
}

test('hands loaded from skinned glTF: the native command\'s file is the hand the engine generates, and the WebXR generic hands work', () => {
  const lines = recordingLines('gestures-joints.jsonl').slice(0, 900);
  const files = Object.fromEntries(['right', 'left'].map((side) => {
    const file = path.join(out, `${side}.glb`);
    execFileSync(dqhand, ['hand', '--side', side, '--out', file], { stdio: 'ignore' });
    return [side, readFileSync(file)];
  }));
  // The file `dqhand hand --out` writes drives as the hand the WASM engine builds itself.
  const generated = drive(new Interaction('right', ''), lines);
  const loaded = drive(Interaction.withModels('', files.right, undefined), lines);
  assert.ok(generated.events.split('\n').length > 6, 'the records name gestures');
  assert.equal(loaded.events, generated.events);
  assert.ok(largestGap(loaded.skin, generated.skin) < 1e-5, `skins ${largestGap(loaded.skin, generated.skin)} m apart`);
  const two = Interaction.withModels('two-hands', files.right, files.left);
  assert.deepEqual([two.handCount, two.side(0), two.side(1)], [2, 'left', 'right']);

  // Hands the project did not make: the WebXR input profiles' generic hands (1360 vertices),
  // both at once; the right one follows the records and names their gestures.
  const generic = path.join(root, 'third_party', 'node_modules', '@webxr-input-profiles', 'assets', 'dist', 'profiles', 'generic-hand');
  const [right, left] = ['right', 'left'].map((side) => readFileSync(path.join(generic, `${side}.glb`)));
  const xr = Interaction.withModels('', right, left);
  assert.deepEqual([xr.side(0), xr.side(1), xr.vertexCount(1)], ['left', 'right', 1360]);
  const driven = drive(xr, lines, 1);
  assert.equal(xr.tracking(1), 'tracking');
  const tip = JSON.parse(lines.at(-1)).joints['middle-finger-tip'].p;
  assert.ok(nearestVertex(driven.skin, tip) < 0.01, `the generic hand's skin is ${nearestVertex(driven.skin, tip)} m from the tracked middle fingertip`);
  const names = (events) => events.trim().split('\n').map((l) => JSON.parse(l)).filter((e) => e.event === 'start').map((e) => e.gesture);
  assert.deepEqual(names(driven.events), names(generated.events));

  // Wrong files: one line naming the file, whichever is wrong.
  const oneLine = (start) => (e) => e instanceof Error && e.message.startsWith(start) && !e.message.includes('\n');
  assert.throws(() => Interaction.withModels('', files.left, undefined), oneLine('right model: the file holds a left hand'));
  assert.throws(() => Interaction.withModels('', files.right, files.right), oneLine('left model: the file holds a right hand'));
  assert.throws(() => Interaction.withModels('', files.right, new Uint8Array([0x67, 0x6c, 0x54, 0x46, 2, 0, 0, 0])), oneLine('left model: '));
  assert.throws(() => Interaction.withModels('', files.right.subarray(0, 1000), undefined), oneLine('right model: '));
  assert.throws(() => Interaction.withModels('', undefined, undefined), oneLine('withModels: no model given'));

  // The viewer's engine takes the same files (as hands/right.glb and hands/left.glb), and an
  // input configuration as JSON text.
  const page = new LocalStream('two-hands', true, files.right, files.left, '{"grace_s": 1.5}');
  const hello = JSON.parse(page.hello());
  assert.match(hello.description, /^anatomical right hand, .*\(glTF file right\.glb\)$/);
  assert.match(hello.second_hand.description, /^anatomical left hand, .*\(glTF file left\.glb\)$/);
  page.free();
  assert.throws(() => new LocalStream('', false, files.right, undefined, '{"grace_s": -1}'), oneLine('input configuration: grace_s: must be a positive number of seconds'));
  assert.throws(() => new LocalStream('', false, new Uint8Array(12), undefined, undefined), oneLine('hands/right.glb: '));
  assert.throws(() => new LocalStream('two-hands', true, files.left, files.right, undefined), oneLine('hands/right.glb: the file holds a left hand'));
});

test('the viewer\'s engine from dqhand demo\'s settings: its glove, joint model, input and gestures; bad settings are one line', () => {
  const oneLine = (start) => (e) => e instanceof Error && e.message.startsWith(start) && !e.message.includes('\n');
  const defaults = JSON.parse(LocalStream.defaultSettings());
  assert.deepEqual([defaults.hands, defaults.scene, defaults.glove, defaults.joint_model, defaults.calibration], [1, null, '5dt-14', 'full', null]);
  // A glove table given as a file's text (here the 5-sensor 5DT's), as `demo --glove FILE` sends it.
  const table = JSON.parse(readFileSync(path.join(root, 'crates', 'dqhand', 'data', 'gloves', '5dt-5.json'), 'utf8'));
  const sensors = table.sensors.map((s) => s.name);
  const settings = { ...defaults, glove: JSON.stringify(table), joint_model: 'paper', source: 'udp 127.0.0.1:9000', announce: true };
  const page = LocalStream.fromSettings(JSON.stringify(settings), undefined, undefined);
  const hello = JSON.parse(page.hello());
  assert.equal(hello.joint_model, 'paper');
  assert.equal(hello.input.source, 'udp 127.0.0.1:9000, relayed by dqhand demo', 'announced from the start, named as the demo names it');
  // A fist on the glove, its values named by the table's sensors, is taken and bends the fingers.
  const glove = (value) => Object.fromEntries(sensors.map((s) => [s, value]));
  const inputs = [];
  for (let k = 0; k < 90; k++) {
    page.push(JSON.stringify({ t: k / 60, hand: 'right', glove: glove(k < 10 ? 0 : 4095) }));
    page.step(1 / 60);
    inputs.push(...page.takeTexts().map((t) => JSON.parse(t)).filter((m) => m.type === 'input'));
  }
  assert.ok(inputs.at(-1).accepted > 0 && inputs.every((m) => m.rejected === 0), 'taken, none refused');
  assert.ok(inputs.some((m) => m.gesture === 'fist'), `the glove's fist is named: ${JSON.stringify(inputs.map((m) => m.gesture))}`);
  assert.throws(() => page.push(JSON.stringify({ t: 0.02, hand: 'right', glove: { thumb_far: 1 } })), oneLine('glove: unknown sensor "thumb_far"'));
  // The gestures the demo relays after it learns one.
  page.setGestures(defaults.gestures);
  assert.throws(() => page.setGestures('{'), oneLine('the relayed gestures'));
  page.free();
  assert.throws(() => LocalStream.fromSettings('{"hands": 1}', undefined, undefined), oneLine('engine settings: missing field'));
  assert.throws(() => LocalStream.fromSettings(JSON.stringify({ ...defaults, hands: 3 }), undefined, undefined), oneLine('engine settings: hands: 3 is neither 1 nor 2'));
  assert.throws(() => LocalStream.fromSettings(JSON.stringify({ ...defaults, joint_model: 'elbow' }), undefined, undefined), oneLine('engine settings: joint_model: '));
  assert.throws(() => LocalStream.fromSettings(JSON.stringify({ ...defaults, glove: 'mitten-3' }), undefined, undefined), (e) => e instanceof Error && e.message.includes('mitten-3') && !e.message.includes('\n'));
  assert.throws(() => LocalStream.fromSettings(JSON.stringify({ ...defaults, hands: 2 }), undefined, undefined), oneLine('two hands: only a scene drives two'));
});
