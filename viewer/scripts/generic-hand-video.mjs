// A webcam video of a hand that is not ours: the WebXR generic hand (the skinned glTF of
// @webxr-input-profiles/assets, third_party/), posed joint by joint from a joints recording, held
// before a camera that sees its palm, written as webcam-video.mjs writes its video.
//
//   node scripts/generic-hand-video.mjs OUT_DIR --input REC.jsonl
//     → OUT_DIR/generic-hand.y4m, .labels.json (as webcam-video.mjs's) and .truth.json
//
// REC.jsonl is a joints recording as `dqhand synthesize --format joints` writes it, with
// REC.labels.json beside it (its holds). The hand drawn is the recording's side: right.glb,
// or left.glb for a left-hand recording (OUT_DIR/generic-hand-left.*), not a mirrored image.
// Each bone takes its joint's pose as three.js's XRHandMeshModel gives a WebXR hand's bones
// theirs (the glTF's bones are flat, children of one armature, named after the joints): the
// mesh is the generic hand's, the skeleton the recording's.
//
// The recording's world is a headset's: +Y up, a hand at rest palm down with its fingers
// forward (−Z). The camera is the page's webcam as landmarks.ts takes it: level, looking along
// +Z, so that image up is the engine's +Y. A webcam's user raises the hand, fingers up and palm
// to the camera: the whole hand is turned a quarter about X at the wrist (the recording's
// origin) for each hold, except for gestures defined by a direction in the world (thumbs up
// and down: `thumb.up` in crates/dqhand/data/gestures.json), which keep the recording's turn,
// and shifted so that the hold's joints are centred before the camera; the moves between holds
// go from one placement to the next. A rigid motion changes no joint angle.
//
// Frame k shows the record nearest its time in the recording, except that a hold shorter
// than HOLD_S is shown for HOLD_S by repeating the record in its middle (synthesize's holds
// are 1 s; MediaPipe on a small machine sees 2–6 frames a second, and the engine shows a new
// pose 1–2 s after the camera does: the camera test samples a hold from then to its end); the
// moves between holds play as recorded. Every frame carries its number in its top-left corner (y4m.mjs, MARKER), so a
// page playing the looping file can tell which frame it is given. The truth file has each
// frame's record time and the 25 joints' positions in the camera's frame (MediaPipe's axes: x
// right in the image, y down, z away from the camera; metres).

import { closeSync, mkdirSync, openSync, readFileSync, writeFileSync, writeSync } from 'node:fs';
import path from 'node:path';
import { Quaternion, Vector3 } from 'three';
import { launchBrowser, root } from './harness.mjs';
import { MARKER, readCanvas, stampFrame, toI420 } from './y4m.mjs';

const SIZE = [320, 240];
const FPS = 10;
/** Shortest hold shown (s). */
const HOLD_S = 4;
/** The WebXR joints in the spec's order (the truth file's). */
const JOINTS = ['wrist', 'thumb-metacarpal', 'thumb-phalanx-proximal', 'thumb-phalanx-distal', 'thumb-tip'].concat(
  ...['index', 'middle', 'ring', 'pinky'].map((f) => ['metacarpal', 'phalanx-proximal', 'phalanx-intermediate', 'phalanx-distal', 'tip'].map((j) => `${f}-finger-${j}`)),
);
/** Where the page's files come from: a made-up origin whose requests the script answers itself. */
const ORIGIN = 'http://generic-hand.invalid';
const FILES = {
  '/three/': path.join(root, 'viewer/node_modules/three/'),
  '/hand/': path.join(root, 'third_party/node_modules/@webxr-input-profiles/assets/dist/profiles/generic-hand/'),
};

const out = process.argv[2];
const input = process.argv[process.argv.indexOf('--input') + 1];
if (!out || out.startsWith('--') || !process.argv.includes('--input') || !input) throw new Error('usage: node scripts/generic-hand-video.mjs OUT_DIR --input REC.jsonl');
const records = readFileSync(input, 'utf8').split('\n').filter(Boolean).map((l) => JSON.parse(l));
const recLabels = JSON.parse(readFileSync(input.replace(/\.jsonl$/, '') + '.labels.json', 'utf8'));
const side = records[0].hand;
if (!['left', 'right'].includes(side) || records.some((r) => r.hand !== side || !r.joints)) throw new Error(`${input}: every record needs the same "hand" and "joints"`);
const name = side === 'left' ? 'generic-hand-left' : 'generic-hand';

/** The gestures that name a direction in the world, shown as recorded (not turned). */
const DIRECTED = new Set(JSON.parse(readFileSync(path.join(root, 'crates/dqhand/data/gestures.json'), 'utf8')).gestures.filter((g) => (g.when ?? []).some((c) => /\b(palm|thumb)\.up\b/.test(c))).map((g) => g.name));
const RAISED = new Quaternion().setFromAxisAngle(new Vector3(1, 0, 0), Math.PI / 2);
/** Where the camera looks (m): the centre of the hand in each hold. */
const TARGET = new Vector3(0, 0, 0);
/** The record nearest time `t` of the recording. */
const nearest = (t) => {
  let best = 0;
  for (let i = 1; i < records.length && Math.abs(records[i].t - t) <= Math.abs(records[best].t - t); i++) best = i;
  return best;
};

/** Each hold's placement: the turn, and the shift that puts the centre of its joints on TARGET. */
const placements = recLabels.holds.map((h) => {
  const q = DIRECTED.has(h.gesture) ? new Quaternion() : RAISED;
  const joints = Object.values(records[nearest((h.reached + h.until) / 2)].joints);
  const centre = joints.reduce((c, j) => c.add(new Vector3(...j.p)), new Vector3()).divideScalar(joints.length);
  return { q, shift: TARGET.clone().sub(centre.applyQuaternion(q)) };
});
/** The hand's placement at time `t` of the recording: its hold's, or between two holds' in a move. */
const placement = (t) => {
  const holds = recLabels.holds;
  const next = holds.findIndex((h) => t < h.reached);
  if (next <= 0) return placements[next === 0 ? 0 : holds.length - 1];
  const f = Math.min(1, Math.max(0, (t - holds[next - 1].until) / (holds[next].reached - holds[next - 1].until)));
  const [a, b] = [placements[next - 1], placements[next]];
  return { q: a.q.clone().slerp(b.q, f), shift: a.shift.clone().lerp(b.shift, f) };
};

// The video as segments: moves played as recorded, holds (labelled) at least HOLD_S long.
const segments = [];
let cursor = records[0].t;
for (const h of recLabels.holds) {
  segments.push({ from: cursor, to: h.reached });
  if (h.until - h.reached >= HOLD_S) segments.push({ from: h.reached, to: h.until, gesture: h.gesture });
  else segments.push({ still: nearest((h.reached + h.until) / 2), seconds: HOLD_S, gesture: h.gesture });
  cursor = h.until;
}
segments.push({ from: cursor, to: records[records.length - 1].t });
/** Each frame's record, and the labels: each hold's first and end time in the video. */
const shown = [];
const gestures = [];
for (const s of segments) {
  const start = shown.length;
  const n = Math.round((s.seconds ?? s.to - s.from) * FPS);
  for (let k = 0; k < n; k++) shown.push(s.still ?? nearest(s.from + k / FPS));
  if (s.gesture) gestures.push({ gesture: s.gesture, from_s: start / FPS, to_s: shown.length / FPS });
}
if (shown.length >= 2 ** MARKER.bits) throw new Error(`${shown.length} frames: more than the frame marker counts`);

const page = `<!doctype html>
<body style="margin:0"><canvas id="view" width="${SIZE[0]}" height="${SIZE[1]}"></canvas>
<script type="importmap">{ "imports": { "three": "/three/build/three.module.js", "three/addons/": "/three/examples/jsm/" } }</script>
<script type="module">
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
const canvas = document.getElementById('view');
const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
renderer.setSize(${SIZE[0]}, ${SIZE[1]}, false);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x59636e);
// The webcam, 35 cm before the hand's centre, a little below it and to the thumb's side,
// looking along +Z (image up is +Y).
const target = new THREE.Vector3(${TARGET.toArray()});
const camera = new THREE.PerspectiveCamera(45, ${SIZE[0]} / ${SIZE[1]}, 0.01, 10);
camera.position.copy(target).addScaledVector(new THREE.Vector3(-0.1, -0.15, -1).normalize(), 0.35);
camera.lookAt(target);
camera.updateMatrixWorld();
scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 1.6));
const key = new THREE.DirectionalLight(0xffffff, 2.2);
key.position.copy(camera.position).add(new THREE.Vector3(0.1, 0, -0.2));
scene.add(key);
const gltf = await new GLTFLoader().loadAsync('/hand/${side}.glb');
const hand = gltf.scene.children[0];
scene.add(hand);
const mesh = hand.getObjectByProperty('type', 'SkinnedMesh');
mesh.frustumCulled = false;
// The asset's grey, in a skin's colour: MediaPipe is trained on people's hands.
mesh.material = new THREE.MeshStandardMaterial({ color: 0xd6a07c, roughness: 0.65, metalness: 0 });
const names = ${JSON.stringify(JOINTS)};
const bones = names.map((n) => hand.getObjectByName(n));
if (bones.some((b) => !b)) throw new Error('a joint has no bone');
const v = new THREE.Vector3();
// Poses the bones (each at its joint's pose, XRHandMeshModel's convention), places the hand
// (turn \`q\` about the origin, then \`shift\`), renders, and gives the joints in the camera's
// frame, MediaPipe's axes.
window.pose = (joints, q, shift) => {
  hand.quaternion.fromArray(q);
  hand.position.fromArray(shift);
  bones.forEach((b, i) => {
    const j = joints[names[i]];
    b.position.fromArray(j.p);
    b.quaternion.fromArray(j.q);
  });
  hand.updateMatrixWorld(true);
  renderer.render(scene, camera);
  return bones.map((b) => {
    b.getWorldPosition(v).applyMatrix4(camera.matrixWorldInverse);
    return [v.x, -v.y, -v.z].map((x) => Math.round(x * 1e5) / 1e5);
  });
};
window.ready = true;
</script>`;

mkdirSync(out, { recursive: true });
const browser = await launchBrowser();
const file = path.join(out, `${name}.y4m`);
const fd = openSync(file, 'w');
try {
  const p = await browser.newPage({ viewport: { width: SIZE[0], height: SIZE[1] } });
  p.on('pageerror', (e) => console.error('page error:', e.message));
  await p.route(`${ORIGIN}/**`, (route) => {
    const url = new URL(route.request().url()).pathname;
    if (url === '/') return route.fulfill({ contentType: 'text/html', body: page });
    const [prefix, dir] = Object.entries(FILES).find(([prefix]) => url.startsWith(prefix)) ?? [];
    const local = dir && path.join(dir, url.slice(prefix.length));
    if (!local || !local.startsWith(dir)) return route.fulfill({ status: 404 });
    return route.fulfill({ path: local });
  });
  await p.goto(`${ORIGIN}/`);
  await p.waitForFunction(() => window.ready === true, null, { timeout: 60_000 });
  writeSync(fd, `YUV4MPEG2 W${SIZE[0]} H${SIZE[1]} F${FPS}:1 Ip A1:1 C420jpeg\n`);
  const truth = [];
  let rgba = null;
  for (let k = 0; k < shown.length; k++) {
    const r = records[shown[k]];
    if (k === 0 || shown[k] !== shown[k - 1]) {
      truth.push({ t: r.t, joints: await p.evaluate(([joints, q, shift]) => window.pose(joints, q, shift), [r.joints, placement(r.t).q.toArray(), placement(r.t).shift.toArray()]) });
      rgba = Buffer.from(await p.evaluate(readCanvas, [...SIZE, false]), 'base64');
    } else {
      truth.push(truth[k - 1]);
    }
    const frame = Buffer.from(rgba);
    stampFrame(frame, SIZE[0], k);
    writeSync(fd, 'FRAME\n');
    writeSync(fd, toI420(frame, SIZE[0], SIZE[1]));
  }
  writeFileSync(path.join(out, `${name}.labels.json`), JSON.stringify({ fps: FPS, size: SIZE, frames: shown.length, side, recording: path.resolve(input), gestures }, null, 1));
  writeFileSync(path.join(out, `${name}.truth.json`), JSON.stringify({ fps: FPS, axes: 'camera: x right, y down, z away from the camera (m)', joints: JOINTS, frames: truth }));
  console.log(`${file}: ${shown.length} frames of ${SIZE.join('×')} at ${FPS} fps, the generic ${side} hand in ${gestures.map((g) => g.gesture).join(', ')}`);
} finally {
  closeSync(fd);
  await browser.close();
}
