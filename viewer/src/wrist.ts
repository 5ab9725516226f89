// The wrist sliders: the engine's wrist pose (in each frame's header) as slider values, and the
// command that sets the wrist from them, so the sliders always start from what the engine has.

import * as THREE from 'three';
import type { Command } from './protocol';

/** The six wrist sliders: translation along x, y, z (cm), then rotation about x, y, z (degrees). */
export const WRIST_SLIDERS = [
  { label: 'x cm', min: -15, max: 15, step: 0.5 },
  { label: 'y cm', min: -15, max: 15, step: 0.5 },
  { label: 'z cm', min: -15, max: 15, step: 0.5 },
  { label: 'rot x°', min: -180, max: 180, step: 1 },
  { label: 'rot y°', min: -180, max: 180, step: 1 },
  { label: 'rot z°', min: -180, max: 180, step: 1 },
] as const;

/**
 * The engine's Euler convention: it builds the rotation as glam's
 * `Quat::from_euler(EulerRot::ZYX, z, y, x)`, that is Rz·Ry·Rx, which is three.js's order 'ZYX'.
 */
const ORDER = 'ZYX';
const _quaternion = new THREE.Quaternion();
const _euler = new THREE.Euler();

/**
 * The slider values of a frame's wrist (translation xyz in m, rotation quaternion xyzw),
 * exactly (a slider snaps what it shows to its step), written into `out`.
 */
export function wristSliderValues(wrist: Float32Array, out: number[]): number[] {
  _euler.setFromQuaternion(_quaternion.fromArray(wrist, 3), ORDER);
  out[0] = 100 * wrist[0];
  out[1] = 100 * wrist[1];
  out[2] = 100 * wrist[2];
  out[3] = THREE.MathUtils.radToDeg(_euler.x);
  out[4] = THREE.MathUtils.radToDeg(_euler.y);
  out[5] = THREE.MathUtils.radToDeg(_euler.z);
  return out;
}

/** The command that sets the wrist to the six slider values (cm, degrees). */
export function wristCommand(values: readonly number[]): Command {
  return { type: 'wrist', translation: [values[0] / 100, values[1] / 100, values[2] / 100], rotation_deg: [values[3], values[4], values[5]] };
}
