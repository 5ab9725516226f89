import { Vector4, type SkinnedMesh, type Vector3 } from 'three';
import { FLOATS_PER_BONE } from './bone_dual_quaternions.js';
import type { SkinningMode } from './skinning_chunks.js';

/**
 * One vertex skinned on the CPU exactly as the shader does it (the same bone data, the same
 * steps): what `SkinnedMesh.applyBoneTransform` returns once the mesh uses dual quaternions,
 * so raycasting, `computeBoundingBox` and `computeBoundingSphere` see what is drawn. In
 * double precision, so it serves as the GPU's reference too.
 */
export class CpuSkinning {
  private readonly real = new Float64Array(4);
  private readonly dual = new Float64Array(4);
  private readonly scale = new Float64Array(9);
  private readonly linear = new Float64Array(3);
  private readonly local = new Vector4();

  constructor(
    private readonly bones: Float32Array,
    private readonly mode: SkinningMode,
  ) {}

  /**
   * Skins `target` (a point in `mesh`'s space) for vertex `index` of its geometry, through its
   * bind matrix as the shader does; a `Vector4` with w 0 is a direction.
   */
  apply(mesh: SkinnedMesh, index: number, target: Vector3 | Vector4): void {
    const geometry = mesh.geometry;
    const skinIndex = geometry.attributes.skinIndex;
    const skinWeight = geometry.attributes.skinWeight;
    const point = 'w' in target ? target.w : 1;
    const { x, y, z } = this.local.set(target.x, target.y, target.z, point).applyMatrix4(mesh.bindMatrix);
    const d = this.bones;
    const weights = [skinWeight.getX(index), skinWeight.getY(index), skinWeight.getZ(index), skinWeight.getW(index)];
    const offsets = [skinIndex.getX(index), skinIndex.getY(index), skinIndex.getZ(index), skinIndex.getW(index)].map((b) => b * FLOATS_PER_BONE);
    let heaviest = 0;
    for (let j = 1; j < 4; j++) if (weights[j] > weights[heaviest]) heaviest = j;
    const p = offsets[heaviest];
    this.real.fill(0);
    this.dual.fill(0);
    this.scale.fill(0);
    this.linear.fill(0);
    for (let j = 0; j < 4; j++) {
      const o = offsets[j];
      const w = weights[j];
      // (An unused influence may name any bone, even one the skeleton lacks.)
      if (w === 0) continue;
      const aligned = d[o] * d[p] + d[o + 1] * d[p + 1] + d[o + 2] * d[p + 2] + d[o + 3] * d[p + 3] < 0 ? -w : w;
      for (let k = 0; k < 4; k++) {
        this.real[k] += aligned * d[o + k];
        this.dual[k] += aligned * d[o + 4 + k];
      }
      // A rigid bone's scale–shear is the identity (its flag, the first column's w, is 0).
      const scaleOf = (c: number, r: number) => (d[o + 11] === 0 ? Number(c === r) : d[o + 8 + 4 * c + r]);
      for (let c = 0; c < 3; c++) for (let r = 0; r < 3; r++) this.scale[3 * c + r] += w * scaleOf(c, r);
      if (this.mode !== 'dqs') {
        const s = [0, 1, 2].map((r) => scaleOf(0, r) * x + scaleOf(1, r) * y + scaleOf(2, r) * z);
        const moved = rotate([d[o], d[o + 1], d[o + 2], d[o + 3]], s);
        const t = translation([d[o], d[o + 1], d[o + 2], d[o + 3]], [d[o + 4], d[o + 5], d[o + 6], d[o + 7]]);
        for (let k = 0; k < 3; k++) this.linear[k] += w * (moved[k] + point * t[k]);
      }
    }
    const length = Math.max(Math.hypot(this.real[0], this.real[1], this.real[2], this.real[3]), 1e-20);
    const q = [0, 1, 2, 3].map((k) => this.real[k] / length);
    const qd = [0, 1, 2, 3].map((k) => this.dual[k] / length);
    // (The scale–shear divided by the weights' sum, as the dual quaternion is normalised.)
    const total = Math.max(weights[0] + weights[1] + weights[2] + weights[3], 1e-20);
    for (let i = 0; i < 9; i++) this.scale[i] /= total;
    const m = this.scale;
    const scaled = [0, 1, 2].map((r) => m[r] * x + m[3 + r] * y + m[6 + r] * z);
    const moved = rotate(q, scaled);
    const t = translation(q, qd);
    const dualResult = [0, 1, 2].map((k) => moved[k] + point * t[k]);
    let blend = this.mode === 'lbs' ? 0 : 1;
    if (this.mode === 'blend') blend = geometry.attributes.dqsBlend?.getX(index) ?? 1;
    this.local.set(...([0, 1, 2].map((k) => this.linear[k] + (dualResult[k] - this.linear[k]) * blend) as [number, number, number]), point).applyMatrix4(mesh.bindMatrixInverse);
    target.x = this.local.x;
    target.y = this.local.y;
    target.z = this.local.z;
  }
}

/** `v` turned by the unit quaternion `q` (x, y, z, w). */
function rotate(q: number[], v: number[]): number[] {
  const c1 = [q[1] * v[2] - q[2] * v[1] + q[3] * v[0], q[2] * v[0] - q[0] * v[2] + q[3] * v[1], q[0] * v[1] - q[1] * v[0] + q[3] * v[2]];
  return [v[0] + 2 * (q[1] * c1[2] - q[2] * c1[1]), v[1] + 2 * (q[2] * c1[0] - q[0] * c1[2]), v[2] + 2 * (q[0] * c1[1] - q[1] * c1[0])];
}

/** The translation of the unit dual quaternion (`real`, `dual`): 2 · dual · conj(real). */
function translation(real: number[], dual: number[]): number[] {
  return [
    2 * (real[3] * dual[0] - dual[3] * real[0] + real[1] * dual[2] - real[2] * dual[1]),
    2 * (real[3] * dual[1] - dual[3] * real[1] + real[2] * dual[0] - real[0] * dual[2]),
    2 * (real[3] * dual[2] - dual[3] * real[2] + real[0] * dual[1] - real[1] * dual[0]),
  ];
}
