// The conformance protocol, one for both renderers: the package's GPU skinning read back (per
// vertex, from a float render target) and compared with dqhand's native output of the same frame
// (`dqhand export-skinning`: rig.json and rig.bin beside the page) and, over random poses, with
// the reference written from the definitions (reference.ts).

import * as THREE from 'three';
import type { SkinningMode } from '../src/index';
import { alternate, limbRig, outsideHand, randomPose, scaledPose, twistedLimb } from './poses';
import { reference, worst } from './reference';
import { loadRig, type Rig } from './rig';

/** A renderer's way of running the package: GPU read-back of every vertex, and the CPU path. */
export interface Backend {
  /** The mesh's skinned positions or normals as the GPU computes them, 3 floats per vertex in the skeleton's space (`'three'`: three.js's own skinning; `unaligned`: the package's without its sign alignment). */
  readBack(rig: Rig, matrices: ArrayLike<number>, mode: SkinningMode | 'three', output: 'position' | 'normal', unaligned?: boolean): Promise<Float32Array>;
  /** The package's CPU path (applyBoneTransform) for every vertex. */
  cpuPositions(rig: Rig, matrices: ArrayLike<number>): Float32Array;
}

/** The diagonal of the rig's rest box: the bounds are fractions of it. */
const sizeOf = (rig: Rig) => new THREE.Box3().setFromArray(rig.rest).getSize(new THREE.Vector3()).length();

/**
 * Everything the test asserts, measured in one go. `exports` names more frames of the same hand
 * that dqhand exported in other poses (`name`.json, `name`.bin), each compared with dqhand's own
 * DQB of it.
 */
export async function conformance(backend: Backend, exports: string[] = []) {
  const { readBack, cpuPositions } = backend;
  const rig = await loadRig();
  const size = sizeOf(rig);
  const exported = {
    three: worst(await readBack(rig, rig.skinning, 'three', 'position'), rig.lb),
    lbs: worst(await readBack(rig, rig.skinning, 'lbs', 'position'), rig.lb),
    dqs: worst(await readBack(rig, rig.skinning, 'dqs', 'position'), rig.dqb),
    dqsNormals: worst(await readBack(rig, rig.skinning, 'dqs', 'normal'), rig.dqbNormals, true),
    cpu: worst(cpuPositions(rig, rig.skinning), rig.dqb),
    blend: worst(await readBack(rig, rig.skinning, 'blend', 'position'), alternate(rig.lb, rig.dqb)),
  };
  /** One pose's GPU positions and normals, and CPU positions, against `positions` and `normals`. */
  const measure = async (r: Rig, matrices: ArrayLike<number>, positions: ArrayLike<number>, normals: ArrayLike<number>) => ({
    dqs: worst(await readBack(r, matrices, 'dqs', 'position'), positions),
    dqsNormals: worst(await readBack(r, matrices, 'dqs', 'normal'), normals, true),
    cpu: worst(cpuPositions(r, matrices), positions),
  });
  const native = [];
  for (const name of exports) {
    const other = await loadRig(name);
    native.push({ name, ...(await measure(other, other.skinning, other.dqb, other.dqbNormals)) });
  }
  const random = [];
  for (let seed = 1; seed <= 6; seed++) {
    const pose = randomPose(rig, seed);
    const ref = reference(rig, pose);
    random.push({ seed, ...(await measure(rig, pose, ref.positions, ref.normals)), unaligned: worst(await readBack(rig, pose, 'dqs', 'position', true), ref.positions) });
  }
  const scaled = [];
  for (let seed = 11; seed <= 13; seed++) {
    const pose = scaledPose(rig, seed);
    const ref = reference(rig, pose.rigid, pose.scales);
    scaled.push({ seed, ...(await measure(rig, pose.matrices, ref.positions, ref.normals)) });
  }
  // The limb of the figures, its second bone twisted 90–180° about its axis, both bones scaled and sheared.
  const cylinder = limbRig();
  const limb = [];
  for (let seed = 31; seed <= 33; seed++) {
    const pose = scaledPose(cylinder, seed, twistedLimb(seed));
    const ref = reference(cylinder, pose.rigid, pose.scales);
    limb.push({ seed, ...(await measure(cylinder, pose.matrices, ref.positions, ref.normals)) });
  }
  const outside = await outsideHand();
  const generic = [];
  for (const [k, pose] of outside.poses.entries()) {
    const ref = reference(outside.rig, pose);
    generic.push({ seed: 21 + k, ...(await measure(outside.rig, pose, ref.positions, ref.normals)) });
  }
  return { size, vertices: rig.vertices, exported, native, random, scaled, limb: { size: sizeOf(cylinder), vertices: cylinder.vertices, poses: limb }, outside: { size: sizeOf(outside.rig), vertices: outside.rig.vertices, poses: generic } };
}

/**
 * The rig's shadow in two random poses (turned up to 180°, joints up to 60°), as `pictures`
 * draws it (see webgpu_readback.ts) against the reference's DQB of the pose.
 */
export async function shadowConformance(pictures: (rig: Rig, matrices: ArrayLike<number>, positions: ArrayLike<number>) => Promise<object>) {
  const rig = await loadRig();
  const out = [];
  for (const seed of [2, 4]) {
    const pose = randomPose(rig, seed);
    out.push({ seed, ...(await pictures(rig, pose, reference(rig, pose).positions)) });
  }
  return out;
}

/**
 * Two meshes of one material in two random poses, drawn in one frame through one shared build
 * (`draw`: see webgpu_readback.ts): each one's positions against the reference of its own pose,
 * and the number of builds made.
 */
export async function sharedBuildConformance(draw: (rig: Rig, a: ArrayLike<number>, b: ArrayLike<number>) => Promise<{ positions: Float32Array[]; builds: number }>) {
  const rig = await loadRig();
  const poses = [randomPose(rig, 7), randomPose(rig, 8)];
  const { positions, builds } = await draw(rig, poses[0], poses[1]);
  return { size: sizeOf(rig), builds, worst: positions.map((p, k) => worst(p, reference(rig, poses[k]).positions)) };
}
