import { DataTexture, FloatType, Matrix4, Quaternion, RGBAFormat, type Skeleton } from 'three';

/**
 * Floats per bone: the dual quaternion's real and dual parts, then the scale–shear matrix's
 * three columns, each padded to four; the first column's fourth is 1 where the bone scales or
 * shears at all (else the shader reads no more of it: rigid bones, the common case, cost two
 * fewer texels an influence).
 */
export const FLOATS_PER_BONE = 20;

/** How far from the identity a bone's scale–shear may be and still count as rigid. */
const RIGID = 1e-6;

/** A bone's 3×3 part with a determinant this small is singular (scaled to nothing). */
const SINGULAR = 1e-12;

/** Texels per bone in {@link BoneDualQuaternions.texture} (one row per bone). */
export const TEXELS_PER_BONE = FLOATS_PER_BONE / 4;

/**
 * Each bone's skinning matrix (`boneMatrix`, the bone's world matrix times its inverse bind
 * matrix, as three.js's skeleton computes it) split as dual quaternion skinning needs it:
 * `T = [R | t] · S`, a rigid part (a unit dual quaternion, blended by DQB) after a scale–shear
 * `S` (symmetric, blended linearly, as Kavan et al. 2008 §4 do for scaled bones).
 *
 * One per skeleton, like three.js's own bone texture, whose place it takes: every mesh of the
 * skeleton reads it, each through its own bind matrix. Computed once per frame per bone, on
 * the CPU, never per vertex.
 */
export class BoneDualQuaternions {
  /** {@link FLOATS_PER_BONE} floats per bone, in the skeleton's bone order. */
  readonly data: Float32Array;
  /** The same, as a float texture of {@link TEXELS_PER_BONE} texels per row, a row per bone. */
  readonly texture: DataTexture;

  private readonly full = new Matrix4();
  private readonly rotation = new Matrix4();
  private readonly quaternion = new Quaternion();

  constructor(readonly boneCount: number) {
    this.data = new Float32Array(Math.max(boneCount, 1) * FLOATS_PER_BONE);
    this.texture = new DataTexture(this.data, TEXELS_PER_BONE, Math.max(boneCount, 1), RGBAFormat, FloatType);
    this.texture.needsUpdate = true;
  }

  /** Recomputes every bone's parts from `skeleton`'s `boneMatrices` (as its last `update` left them). */
  update(skeleton: Skeleton): void {
    const matrices = skeleton.boneMatrices;
    if (!matrices) return;
    for (let b = 0; b < this.boneCount; b++) {
      this.full.fromArray(matrices, b * 16);
      this.split(b);
    }
    this.texture.needsUpdate = true;
  }

  /** Splits `this.full` (an affine transform) into bone `b`'s dual quaternion and scale–shear. */
  private split(b: number): void {
    const e = this.full.elements;
    const a = [e[0], e[1], e[2], e[4], e[5], e[6], e[8], e[9], e[10]];
    const det = determinant(a);
    // A bone scaled to nothing (glTF animations hide parts so) has no rotation to find: it is
    // all S. A mirroring bone (negative determinant) has no rotation either: its mirror goes
    // into S.
    const r = Math.abs(det) < SINGULAR ? [1, 0, 0, 0, 1, 0, 0, 0, 1] : polarRotation(a.map((x) => (det < 0 ? -x : x)));
    this.rotation.set(r[0], r[3], r[6], 0, r[1], r[4], r[7], 0, r[2], r[5], r[8], 0, 0, 0, 0, 1);
    const q = this.quaternion.setFromRotationMatrix(this.rotation);
    const [tx, ty, tz] = [e[12], e[13], e[14]];
    const o = b * FLOATS_PER_BONE;
    const d = this.data;
    d[o] = q.x;
    d[o + 1] = q.y;
    d[o + 2] = q.z;
    d[o + 3] = q.w;
    // The dual part ½ t q, t the translation as a pure quaternion.
    d[o + 4] = 0.5 * (tx * q.w + ty * q.z - tz * q.y);
    d[o + 5] = 0.5 * (-tx * q.z + ty * q.w + tz * q.x);
    d[o + 6] = 0.5 * (tx * q.y - ty * q.x + tz * q.w);
    d[o + 7] = -0.5 * (tx * q.x + ty * q.y + tz * q.z);
    // S = Rᵀ A, column by column (column-major like three's matrices).
    let off = 0;
    for (let c = 0; c < 3; c++) {
      for (let row = 0; row < 3; row++) {
        const value = r[3 * row] * a[3 * c] + r[3 * row + 1] * a[3 * c + 1] + r[3 * row + 2] * a[3 * c + 2];
        d[o + 8 + 4 * c + row] = value;
        off = Math.max(off, Math.abs(value - (row === c ? 1 : 0)));
      }
      d[o + 8 + 4 * c + 3] = 0;
    }
    d[o + 11] = off > RIGID ? 1 : 0;
  }

  dispose(): void {
    this.texture.dispose();
  }
}

/** The determinant of a column-major 3×3 matrix. */
function determinant(m: number[]): number {
  return m[0] * (m[4] * m[8] - m[7] * m[5]) - m[3] * (m[1] * m[8] - m[7] * m[2]) + m[6] * (m[1] * m[5] - m[4] * m[2]);
}

/**
 * The rotation of the polar decomposition `A = R S` of a column-major 3×3 matrix with a
 * positive determinant: Higham's iteration `X ← (X + X⁻ᵀ) / 2`, which converges quadratically
 * (a rigid bone's matrix, a rotation up to float rounding, stops after two steps).
 */
function polarRotation(a: number[]): number[] {
  let x = a.slice();
  for (let k = 0; k < 32; k++) {
    // X⁻ᵀ = cofactor matrix / det.
    const det = determinant(x);
    const inverseTranspose = [
      (x[4] * x[8] - x[7] * x[5]) / det, (x[6] * x[5] - x[3] * x[8]) / det, (x[3] * x[7] - x[6] * x[4]) / det,
      (x[7] * x[2] - x[1] * x[8]) / det, (x[0] * x[8] - x[6] * x[2]) / det, (x[6] * x[1] - x[0] * x[7]) / det,
      (x[1] * x[5] - x[4] * x[2]) / det, (x[3] * x[2] - x[0] * x[5]) / det, (x[0] * x[4] - x[3] * x[1]) / det,
    ];
    let change = 0;
    x = x.map((v, i) => {
      const next = 0.5 * (v + inverseTranspose[i]);
      change = Math.max(change, Math.abs(next - v));
      return next;
    });
    if (change < 1e-12) break;
  }
  return x;
}
