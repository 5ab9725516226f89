// A hand's look from its glTF file, as three.js's GLTFLoader reads it: the built-in hand's
// regions (back, palm, nails), each a primitive over the same vertices with its own
// physically based material and skin maps (crates/dqhand/src/appearance.rs). The engine gives
// positions and normals only; the UVs, the regions' triangle ranges and the materials come
// once from the file, and are used only where the file's triangles are the engine's mesh's, in
// order, and the file has maps (a user's model keeps the caller's material).

import type * as THREE from 'three';

/** The mesh a look is for: its vertex count and triangle corners, as the engine has them. */
export interface LookTarget {
  vertexCount: number;
  indices: Uint32Array;
}

/** What a hand's file gives its view: the UVs, one draw group per region and its material. */
export interface Look {
  uv: THREE.BufferAttribute;
  groups: { start: number; count: number }[];
  materials: THREE.Material[];
}

/**
 * The look of the first skinned mesh (one object per primitive) under `root` (a loaded glTF's
 * scene) for `target`, or null: not the same mesh, or no maps in the file.
 */
export function lookOf(root: THREE.Object3D, target: LookTarget): Look | null {
  const meshes: THREE.Mesh[] = [];
  root.traverse((o) => {
    if ((o as THREE.SkinnedMesh).isSkinnedMesh && (meshes.length === 0 || o.parent === meshes[0].parent)) meshes.push(o as THREE.Mesh);
  });
  const uv = meshes[0]?.geometry.getAttribute('uv');
  if (!uv || uv.count !== target.vertexCount) return null;
  const groups: Look['groups'] = [];
  const materials: THREE.Material[] = [];
  let start = 0;
  for (const m of meshes) {
    const index = m.geometry.getIndex();
    const material = m.material as THREE.MeshStandardMaterial;
    if (!index || Array.isArray(m.material) || m.geometry.getAttribute('uv') !== uv) return null;
    for (let i = 0; i < index.count; i++) if (index.getX(i) !== target.indices[start + i]) return null;
    groups.push({ start, count: index.count });
    materials.push(material);
    start += index.count;
  }
  if (start !== target.indices.length || !materials.some((m) => (m as THREE.MeshStandardMaterial).map)) return null;
  return { uv: uv as THREE.BufferAttribute, groups, materials };
}

/** Frees `look`'s materials and the maps they draw with. */
export function disposeLook(look: Look): void {
  for (const m of look.materials) {
    for (const value of Object.values(m)) if ((value as THREE.Texture | null)?.isTexture) (value as THREE.Texture).dispose();
    m.dispose();
  }
}
