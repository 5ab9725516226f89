// The npm package `dqhand` (packages/dqhand, built by `make package`) in Node: the engine
// loaded from the package's own files, hands driven by a recording, the three.js meshes fed in
// place from the engine's memory, scenes with objects added and grasped, and its bad input.
// The browser and the example app built from the tarball: viewer/tests/package.test.ts.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const pkg = path.join(root, 'packages', 'dqhand');
const { loadEngine, HandMesh, SceneObjects, simdSupported } = await import(path.join(pkg, 'dist', 'index.js'));
const recording = (name) => readFileSync(path.join(root, 'crates', 'dqhand', 'data', 'recordings', name), 'utf8').split('\n').filter((l) => l.trim() !== '');

const engine = await loadEngine({ module: readFileSync(path.join(pkg, 'wasm', simdSupported() ? 'dqhand_wasm_simd_bg.wasm' : 'dqhand_wasm_bg.wasm')) });

test('the package ships both builds with one glue module, and Node 20 loads the SIMD one', () => {
  assert.equal(engine.simd, true);
  const manifest = JSON.parse(readFileSync(path.join(pkg, 'package.json'), 'utf8'));
  assert.deepEqual(Object.keys(manifest.peerDependencies), ['three']);
  assert.equal(manifest.dependencies, undefined, 'nothing but three, as a peer');
});

test('a hand mesh follows a recording through its own attributes: the engine\'s skin, copied in place, bounds included', () => {
  const hands = engine.hands({ hands: 'right' });
  const mesh = new HandMesh(hands);
  const position = mesh.geometry.attributes.position;
  const arrays = [position.array, mesh.geometry.attributes.normal.array];
  let events = 0;
  let centre = null;
  const views = new Set();
  for (const line of recording('gestures-joints.jsonl').slice(0, 400)) {
    hands.pushLine(line);
    events += hands.step(JSON.parse(line).t).length;
    mesh.update();
    const [positions, normals] = [hands.positions(0), hands.normals(0)];
    assert.deepEqual(mesh.geometry.attributes.position.array, positions);
    assert.deepEqual(mesh.geometry.attributes.normal.array, normals);
    views.add(positions).add(normals);
    centre = mesh.geometry.boundingSphere.center.clone();
  }
  // The same two views of the engine's memory every frame: made again only when that memory
  // grows, which it does not once the hands run.
  assert.equal(views.size, 2);
  // The attributes keep their arrays (three.js uploads them again; nothing new per frame).
  assert.equal(mesh.geometry.attributes.position.array, arrays[0]);
  assert.equal(mesh.geometry.attributes.normal.array, arrays[1]);
  assert.ok(events > 0, 'the first 400 records of the gesture recording name gestures');
  assert.equal(hands.tracking(0), 'tracking');
  // Where the recording's hand is: its wrist.
  const wrist = JSON.parse(recording('gestures-joints.jsonl')[399]).joints.wrist.p;
  assert.ok(centre.distanceTo({ x: wrist[0], y: wrist[1], z: wrist[2] }) < 0.15, `the bounding sphere's centre ${centre.toArray()} is by the wrist ${wrist}`);
  mesh.dispose();
  hands.dispose();
});

test('a posed hand takes angles by name, and another method changes the skin', () => {
  const hand = engine.posedHand({ side: 'left', jointModel: 'paper' });
  const names = hand.dofNames();
  assert.equal(names.length, 18);
  const mesh = new HandMesh(hand);
  const rest = Float32Array.from(mesh.geometry.attributes.position.array);
  const angles = new Float32Array(names.length);
  angles[names.indexOf('index-finger-phalanx-proximal.flex')] = 1.4;
  hand.setAngles(angles);
  mesh.update();
  const bent = Float32Array.from(mesh.geometry.attributes.position.array);
  assert.notDeepEqual(bent, rest);
  hand.setMethod('lb');
  mesh.update();
  assert.notDeepEqual(Float32Array.from(mesh.geometry.attributes.position.array), bent, 'LB and DQB differ on a bent finger');
  assert.throws(() => hand.setAngles(new Float32Array(3)), /angles: 3 given, the paper joint model has 18/);
  hand.dispose();
});

test('a scene of objects drawn where the engine has them: an object added falls onto the table, and the others stay where they are', () => {
  const scene = {
    table: { height: 0.75 },
    objects: [{ name: 'ball', shape: 'sphere', radius: 0.04, position: [0.1, 0.79, -0.3], mass: 0.15 }],
  };
  const hands = engine.hands({ hands: 'right', scene });
  const objects = new SceneObjects(hands);
  assert.deepEqual(objects.children.map((c) => c.name), ['table', 'ball']);
  for (let t = 0; t < 1; t += 1 / 60) hands.step(t);
  objects.update();
  const ball = objects.getObjectByName('ball');
  assert.ok(Math.abs(ball.position.y - 0.79) < 0.002, `the ball rests on the table (y ${ball.position.y})`);
  // A box dropped beside it: the ball stays where it rolled to.
  const before = ball.position.clone();
  hands.addObject({ name: 'box', shape: 'box', size: [0.05, 0.05, 0.05], position: [-0.1, 0.9, -0.3], mass: 0.1 });
  const more = new SceneObjects(hands);
  assert.deepEqual(hands.objects().map((o) => o.name), ['ball', 'box']);
  for (let t = 1; t < 2; t += 1 / 60) hands.step(t);
  more.update();
  assert.ok(more.getObjectByName('ball').position.distanceTo(before) < 0.002);
  assert.ok(Math.abs(more.getObjectByName('box').position.y - 0.775) < 0.003, `the box fell onto the table (y ${more.getObjectByName('box').position.y})`);
  assert.throws(() => hands.addObject({ name: 'ball', shape: 'sphere', radius: 0.02, position: [0, 1, 0], mass: 0.1 }), /ball/);
  hands.dispose();
});

test('the grasp recording grasps the built-in scene\'s ball and teapot, as events and as held objects', () => {
  const hands = engine.hands({ scene: 'grasp' });
  const grasped = new Set();
  let held = 0;
  const lines = recording('grasp-joints.jsonl');
  let now = JSON.parse(lines[0]).t;
  let next = 0;
  while (next < lines.length) {
    while (next < lines.length && JSON.parse(lines[next]).t <= now) hands.pushLine(lines[next++]);
    for (const e of hands.step(now)) if (e.event === 'grasp') grasped.add(e.object);
    if (hands.held(0) !== null) held++;
    now += 1 / 60;
  }
  assert.deepEqual([...grasped].sort(), ['ball', 'teapot']);
  assert.ok(held > 60, `${held} frames held`);
  assert.throws(() => hands.addObject({ name: 'cube', shape: 'box', size: [0.05, 0.05, 0.05], position: [0, 1, 0], mass: 0.1 }), /built-in "grasp"/);
  hands.dispose();
});

test('bad options and records are one-line errors, and the hands go on', () => {
  assert.throws(() => engine.hands({ hands: 'middle' }), (e) => e instanceof Error && /hands "middle"/.test(e.message) && !e.message.includes('\n'));
  assert.throws(() => engine.hands({ scene: { objects: [{ name: 'x', shape: 'cone', position: [0, 0, 0], mass: 1 }] } }), (e) => e instanceof Error && !e.message.includes('\n'));
  const hands = engine.hands({ hands: 'both' });
  assert.deepEqual([hands.count, hands.side(0), hands.side(1), hands.handOf('right')], [2, 'left', 'right', 1]);
  assert.throws(() => hands.pushLine('{"t": 0, "joints": '), (e) => !e.message.includes('\n'));
  assert.throws(() => hands.pushLandmarks('left', 0, new Float32Array(10)), /landmarks: 10 floats/);
  assert.deepEqual(hands.counts(), { accepted: 0, refused: 2 });
  assert.equal(hands.pushMediaPipe({}, 0, 4 / 3), 0);
  assert.equal(hands.step(0.1).length, 0);
  hands.dispose();
});

test('hands from skinned glTF files: the WebXR generic hands (made elsewhere) follow a recording in a scene, and fetchModel names a bad URL', async () => {
  const generic = path.join(root, 'third_party', 'node_modules', '@webxr-input-profiles', 'assets', 'dist', 'profiles', 'generic-hand');
  const [right, left] = ['right', 'left'].map((side) => readFileSync(path.join(generic, `${side}.glb`)));
  // An ArrayBuffer and a Uint8Array (a Node Buffer) both do.
  const hands = engine.hands({ scene: 'objects', models: { right: right.buffer.slice(right.byteOffset, right.byteOffset + right.byteLength), left } });
  assert.deepEqual([hands.count, hands.side(0), hands.side(1), hands.vertexCount(1)], [2, 'left', 'right', 1360]);
  const mesh = new HandMesh(hands, 1);
  const lines = recording('gestures-joints.jsonl').slice(0, 300);
  for (const line of lines) {
    hands.pushLine(line);
    hands.step(JSON.parse(line).t);
    mesh.update();
  }
  assert.equal(hands.tracking(1), 'tracking');
  const wrist = JSON.parse(lines.at(-1)).joints.wrist.p;
  const centre = mesh.geometry.boundingSphere.center;
  assert.ok(Math.hypot(centre.x - wrist[0], centre.y - wrist[1], centre.z - wrist[2]) < 0.15, 'the generic hand is where the tracked one is');
  hands.dispose();
  // The sides given are the hands: asking for others, or giving a hand as the wrong side, is one line.
  assert.throws(() => engine.hands({ hands: 'left', models: { right } }), /^Error: models: right given for hands "left"$/);
  assert.throws(() => engine.hands({ models: { right: left } }), (e) => e.message === 'right model: the file holds a left hand, given as the right one');
  const { fetchModel } = await import(path.join(pkg, 'dist', 'index.js'));
  await assert.rejects(fetchModel('http://127.0.0.1:9/none.glb'), (e) => e.message.startsWith('http://127.0.0.1:9/none.glb: ') && !e.message.includes('\n'));
  // A server that answers, but not with the file: its status, naming the URL.
  const { createServer } = await import('node:http');
  const server = createServer((_, res) => res.writeHead(404, 'Not Found').end());
  await new Promise((done) => server.listen(0, '127.0.0.1', done));
  const url = `http://127.0.0.1:${server.address().port}/hands/right.glb`;
  await assert.rejects(fetchModel(url), (e) => e.message === `${url}: HTTP 404 Not Found`);
  server.close();
});

test('a lone hand whose MediaPipe label flickers keeps its side; a label that holds for 5 frames changes it', () => {
  const hands = engine.hands({ hands: 'both' });
  const [aspect, fx] = [4 / 3, 1 / (2 * Math.tan(Math.PI / 6))];
  /** MediaPipe's results for a recorded hand (the engine's axes back to the camera's, half a metre ahead), labelled `label`. */
  const results = (landmarks, label) => {
    const world = landmarks.map(([x, y, z]) => ({ x: -x, y: -y, z }));
    const image = world.map((w) => ({ x: 0.5 + (fx * w.x) / (w.z + 0.5), y: 0.5 + (fx * aspect * w.y) / (w.z + 0.5), z: 0 }));
    return { multiHandWorldLandmarks: [world], multiHandLandmarks: [image], multiHandedness: [{ label }] };
  };
  const lines = recording('gestures-landmarks.jsonl').slice(0, 40).map((l) => JSON.parse(l).landmarks);
  const right = hands.handOf('right');
  let t = 0;
  const frame = (label) => {
    t += 1 / 30;
    const pushed = hands.pushMediaPipe(results(lines[Math.round(t * 30) % lines.length], label), t, aspect);
    hands.step(t);
    return pushed;
  };
  // MediaPipe's "Right" is the user's left hand (its labels assume a mirrored image).
  for (let i = 0; i < 10; i++) assert.equal(frame('Right'), 1);
  assert.deepEqual([hands.tracking(hands.handOf('left')), hands.tracking(right)], ['tracking', 'waiting']);
  // Four frames labelled the other hand: still the left one, the right hand still waits.
  for (let i = 0; i < 4; i++) assert.equal(frame('Left'), 1);
  assert.equal(hands.tracking(right), 'waiting');
  assert.equal(hands.counts().accepted, 14);
  // The fifth in a row: the label is believed.
  frame('Left');
  assert.equal(hands.tracking(right), 'tracking');
  hands.dispose();
});
