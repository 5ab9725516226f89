// Does MediaPipe Hands see our hand? (issue 32: "MediaPipe finds the rendered hand in ≥ 95 % of
// 100 random views of it in the library's gestures".) The built page, on a plain static host
// with the engine in the page, renders the built-in hand (DQB) in a random gesture of the
// library from a random direction and distance; MediaPipe Hands (the page's own offline copy,
// with the settings the Camera button uses) runs on that image alone, its tracking reset
// before each view; and each hand it reports is graded against where our joints are drawn
// (`window.dqhand.jointsOnScreen`), so a detection elsewhere in the image is not counted.
//
//   node scripts/mediapipe-views.mjs [--views N] [--seed S] [--json FILE] [--save DIR] [--model GLB]
//
// `--model GLB` draws another skinned hand with WebXR joint names instead (through `dqhand demo
// --model`, the engine in that process), in the same material: the WebXR generic hand, say,
// to see whether MediaPipe does better on a hand someone else modelled.
//
// A view counts as found when a reported hand's 21 landmarks lie, at the median, within
// LOCATED of the hand's drawn size (the diagonal of its joints' bounding box on screen) from our
// matching joints. Directions are uniform over the sphere between ELEVATION_DEG[0] and [1]
// of elevation (the table-less page has a ground plane below the hand: views from further
// below look through it); distances uniform in DISTANCE_M. The views depend on the seed
// only: seed 1 is the measured set, seed 2 a second one to check a change against that it
// was not made on.

import { mkdirSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { launchBrowser, newPage, root, serveStatic, settle, startServer, waitState } from './harness.mjs';

const arg = (name, fallback) => {
  const i = process.argv.indexOf(name);
  return i >= 0 ? process.argv[i + 1] : fallback;
};
const VIEWS = Number(arg('--views', 100));
const SEED = Number(arg('--seed', 1));
const JSON_OUT = arg('--json', null);
const SAVE = arg('--save', null);
const MODEL = arg('--model', null);
const SIZE = { width: 640, height: 480 };
const ELEVATION_DEG = [-40, 70];
const DISTANCE_M = [0.35, 0.6];
/** Largest median landmark error of a found hand, as a share of its drawn size. */
const LOCATED = 0.1;
/** Our joint (WebXR name) under each of MediaPipe's 21 landmarks, in MediaPipe's order. */
const LANDMARK_JOINTS = [
  'wrist',
  'thumb-metacarpal', 'thumb-phalanx-proximal', 'thumb-phalanx-distal', 'thumb-tip',
  ...['index-finger', 'middle-finger', 'ring-finger', 'pinky-finger'].flatMap((f) => ['phalanx-proximal', 'phalanx-intermediate', 'phalanx-distal', 'tip'].map((j) => `${f}-${j}`)),
];

/** mulberry32: a small seeded generator, so a seed names the same views everywhere. */
function random(seed) {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

const median = (xs) => {
  const s = [...xs].sort((a, b) => a - b);
  return s.length % 2 ? s[(s.length - 1) / 2] : (s[s.length / 2 - 1] + s[s.length / 2]) / 2;
};

const host = MODEL ? await startServer({ args: ['--model', path.resolve(MODEL)] }) : await serveStatic(path.join(root, 'viewer/dist'));
const browser = await launchBrowser();
try {
  const page = await newPage(browser, SIZE);
  await page.goto(`${host.url}?figure`);
  await waitState(page, 's.connected && s.frame !== null && s.gestures.length > 0');
  await page.evaluate(() => window.dqhand.send({ type: 'pause' }));
  const { gestures, joints } = await page.evaluate(() => window.dqhand.state());
  const landmarkJoint = LANDMARK_JOINTS.map((name) => {
    const i = joints.indexOf(name);
    if (i < 0) throw new Error(`the page's hand has no joint ${name}`);
    return i;
  });
  // MediaPipe, as the Camera button loads it (src/webcam.ts): the page's own files.
  await page.evaluate(async () => {
    await new Promise((resolve, reject) => {
      const script = Object.assign(document.createElement('script'), { src: 'mediapipe/hands.js', onload: resolve, onerror: () => reject(new Error('mediapipe/hands.js: not in the build (make viewer)')) });
      document.head.append(script);
    });
    const hands = new window.Hands({ locateFile: (file) => `mediapipe/${file}` });
    hands.setOptions({ useCpuInference: true, selfieMode: false, maxNumHands: 2, modelComplexity: 1, minDetectionConfidence: 0.5, minTrackingConfidence: 0.5 });
    let resolveResults = null;
    hands.onResults((r) => resolveResults?.(r));
    await hands.initialize();
    window.detect = async () => {
      // The WebGL canvas copied as the image a camera would give.
      const view = document.getElementById('view');
      const image = Object.assign(document.createElement('canvas'), { width: view.width, height: view.height });
      image.getContext('2d').drawImage(view, 0, 0);
      hands.reset();
      const results = new Promise((resolve) => (resolveResults = resolve));
      await hands.send({ image });
      const r = await results;
      return {
        png: image.toDataURL('image/png'),
        hands: (r.multiHandLandmarks ?? []).map((landmarks, i) => ({
          label: r.multiHandedness?.[i]?.label ?? null,
          score: r.multiHandedness?.[i]?.score ?? null,
          landmarks: landmarks.map((p) => [p.x, p.y]),
        })),
      };
    };
  });
  if (SAVE) mkdirSync(SAVE, { recursive: true });

  const next = random(SEED);
  const rows = [];
  for (let v = 0; v < VIEWS; v++) {
    const gesture = gestures[Math.floor(next() * gestures.length)];
    const azimuth = 2 * Math.PI * next();
    const [lo, hi] = ELEVATION_DEG.map((d) => Math.sin((d * Math.PI) / 180));
    const elevation = Math.asin(lo + (hi - lo) * next());
    const distance = DISTANCE_M[0] + (DISTANCE_M[1] - DISTANCE_M[0]) * next();
    // +Z is the default camera's side: the palm's.
    const direction = [Math.cos(elevation) * Math.sin(azimuth), Math.sin(elevation), Math.cos(elevation) * Math.cos(azimuth)];
    const before = (await page.evaluate(() => window.dqhand.state().framesReceived));
    await page.evaluate((name) => window.dqhand.send({ type: 'gesture', name, seconds: 0 }), gesture);
    await waitState(page, `s.framesReceived > ${before + 2}`);
    await page.evaluate(([d, r]) => window.dqhand.view(d, undefined, r), [direction, distance]);
    await settle(page, 4);
    const drawn = await page.evaluate(() => window.dqhand.jointsOnScreen());
    const { png, hands } = await page.evaluate(() => window.detect());
    const ours = landmarkJoint.map((j) => [drawn[j][0] * SIZE.width, drawn[j][1] * SIZE.height]);
    const xs = drawn.map((p) => p[0] * SIZE.width);
    const ys = drawn.map((p) => p[1] * SIZE.height);
    const size = Math.hypot(Math.max(...xs) - Math.min(...xs), Math.max(...ys) - Math.min(...ys));
    const graded = hands.map((h) => ({
      ...h,
      error: median(h.landmarks.map(([x, y], k) => Math.hypot(x * SIZE.width - ours[k][0], y * SIZE.height - ours[k][1]))) / size,
    }));
    const best = graded.reduce((a, b) => (a === null || b.error < a.error ? b : a), null);
    const found = best !== null && best.error <= LOCATED;
    // selfieMode off: MediaPipe's label is the mirror image's (src/webcam.ts, userSide).
    const side = best ? (best.label === 'Left' ? 'right' : best.label === 'Right' ? 'left' : null) : null;
    const row = {
      view: v, gesture, direction: direction.map((x) => Number(x.toFixed(4))), distance_m: Number(distance.toFixed(3)),
      palm_side: direction[2] > 0, size_px: Number(size.toFixed(1)), detected: hands.length, found,
      error: best ? Number(best.error.toFixed(4)) : null, side, score: best?.score ?? null,
    };
    rows.push(row);
    if (SAVE) writeFileSync(path.join(SAVE, `view-${String(v).padStart(3, '0')}-${gesture}-${found ? 'found' : 'missed'}.png`), Buffer.from(png.split(',')[1], 'base64'));
    process.stderr.write(`${v + 1}/${VIEWS} ${gesture} ${found ? 'found' : hands.length ? `detected off (${best.error.toFixed(2)})` : 'missed'}\n`);
  }

  const share = (rs) => (rs.length ? rs.filter((r) => r.found).length / rs.length : null);
  const byGesture = Object.fromEntries(gestures.map((g) => [g, rows.filter((r) => r.gesture === g)]).filter(([, rs]) => rs.length).map(([g, rs]) => [g, { views: rs.length, found: rs.filter((r) => r.found).length }]));
  const report = {
    model: MODEL ?? 'builtin',
    views: VIEWS,
    seed: SEED,
    size: SIZE,
    elevation_deg: ELEVATION_DEG,
    distance_m: DISTANCE_M,
    located: LOCATED,
    found: rows.filter((r) => r.found).length,
    detected: rows.filter((r) => r.detected > 0).length,
    found_palm_side: share(rows.filter((r) => r.palm_side)),
    found_back_side: share(rows.filter((r) => !r.palm_side)),
    side_right_of_found: rows.some((r) => r.found) ? rows.filter((r) => r.found && r.side === 'right').length / rows.filter((r) => r.found).length : null,
    median_error_of_found: rows.some((r) => r.found) ? median(rows.filter((r) => r.found).map((r) => r.error)) : null,
    by_gesture: byGesture,
    rows,
  };
  if (JSON_OUT) writeFileSync(JSON_OUT, JSON.stringify(report, null, 1));
  const pct = (x) => (x === null ? '—' : `${(100 * x).toFixed(1)} %`);
  console.log(`MediaPipe Hands on ${MODEL ? path.basename(MODEL) : 'the built-in hand'} (DQB), ${VIEWS} random views (seed ${SEED}), ${SIZE.width}×${SIZE.height}, software WebGL, CPU inference:`);
  console.log(`  found (median landmark error ≤ ${LOCATED * 100} % of the hand's drawn size): ${report.found} of ${VIEWS} (${pct(report.found / VIEWS)}); a hand reported at all: ${report.detected}`);
  console.log(`  palm side ${pct(report.found_palm_side)}, back side ${pct(report.found_back_side)}; of those found, labelled a right hand ${pct(report.side_right_of_found)}; median error of those found ${report.median_error_of_found === null ? '—' : pct(report.median_error_of_found)}`);
  console.log(`  by gesture: ${Object.entries(byGesture).map(([g, c]) => `${g} ${c.found}/${c.views}`).join(', ')}`);
} finally {
  await browser.close();
  await host.stop();
}
