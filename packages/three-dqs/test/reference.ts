// The reference the conformance pages hold the package to, written here from the definitions
// (Kavan et al. 2008), in double precision: it shares no code with the package.

import type { Rig } from './rig';

/** A rotation matrix's unit quaternion (x, y, z, w), Shepperd's method, from a column-major 4×4. */
function quaternionOf(m: ArrayLike<number>, o: number): number[] {
  const r = (row: number, col: number) => m[o + 4 * col + row];
  const trace = r(0, 0) + r(1, 1) + r(2, 2);
  const candidates = [trace, r(0, 0), r(1, 1), r(2, 2)];
  const k = candidates.indexOf(Math.max(...candidates));
  let q: number[];
  if (k === 0) {
    const s = 2 * Math.sqrt(1 + trace);
    q = [(r(2, 1) - r(1, 2)) / s, (r(0, 2) - r(2, 0)) / s, (r(1, 0) - r(0, 1)) / s, s / 4];
  } else if (k === 1) {
    const s = 2 * Math.sqrt(1 + r(0, 0) - r(1, 1) - r(2, 2));
    q = [s / 4, (r(0, 1) + r(1, 0)) / s, (r(0, 2) + r(2, 0)) / s, (r(2, 1) - r(1, 2)) / s];
  } else if (k === 2) {
    const s = 2 * Math.sqrt(1 + r(1, 1) - r(0, 0) - r(2, 2));
    q = [(r(0, 1) + r(1, 0)) / s, s / 4, (r(1, 2) + r(2, 1)) / s, (r(0, 2) - r(2, 0)) / s];
  } else {
    const s = 2 * Math.sqrt(1 + r(2, 2) - r(0, 0) - r(1, 1));
    q = [(r(0, 2) + r(2, 0)) / s, (r(1, 2) + r(2, 1)) / s, s / 4, (r(1, 0) - r(0, 1)) / s];
  }
  return q;
}

/** Hamilton product of quaternions (x, y, z, w). */
function mul(a: number[], b: number[]): number[] {
  return [
    a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
    a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
    a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
    a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2],
  ];
}

/**
 * Reference DQB positions and normals: per vertex, dual quaternions aligned with the heaviest
 * influence, blended, normalised, applied as q v q* + t; with `scales` (a symmetric 3×3 per
 * joint, column-major, the bone's matrix being its rigid `matrices` one times it), the vertex is
 * first moved by the weighted sum of the scales, and the normal by that sum's inverse transpose.
 */
export function reference(rig: Rig, matrices: ArrayLike<number>, scales?: number[][]): { positions: Float64Array; normals: Float64Array } {
  const duals = Array.from({ length: rig.joints }, (_, j) => {
    const q = quaternionOf(matrices, 16 * j);
    const t = [matrices[16 * j + 12], matrices[16 * j + 13], matrices[16 * j + 14], 0];
    return { q, d: mul(t, q).map((x) => x / 2) };
  });
  const positions = new Float64Array(3 * rig.vertices);
  const normals = new Float64Array(3 * rig.vertices);
  for (let v = 0; v < rig.vertices; v++) {
    const w = Array.from(rig.weight.subarray(4 * v, 4 * v + 4));
    const ids = Array.from(rig.joint.subarray(4 * v, 4 * v + 4));
    const pivot = duals[ids[w.indexOf(Math.max(...w))]].q;
    const real = [0, 0, 0, 0];
    const dual = [0, 0, 0, 0];
    for (let k = 0; k < 4; k++) {
      const { q, d } = duals[ids[k]];
      const s = q.reduce((a, x, i) => a + x * pivot[i], 0) < 0 ? -w[k] : w[k];
      for (let i = 0; i < 4; i++) {
        real[i] += s * q[i];
        dual[i] += s * d[i];
      }
    }
    const length = Math.hypot(...real);
    const q = real.map((x) => x / length);
    const d = dual.map((x) => x / length);
    const conj = [-q[0], -q[1], -q[2], q[3]];
    const turn = (x: ArrayLike<number>) => mul(mul(q, [x[0], x[1], x[2], 0]), conj);
    const t = mul(d, conj).map((x) => 2 * x);
    let rest: ArrayLike<number> = rig.rest.subarray(3 * v, 3 * v + 3);
    let restNormal: ArrayLike<number> = rig.restNormals.subarray(3 * v, 3 * v + 3);
    if (scales) {
      const m = [0, 0, 0, 0, 0, 0, 0, 0, 0];
      for (let k = 0; k < 4; k++) for (let i = 0; i < 9; i++) m[i] += w[k] * scales[ids[k]][i];
      const times = (x: ArrayLike<number>) => [0, 1, 2].map((r) => m[r] * x[0] + m[3 + r] * x[1] + m[6 + r] * x[2]);
      // The inverse transpose, up to its (positive) determinant: solve mᵀ y = n by Cramer's rule.
      const col = (c: number) => [m[3 * c], m[3 * c + 1], m[3 * c + 2]];
      const cross = (a: number[], b: number[]) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
      const cof = [cross(col(1), col(2)), cross(col(2), col(0)), cross(col(0), col(1))];
      const n0 = restNormal;
      restNormal = [0, 1, 2].map((r) => cof[0][r] * n0[0] + cof[1][r] * n0[1] + cof[2][r] * n0[2]);
      rest = times(rest);
    }
    const p = turn(rest);
    const n = turn(restNormal);
    const nl = Math.hypot(n[0], n[1], n[2]);
    for (let i = 0; i < 3; i++) {
      positions[3 * v + i] = p[i] + t[i];
      normals[3 * v + i] = n[i] / nl;
    }
  }
  return { positions, normals };
}

/** Largest distance between two position arrays, and largest angle between two normal arrays (rad). */
export function worst(a: ArrayLike<number>, b: ArrayLike<number>, angles = false): number {
  let most = 0;
  for (let v = 0; v < a.length / 3; v++) {
    const [x, y, z] = [a[3 * v], a[3 * v + 1], a[3 * v + 2]];
    const [u, s, t] = [b[3 * v], b[3 * v + 1], b[3 * v + 2]];
    const value = angles ? Math.acos(Math.min(1, (x * u + y * s + z * t) / (Math.hypot(x, y, z) * Math.hypot(u, s, t)))) : Math.hypot(x - u, y - s, z - t);
    most = Math.max(most, value);
  }
  return most;
}

