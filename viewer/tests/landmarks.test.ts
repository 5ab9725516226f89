// MediaPipe's results as landmark records (src/landmarks.ts), against the pinhole camera and
// the axes written out here from their definitions.

import { describe, expect, test } from 'vitest';
import { CAMERA_FOV_DEG, HAND_DISTANCE_M, SIDE_CHANGE_FRAMES, SideFilter, chosenHand, handTranslation, handsToSend, landmarkRecord, userSide, type Point, type Vec3 } from '../../packages/dqhand/src/landmarks';

/** A right hand's 21 landmarks about their mean, as MediaPipe's world landmarks of a palm facing the camera, fingers up (m, camera axes: y down). */
function rightHandFacingCamera(): Point[] {
  const p: Vec3[] = [[0, 0.07, 0]]; // wrist below the centre
  // Thumb towards the camera's +x (a right palm seen from the front has its thumb on the image's right).
  p.push([0.03, 0.055, -0.01], [0.05, 0.035, -0.015], [0.065, 0.015, -0.02], [0.075, 0, -0.02]);
  for (const x of [0.025, 0.008, -0.01, -0.027]) for (const y of [0, -0.04, -0.065, -0.085]) p.push([x, y, -0.005]);
  const mean = [0, 1, 2].map((k) => p.reduce((s, q) => s + q[k], 0) / p.length);
  return p.map(([x, y, z]) => ({ x: x - mean[0], y: y - mean[1], z: z - mean[2] }));
}

/** The pinhole projection the camera is assumed to make: normalised image x, y of a camera-space point. */
function project([x, y, z]: Vec3, aspect: number): Point {
  const fx = 0.5 / Math.tan((CAMERA_FOV_DEG / 2) * (Math.PI / 180));
  return { x: 0.5 + (fx * x) / z, y: 0.5 + (fx * aspect * y) / z, z: 0 };
}

const imageOf = (world: Point[], centre: Vec3, aspect: number) => world.map((w) => project([w.x + centre[0], w.y + centre[1], w.z + centre[2]], aspect));

describe('placing the hand from the image', () => {
  test('the fitted translation is the one the image was made with', () => {
    const world = rightHandFacingCamera();
    for (const centre of [[0, 0, 0.5], [0.12, -0.08, 0.35], [-0.2, 0.1, 0.9]] as Vec3[]) {
      for (const aspect of [4 / 3, 16 / 9]) {
        const t = handTranslation(world, imageOf(world, centre, aspect), aspect)!;
        t.forEach((v, i) => expect(v).toBeCloseTo(centre[i], 6));
      }
    }
  });

  test('a degenerate image places nothing', () => {
    const world = rightHandFacingCamera();
    expect(handTranslation(world, world.map(() => ({ x: 0.5, y: 0.5, z: 0 })), 4 / 3)).toBeNull();
    expect(landmarkRecord(1, 'right', world.slice(1), imageOf(world, [0, 0, 0.5], 4 / 3).slice(1), 4 / 3, [0, 0, 0])).toBeNull();
  });

  test("the user's moves are the hand's moves on screen, and a right hand stays right", () => {
    const world = rightHandFacingCamera();
    const anchor: Vec3 = [0.1, 1.0, -0.2];
    const at = (centre: Vec3) => landmarkRecord(2, 'right', world, imageOf(world, centre, 4 / 3), 4 / 3, anchor)!.landmarks;
    const mean = (l: Vec3[]) => [0, 1, 2].map((k) => l.reduce((s, p) => s + p[k], 0) / l.length);
    // Before the camera at the hand distance: the centre lands on the anchor.
    mean(at([0, 0, HAND_DISTANCE_M])).forEach((v, k) => expect(v).toBeCloseTo(anchor[k], 4));
    // The camera's +x is the user's left; its +y is down; its +z is towards the user.
    const [left, down, back] = [at([0.1, 0, HAND_DISTANCE_M]), at([0, 0.1, HAND_DISTANCE_M]), at([0, 0, HAND_DISTANCE_M + 0.1])].map(mean);
    expect(left[0]).toBeCloseTo(anchor[0] - 0.1, 4);
    expect(down[1]).toBeCloseTo(anchor[1] - 0.1, 4);
    expect(back[2]).toBeCloseTo(anchor[2] + 0.1, 4);
    // Fingers up, palm away from the user, thumb on the user's left: a right hand seen from behind.
    const l = at([0, 0, HAND_DISTANCE_M]);
    const sub = (a: Vec3, b: Vec3) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    const [up, thumb] = [sub(l[12], l[0]), sub(l[4], l[0])];
    expect(up[1]).toBeGreaterThan(0.1);
    expect(thumb[0]).toBeLessThan(-0.05);
    // The palm's normal (index × pinky bases from the wrist) turns with the hand: a mirror would flip it.
    const [a, b] = [sub(l[5], l[0]), sub(l[17], l[0])];
    const normal = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
    const [ca, cb] = [sub([world[5].x, world[5].y, world[5].z], [world[0].x, world[0].y, world[0].z]), sub([world[17].x, world[17].y, world[17].z], [world[0].x, world[0].y, world[0].z])];
    const cameraNormal = [ca[1] * cb[2] - ca[2] * cb[1], ca[2] * cb[0] - ca[0] * cb[2], ca[0] * cb[1] - ca[1] * cb[0]];
    // A half turn about z turns a cross product as it turns vectors: x and y flip, z stays.
    expect(normal[2]).toBeCloseTo(cameraNormal[2], 9);
    expect(normal[0]).toBeCloseTo(-cameraNormal[0], 9);
  });
});

describe('which hand', () => {
  test("MediaPipe's labels are the other hand in the camera's own image", () => {
    expect(userSide('Left')).toBe('right');
    expect(userSide('Right')).toBe('left');
  });

  test("the user's right hand is followed when both are seen", () => {
    expect(chosenHand(['Right', 'Left'])).toBe(1);
    expect(chosenHand(['Right'])).toBe(0);
    expect(chosenHand([])).toBe(-1);
  });

  test('a flickering label does not change the side; one that stays does', () => {
    const f = new SideFilter();
    expect(f.update('right')).toBe('right');
    for (let i = 1; i < SIDE_CHANGE_FRAMES; i++) expect(f.update('left')).toBe('right');
    expect(f.update('right')).toBe('right');
    for (let i = 1; i < SIDE_CHANGE_FRAMES; i++) expect(f.update('left')).toBe('right');
    expect(f.update('left')).toBe('left');
    f.reset();
    expect(f.update('right')).toBe('right');
  });
});

describe('the hands a camera frame sends', () => {
  test('to an engine of two hands, both when their labels differ; else the one followed', () => {
    expect(handsToSend(['left', 'right'], 1, true)).toEqual([0, 1]);
    expect(handsToSend(['left', 'right'], 1, false)).toEqual([1]);
    // Labelled alike: one of them, or the engine's one hand would jump between two.
    expect(handsToSend(['right', 'right'], 0, true)).toEqual([0]);
    expect(handsToSend(['left'], 0, true)).toEqual([0]);
    expect(handsToSend([], -1, true)).toEqual([]);
  });
});
