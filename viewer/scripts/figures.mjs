// `make figures`: the paper's Figures 5–7 reproduced on our hand with the real page in
// headless Chromium, written to docs/figures/ as PNG.
//
//   fig5-index-bend.png   index PIP bent 0–120° under QB, DQB and LB (paper Fig. 5, plus LB)
//   fig6-pip-zoom.png     close-up of the PIP joint at 120°, shaded and as a heat map (Fig. 6)
//   fig7-gestures-{dqb,qb,lb}.png   the daily gestures (Fig. 7)
//   viewer-split.png      the viewer itself, split view on the fist
//
// Joint limits are switched off for Figure 5/6 so the PIP can reach 120° (its range is 0–110°).

import { mkdirSync, writeFileSync } from 'node:fs';
import path from 'node:path';
import { launchBrowser, root, settle, startServer, waitState } from './harness.mjs';

const out = path.join(root, 'docs/figures');
mkdirSync(out, { recursive: true });
const PIP = 'index-finger-phalanx-intermediate.flex';
const CELL = 360;

const server = await startServer();
const browser = await launchBrowser();
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
  await waitState(ui, 's.visible.length === 3 && !s.frame.playing');
  await ui.waitForTimeout(500);
  await settle(ui, 4);
  writeFileSync(path.join(out, 'viewer-split.png'), await ui.screenshot());

  // Compose the grids in a plain page.
  const sheet = await browser.newPage({ viewport: { width: 1900, height: 1000 } });
  const compose = async (file, title, rows, columns) => {
    const cell = (c) => `<figure><img src="${c.src}"><figcaption>${c.caption}</figcaption></figure>`;
    const body = rows
      .map((r) => `<div class="row">${r.label ? `<div class="label">${r.label}</div>` : ''}<div class="cells" style="grid-template-columns: repeat(${columns}, ${CELL / 1.5}px)">${r.cells.map(cell).join('')}</div></div>`)
      .join('');
    await sheet.setContent(`<!doctype html><style>
      body { margin: 0; font: 15px system-ui, sans-serif; background: #fff; }
      #sheet { display: inline-block; padding: 10px 14px; }
      h1 { font-size: 16px; margin: 0 0 8px; }
      .row { display: flex; align-items: center; gap: 8px; margin-bottom: 4px; }
      .label { width: 44px; font-weight: 700; }
      .cells { display: grid; gap: 4px; }
      figure { margin: 0; text-align: center; }
      img { width: ${CELL / 1.5}px; height: ${CELL / 1.5}px; display: block; }
      figcaption { font-size: 13px; color: #444; }
    </style><div id="sheet"><h1>${title}</h1>${body}</div>`);
    await sheet.locator('#sheet').screenshot({ path: path.join(out, file) });
    console.log(`wrote docs/figures/${file}`);
  };
  await compose('fig5-index-bend.png', 'Index finger PIP bent 0–120° (paper Fig. 5, with LB added)', fig5, angles.length);
  await compose('fig6-pip-zoom.png', 'PIP joint at 120°, close up (paper Fig. 6): shaded and per-vertex edge-length change', fig6, 2);
  for (const [method, cells] of Object.entries(fig7)) {
    const rows = [cells.slice(0, 7), cells.slice(7)].map((c) => ({ label: '', cells: c }));
    await compose(`fig7-gestures-${method}.png`, `Daily gestures under ${method.toUpperCase()} (paper Fig. 7)`, rows, 7);
  }
} finally {
  await browser.close();
  await server.stop();
}
