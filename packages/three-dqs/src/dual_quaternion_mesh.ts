import type { Skeleton, SkinnedMesh, Vector3, Vector4 } from 'three';
import { BoneDualQuaternions } from './bone_dual_quaternions.js';
import { CpuSkinning } from './cpu_skinning.js';
import type { SkinningMode } from './skinning_chunks.js';

/** A skeleton's bone data, shared by the meshes that use it: its texture takes the place of three.js's. */
interface SkeletonState {
  bones: BoneDualQuaternions;
  users: number;
  update: Skeleton['update'];
  boneTexture: Skeleton['boneTexture'];
}

const skeletons = new WeakMap<Skeleton, SkeletonState>();
/** Meshes skinned with dual quaternions now. */
const attachedMeshes = new WeakSet<SkinnedMesh>();

/** The dual quaternions of `skeleton`, if a mesh of it uses them. */
export function bonesOf(skeleton: Skeleton): BoneDualQuaternions | undefined {
  return skeletons.get(skeleton)?.bones;
}

/** The bone data of `skeleton`, made and hooked into its `update` by the first mesh to ask. */
function share(skeleton: Skeleton): SkeletonState {
  let state = skeletons.get(skeleton);
  if (!state) {
    const bones = new BoneDualQuaternions(skeleton.bones.length);
    const made: SkeletonState = { bones, users: 0, update: skeleton.update, boneTexture: skeleton.boneTexture };
    // Both renderers update each skeleton once a frame before drawing; WebGLRenderer binds
    // `boneTexture` to every mesh of it (each through its own bind matrix): the dual
    // quaternions go there.
    skeleton.update = function (this: Skeleton) {
      made.update.call(this);
      bones.update(this);
    };
    skeleton.boneTexture = bones.texture;
    skeletons.set(skeleton, made);
    state = made;
  }
  state.users++;
  return state;
}

/** Gives `skeleton` back its own update and texture once no mesh uses its dual quaternions. */
function unshare(skeleton: Skeleton, state: SkeletonState): void {
  if (--state.users > 0) return;
  skeleton.update = state.update;
  skeleton.boneTexture = state.boneTexture;
  state.bones.dispose();
  skeletons.delete(skeleton);
}

/** What {@link attach} did to a mesh, and how to undo it. */
export interface Attached {
  readonly bones: BoneDualQuaternions;
  detach(): void;
}

/**
 * The renderer-independent part of dual quaternion skinning on `mesh`: its skeleton's bone
 * data (shared with the skeleton's other meshes) and the CPU path (`applyBoneTransform`, which
 * raycasting and bounding volumes use) doing in double precision what the GPU does. Throws,
 * naming the mesh, where it cannot skin it in `mode`.
 */
export function attach(mesh: SkinnedMesh, mode: SkinningMode): Attached {
  const name = mesh.name || 'mesh';
  if (!mesh.isSkinnedMesh || !mesh.skeleton) throw new Error(`${name}: not a SkinnedMesh with a skeleton`);
  if (mode === 'blend' && !mesh.geometry.attributes.dqsBlend) throw new Error(`${name}: mode 'blend' needs the vertex attribute dqsBlend`);
  if (attachedMeshes.has(mesh)) throw new Error(`${name}: already skinned with dual quaternions (dispose that first)`);
  attachedMeshes.add(mesh);
  const skeleton = mesh.skeleton;
  const state = share(skeleton);
  skeleton.update();
  const cpu = new CpuSkinning(state.bones.data, mode);
  mesh.applyBoneTransform = (index: number, target: Vector3 | Vector4) => {
    cpu.apply(mesh, index, target);
    return target as never;
  };
  // three.js's own CPU path reads the bones as they are; this one reads the data of the last
  // skeleton update, so the bounding volumes and raycasting update it first (once per call).
  const refreshed = (['computeBoundingBox', 'computeBoundingSphere', 'raycast'] as const).map((method) => {
    const own = mesh[method];
    mesh[method] = function (this: SkinnedMesh, ...args: unknown[]) {
      skeleton.update();
      return (own as (...a: unknown[]) => void).apply(this, args);
    } as never;
    return method;
  });
  return {
    bones: state.bones,
    detach() {
      for (const method of [...refreshed, 'applyBoneTransform']) delete (mesh as unknown as Record<string, unknown>)[method];
      unshare(skeleton, state);
      attachedMeshes.delete(mesh);
    },
  };
}
