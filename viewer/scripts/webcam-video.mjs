// The camera test's video: our own hand, rendered by the real page, held in known gestures
// before a camera that sees its palm, written as a YUV4MPEG2 (.y4m) file that Chromium plays as
// a webcam (--use-file-for-fake-video-capture), with a labels file saying which gesture each
// stretch of frames shows.
//
//   node scripts/webcam-video.mjs OUT_DIR           → OUT_DIR/hand.y4m, OUT_DIR/hand.labels.json
//   node scripts/webcam-video.mjs OUT_DIR --left    → OUT_DIR/hand-left.*: the frames mirrored,
//                                                      a left hand before the camera
//
// The frames are the page's canvas read back at SIZE, converted to 4:2:0 (BT.601, full range,
// as `C420jpeg` says), at FPS, each with its number in its top-left corner (y4m.mjs, MARKER).
// The hand is the built-in one in the page's front view (fingers up, palm to the camera), as a
// user's right hand before a webcam; mirrored, their left.

import { mkdirSync, openSync, writeSync, closeSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { launchBrowser, startServer, waitState, settle } from './harness.mjs';
import { readCanvas, stampFrame, toI420 } from './y4m.mjs';

const left = process.argv.includes('--left');
/** The gestures shown, in order, each held for HOLD_FRAMES after a move of MOVE_FRAMES. */
const GESTURES = left ? ['open_palm', 'fist', 'point'] : ['open_palm', 'fist', 'victory', 'open_palm', 'point', 'fist'];
const NAME = left ? 'hand-left' : 'hand';
const SIZE = [320, 240];
const FPS = 10;
const HOLD_FRAMES = 40;
const MOVE_FRAMES = 3;
/** How long the engine takes to move to a gesture (s) — the frames of the move sample it. */
const MOVE_S = 0.5;

const out = process.argv[2];
if (!out || out.startsWith('--')) throw new Error('usage: node scripts/webcam-video.mjs OUT_DIR [--left]');
mkdirSync(out, { recursive: true });

const server = await startServer();
const browser = await launchBrowser();
const file = path.join(out, `${NAME}.y4m`);
const fd = openSync(file, 'w');
try {
  const page = await browser.newPage({ viewport: { width: SIZE[0], height: SIZE[1] } });
  await page.goto(`${server.url}?figure`);
  await waitState(page, 's.connected && s.frame !== null');
  await page.evaluate(() => window.dqhand.send({ type: 'pause' }));
  await page.evaluate(() => window.dqhand.view([0.25, -0.2, 1], undefined, 0.42));
  writeSync(fd, `YUV4MPEG2 W${SIZE[0]} H${SIZE[1]} F${FPS}:1 Ip A1:1 C420jpeg\n`);
  const labels = [];
  let frame = 0;
  const write = (rgba) => {
    const stamped = Buffer.from(rgba);
    stampFrame(stamped, SIZE[0], frame++);
    writeSync(fd, 'FRAME\n');
    writeSync(fd, toI420(stamped, SIZE[0], SIZE[1]));
  };
  const capture = async () => {
    await settle(page, 2);
    write(Buffer.from(await page.evaluate(readCanvas, [...SIZE, left]), 'base64'));
  };
  for (const name of GESTURES) {
    await page.evaluate(([name, seconds]) => window.dqhand.send({ type: 'gesture', name, seconds }), [name, MOVE_S]);
    const moveStart = performance.now();
    for (let k = 0; k < MOVE_FRAMES; k++) {
      const due = moveStart + ((k + 1) * MOVE_S * 1000) / MOVE_FRAMES;
      await new Promise((r) => setTimeout(r, Math.max(0, due - performance.now())));
      await capture();
    }
    await new Promise((r) => setTimeout(r, 200)); // the move has ended: the pose is the gesture's
    const from = frame;
    await capture();
    // The hand is still: the rest of the hold repeats the frame.
    const still = Buffer.from(await page.evaluate(readCanvas, [...SIZE, left]), 'base64');
    for (let k = 1; k < HOLD_FRAMES; k++) write(still);
    labels.push({ gesture: name, from_s: from / FPS, to_s: frame / FPS });
  }
  writeFileSync(path.join(out, `${NAME}.labels.json`), JSON.stringify({ fps: FPS, size: SIZE, frames: frame, side: left ? 'left' : 'right', gestures: labels }, null, 1));
  console.log(`${file}: ${frame} frames of ${SIZE.join('×')} at ${FPS} fps, ${GESTURES.join(', ')}`);
} finally {
  closeSync(fd);
  await browser.close();
  await server.stop();
}
