// The Khronos glTF validator on every kind of GLB dqhand writes: the rigged, skinned hand and
// posed meshes. Run by `make test` after the Rust tests (which build target/debug/dqhand).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync, readdirSync } from 'node:fs';
import { createRequire } from 'node:module';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const require = createRequire(path.join(root, 'third_party', 'package.json'));
const validator = require('gltf-validator');
const dqhand = process.env.DQHAND_BIN ?? path.join(root, 'target', 'debug', 'dqhand');

async function validate(file) {
  const report = await validator.validateBytes(new Uint8Array(readFileSync(file)));
  const errors = report.issues.messages.filter((m) => m.severity === 0);
  assert.equal(report.issues.numErrors, 0, `${file}: ${JSON.stringify(errors, null, 1)}`);
  return report;
}

const out = mkdtempSync(path.join(tmpdir(), 'dqhand-gltf-'));
execFileSync(dqhand, ['demo', '--out', out]);

test('the rigged, skinned hand is valid glTF 2.0 with one skin and 25 joints', async () => {
  const report = await validate(path.join(out, 'hand.glb'));
  assert.equal(report.info.skinCount ?? 1, 1);
  assert.ok(report.info.totalVertexCount === undefined || report.info.totalVertexCount === 8668);
  const json = JSON.parse(readGlbJson(path.join(out, 'hand.glb')));
  assert.equal(json.skins[0].joints.length, 25);
});

test('every posed mesh of the demo is valid glTF 2.0', async () => {
  const files = readdirSync(out).filter((f) => f.endsWith('.glb') && f !== 'hand.glb');
  assert.equal(files.length, 11 * 3); // the 11 library gestures, each with LB, QB, DQB
  for (const f of files) await validate(path.join(out, f));
});

test('a posed mesh of the WebXR generic hand is valid glTF 2.0', async () => {
  const hand = path.join(root, 'third_party/node_modules/@webxr-input-profiles/assets/dist/profiles/generic-hand/left.glb');
  const file = path.join(out, 'webxr-left.glb');
  execFileSync(dqhand, ['skin', '--mesh', hand, '--pose', path.join(out, '01-fist.pose.json'), '--out', file]);
  await validate(file);
});

/** The JSON chunk of a GLB. */
function readGlbJson(file) {
  const b = readFileSync(file);
  const length = b.readUInt32LE(12);
  return b.subarray(20, 20 + length).toString('utf8');
}
