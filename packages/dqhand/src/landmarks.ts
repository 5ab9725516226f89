// MediaPipe Hands' results as the engine's landmark records (crates/dqhand/src/input/json_record.rs):
// the world landmarks (metres, about the hand's centre) placed where the camera sees the hand,
// then turned from the camera's axes into the engine's world. No DOM: the tests run it in Node.
//
// The camera's axes are MediaPipe's: x right in the camera's own (unmirrored) image, y down,
// z away from the camera, towards the user. The engine's world is glTF's: +Y up, and the
// viewer looks along −Z. The user faces the screen with the camera on it, so their right is
// the camera's −x, their up −y, and towards them +z: a half turn about z, a rotation, so a
// right hand stays a right hand. The hand moves on screen as the user's hand moves before it.

/** A landmark as MediaPipe gives it (world: metres; image: x, y in [0, 1] of the image, z relative). */
export interface Point {
  x: number;
  y: number;
  z: number;
}

/** A user's hand. */
export type Side = 'left' | 'right';

export type Vec3 = [number, number, number];

/** Horizontal field of view assumed for a webcam, degrees (most are 55° to 78°). */
export const CAMERA_FOV_DEG = 60;
/** A hand this far from the camera (m), in the image's centre, is placed at the anchor. */
export const HAND_DISTANCE_M = 0.5;
/** Nearest a hand may be to the camera (m); a fit nearer is not a hand's (a degenerate image). */
const NEAREST_M = 0.05;

/** The engine's landmarks record (`landmarks`: 21 positions in MediaPipe's order, m, world axes). */
export interface LandmarkRecord {
  t: number;
  hand: Side;
  landmarks: Vec3[];
}

/**
 * The user's hand from MediaPipe's label. MediaPipe labels hands as if the image were
 * mirrored (a selfie view); the page gives it the camera's own image, so the label is the
 * other hand (MediaPipe's documentation says to swap it then).
 */
export function userSide(label: 'Left' | 'Right'): Side {
  return label === 'Left' ? 'right' : 'left';
}

/**
 * Where the hand's centre is in the camera's space (m): the translation `T` whose pinhole
 * projection of the world landmarks `W + T` best fits the image landmarks, in the least-squares
 * sense. Each landmark gives two equations linear in `T` (u − ½)(W_z + T_z) = f_x (W_x + T_x)
 * and the same in y; the world landmarks are already in the camera's axes, so no rotation is
 * fitted. `aspect` is the image's width over its height. Null for a degenerate fit.
 */
export function handTranslation(world: readonly Point[], image: readonly Point[], aspect: number, fovDeg = CAMERA_FOV_DEG): Vec3 | null {
  const fx = 1 / (2 * Math.tan((fovDeg * Math.PI) / 360));
  const fy = fx * aspect;
  // The normal equations AᵀA T = Aᵀb, accumulated row by row.
  const m = [0, 0, 0, 0, 0, 0, 0, 0, 0];
  const r = [0, 0, 0];
  const row = (a: Vec3, b: number) => {
    for (let i = 0; i < 3; i++) {
      for (let j = 0; j < 3; j++) m[3 * i + j] += a[i] * a[j];
      r[i] += a[i] * b;
    }
  };
  for (let i = 0; i < Math.min(world.length, image.length); i++) {
    const [w, u, v] = [world[i], image[i].x - 0.5, image[i].y - 0.5];
    row([fx, 0, -u], u * w.z - fx * w.x);
    row([0, fy, -v], v * w.z - fy * w.y);
  }
  const t = solve3(m, r);
  return t && t[2] > NEAREST_M ? t : null;
}

/** Solves the 3 × 3 system `m x = r` (row-major) by Cramer's rule; null if it is singular. */
function solve3(m: number[], r: number[]): Vec3 | null {
  const det = (a: number[]) => a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) + a[2] * (a[3] * a[7] - a[4] * a[6]);
  const d = det(m);
  if (!Number.isFinite(d) || Math.abs(d) < 1e-12) return null;
  const column = (c: number) => det(m.map((x, k) => (k % 3 === c ? r[Math.floor(k / 3)] : x)));
  return [column(0) / d, column(1) / d, column(2) / d];
}

/**
 * One hand of MediaPipe's results in the engine's world, into `out` (63 floats: 21 landmarks,
 * x y z, m): its world landmarks placed by [`handTranslation`] and turned about `anchor`.
 * False (and `out` untouched) when the hand cannot be placed. Allocates nothing but the fit.
 */
export function placeLandmarks(world: readonly Point[], image: readonly Point[], aspect: number, anchor: Vec3, out: Float32Array | Float64Array): boolean {
  if (world.length !== 21 || image.length !== 21 || out.length !== 63) return false;
  const centre = handTranslation(world, image, aspect);
  if (!centre) return false;
  world.forEach((w, i) => {
    // The camera's axes turned half about z (the file's header), a hand HAND_DISTANCE_M ahead on the anchor.
    out[3 * i] = anchor[0] - (w.x + centre[0]);
    out[3 * i + 1] = anchor[1] - (w.y + centre[1]);
    out[3 * i + 2] = anchor[2] + (w.z + centre[2]) - HAND_DISTANCE_M;
  });
  return true;
}

/**
 * One hand of MediaPipe's results, the user's `side` one, as a landmarks record at time `t` (s),
 * placed as [`placeLandmarks`] does. Null when the hand cannot be placed.
 */
export function landmarkRecord(t: number, side: Side, world: readonly Point[], image: readonly Point[], aspect: number, anchor: Vec3): LandmarkRecord | null {
  const placed = new Float64Array(63);
  if (!placeLandmarks(world, image, aspect, anchor, placed)) return null;
  const round = (x: number) => Math.round(x * 1e5) / 1e5; // 10 µm: the record stays small
  const landmarks = Array.from({ length: 21 }, (_, i) => [round(placed[3 * i]), round(placed[3 * i + 1]), round(placed[3 * i + 2])] as Vec3);
  return { t, hand: side, landmarks };
}

/** Frames a lone hand's label must disagree in a row before its side changes. */
export const SIDE_CHANGE_FRAMES = 5;

/**
 * The side of a lone hand in view, steadied: MediaPipe's label of one hand flickers now and
 * then (a fist seen from the palm is much the same either way), and every flicker would have
 * the engine mirror the hand across the world. A side holds until the label has said the
 * other for `SIDE_CHANGE_FRAMES` frames in a row; `reset` when no hand is in view.
 */
export class SideFilter {
  private side: Side | null = null;
  private against = 0;

  /** The steadied side after a frame whose label says `seen`. */
  update(seen: Side): Side {
    if (this.side === null || seen === this.side) this.against = 0;
    else if (++this.against >= SIDE_CHANGE_FRAMES) this.against = 0;
    else return this.side;
    this.side = seen;
    return seen;
  }

  reset(): void {
    this.side = null;
    this.against = 0;
  }
}

/** The hand the engine follows (it drives one): the user's right one when both are seen. */
export function chosenHand(labels: readonly ('Left' | 'Right')[]): number {
  const right = labels.findIndex((l) => userSide(l) === 'right');
  return right >= 0 ? right : labels.length > 0 ? 0 : -1;
}

/**
 * The hands of a frame to send (indices into its `sides`): to an engine driving two (`both`),
 * every hand when two are seen with different sides, each driving the engine's hand of its
 * side; else only `followed` (none when it is −1). Two hands labelled alike are one hand seen
 * twice as far as the engine can tell: sending both would make one engine hand jump between them.
 */
export function handsToSend(sides: readonly Side[], followed: number, both: boolean): number[] {
  if (followed < 0) return [];
  return both && sides.length === 2 && sides[0] !== sides[1] ? [0, 1] : [followed];
}
