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

  /** The bone matrices the data was last computed from: an update that finds them unchanged does nothing. */
  private readonly last: Float32Array;
  private readonly rotation = new Matrix4();
  private readonly quaternion = new Quaternion();
  // Scratch for one bone (column-major 3×3s), so a frame allocates nothing.
  private readonly linear = new Float64Array(9);
  private readonly polar = new Float64Array(9);
  private readonly cofactors = new Float64Array(9);

  constructor(readonly boneCount: number) {
    this.data = new Float32Array(Math.max(boneCount, 1) * FLOATS_PER_BONE);
    this.last = new Float32Array(16 * boneCount).fill(NaN);
    this.texture = new DataTexture(this.data, TEXELS_PER_BONE, Math.max(boneCount, 1), RGBAFormat, FloatType);
    this.texture.needsUpdate = true;
  }

  /**
   * Recomputes every bone's parts from `skeleton`'s `boneMatrices` (as its last `update` left
   * them), unless they are what they were last time (a skeleton updated twice in a frame, by
   * a shadow pass and the main one, or not moving).
   */
  update(skeleton: Skeleton): void {
    const matrices = skeleton.boneMatrices;
    if (!matrices || sameValues(matrices, this.last)) return;
    this.last.set(matrices.subarray(0, this.last.length));
    for (let b = 0; b < this.boneCount; b++) this.split(matrices, 16 * b, b);
    this.texture.needsUpdate = true;
  }

  /** Splits the affine transform at `m[o…o+15]` into bone `b`'s dual quaternion and scale–shear. */
  private split(m: ArrayLike<number>, o: number, b: number): void {
    const a = this.linear;
    for (let c = 0; c < 3; c++) for (let r = 0; r < 3; r++) a[3 * c + r] = m[o + 4 * c + r];
    const det = determinant(a);
    // A bone scaled to nothing (glTF animations hide parts so) has no rotation to find: it is
    // all S. A mirroring bone (negative determinant) has no rotation either: its mirror goes
    // into S.
    const r = this.polar;
    if (Math.abs(det) < SINGULAR) r.set(IDENTITY);
    else {
      for (let i = 0; i < 9; i++) r[i] = det < 0 ? -a[i] : a[i];
      polarRotation(r, this.cofactors);
    }
    this.rotation.set(r[0], r[3], r[6], 0, r[1], r[4], r[7], 0, r[2], r[5], r[8], 0, 0, 0, 0, 1);
    const q = this.quaternion.setFromRotationMatrix(this.rotation);
    const [tx, ty, tz] = [m[o + 12], m[o + 13], m[o + 14]];
    const f = b * FLOATS_PER_BONE;
    const d = this.data;
    d[f] = q.x;
    d[f + 1] = q.y;
    d[f + 2] = q.z;
    d[f + 3] = q.w;
    // The dual part ½ t q, t the translation as a pure quaternion.
    d[f + 4] = 0.5 * (tx * q.w + ty * q.z - tz * q.y);
    d[f + 5] = 0.5 * (-tx * q.z + ty * q.w + tz * q.x);
    d[f + 6] = 0.5 * (tx * q.y - ty * q.x + tz * q.w);
    d[f + 7] = -0.5 * (tx * q.x + ty * q.y + tz * q.z);
    // S = Rᵀ A, column by column (column-major like three's matrices).
    let off = 0;
    for (let c = 0; c < 3; c++) {
      for (let row = 0; row < 3; row++) {
        const value = r[3 * row] * a[3 * c] + r[3 * row + 1] * a[3 * c + 1] + r[3 * row + 2] * a[3 * c + 2];
        d[f + 8 + 4 * c + row] = value;
        off = Math.max(off, Math.abs(value - (row === c ? 1 : 0)));
      }
      d[f + 8 + 4 * c + 3] = 0;
    }
    d[f + 11] = off > RIGID ? 1 : 0;
  }

  dispose(): void {
    this.texture.dispose();
  }
}

const IDENTITY = [1, 0, 0, 0, 1, 0, 0, 0, 1];

/** Whether `a` starts with `b`'s values (NaN never equals: a fresh `b` always differs). */
function sameValues(a: ArrayLike<number>, b: Float32Array): boolean {
  for (let i = 0; i < b.length; i++) if (a[i] !== b[i]) return false;
  return true;
}

/** The determinant of a column-major 3×3 matrix. */
function determinant(m: ArrayLike<number>): number {
  return m[0] * (m[4] * m[8] - m[7] * m[5]) - m[3] * (m[1] * m[8] - m[7] * m[2]) + m[6] * (m[1] * m[5] - m[4] * m[2]);
}

/**
 * Turns `x`, a column-major 3×3 matrix with a positive determinant, into the rotation of its
 * polar decomposition `A = R S`: Higham's iteration `X ← (X + X⁻ᵀ) / 2`, which converges
 * quadratically (a rigid bone's matrix, a rotation up to float rounding, stops after two
 * steps). `scratch` holds X⁻ᵀ.
 */
function polarRotation(x: Float64Array, scratch: Float64Array): void {
  for (let k = 0; k < 32; k++) {
    // X⁻ᵀ = cofactor matrix / det.
    const det = determinant(x);
    scratch[0] = (x[4] * x[8] - x[7] * x[5]) / det;
    scratch[1] = (x[6] * x[5] - x[3] * x[8]) / det;
    scratch[2] = (x[3] * x[7] - x[6] * x[4]) / det;
    scratch[3] = (x[7] * x[2] - x[1] * x[8]) / det;
    scratch[4] = (x[0] * x[8] - x[6] * x[2]) / det;
    scratch[5] = (x[6] * x[1] - x[0] * x[7]) / det;
    scratch[6] = (x[1] * x[5] - x[4] * x[2]) / det;
    scratch[7] = (x[3] * x[2] - x[0] * x[5]) / det;
    scratch[8] = (x[0] * x[4] - x[3] * x[1]) / det;
    let change = 0;
    for (let i = 0; i < 9; i++) {
      const next = 0.5 * (x[i] + scratch[i]);
      change = Math.max(change, Math.abs(next - x[i]));
      x[i] = next;
    }
    if (change < 1e-12) break;
  }
}
