// `make figures`: the paper's Figures 5–7 and 9 reproduced on our hand with the real page in
// headless Chromium, written to docs/figures/ as PNG.
//
//   fig5-index-bend.png   index PIP bent 0–120° under QB, DQB and LB (paper Fig. 5, plus LB)
//   fig6-pip-zoom.png     close-up of the PIP joint at 120°, shaded and as a heat map (Fig. 6)
//   fig7-gestures-{dqb,qb,lb}.png   the daily gestures (Fig. 7)
//   viewer-split.png      the viewer itself, split view on the fist
//   hand-look.png         the built-in hand before and after its look (regions, skin maps, nails): palm, back, fist
//   fig9-grasp.png        the ball and the Utah teapot grasped, lifted, carried and set down (Fig. 9)
//   dqs-twist-bend.png    three.js's linear skinning beside three-dqs on a twisted and a bent limb
//   dqs-hand.png          the same on the WebXR generic hand (a glTF made elsewhere), its index finger twisted and bent
//
// `node scripts/figures.mjs hand` makes the first four only, `… look` the hand's look, `… grasp`
// Figure 9 only, `… dqs` the last two (they need `make dqs-package`'s install); no argument,
// all of them.
//
// Joint limits are switched off for Figure 5/6 so the PIP can reach 120° (its range is 0–110°).

import { execFileSync } from 'node:child_process';
import { copyFileSync, mkdirSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { dqhandBin, launchBrowser, root, serveStatic, settle, startServer, waitState } from './harness.mjs';

const out = path.join(root, 'docs/figures');
mkdirSync(out, { recursive: true });
const PIP = 'index-finger-phalanx-intermediate.flex';
const CELL = 360;
/** How long the hand holds still at each stage of Figure 9 (s). */
const HOLD_S = 4;
/** The stages of Figure 9 in each scripted grasp: when (from its labelled times, s), what is held then, and the caption. */
const STAGES = [
  { at: (t) => t.reached - 0.25, held: false, caption: 'approach' },
  { at: (t) => t.closed + 0.15, held: true, caption: 'fingers closed: grasped' },
  { at: (t) => t.carry_end + 0.1, held: true, caption: 'lifted and carried 20 cm' },
  { at: (t) => t.release + 0.75, held: false, caption: 'set down and let go' },
];
const GROUPS = ['hand', 'look', 'grasp', 'dqs'];
const asked = process.argv.slice(2);
for (const a of asked) if (!GROUPS.includes(a)) throw new Error(`unknown figure group ${JSON.stringify(a)}: ${GROUPS.join(', ')}`);
const wanted = (group) => asked.length === 0 || asked.includes(group);

const browser = await launchBrowser();
try {
  const sheet = await browser.newPage({ viewport: { width: 1900, height: 1000 } });
  /**
   * Composes a grid of screenshots in a plain page and writes it to docs/figures/`file`.
   * `size`: how large each cell is shown (px); `label`: the width of the row labels (px).
   */
  const compose = async (file, title, rows, columns, { size = [CELL / 1.5, CELL / 1.5], label = 44, note = '' } = {}) => {
    const cell = (c) => `<figure><img src="${c.src}"><figcaption>${c.caption}</figcaption></figure>`;
    const body = rows
      .map((r) => `<div class="row">${r.label ? `<div class="label">${r.label}</div>` : ''}<div class="cells" style="grid-template-columns: repeat(${columns}, ${size[0]}px)">${r.cells.map(cell).join('')}</div></div>`)
      .join('');
    await sheet.setContent(`<!doctype html><style>
      body { margin: 0; font: 15px system-ui, sans-serif; background: #fff; }
      #sheet { display: inline-block; padding: 10px 14px; }
      h1 { font-size: 16px; margin: 0 0 8px; }
      .row { display: flex; align-items: center; gap: 8px; margin-bottom: 4px; }
      .label { width: ${label}px; font-weight: 700; }
      .cells { display: grid; gap: 4px; }
      figure { margin: 0; text-align: center; }
      img { width: ${size[0]}px; height: ${size[1]}px; display: block; }
      figcaption { font-size: 13px; color: #444; }
      .note { font-size: 13px; color: #444; margin: 6px 0 0; max-width: ${label + 8 + columns * (size[0] + 4)}px; }
    </style><div id="sheet"><h1>${title}</h1>${body}${note ? `<p class="note">${note}</p>` : ''}</div>`);
    await sheet.locator('#sheet').screenshot({ path: path.join(out, file) });
    console.log(`wrote docs/figures/${file}`);
  };
  if (wanted('hand')) await handFigures(compose);
  if (wanted('look')) await lookFigure(compose);
  if (wanted('grasp')) await graspFigure(compose);
  if (wanted('dqs')) await dqsFigure(compose);
} finally {
  await browser.close();
}

/**
 * The built-in hand in the viewer's plain skin material (before) and in its look from its file
 * (after: back and palm in their skin maps with sheen, nails glossy): close on the palm, on the
 * back of the fingers, the fist, and the index finger from the side, DQB.
 */
async function lookFigure(compose) {
  const server = await startServer();
  try {
    const page = await browser.newPage({ viewport: { width: CELL, height: CELL } });
    await page.goto(`${server.url}?figure`);
    await waitState(page, 's.connected && s.framesReceived > 2 && s.looks[0] !== null');
    const command = (c) => page.evaluate((c) => window.dqhand.send(c), c);
    await command({ type: 'pause' });
    await page.evaluate(() => window.dqhand.setting({ type: 'view', methods: ['dqb'] }));
    const views = [
      { gesture: 'open', view: [[0, 0, 1], 'middle-finger-metacarpal', 0.2], caption: 'palm' },
      { gesture: 'open', view: [[0, 0, -1], 'middle-finger-phalanx-intermediate', 0.14], caption: 'back of the fingers' },
      { gesture: 'fist', view: [[0.3, 0.2, 1], 'middle-finger-phalanx-proximal', 0.25], caption: 'fist' },
      { gesture: 'point', view: ['side', 'index-finger-phalanx-intermediate', 0.12], caption: 'index finger, side' },
    ];
    const rows = [{ label: 'before', cells: [] }, { label: 'after', cells: [] }];
    for (const v of views) {
      const before = (await page.evaluate(() => window.dqhand.state().frame.sequence)) ?? 0;
      await command({ type: 'gesture', name: v.gesture, seconds: 0 });
      await waitState(page, `!s.frame.playing && s.frame.methods.join() === 'dqb' && s.frame.sequence > ${before + 3}`);
      await page.evaluate((view) => window.dqhand.view(...view), v.view);
      // The same pose and view in each: the plain material, then the look.
      for (const [k, on] of [false, true].entries()) {
        await page.evaluate((on) => window.dqhand.showLook(on), on);
        await settle(page, 4);
        rows[k].cells.push({ src: `data:image/png;base64,${(await page.screenshot()).toString('base64')}`, caption: v.caption });
      }
    }
    await compose('hand-look.png', 'The built-in hand before and after its look (DQB, software WebGL)', rows, views.length, {
      size: [CELL, CELL],
      label: 60,
      note: 'Before: one skin-coloured material. After: the regions of the hand\'s glTF (crates/dqhand/src/hand/surface_regions.rs) in their materials, the back and the palm with their generated albedo and normal maps (creases, palm lines, knuckle wrinkles, pores; skin_texture.rs) and sheen, the nails glossy and coated.',
    });
  } finally {
    await server.stop();
  }
}

/** Figures 5–7 and the viewer's split view, from one `dqhand demo` on the built-in hand. */
async function handFigures(compose) {
  const server = await startServer();
  try {
    const page = await browser.newPage({ viewport: { width: CELL, height: CELL } });
    await page.goto(`${server.url}?figure`);
    await waitState(page, 's.connected && s.framesReceived > 2');
    const send = (c) => page.evaluate((c) => window.dqhand.setting(c), c);
    const command = (c) => page.evaluate((c) => window.dqhand.send(c), c);
    const dofIndex = async (name) => (await page.evaluate(() => window.dqhand.state().dofs)).indexOf(name);
    /** Waits until the engine's frame shows `methods` and every angle in `angles` (degrees). */
    const reached = async (methods, angles = {}) => {
      const checks = await Promise.all(Object.entries(angles).map(async ([n, deg]) => `Math.abs(s.frame.anglesDeg[${await dofIndex(n)}] - ${deg}) < 0.01`));
      await waitState(page, [`s.frame && s.frame.methods.join() === ${JSON.stringify(methods.join())}`, `s.visible.join() === ${JSON.stringify(methods.join())}`, ...checks].join(' && '));
      await settle(page, 4);
    };
    const shot = async () => `data:image/png;base64,${(await page.screenshot()).toString('base64')}`;

    await command({ type: 'pause' });
    await send({ type: 'limits', on: false });

    // Figures 5 and 6.
    const angles = [0, 30, 60, 90, 120];
    const fig5 = [];
    const fig6 = [];
    for (const method of ['qb', 'dqb', 'lb']) {
      await send({ type: 'view', methods: [method] });
      await send({ type: 'heatmap', on: false });
      await command({ type: 'rest' });
      const row = [];
      for (const deg of angles) {
        await command({ type: 'angle', dof: PIP, deg });
        await reached([method], { [PIP]: deg });
        await page.evaluate(() => window.dqhand.view('side', 'index-finger-phalanx-intermediate', 0.3));
        await settle(page, 3);
        row.push({ src: await shot(), caption: `${deg}°` });
      }
      fig5.push({ label: method.toUpperCase(), cells: row });
      const zoom = [];
      await page.evaluate(() => window.dqhand.view('side', 'index-finger-phalanx-intermediate', 0.1));
      await settle(page, 3);
      zoom.push({ src: await shot(), caption: 'shaded' });
      await send({ type: 'heatmap', on: true });
      await page.waitForFunction(() => window.dqhand.state().frame.distortion);
      await settle(page, 4);
      zoom.push({ src: await shot(), caption: 'edge-length change' });
      fig6.push({ label: method.toUpperCase(), cells: zoom });
    }
    await send({ type: 'heatmap', on: false });
    await send({ type: 'limits', on: true });

    // Figure 7.
    const gestures = await page.evaluate(() => [...document.querySelectorAll('button[data-gesture]')].map((b) => b.dataset.gesture));
    const fig7 = {};
    for (const method of ['dqb', 'qb', 'lb']) {
      await send({ type: 'view', methods: [method] });
      const cells = [];
      for (const name of gestures) {
        await command({ type: 'gesture', name, seconds: 0 });
        await waitState(page, `!s.frame.playing && s.frame.methods[0] === ${JSON.stringify(method)}`);
        await page.waitForTimeout(150);
        await reached([method]);
        await page.evaluate(() => window.dqhand.view('default', undefined, 0.42));
        await settle(page, 3);
        cells.push({ src: await shot(), caption: name });
      }
      fig7[method] = cells;
    }

    // The viewer itself, split view.
    const ui = await browser.newPage({ viewport: { width: 1280, height: 720 } });
    await ui.goto(server.url);
    await waitState(ui, 's.connected && s.framesReceived > 2');
    await ui.evaluate(() => window.dqhand.send({ type: 'gesture', name: 'point', seconds: 0 }));
    await ui.check('#split');
    await waitState(ui, 's.visible.length === 4 && !s.frame.playing');
    await ui.waitForTimeout(500);
    await settle(ui, 4);
    writeFileSync(path.join(out, 'viewer-split.png'), await ui.screenshot());
    await Promise.all([page.close(), ui.close()]);

    await compose('fig5-index-bend.png', 'Index finger PIP bent 0–120° (paper Fig. 5, with LB added)', fig5, angles.length);
    await compose('fig6-pip-zoom.png', 'PIP joint at 120°, close up (paper Fig. 6): shaded and per-vertex edge-length change', fig6, 2);
    for (const [method, cells] of Object.entries(fig7)) {
      const rows = [cells.slice(0, 7), cells.slice(7)].map((c) => ({ label: '', cells: c }));
      await compose(`fig7-gestures-${method}.png`, `Daily gestures under ${method.toUpperCase()} (paper Fig. 7)`, rows, 7);
    }
  } finally {
    await server.stop();
  }
}

/**
 * Figure 9: our hand grasping the ball and the Utah teapot of the `grasp` scene, four stages
 * each, through the real manipulation loop and page (`dqhand demo --scene`).
 *
 * The grasp is `dqhand synthesize --scene`'s script (synthetic). For still pictures the
 * recording is played with the hand held still for HOLD_S at each stage (the record repeated
 * at 60 Hz, the rest shifted later); the page knows it is in a hold from the count of records
 * the input has taken, and each still is taken inside one and checked to be (else the next
 * pass is used). The grasp scene is used without its gesture action: an open palm held still
 * for 1 s would put the objects back; gesture commands on the view are off too.
 */
async function graspFigure(compose) {
  const work = mkdtempSync(path.join(tmpdir(), 'dqhand-fig9-'));
  const dqhand = (...args) => execFileSync(dqhandBin(), args, { stdio: ['ignore', 'ignore', 'inherit'] });
  let server = null;
  try {
    const scenes = path.join(root, 'crates/dqhand/data/scenes');
    const sceneFile = path.join(work, 'grasp.json');
    const scene = JSON.parse(readFileSync(path.join(scenes, 'grasp.json'), 'utf8'));
    delete scene.actions;
    for (const o of scene.objects) if (o.file) o.file = path.resolve(scenes, o.file);
    writeFileSync(sceneFile, JSON.stringify(scene));
    const config = path.join(work, 'config.json');
    writeFileSync(config, JSON.stringify({ actions: [] }));

    // The scripted recording, and the same with the holds.
    const scripted = path.join(work, 'scripted.jsonl');
    dqhand('synthesize', '--scene', sceneFile, '--side', 'right', '--out', scripted);
    const labels = JSON.parse(readFileSync(path.join(work, 'scripted.labels.json'), 'utf8'));
    const records = readFileSync(scripted, 'utf8').split('\n').filter(Boolean).map((l) => JSON.parse(l));
    const stops = labels.tasks.flatMap(({ object, times }) => STAGES.map((s) => ({ object, held: s.held ? object : null, caption: s.caption, t: s.at(times) })));
    const hold = Math.round(HOLD_S * 60);
    const played = [];
    let shift = 0;
    let next = 0;
    for (const [i, r] of records.entries()) {
      played.push({ ...r, t: r.t + shift });
      // The hold goes after the last record at or before the stop.
      while (next < stops.length && (i + 1 === records.length || records[i + 1].t > stops[next].t)) {
        const stop = stops[next++];
        stop.first = played.length; // records taken when the hold begins
        for (let k = 1; k <= hold; k++) played.push({ ...r, t: r.t + shift + k / 60 });
        shift += hold / 60;
        stop.middle = r.t + shift - HOLD_S / 2;
      }
    }
    if (next !== stops.length) throw new Error('fig9: a stage lies past the end of the recording');
    const recording = path.join(work, 'held.jsonl');
    writeFileSync(recording, played.map((r) => JSON.stringify(r)).join('\n') + '\n');

    // The loop offline first: each stage must hold (or not) what it says, and the objects'
    // places frame the camera.
    const traceFile = path.join(work, 'trace.jsonl');
    dqhand('grasp', '--scene', sceneFile, '--input', recording, '--trace', traceFile);
    const trace = readFileSync(traceFile, 'utf8').split('\n').filter(Boolean).map((l) => JSON.parse(l));
    const frameAt = (t) => trace.reduce((best, f) => (Math.abs(f.t - t) < Math.abs(best.t - t) ? f : best));
    for (const stop of stops) {
      const f = frameAt(stop.middle);
      if (f.held !== stop.held) throw new Error(`fig9: ${stop.object}, ${stop.caption}: the offline loop holds ${f.held} at ${f.t.toFixed(2)} s, not ${stop.held}`);
      stop.place = f.objects[stop.object].p;
    }

    server = await startServer({ args: ['--scene', sceneFile, '--input', recording, '--config', config] });
    const page = await browser.newPage({ viewport: { width: 480, height: 360 } });
    await page.goto(`${server.url}?figure`);
    const names = scene.objects.map((o) => o.name).join();
    await waitState(page, `s.connected && s.framesReceived > 2 && s.input !== null && s.scene !== null && s.scene.drawn.join() === ${JSON.stringify(names)}`, 120_000);
    await page.evaluate((c) => window.dqhand.setting(c), { type: 'view', methods: ['dqb'] });
    await waitState(page, 's.visible.join() === "dqb"');

    const count = played.length;
    const taken = `((s.input.accepted + s.input.rejected) % ${count})`;
    const rows = [];
    for (const { object } of labels.tasks) {
      const own = stops.filter((s) => s.object === object);
      // One camera per row: from the object's side of the table, on the middle of its path.
      const [first, last] = [own[0].place, own[own.length - 1].place];
      const focus = [0, 1, 2].map((k) => (first[k] + last[k]) / 2 + (k === 1 ? 0.08 : 0));
      const side = Math.sign(first[0]) || 1;
      await page.evaluate(([d, f]) => window.dqhand.view(d, f, 0.7), [[0.9 * side, 0.55, 0.75], focus]);
      const cells = [];
      for (const stop of own) {
        const [lo, hi] = [stop.first + 60, stop.first + hold - 90];
        let src = null;
        for (let attempt = 0; attempt < 3 && !src; attempt++) {
          await waitState(page, `s.input && ${taken} >= ${lo} && ${taken} <= ${hi} && s.scene.held === ${JSON.stringify(stop.held)}`, 3 * (count / 60) * 1000);
          await settle(page, 4);
          const png = await page.screenshot();
          // Still in the same hold (the counters reach the page at most every 0.25 s)?
          const ok = await page.evaluate(([lo, end, held, count]) => {
            const s = window.dqhand.state();
            const k = (s.input.accepted + s.input.rejected) % count;
            return k >= lo && k <= end && s.scene.held === held;
          }, [lo, stop.first + hold - 30, stop.held, count]);
          if (ok) src = `data:image/png;base64,${png.toString('base64')}`;
        }
        if (!src) throw new Error(`fig9: ${object}, ${stop.caption}: no still inside the hold in 3 tries`);
        cells.push({ src, caption: stop.caption });
      }
      rows.push({ label: object, cells });
    }
    await page.close();
    await compose('fig9-grasp.png', 'Grasping a ball and the Utah teapot (paper Fig. 9): our hand, DQB skin, contact-constrained', rows, STAGES.length, {
      size: [360, 270],
      label: 56,
      note: 'Driven by a scripted, synthetic grasp recording (<code>dqhand synthesize --scene grasp</code>, our own kinematics; not captured from a person), played through the live manipulation loop (<code>dqhand demo --scene</code>) with the hand held still at each stage. The object held is tinted orange; red dots and lines: contacts and their normals.',
    });
  } finally {
    await server?.stop();
    rmSync(work, { recursive: true, force: true });
  }
}

/** three.js's linear skinning beside three-dqs (packages/three-dqs, its test page's `?figure`). */
async function dqsFigure(compose) {
  const pkg = path.join(root, 'packages/three-dqs');
  const work = mkdtempSync(path.join(process.env.TMPDIR ?? tmpdir(), 'dqs-figure-'));
  execFileSync(path.join(pkg, 'node_modules/.bin/vite'), ['build', '--config', 'test/vite.config.js', '--outDir', work, '--logLevel', 'warn'], { cwd: pkg, stdio: 'inherit' });
  copyFileSync(path.join(root, 'third_party/node_modules/@webxr-input-profiles/assets/dist/profiles/generic-hand/right.glb'), path.join(work, 'hand.glb'));
  const server = await serveStatic(work);
  try {
    const page = await browser.newPage({ viewport: { width: 400, height: 400 } });
    await page.goto(`${server.url}?figure`);
    await page.waitForFunction(() => document.title === 'ready');
    /** The picture `draw` (window.figure or window.handFigure) makes of `kind`, as a data URL. */
    const shot = async (draw, kind, dual) => {
      await page.evaluate(([draw, kind, dual]) => window[draw](kind, dual, 360), [draw, kind, dual]);
      const png = await page.locator('#view').screenshot();
      return `data:image/png;base64,${png.toString('base64')}`;
    };
    const rowsOf = async (draw, kinds) => {
      const rows = [];
      for (const [kind, label] of kinds) {
        rows.push({ label, cells: [{ src: await shot(draw, kind, false), caption: "three.js's linear skinning" }, { src: await shot(draw, kind, true), caption: 'three-dqs' }] });
      }
      return rows;
    };
    const rows = await rowsOf('figure', [['twist', 'twisted 150°'], ['bend', 'bent 120°']]);
    const hand = await rowsOf('handFigure', [['twist', 'twisted 150°'], ['bend', 'bent 30° + 120°']]);
    await page.close();
    await compose('dqs-hand.png', 'Linear and dual quaternion skinning in three.js, the WebXR generic hand (glTF)', hand, 2, {
      size: [300, 300],
      label: 80,
      note: "The WebXR input profiles' generic hand, as GLTFLoader gives it, its index finger twisted 150° about its own axis at the knuckle (seen from the back of the hand), or bent 30° at the knuckle and 120° at the middle joint (seen from the side). Linear skinning wrings the twisted knuckle thin and folds the bent joint's inside in; dual quaternions keep the finger's thickness.",
    });
    await compose('dqs-twist-bend.png', 'Linear and dual quaternion skinning in three.js, a limb on two bones', rows, 2, {
      size: [300, 300],
      label: 80,
      note: 'A cylinder 30 cm long, 3.5 cm in radius, its skin shared by the two bones over 8 cm around the joint. Linear skinning pinches the twist into a candy wrapper and thins the bend; dual quaternions keep the limb round (and bulge a little at the bend\'s outside).',
    });
  } finally {
    await server.stop();
    rmSync(work, { recursive: true, force: true });
  }
}
