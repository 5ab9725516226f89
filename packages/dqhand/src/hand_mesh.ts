// A skinned hand as a three.js mesh: its position and normal attributes are the engine's skin,
// copied in place from the module's memory each frame (one copy each, nothing allocated; the
// attributes own their arrays, so the module's memory growing never leaves them dangling).

import { BufferAttribute, BufferGeometry, DynamicDrawUsage, Mesh, MeshStandardMaterial, type Material, type Object3D } from 'three';
import { disposeLook, lookOf, type Look } from './look.js';
import type { SkinSource } from './engine.js';

/** The skin's colour (a light skin tone, lit). */
export const SKIN_COLOUR = 0xe0a98f;

/**
 * Hand `hand` of `source`, drawn. Its vertices are in world metres already (the engine places
 * the hand where the tracked one is): leave the mesh's own transform at the identity, or put it
 * under a parent to move the whole world. Call `update()` after each `step` (or `setAngles`).
 */
export class HandMesh extends Mesh<BufferGeometry, Material | Material[]> {
  constructor(
    readonly source: SkinSource,
    readonly hand = 0,
    material: Material = new MeshStandardMaterial({ color: SKIN_COLOUR, roughness: 0.55, metalness: 0 }),
  ) {
    const n = source.vertexCount(hand);
    const geometry = new BufferGeometry();
    for (const name of ['position', 'normal']) {
      geometry.setAttribute(name, new BufferAttribute(new Float32Array(3 * n), 3).setUsage(DynamicDrawUsage));
    }
    geometry.setIndex(new BufferAttribute(source.indices(hand), 1));
    super(geometry, material);
    this.name = 'dqhand';
    this.update();
  }

  /** Copies the engine's latest skin into the attributes (and the bounds three.js culls and picks by). */
  update(): void {
    const { position, normal } = this.geometry.attributes as Record<string, BufferAttribute>;
    (position.array as Float32Array).set(this.source.positions(this.hand));
    (normal.array as Float32Array).set(this.source.normals(this.hand));
    position.needsUpdate = normal.needsUpdate = true;
    this.geometry.computeBoundingSphere();
    this.geometry.computeBoundingBox();
  }

  /** The look drawn (`useLook`), or null: the material given. */
  look: Look | null = null;

  /**
   * Draws the hand in the look of its glTF file (`root`: GLTFLoader's `gltf.scene` of the same
   * file the engine loaded): each region in its material and maps, in place of the material
   * given (which stays the caller's). Null, and nothing changed, where the file is not this
   * mesh or has no maps. The look is the mesh's: `dispose()` frees it.
   */
  useLook(root: Object3D): Look | null {
    const look = lookOf(root, { vertexCount: this.source.vertexCount(this.hand), indices: this.source.indices(this.hand) });
    if (!look) return null;
    if (this.look) disposeLook(this.look);
    this.look = look;
    this.geometry.setAttribute('uv', look.uv);
    this.geometry.clearGroups();
    look.groups.forEach((group, k) => this.geometry.addGroup(group.start, group.count, k));
    this.material = look.materials;
    return look;
  }

  /** Frees the geometry and the look (the material given is the caller's). */
  dispose(): void {
    this.geometry.dispose();
    if (this.look) disposeLook(this.look);
    this.look = null;
  }
}
