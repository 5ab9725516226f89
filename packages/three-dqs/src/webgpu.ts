import { MathUtils, type Material, type SkinnedMesh } from 'three';
import {
  MeshBasicNodeMaterial,
  MeshLambertNodeMaterial,
  MeshMatcapNodeMaterial,
  MeshNormalNodeMaterial,
  MeshPhongNodeMaterial,
  MeshPhysicalNodeMaterial,
  MeshStandardNodeMaterial,
  MeshToonNodeMaterial,
  NodeMaterial,
  type NodeBuilder,
} from 'three/webgpu';
import { morphReference } from 'three/tsl';
import { attach } from './dual_quaternion_mesh.js';
import type { SkinningMode } from './skinning_chunks.js';
import { dualQuaternionSkinnedPosition, dualQuaternionSkinning } from './skinning_nodes.js';
import type { DualQuaternionSkinning } from './index.js';

export { dualQuaternionSkinnedPosition, dualQuaternionSkinning } from './skinning_nodes.js';
export { BoneDualQuaternions, FLOATS_PER_BONE, TEXELS_PER_BONE } from './bone_dual_quaternions.js';
export { CpuSkinning } from './cpu_skinning.js';
export type { SkinningMode } from './skinning_chunks.js';
export type { DualQuaternionSkinning } from './index.js';

/** Options of {@link useDualQuaternionSkinning} for WebGPURenderer. */
export interface DualQuaternionNodeSkinningOptions {
  /**
   * `'dqs'` (the default), `'lbs'` (linear blending of the same bone data, for comparison), or
   * `'blend'`: per vertex, the attribute `dqsBlend` (0 linear, 1 dual quaternion, any mix).
   */
  mode?: SkinningMode;
}

/** The node material WebGPURenderer would draw a classic material with (as its node library does). */
const NODE_MATERIALS: Record<string, new () => NodeMaterial> = {
  MeshBasicMaterial: MeshBasicNodeMaterial,
  MeshLambertMaterial: MeshLambertNodeMaterial,
  MeshMatcapMaterial: MeshMatcapNodeMaterial,
  MeshNormalMaterial: MeshNormalNodeMaterial,
  MeshPhongMaterial: MeshPhongNodeMaterial,
  MeshPhysicalMaterial: MeshPhysicalNodeMaterial,
  MeshStandardMaterial: MeshStandardNodeMaterial,
  MeshToonMaterial: MeshToonNodeMaterial,
};

/** A node material of `material`'s own for `mesh`: a copy if it is one, else its node equivalent. */
function nodeMaterialOf(material: Material, name: string): NodeMaterial {
  if ((material as NodeMaterial).isNodeMaterial) return (material as NodeMaterial).clone();
  const Class = NODE_MATERIALS[material.type];
  if (!Class) throw new Error(`${name}: material ${material.name || material.type} has no node material to skin with dual quaternions (use a node material)`);
  const converted = new Class();
  // What WebGPURenderer's node library does with a classic material: every property carried
  // over; but the copy lives on, so it gets its own identity and its own listeners.
  const fields = converted as unknown as Record<string, unknown>;
  for (const key in material) fields[key] = (material as unknown as Record<string, unknown>)[key];
  delete fields._listeners;
  fields.uuid = MathUtils.generateUUID();
  return converted;
}

/**
 * `material` drawing skinned meshes with dual quaternions: its `setupPosition` runs three.js's
 * stages in their order (morph targets, skinning, displacement, the material's `positionNode`)
 * with this package's skinning in place of three.js's; shadow maps draw the skinned geometry
 * through `castShadowPositionNode` (unless the material has its own). Any skinned mesh drawn
 * with it (a `mesh.clone()` shares it) must have dual quaternions: builds are shared.
 */
function skinWith(material: NodeMaterial, mode: SkinningMode): NodeMaterial {
  const own = material.setupPosition;
  material.setupPosition = function (this: NodeMaterial, builder: NodeBuilder) {
    const object = builder.object as SkinnedMesh;
    const geometry = builder.geometry;
    if (!object.isSkinnedMesh) return own.call(this, builder);
    // Morph targets are offsets of the bind pose: they go before the skinning, as in three.js.
    const morphs = geometry.morphAttributes;
    if (morphs.position || morphs.normal || morphs.color) morphReference(object);
    dualQuaternionSkinning(object, mode);
    // three.js's own stages after it, which would morph again and skin linearly: for this
    // call they see neither the morph targets nor a skinned mesh.
    geometry.morphAttributes = {};
    const flag = object as { isSkinnedMesh: boolean };
    flag.isSkinnedMesh = false;
    try {
      return own.call(this, builder);
    } finally {
      geometry.morphAttributes = morphs;
      flag.isSkinnedMesh = true;
    }
  };
  if (!material.castShadowPositionNode) material.castShadowPositionNode = dualQuaternionSkinnedPosition(mode);
  // Builds are shared between meshes of equal keys: this one's differs from three.js's skinning.
  const key = material.customProgramCacheKey;
  material.customProgramCacheKey = function (this: NodeMaterial) {
    return `${key.call(this)}|dqs-${mode}`;
  };
  material.needsUpdate = true;
  return material;
}

/**
 * Skins `mesh` with dual quaternions from now on, for **WebGPURenderer** (either backend): a
 * copy of each of its materials, as a node material, skins it with {@link dualQuaternionSkinning}
 * where three.js's skinning node would, and its shadows with
 * {@link dualQuaternionSkinnedPosition}; the CPU path (`applyBoneTransform`, raycasting,
 * bounding volumes) and the bone data are the WebGL entry's. Bones may scale and shear (Kavan
 * et al. 2008, §4). Meshes sharing a skeleton share its dual quaternions, computed once a frame.
 *
 * ```js
 * import { useDualQuaternionSkinning } from 'three-dqs/webgpu';
 * gltf.scene.traverse((o) => { if (o.isSkinnedMesh) useDualQuaternionSkinning(o); });
 * ```
 */
export function useDualQuaternionSkinning(mesh: SkinnedMesh, options: DualQuaternionNodeSkinningOptions = {}): DualQuaternionSkinning {
  const mode = options.mode ?? 'dqs';
  const name = mesh.name || 'mesh';
  const attached = attach(mesh, mode);
  const original = mesh.material;
  const skinned = (m: Material) => skinWith(nodeMaterialOf(m, name), mode);
  let copies: NodeMaterial[];
  try {
    copies = [original].flat().map(skinned);
  } catch (error) {
    attached.detach();
    throw error;
  }
  mesh.material = Array.isArray(original) ? copies : copies[0];
  return {
    bones: attached.bones,
    dispose() {
      for (const m of copies) m.dispose();
      mesh.material = original;
      attached.detach();
    },
  };
}
