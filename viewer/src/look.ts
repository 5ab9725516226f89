// The hand's look from its glTF file: the built-in hand's regions (back, palm, nails), each
// a primitive over the same vertices with its own physically based material and skin maps
// (crates/dqhand/src/appearance.rs). The engine streams positions and normals only; the UVs,
// the regions' triangle ranges and the materials come once from the file the page or the
// server already has, and are used only where the file's triangles are the topology's, in
// order (the same mesh), and the file has maps (a user's model keeps the viewer's skin).

import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import type { Topology } from './protocol';

/** What a hand's file gives its view: the UVs, one draw group per region and its material. */
export interface Look {
  uv: THREE.BufferAttribute;
  groups: { start: number; count: number }[];
  materials: THREE.Material[];
}

/**
 * The look in the GLB at `url` for `topology`, or null: no file, not the same mesh, or no
 * maps in it. Never throws: a hand without its look is still drawn.
 */
export async function loadLook(url: string, topology: Topology): Promise<Look | null> {
  try {
    const response = await fetch(url);
    if (!response.ok) return null;
    const gltf = await new GLTFLoader().parseAsync(await response.arrayBuffer(), '');
    return lookOf(gltf.scene, topology);
  } catch {
    return null;
  }
}

/** The look of the first skinned mesh (one object per primitive) under `root`, as [`loadLook`]. */
export function lookOf(root: THREE.Object3D, topology: Topology): Look | null {
  const meshes: THREE.Mesh[] = [];
  root.traverse((o) => {
    if ((o as THREE.SkinnedMesh).isSkinnedMesh && (meshes.length === 0 || o.parent === meshes[0].parent)) meshes.push(o as THREE.Mesh);
  });
  const uv = meshes[0]?.geometry.getAttribute('uv');
  if (!uv || uv.count !== topology.vertexCount) return null;
  const groups: Look['groups'] = [];
  const materials: THREE.Material[] = [];
  let start = 0;
  for (const m of meshes) {
    const index = m.geometry.getIndex();
    const material = m.material as THREE.MeshStandardMaterial;
    if (!index || Array.isArray(m.material) || m.geometry.getAttribute('uv') !== uv) return null;
    for (let i = 0; i < index.count; i++) if (index.getX(i) !== topology.indices[start + i]) return null;
    groups.push({ start, count: index.count });
    materials.push(material);
    start += index.count;
  }
  if (start !== topology.indices.length || !materials.some((m) => (m as THREE.MeshStandardMaterial).map)) return null;
  return { uv: uv as THREE.BufferAttribute, groups, materials };
}

/** Frees `look`'s materials and the maps they draw with. */
export function disposeLook(look: Look): void {
  for (const m of look.materials) {
    for (const value of Object.values(m)) if ((value as THREE.Texture | null)?.isTexture) (value as THREE.Texture).dispose();
    m.dispose();
  }
}
