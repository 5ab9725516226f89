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

test('the rigged, skinned hand is valid glTF 2.0 with one skin and 25 joints, in its three regions\' materials and maps', async () => {
  const file = path.join(out, 'hand.glb');
  const report = await validate(file);
  // What the validator counts (its report.info has no skin count: hasSkins and maxInfluences):
  // a draw call per region (back, palm, nails), each over the same 8,668 vertices, which it
  // counts once per draw call.
  const { hasSkins, maxInfluences, drawCallCount, totalVertexCount, totalTriangleCount, animationCount, materialCount, hasTextures } = report.info;
  assert.deepEqual(
    { hasSkins, maxInfluences, drawCallCount, totalVertexCount, totalTriangleCount, animationCount, materialCount, hasTextures },
    { hasSkins: true, maxInfluences: 4, drawCallCount: 3, totalVertexCount: 3 * 8668, totalTriangleCount: 2 * 8668 - 4, animationCount: 0, materialCount: 3, hasTextures: true },
  );
  // The maps: four PNGs (albedo and normals of the back and of the palm), read by the validator.
  const images = report.info.resources.filter((r) => r.image);
  assert.deepEqual(images.map((r) => [r.mimeType, r.image.format]), Array(4).fill(['image/png', 'rgb']));
  // The skin itself, from the file's JSON: one, on the hand's mesh node, 25 joints that are
  // nodes of the file, and an inverse bind matrix for each.
  const json = JSON.parse(readGlbJson(file));
  assert.equal(json.skins.length, 1);
  const [skin] = json.skins;
  assert.equal(skin.joints.length, 25);
  assert.equal(new Set(skin.joints).size, 25);
  assert.ok(skin.joints.every((j) => Number.isInteger(j) && j >= 0 && j < json.nodes.length), `joints ${skin.joints}`);
  const ibm = json.accessors[skin.inverseBindMatrices];
  assert.deepEqual({ count: ibm.count, type: ibm.type }, { count: 25, type: 'MAT4' });
  const skinned = json.nodes.filter((n) => n.skin !== undefined);
  assert.deepEqual(skinned.map((n) => [n.skin, n.mesh]), [[0, 0]]);
  const { attributes } = json.meshes[0].primitives[0];
  assert.ok('JOINTS_0' in attributes && 'WEIGHTS_0' in attributes, JSON.stringify(attributes));
  // The regions share one set of vertex attributes.
  assert.ok(json.meshes[0].primitives.every((p) => JSON.stringify(p.attributes) === JSON.stringify(attributes)));
});

test('every posed mesh of the demo is valid glTF 2.0', async () => {
  const files = readdirSync(out).filter((f) => f.endsWith('.glb') && f !== 'hand.glb');
  assert.equal(files.length, 11 * 4); // the 11 library gestures, each with LB, QB, DQB, CoR
  for (const f of files) {
    const { info } = await validate(path.join(out, f));
    assert.deepEqual([info.hasSkins, info.drawCallCount, info.totalVertexCount], [false, 1, 8668], f);
  }
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
