// The engine's two WebAssembly builds (`make wasm`: target/wasm/node without SIMD, node-simd
// with the simd128 kernel) against an independent reference: LB, QB and DQB written here from
// their definitions (paper eqs. 3-6; Kavan et al. 2008 for the sign alignment), in doubles,
// sharing nothing with the engine but the mesh's rest geometry and influences. Random
// skinning transforms with rotations of every angle up to 180° (some exactly 180°, where a
// rotation's quaternion has w = 0 and its sign is arbitrary), every method, positions and
// normals, every kernel each build runs. And the builds themselves: the SIMD build holds SIMD
// instructions and the other none, and the probe a page loads by validates here.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { createRequire } from 'node:module';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

import { countInstructions } from './support_wasm_code.mjs';
import { simdSupported, SIMD_PROBE } from '../packages/dqhand/dist/simd.js';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const require = createRequire(import.meta.url);
const builds = ['node', 'node-simd'].map((dir) => ({ dir, wasm: require(path.join(root, 'target', 'wasm', dir, 'dqhand_wasm.js')) }));

/** A seeded generator of uniform numbers in [0, 1). */
function random(seed) {
  let s = seed >>> 0;
  return () => {
    s = (Math.imul(s, 1664525) + 1013904223) >>> 0;
    return s / 2 ** 32;
  };
}

/** Per joint a 3 × 4 matrix [R | t], row by row: a rotation of up to 180° about a random axis
 * (every fifth exactly 180°) and a translation of up to 10 cm. */
function transforms(joints, seed) {
  const u = random(seed);
  const out = new Float64Array(12 * joints);
  for (let j = 0; j < joints; j++) {
    const z = 2 * u() - 1;
    const phi = 2 * Math.PI * u();
    const r = Math.sqrt(1 - z * z);
    const [x, y] = [r * Math.cos(phi), r * Math.sin(phi)];
    const angle = j % 5 === 4 ? Math.PI : Math.PI * u();
    const [c, s] = [Math.cos(angle), Math.sin(angle)];
    const C = 1 - c;
    const R = [
      [c + x * x * C, x * y * C - z * s, x * z * C + y * s],
      [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
      [z * x * C - y * s, z * y * C + x * s, c + z * z * C],
    ];
    for (let i = 0; i < 3; i++) {
      out.set([...R[i], 0.2 * u() - 0.1], 12 * j + 4 * i);
    }
  }
  return out;
}

/** The unit quaternion [x, y, z, w] of rotation matrix rows `m` (Shepperd's method). */
function quaternion(m) {
  const [a, b, c] = [m[0], m[5], m[10]];
  const trace = a + b + c;
  let q;
  if (trace > 0) {
    const s = 2 * Math.sqrt(trace + 1);
    q = [(m[9] - m[6]) / s, (m[2] - m[8]) / s, (m[4] - m[1]) / s, s / 4];
  } else if (a > b && a > c) {
    const s = 2 * Math.sqrt(1 + a - b - c);
    q = [s / 4, (m[1] + m[4]) / s, (m[2] + m[8]) / s, (m[9] - m[6]) / s];
  } else if (b > c) {
    const s = 2 * Math.sqrt(1 + b - a - c);
    q = [(m[1] + m[4]) / s, s / 4, (m[6] + m[9]) / s, (m[2] - m[8]) / s];
  } else {
    const s = 2 * Math.sqrt(1 + c - a - b);
    q = [(m[2] + m[8]) / s, (m[6] + m[9]) / s, s / 4, (m[4] - m[1]) / s];
  }
  const n = Math.hypot(...q);
  return q.map((v) => v / n);
}

const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const dot = (a, b) => a.reduce((s, v, i) => s + v * b[i], 0);
const normalize = (v) => v.map((x) => x / Math.hypot(...v));

/** `v` rotated by the unit quaternion `q`: q v q*. */
function rotate(q, v) {
  const d = q.slice(0, 3);
  const t = cross(d, v).map((x) => 2 * x);
  const u = cross(d, t);
  return v.map((x, i) => x + q[3] * t[i] + u[i]);
}

/** The Hamilton product of quaternions [x, y, z, w]. */
function mul(a, b) {
  const [av, bv] = [a.slice(0, 3), b.slice(0, 3)];
  const c = cross(av, bv);
  return [...av.map((x, i) => a[3] * bv[i] + b[3] * x + c[i]), a[3] * b[3] - dot(av, bv)];
}

/**
 * The reference skin of one vertex: rest position `p` and normal `n`, influences `inf` ([joint,
 * weight] pairs, heaviest first), by `method`; returns [position, normal] and whether the
 * quaternion methods' sign alignment is ill-posed there (an influence's rotation nearly
 * square to the heaviest's in 4D: a sign either way is right, and the blends differ).
 */
function reference(method, m, q, p, n, inf) {
  const heaviest = q[inf[0][0]];
  const ambiguous = inf.some(([j]) => Math.abs(dot(q[j], heaviest)) < 1e-3);
  if (method === 'lb') {
    const M = new Array(12).fill(0);
    for (const [j, w] of inf) for (let i = 0; i < 12; i++) M[i] += w * m[12 * j + i];
    const rows = [0, 1, 2].map((i) => M.slice(4 * i, 4 * i + 3));
    const position = rows.map((r, i) => dot(r, p) + M[4 * i + 3]);
    // Normals by the inverse transpose (the cofactor matrix, up to the determinant's sign).
    const cof = [cross(rows[1], rows[2]), cross(rows[2], rows[0]), cross(rows[0], rows[1])];
    const det = dot(rows[0], cof[0]);
    const normal = normalize(cof.map((c) => dot(c, n) * Math.sign(det)));
    return { position, normal, ambiguous: false };
  }
  const sign = (j) => (dot(q[j], heaviest) < 0 ? -1 : 1);
  const t = (j) => [m[12 * j + 3], m[12 * j + 7], m[12 * j + 11]];
  const b0 = [0, 0, 0, 0];
  for (const [j, w] of inf) for (let i = 0; i < 4; i++) b0[i] += w * sign(j) * q[j][i];
  const c0 = normalize(b0);
  if (method === 'qb') {
    const tb = [0, 0, 0];
    for (const [j, w] of inf) for (let i = 0; i < 3; i++) tb[i] += w * t(j)[i];
    return { position: rotate(c0, p).map((x, i) => x + tb[i]), normal: rotate(c0, n), ambiguous };
  }
  // DQB: the dual parts ½ (t, 0) q, blended with the same signs, normalised by ‖b₀‖.
  const be = [0, 0, 0, 0];
  for (const [j, w] of inf) {
    const dual = mul([...t(j), 0], q[j]).map((x) => x / 2);
    for (let i = 0; i < 4; i++) be[i] += w * sign(j) * dual[i];
  }
  const norm = Math.hypot(...b0);
  const ce = be.map((x) => x / norm);
  // The translation: 2 cε c₀*.
  const tr = mul(ce, [-c0[0], -c0[1], -c0[2], c0[3]]).slice(0, 3).map((x) => 2 * x);
  return { position: rotate(c0, p).map((x, i) => x + tr[i]), normal: rotate(c0, n), ambiguous };
}

test('the SIMD build holds SIMD instructions and the other none; the probe picks the SIMD build here, and the package ships both', () => {
  const count = (dir) => countInstructions(readFileSync(path.join(root, 'target', 'wasm', dir, 'dqhand_wasm_bg.wasm')));
  const [plain, simd] = builds.map((b) => count(b.dir));
  assert.ok(plain.total > 10000 && simd.total > 10000, `instructions read: ${plain.total}, ${simd.total}`);
  assert.equal(plain.simd, 0, 'the build without SIMD holds none');
  assert.ok(simd.simd > 1000, `the SIMD build holds ${simd.simd} SIMD instructions`);
  assert.deepEqual(builds.map((b) => b.wasm.Skinner.kernels()), [['portable'], ['portable', 'simd128']]);
  // Node has had SIMD since 16.4; the probe is a module that validates only with it, and a
  // truncated one does not validate at all.
  assert.equal(simdSupported(), true);
  // What the npm package ships (`make package`): its SIMD file holds them, its other none.
  const shipped = (file) => countInstructions(readFileSync(path.join(root, 'packages', 'dqhand', 'wasm', file)));
  assert.equal(shipped('dqhand_wasm_simd_bg.wasm').simd, simd.simd);
  assert.equal(shipped('dqhand_wasm_bg.wasm').simd, 0);
  assert.equal(WebAssembly.validate(SIMD_PROBE.slice(0, -1)), false);
});

test('every kernel of both builds skins as LB, QB and DQB are defined, for rotations up to 180°', () => {
  for (const { dir, wasm } of builds) {
    const skinner = wasm.Skinner.builtin(0.19, 0.085, 'right');
    const [rest, normals, influences, k] = [skinner.restPositions(), skinner.restNormals(), skinner.influences(), skinner.influenceCount];
    const vertices = skinner.vertexCount;
    for (const seed of [1, 2, 3]) {
      const m = transforms(skinner.jointCount, seed);
      const q = Array.from({ length: skinner.jointCount }, (_, j) => quaternion(m.subarray(12 * j, 12 * j + 12)));
      for (const method of ['lb', 'qb', 'dqb']) {
        const expected = [];
        let ambiguous = 0;
        for (let v = 0; v < vertices; v++) {
          const inf = [];
          for (let i = 0; i < k; i++) if (influences[2 * (v * k + i)] >= 0) inf.push([influences[2 * (v * k + i)], influences[2 * (v * k + i) + 1]]);
          const r = reference(method, m, q, [...rest.subarray(3 * v, 3 * v + 3)], [...normals.subarray(3 * v, 3 * v + 3)], inf);
          expected.push(r);
          ambiguous += r.ambiguous ? 1 : 0;
        }
        assert.ok(ambiguous < vertices / 50, `${ambiguous} of ${vertices} vertices with an ill-posed sign`);
        let first = null;
        for (const kernel of wasm.Skinner.kernels()) {
          skinner.setMethod(method, kernel);
          skinner.deform(Float32Array.from(m));
          const memory = wasm.wasmMemory().buffer;
          const got = { p: new Float32Array(memory, skinner.positionsPtr(), 3 * vertices).slice(), n: new Float32Array(memory, skinner.normalsPtr(), 3 * vertices).slice() };
          let [dp, dn] = [0, 0];
          for (let v = 0; v < vertices; v++) {
            if (expected[v].ambiguous) continue;
            for (let i = 0; i < 3; i++) {
              dp = Math.max(dp, Math.abs(got.p[3 * v + i] - expected[v].position[i]));
              dn = Math.max(dn, Math.abs(got.n[3 * v + i] - expected[v].normal[i]));
            }
          }
          const what = `${dir} ${skinner.describe()}, seed ${seed}`;
          assert.ok(dp < 1e-6, `${what}: positions ${dp} m from the reference`);
          assert.ok(dn < 2e-5, `${what}: normals ${dn} from the reference`);
          // The kernels of a build agree with each other (they sum in the same order).
          if (first) {
            const apart = got.p.reduce((s, x, i) => Math.max(s, Math.abs(x - first.p[i])), 0);
            assert.ok(apart < 1e-6, `${what}: ${apart} m from the portable kernel`);
          }
          first ??= got;
        }
      }
    }
  }
});

test('bad transforms and unknown kernels are refused with the input named', () => {
  const { Skinner } = builds[0].wasm;
  const skinner = Skinner.builtin(0.19, 0.085, 'left');
  assert.throws(() => skinner.deform(new Float32Array(5)), /^Error: transforms: 5 floats given, \d+ joints need \d+$/);
  const nan = new Float32Array(12 * skinner.jointCount);
  nan[7] = NaN;
  assert.throws(() => skinner.deform(nan), /^Error: transforms\[7\] \(NaN\): not a finite number$/);
  assert.throws(() => skinner.setMethod('dqb', 'simd128'), /^Error: kernel "simd128": this build runs portable$/);
  assert.throws(() => skinner.setMethod('xx', 'portable'), /xx/);
  assert.equal(skinner.describe(), 'dqb portable');
});
