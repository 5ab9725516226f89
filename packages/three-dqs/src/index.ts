import { MeshDepthMaterial, MeshDistanceMaterial, RGBADepthPacking, type Material, type SkinnedMesh, type WebGLProgramParametersWithUniforms } from 'three';
import type { BoneDualQuaternions } from './bone_dual_quaternions.js';
import { attach } from './dual_quaternion_mesh.js';
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

/** Materials already patched, and for which mode. */
const patchedMaterials = new WeakMap<Material, SkinningMode>();

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
  const attached = attach(mesh, mode);
  const original = { material: mesh.material, depth: mesh.customDepthMaterial, distance: mesh.customDistanceMaterial };
  const patch = (m: Material) => patchMaterial(m, mode, options.shareMaterials ?? false);
  try {
    mesh.material = Array.isArray(original.material) ? original.material.map(patch) : patch(original.material);
    // Shadow maps draw the mesh with their own depth materials, which would read the dual
    // quaternions as three.js's matrices: the mesh gets patched ones (three.js's defaults for a
    // shadow's depth, or copies of its own).
    mesh.customDepthMaterial = patchMaterial(original.depth ?? new MeshDepthMaterial({ depthPacking: RGBADepthPacking }), mode, !original.depth);
    mesh.customDistanceMaterial = patchMaterial(original.distance ?? new MeshDistanceMaterial(), mode, !original.distance);
  } catch (error) {
    mesh.material = original.material;
    mesh.customDepthMaterial = original.depth;
    mesh.customDistanceMaterial = original.distance;
    attached.detach();
    throw error;
  }
  return {
    bones: attached.bones,
    dispose() {
      const patched = [mesh.material, mesh.customDepthMaterial, mesh.customDistanceMaterial].flat();
      if (!options.shareMaterials) for (const m of patched) m?.dispose();
      mesh.material = original.material;
      mesh.customDepthMaterial = original.depth;
      mesh.customDistanceMaterial = original.distance;
      attached.detach();
    },
  };
}
