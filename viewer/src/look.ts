// The hand's look, from the file the page or the server already has (`lookOf` in the npm
// package's look.ts): loaded once per topology, never failing the hand (without it, the plain
// skin).

import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { lookOf, type Look } from '../../packages/dqhand/src/look';
import type { Topology } from './protocol';

export { disposeLook, type Look } from '../../packages/dqhand/src/look';

/** The look in the GLB at `url` for `topology`, or null: no file, not the same mesh, or no maps in it. */
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
