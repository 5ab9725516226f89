import { MeshDepthMaterial, MeshDistanceMaterial, RGBADepthPacking, type Material, type Skeleton, type SkinnedMesh, type Vector3, type Vector4, type WebGLProgramParametersWithUniforms } from 'three';
import { BoneDualQuaternions } from './bone_dual_quaternions.js';
import { CpuSkinning } from './cpu_skinning.js';
import { patchVertexShader, type SkinningMode } from './skinning_chunks.js';

export { BoneDualQuaternions, FLOATS_PER_BONE, TEXELS_PER_BONE } from './bone_dual_quaternions.js';
export { CpuSkinning } from './cpu_skinning.js';
export { MODES, patchVertexShader, skinbaseVertex, skinningParsVertex, skinningVertex, skinnormalVertex, type SkinningMode } from './skinning_chunks.js';

/** Options of {@link useDualQuaternionSkinning}. */
export interface DualQuaternionSkinningOptions {
  /**
   * `'dqs'` (the default), `'lbs'` (linear blending of the same bone data, for comparison), or
   * `'blend'`: per vertex, the attribute `dqsBlend` (0 linear, 1 dual quaternion, any mix).
   */
  mode?: SkinningMode;
  /**
   * Patch the mesh's own materials rather than copies of them (default false: other meshes
   * sharing them keep three.js's skinning). Shared, every skinned mesh drawn with them is
   * skinned this way, must use the same mode, and they stay so after `dispose`.
   */
  shareMaterials?: boolean;
}

/** What {@link useDualQuaternionSkinning} returns. */
export interface DualQuaternionSkinning {
  /** The per-bone data the shader reads (its skeleton's), refreshed whenever the skeleton updates. */
  readonly bones: BoneDualQuaternions;
  /** Puts back three.js's own skinning and CPU path, and the mesh's materials. */
  dispose(): void;
}

/** A skeleton's bone data, shared by the meshes that use it: its texture takes the place of three.js's. */
interface SkeletonState {
  bones: BoneDualQuaternions;
  users: number;
  update: Skeleton['update'];
  boneTexture: Skeleton['boneTexture'];
}

const skeletons = new WeakMap<Skeleton, SkeletonState>();
/** Materials already patched, and for which mode. */
const patchedMaterials = new WeakMap<Material, SkinningMode>();

/** The bone data of `skeleton`, made and hooked into its `update` by the first mesh to ask. */
function share(skeleton: Skeleton): SkeletonState {
  let state = skeletons.get(skeleton);
  if (!state) {
    const bones = new BoneDualQuaternions(skeleton.bones.length);
    const made: SkeletonState = { bones, users: 0, update: skeleton.update, boneTexture: skeleton.boneTexture };
    // three.js updates each skeleton once a frame before drawing, and binds `boneTexture` to
    // every mesh of it (each through its own bind matrix): the dual quaternions go there.
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

/** `material` (or a copy of it) with three.js's skinning chunks replaced for `mode`. */
function patchMaterial(material: Material, mode: SkinningMode, share: boolean): Material {
  const done = patchedMaterials.get(material);
  if (done !== undefined) {
    if (done !== mode) throw new Error(`${material.name || material.type}: already skinned in mode '${done}', not '${mode}'`);
    return material;
  }
  // The material's own hook and key, which a clone does not copy: they stay in force.
  const before = material.onBeforeCompile;
  const key = material.customProgramCacheKey;
  const patched = share ? material : material.clone();
  patched.onBeforeCompile = (shader: WebGLProgramParametersWithUniforms, renderer) => {
    before.call(patched, shader, renderer);
    shader.vertexShader = patchVertexShader(shader.vertexShader, mode);
  };
  // (three.js's default key is the hook's source, now this wrapper's: the user's goes in.)
  patched.customProgramCacheKey = () => `${before.toString()}|${key.call(patched)}|dqs-${mode}`;
  patched.needsUpdate = true;
  patchedMaterials.set(patched, mode);
  return patched;
}

/**
 * Skins `mesh` with dual quaternions from now on, on the GPU (WebGLRenderer: its materials'
 * and its shadow depth materials' skinning chunks replaced) and on the CPU
 * (`applyBoneTransform`, which raycasting and bounding volumes use; they update the skeleton
 * first, `getVertexPosition` alone reads it as last updated). Bones may scale and shear: that part is blended linearly before the rigid
 * part (Kavan et al. 2008, §4); a mirroring bone's mirror is in that part too. Meshes sharing a
 * skeleton share its dual quaternions, computed once a frame.
 *
 * ```js
 * const gltf = await new GLTFLoader().loadAsync('character.glb');
 * gltf.scene.traverse((o) => { if (o.isSkinnedMesh) useDualQuaternionSkinning(o); });
 * ```
 */
export function useDualQuaternionSkinning(mesh: SkinnedMesh, options: DualQuaternionSkinningOptions = {}): DualQuaternionSkinning {
  const mode = options.mode ?? 'dqs';
  const name = mesh.name || 'mesh';
  if (!mesh.isSkinnedMesh || !mesh.skeleton) throw new Error(`${name}: not a SkinnedMesh with a skeleton`);
  if (mode === 'blend' && !mesh.geometry.attributes.dqsBlend) throw new Error(`${name}: mode 'blend' needs the vertex attribute dqsBlend`);
  const skeleton = mesh.skeleton;
  const state = share(skeleton);
  skeleton.update();
  const cpu = new CpuSkinning(state.bones.data, mode);
  const original = { material: mesh.material, depth: mesh.customDepthMaterial, distance: mesh.customDistanceMaterial };
  const patch = (m: Material) => patchMaterial(m, mode, options.shareMaterials ?? false);
  mesh.material = Array.isArray(original.material) ? original.material.map(patch) : patch(original.material);
  // Shadow maps draw the mesh with their own depth materials, which would read the dual
  // quaternions as three.js's matrices: the mesh gets patched ones (three.js's defaults for a
  // shadow's depth, or copies of its own).
  mesh.customDepthMaterial = patchMaterial(original.depth ?? new MeshDepthMaterial({ depthPacking: RGBADepthPacking }), mode, !original.depth);
  mesh.customDistanceMaterial = patchMaterial(original.distance ?? new MeshDistanceMaterial(), mode, !original.distance);
  mesh.applyBoneTransform = (index: number, target: Vector3 | Vector4) => {
    cpu.apply(mesh, index, target);
    return target as never;
  };
  // three.js's own CPU path reads the bones as they are; this one reads the data of the last
  // skeleton update, so the bounding volumes and raycasting update it first (once per call).
  const refreshed = (['computeBoundingBox', 'computeBoundingSphere', 'raycast'] as const).map((name) => {
    const own = mesh[name];
    mesh[name] = function (this: SkinnedMesh, ...args: unknown[]) {
      skeleton.update();
      return (own as (...a: unknown[]) => void).apply(this, args);
    } as never;
    return name;
  });
  return {
    bones: state.bones,
    dispose() {
      const patched = [mesh.material, mesh.customDepthMaterial, mesh.customDistanceMaterial].flat();
      if (!options.shareMaterials) for (const m of patched) m?.dispose();
      mesh.material = original.material;
      mesh.customDepthMaterial = original.depth;
      mesh.customDistanceMaterial = original.distance;
      for (const name of [...refreshed, 'applyBoneTransform']) delete (mesh as unknown as Record<string, unknown>)[name];
      unshare(skeleton, state);
    },
  };
}
