// What the conformance pages skin: random poses (seeded, the same every run), the WebXR
// generic hand made elsewhere, and the read-back geometry that puts each vertex on its own pixel.

import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import type { Rig } from './rig';

/**
 * The rig's vertices as the conformance pages draw them: each one three times, a tiny triangle
 * (`corner`, in pixels) over pixel `slot` of a float target, with its skinning attributes, and
 * with `blend` the attribute `dqsBlend`; in the space of a mesh bound by {@link bindAtRest}.
 */
export function readbackGeometry(rig: Rig, blend?: (v: number) => number): THREE.BufferGeometry {
  const n = rig.vertices;
  const geometry = new THREE.BufferGeometry();
  const corners = [-0.4, -0.4, 0.8, -0.4, -0.4, 0.8];
  const position = new Float32Array(9 * n);
  const normal = new Float32Array(9 * n);
  const skinIndex = new Uint16Array(12 * n);
  const skinWeight = new Float32Array(12 * n);
  const corner = new Float32Array(6 * n);
  const slot = new Float32Array(3 * n);
  for (let v = 0; v < n; v++) {
    for (let c = 0; c < 3; c++) {
      const k = 3 * v + c;
      position.set(rig.rest.subarray(3 * v, 3 * v + 3), 3 * k);
      normal.set(rig.restNormals.subarray(3 * v, 3 * v + 3), 3 * k);
      skinIndex.set(rig.joint.subarray(4 * v, 4 * v + 4), 4 * k);
      skinWeight.set(rig.weight.subarray(4 * v, 4 * v + 4), 4 * k);
      corner.set(corners.slice(2 * c, 2 * c + 2), 2 * k);
      slot[k] = v;
    }
  }
  geometry.setAttribute('position', new THREE.BufferAttribute(position, 3));
  geometry.setAttribute('normal', new THREE.BufferAttribute(normal, 3));
  geometry.setAttribute('skinIndex', new THREE.BufferAttribute(skinIndex, 4));
  geometry.setAttribute('skinWeight', new THREE.BufferAttribute(skinWeight, 4));
  geometry.setAttribute('corner', new THREE.BufferAttribute(corner, 2));
  geometry.setAttribute('slot', new THREE.BufferAttribute(slot, 1));
  if (blend) geometry.setAttribute('dqsBlend', new THREE.BufferAttribute(slot.map(blend), 1));
  return inMeshSpace(geometry);
}

/** What both renderers offer to draw into a render target. */
export interface Drawer<Target> {
  setRenderTarget(target: Target | null): void;
  setClearColor(color: number, alpha: number): void;
  clear(): unknown;
  render(scene: THREE.Scene, camera: THREE.Camera): unknown;
}

/** `mesh` drawn alone into `target`, cleared to transparent black first (the renderer left drawing there). */
export function drawAlone<Target>(renderer: Drawer<Target>, target: Target, mesh: THREE.Object3D, camera: THREE.Camera): void {
  const scene = new THREE.Scene();
  scene.add(mesh);
  renderer.setRenderTarget(target);
  renderer.setClearColor(0x000000, 0);
  renderer.clear();
  renderer.render(scene, camera);
}

/**
 * The bind matrix of the meshes the pages skin: not the identity (turned 40° and moved), so a
 * skinning that swaps or forgets `bindMatrix` and `bindMatrixInverse` fails.
 */
export const BIND = new THREE.Matrix4().compose(new THREE.Vector3(0.3, -0.2, 0.1), new THREE.Quaternion().setFromAxisAngle(new THREE.Vector3(1, 2, 3).normalize(), 0.7), new THREE.Vector3(1, 1, 1));

/**
 * `geometry`, given in the skeleton's space, carried into the mesh's (by BIND⁻¹, normals
 * too), for a mesh bound by {@link bindAtRest}.
 */
export function inMeshSpace(geometry: THREE.BufferGeometry): THREE.BufferGeometry {
  return geometry.applyMatrix4(BIND.clone().invert());
}

/**
 * Binds `mesh` through BIND to `joints` bones at rest (identity skinning matrices), and returns
 * what poses them: each bone's world matrix set to its skinning matrix (16 per joint,
 * column-major; the inverses are identities).
 */
export function bindAtRest(mesh: THREE.SkinnedMesh, joints: number): (matrices: ArrayLike<number>) => void {
  const bones = Array.from({ length: joints }, () => {
    const bone = new THREE.Bone();
    bone.matrixAutoUpdate = false;
    bone.matrixWorldAutoUpdate = false;
    return bone;
  });
  mesh.bindMode = THREE.DetachedBindMode;
  mesh.bind(new THREE.Skeleton(bones, bones.map(() => new THREE.Matrix4())), BIND);
  return (matrices) => bones.forEach((bone, j) => bone.matrixWorld.fromArray(matrices, 16 * j));
}

/** Skinned values read back (3 a vertex, in the mesh's space) carried into the skeleton's by BIND, in place: points, or unit normals. */
export function toSkeletonSpace(values: Float32Array, normals: boolean): Float32Array {
  const v = new THREE.Vector3();
  const turn = new THREE.Matrix3().getNormalMatrix(BIND);
  for (let k = 0; k < values.length; k += 3) {
    v.fromArray(values, k);
    if (normals) v.applyMatrix3(turn).normalize();
    else v.applyMatrix4(BIND);
    v.toArray(values, k);
  }
  return values;
}

/** The `dqsBlend` of vertex `v` in mode 'blend': 0 (linear) for even vertices, 1 (dual quaternion) for odd ones. */
export const blendOf = (v: number) => v % 2;

/** Positions that are `even`'s on even vertices and `odd`'s on odd ones. */
export function alternate(even: ArrayLike<number>, odd: ArrayLike<number>): Float32Array {
  return Float32Array.from({ length: even.length }, (_, i) => (Math.floor(i / 3) % 2 ? odd[i] : even[i]));
}

/** Numbers in [0, 1) from a linear congruential generator started at `seed`: the same poses every run. */
function seeded(seed: number): () => number {
  let state = seed;
  return () => (state = (state * 1664525 + 1013904223) >>> 0) / 2 ** 32;
}

/** Random rigid skinning matrices: the whole hand turned up to 180° about a random axis, each joint by up to 60° more, and moved. */
export function randomPose(rig: Rig, seed: number): Float32Array {
  const random = seeded(seed);
  const axis = () => new THREE.Vector3(random() - 0.5, random() - 0.5, random() - 0.5).normalize();
  const whole = new THREE.Quaternion().setFromAxisAngle(axis(), Math.PI * (0.5 + 0.5 * random()));
  const out = new Float32Array(16 * rig.joints);
  const m = new THREE.Matrix4();
  for (let j = 0; j < rig.joints; j++) {
    const own = new THREE.Quaternion().setFromAxisAngle(axis(), (Math.PI / 3) * random());
    m.compose(new THREE.Vector3(random() * 0.1, random() * 0.1, random() * 0.1), whole.clone().multiply(own), new THREE.Vector3(1, 1, 1));
    out.set(m.elements, 16 * j);
  }
  return out;
}

/**
 * A random pose whose bones also scale and shear: each joint's matrix is a rigid one (`rigid`,
 * by default {@link randomPose}) times a symmetric positive matrix U diag(s) Uᵀ, s from 0.7 to 1.4 along a
 * random frame U. Returns the matrices and the scales, which the reference takes as given.
 */
export function scaledPose(rig: Rig, seed: number, rigid = randomPose(rig, seed)): { matrices: Float32Array; rigid: Float32Array; scales: number[][] } {
  const random = seeded(seed * 7919);
  const matrices = new Float32Array(rigid.length);
  const scales: number[][] = [];
  for (let j = 0; j < rig.joints; j++) {
    const u = new THREE.Matrix4().makeRotationFromQuaternion(new THREE.Quaternion(random() - 0.5, random() - 0.5, random() - 0.5, random() - 0.5).normalize());
    const d = new THREE.Matrix4().makeScale(0.7 + 0.7 * random(), 0.7 + 0.7 * random(), 0.7 + 0.7 * random());
    const s = u.clone().multiply(d).multiply(u.clone().transpose());
    const e = s.elements;
    scales.push([e[0], e[1], e[2], e[4], e[5], e[6], e[8], e[9], e[10]]);
    matrices.set(new THREE.Matrix4().fromArray(Array.from(rigid.subarray(16 * j, 16 * j + 16))).multiply(s).elements, 16 * j);
  }
  return { matrices, rigid, scales };
}

/**
 * The WebXR generic hand (hand.glb beside the page: a skinned glTF from the WebXR input
 * profiles, made elsewhere) as a rig: its vertices and normals carried into its skeleton's
 * space by its bind matrix, its own influences; and its bones' matrices in three poses, the
 * hand turned up to 180° and every joint up to 90° about a random axis.
 */
export async function outsideHand(): Promise<{ rig: Rig; poses: Float32Array[] }> {
  const gltf = await new GLTFLoader().loadAsync('hand.glb');
  let mesh: THREE.SkinnedMesh | undefined;
  gltf.scene.traverse((o) => {
    if ((o as THREE.SkinnedMesh).isSkinnedMesh) mesh = o as THREE.SkinnedMesh;
  });
  if (!mesh) throw new Error('hand.glb: no skinned mesh');
  const { geometry, skeleton, bindMatrix } = mesh;
  const n = geometry.attributes.position.count;
  const rest = new Float32Array(3 * n);
  const restNormals = new Float32Array(3 * n);
  const joint = new Uint32Array(4 * n);
  const weight = new Float32Array(4 * n);
  const normalMatrix = new THREE.Matrix3().getNormalMatrix(bindMatrix);
  const v = new THREE.Vector3();
  for (let i = 0; i < n; i++) {
    v.fromBufferAttribute(geometry.attributes.position, i).applyMatrix4(bindMatrix).toArray(rest, 3 * i);
    v.fromBufferAttribute(geometry.attributes.normal, i).applyMatrix3(normalMatrix).normalize().toArray(restNormals, 3 * i);
    for (let k = 0; k < 4; k++) {
      joint[4 * i + k] = geometry.attributes.skinIndex.getComponent(i, k);
      weight[4 * i + k] = geometry.attributes.skinWeight.getComponent(i, k);
    }
  }
  const empty = new Float32Array(0);
  const rig: Rig = { vertices: n, joints: skeleton.bones.length, rest, restNormals, joint, weight, triangles: new Uint32Array(0), skinning: empty, lb: empty, dqb: empty, dqbNormals: empty };
  const poses = [21, 22, 23].map((seed) => {
    const random = seeded(seed);
    const axis = () => new THREE.Vector3(random() - 0.5, random() - 0.5, random() - 0.5).normalize();
    skeleton.pose();
    skeleton.bones.forEach((bone, j) => bone.quaternion.multiply(new THREE.Quaternion().setFromAxisAngle(axis(), (j === 0 ? Math.PI : Math.PI / 2) * random())));
    gltf.scene.updateMatrixWorld(true);
    skeleton.update();
    return new Float32Array(skeleton.boneMatrices!);
  });
  return { rig, poses };
}


/** The limb of the figures: a cylinder 0.3 m long, 3.5 cm in radius. */
export const LIMB = { length: 0.3, radius: 0.035, blend: 0.04 };

/**
 * A capless cylinder along y from 0 to {@link LIMB}.length, skinned to a bone at 0 and one at
 * its middle, the second's share rising smoothly over ±{@link LIMB}.blend around the joint.
 */
export function limb(): THREE.BufferGeometry {
  const { length, radius, blend } = LIMB;
  const geometry = new THREE.CylinderGeometry(radius, radius, length, 48, 96, true);
  geometry.translate(0, length / 2, 0);
  const position = geometry.attributes.position;
  const index = new Uint16Array(4 * position.count);
  const weight = new Float32Array(4 * position.count);
  for (let v = 0; v < position.count; v++) {
    const t = THREE.MathUtils.clamp((position.getY(v) - length / 2 + blend) / (2 * blend), 0, 1);
    const second = t * t * (3 - 2 * t);
    index.set([0, 1, 0, 0], 4 * v);
    weight.set([1 - second, second, 0, 0], 4 * v);
  }
  geometry.setAttribute('skinIndex', new THREE.BufferAttribute(index, 4));
  geometry.setAttribute('skinWeight', new THREE.BufferAttribute(weight, 4));
  return geometry;
}

/** {@link limb} as a rig (its bind pose is the skeleton's space). */
export function limbRig(): Rig {
  const g = limb();
  const attribute = (name: string) => g.attributes[name].array;
  const empty = new Float32Array(0);
  return {
    vertices: g.attributes.position.count,
    joints: 2,
    rest: Float32Array.from(attribute('position')),
    restNormals: Float32Array.from(attribute('normal')),
    joint: Uint32Array.from(attribute('skinIndex')),
    weight: Float32Array.from(attribute('skinWeight')),
    triangles: new Uint32Array(0),
    skinning: empty,
    lb: empty,
    dqb: empty,
    dqbNormals: empty,
  };
}

/**
 * The limb turned as a whole up to 180° about a random axis and moved, its second bone twisted
 * 90–180° about the limb's axis at the joint (a wrist turned against its forearm): rigid
 * skinning matrices for {@link scaledPose}.
 */
export function twistedLimb(seed: number): Float32Array {
  const random = seeded(seed);
  const axis = new THREE.Vector3(random() - 0.5, random() - 0.5, random() - 0.5).normalize();
  const whole = new THREE.Matrix4().makeRotationAxis(axis, Math.PI * random()).setPosition(random() * 0.1, random() * 0.1, random() * 0.1);
  const joint = LIMB.length / 2;
  const twist = new THREE.Matrix4().makeTranslation(0, joint, 0).multiply(new THREE.Matrix4().makeRotationY(Math.PI * (0.5 + 0.5 * random()))).multiply(new THREE.Matrix4().makeTranslation(0, -joint, 0));
  const out = new Float32Array(32);
  out.set(whole.elements, 0);
  out.set(whole.clone().multiply(twist).elements, 16);
  return out;
}

/**
 * The positions the CPU path gives (`getVertexPosition`, which `applyBoneTransform` serves) for
 * each rig vertex of a read-back `mesh` (vertex 3v of it is vertex v of the rig) posed by
 * `matrices` through `pose`, in the skeleton's space.
 */
export function cpuSkinned(mesh: THREE.SkinnedMesh, pose: (matrices: ArrayLike<number>) => void, matrices: ArrayLike<number>, vertices: number): Float32Array {
  pose(matrices);
  mesh.skeleton.update();
  const out = new Float32Array(3 * vertices);
  const p = new THREE.Vector3();
  for (let v = 0; v < vertices; v++) mesh.getVertexPosition(3 * v, p).toArray(out, 3 * v);
  return toSkeletonSpace(out, false);
}
