// The conformance page's WebGPURenderer side: the package's TSL skinning (three-dqs/webgpu), run
// by WebGPU or by the renderer's WebGL 2 fallback, read back from a float render target.

import * as THREE from 'three';
import { MeshBasicNodeMaterial, WebGPURenderer, type NodeBuilder } from 'three/webgpu';
import { attribute, floor, mod, normalize, normalLocal, positionLocal, varyingProperty, vec2, vec4 } from 'three/tsl';
import type { SkinningMode } from '../src/index';
import { skinInPlace } from '../src/skinning_nodes';
import { useDualQuaternionSkinning } from '../src/webgpu';
import type { Backend } from './conformance';
import { BIND, bindAtRest, blendOf, cpuSkinned, drawAlone, inMeshSpace, readbackGeometry, toSkeletonSpace } from './poses';
import type { Rig } from './rig';

const WIDTH = 128;

/** What {@link ReadBackMaterial} writes: the skinned value, and the vertex's number + 1 (0 where nothing was drawn). */
const value = varyingProperty('vec4', 'vReadBack');

/**
 * Draws each vertex of a {@link readbackGeometry} over its own pixel, its colour the position
 * (or normal) that `setupPosition` skinned, the skinning three.js or the package put there.
 * Its settings are in `userData`, which a material's copy keeps, and in its key (builds of
 * equal keys are shared, and three.js leaves `userData` out of them).
 */
class ReadBackMaterial extends MeshBasicNodeMaterial {
  constructor() {
    super();
    this.fragmentNode = value;
  }

  customProgramCacheKey(): string {
    return `${super.customProgramCacheKey()}|${JSON.stringify(this.userData)}`;
  }

  setupVertex(builder: NodeBuilder) {
    const { output, height, unaligned } = this.userData as { output: 'position' | 'normal'; height: number; unaligned: boolean };
    // The mistake the test injects, in place of the package's hook: no sign alignment.
    if (unaligned) skinInPlace(builder.object as THREE.SkinnedMesh, 'dqs', false);
    else this.setupPosition(builder);
    const slot = attribute('slot', 'float');
    (value as never as { assign(v: unknown): void }).assign(vec4(output === 'normal' ? normalize(normalLocal) : positionLocal, slot.add(1)));
    const size = vec2(WIDTH, height);
    const pixel = vec2(mod(slot, WIDTH), floor(slot.div(WIDTH))).add(0.5).add(attribute('corner', 'vec2'));
    return vec4(pixel.div(size).mul(2).sub(1), 0, 1);
  }
}

/** The renderer, made once: WebGPU where the browser has it, or `forceWebGL`. */
async function rendererOf(forceWebGL: boolean): Promise<WebGPURenderer> {
  const renderer = new WebGPURenderer({ forceWebGL });
  await renderer.init();
  return renderer;
}

/** The WebGPURenderer backend (`forceWebGL`: its WebGL 2 fallback), and which one it runs on. */
export async function webgpu(forceWebGL: boolean): Promise<
  Backend & {
    backend: string;
    shadows(rig: Rig, matrices: ArrayLike<number>, positions: ArrayLike<number>): Promise<ShadowPictures>;
    twoMeshes(rig: Rig, a: ArrayLike<number>, b: ArrayLike<number>): Promise<{ positions: Float32Array[]; builds: number }>;
  }
> {
  const renderer = await rendererOf(forceWebGL);
  const camera = new THREE.OrthographicCamera();
  /** A read-back mesh bound at rest, and what poses it. */
  const meshOf = (rig: Rig, output: 'position' | 'normal', blend: boolean, unaligned = false) => {
    const height = Math.ceil(rig.vertices / WIDTH);
    const material = new ReadBackMaterial();
    material.userData = { output, height, unaligned };
    const mesh = new THREE.SkinnedMesh(readbackGeometry(rig, blend ? blendOf : undefined), material);
    mesh.frustumCulled = false;
    return { mesh, pose: bindAtRest(mesh, rig.joints) };
  };
  // Drawn once at rest, then posed and drawn again in the next frame (WebGPURenderer updates a
  // skeleton once per animation frame, as three.js's own skinning does): the bone data must
  // follow the bones.
  /** `mesh` drawn into a float target and read back: 3 floats per vertex of `rig`, in the skeleton's space (NaN where none was drawn). */
  const drawAndRead = async (mesh: THREE.SkinnedMesh, rig: Rig, output: 'position' | 'normal') => {
    const height = Math.ceil(rig.vertices / WIDTH);
    const target = new THREE.RenderTarget(WIDTH, height, { type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: false });
    drawAlone(renderer, target, mesh, camera);
    const pixels = (await renderer.readRenderTargetPixelsAsync(target, 0, 0, WIDTH, height)) as Float32Array;
    renderer.setRenderTarget(null);
    target.dispose();
    // Each pixel names its vertex (which way up the rows come differs between backends).
    const out = new Float32Array(3 * rig.vertices).fill(NaN);
    for (let k = 0; k < WIDTH * height; k++) {
      const v = Math.round(pixels[4 * k + 3]) - 1;
      if (v >= 0 && v < rig.vertices) out.set(pixels.subarray(4 * k, 4 * k + 3), 3 * v);
    }
    return toSkeletonSpace(out, output === 'normal');
  };
  const readBack = async (rig: Rig, matrices: ArrayLike<number>, mode: SkinningMode | 'three', output: 'position' | 'normal', unaligned = false) => {
    const { mesh, pose } = meshOf(rig, output, mode === 'blend', unaligned);
    const skin = mode === 'three' ? null : useDualQuaternionSkinning(mesh, { mode });
    await drawAndRead(mesh, rig, output);
    pose(matrices);
    await new Promise(requestAnimationFrame);
    const out = await drawAndRead(mesh, rig, output);
    skin?.dispose();
    return out;
  };
  /**
   * Two meshes of one material (as a mesh and its clone are), each with its own skeleton in its
   * own pose, drawn in the same frame: their material copies have equal keys, so they share one
   * build, whose bone texture must follow each mesh. Their positions, and the builds made.
   */
  const twoMeshes = async (rig: Rig, a: ArrayLike<number>, b: ArrayLike<number>) => {
    const builds = () => (renderer as unknown as { _nodes: { nodeBuilderCache: Map<unknown, unknown> } })._nodes.nodeBuilderCache.size;
    const before = builds();
    const first = meshOf(rig, 'position', false);
    const second = meshOf(rig, 'position', false);
    second.mesh.material = first.mesh.material;
    first.pose(a);
    second.pose(b);
    const skins = [useDualQuaternionSkinning(first.mesh), useDualQuaternionSkinning(second.mesh)];
    const positions = [await drawAndRead(first.mesh, rig, 'position'), await drawAndRead(second.mesh, rig, 'position')];
    const made = builds() - before;
    for (const skin of skins) skin.dispose();
    return { positions, builds: made };
  };
  const cpuPositions = (rig: Rig, matrices: ArrayLike<number>) => {
    const { mesh, pose } = meshOf(rig, 'position', false);
    const skin = useDualQuaternionSkinning(mesh);
    const out = cpuSkinned(mesh, pose, matrices, rig.vertices);
    skin.dispose();
    return out;
  };
  const shadows = (rig: Rig, matrices: ArrayLike<number>, positions: ArrayLike<number>) => shadowPictures(renderer, rig, matrices, positions);
  return { readBack, cpuPositions, shadows, twoMeshes, backend: (renderer.backend as { isWebGPUBackend?: boolean }).isWebGPUBackend ? 'webgpu' : 'webgl2' };
}

/** Pixels of the shadow pictures: shadowed in the reference's, and differing from it in each other one. */
export interface ShadowPictures {
  shadowed: number;
  dqs: number;
  three: number;
}

/**
 * The shadow the rig casts, in `matrices`' pose, on a floor under it, seen from above (the hand
 * itself on a layer only the light's shadow camera sees): cast by the package's skin, by
 * three.js's own, and by a plain mesh of `positions` (the reference's DQB of the pose). Shadow
 * maps draw with their own material, so this shows that the package's skin reaches them.
 */
async function shadowPictures(renderer: WebGPURenderer, rig: Rig, matrices: ArrayLike<number>, positions: ArrayLike<number>): Promise<ShadowPictures> {
  const size = 256;
  renderer.shadowMap.enabled = true;
  const box = new THREE.Box3().setFromArray(positions);
  const centre = box.getCenter(new THREE.Vector3());
  const reach = box.getSize(new THREE.Vector3()).length();
  const picture = async (caster: 'dqs' | 'three' | 'reference') => {
    const geometry = new THREE.BufferGeometry();
    geometry.setIndex(new THREE.BufferAttribute(rig.triangles, 1));
    // (Copies: the skinned meshes' geometry is carried into their space in place.)
    geometry.setAttribute('normal', new THREE.BufferAttribute(Float32Array.from(rig.restNormals), 3));
    let mesh: THREE.Mesh;
    let skin: { dispose(): void } | null = null;
    if (caster === 'reference') {
      geometry.setAttribute('position', new THREE.BufferAttribute(Float32Array.from(positions), 3));
      mesh = new THREE.Mesh(geometry, new THREE.MeshLambertMaterial());
    } else {
      geometry.setAttribute('position', new THREE.BufferAttribute(Float32Array.from(rig.rest), 3));
      geometry.setAttribute('skinIndex', new THREE.BufferAttribute(Uint16Array.from(rig.joint), 4));
      geometry.setAttribute('skinWeight', new THREE.BufferAttribute(rig.weight, 4));
      const skinned = new THREE.SkinnedMesh(inMeshSpace(geometry), new THREE.MeshLambertMaterial());
      // Seen by the camera where the skeleton puts it (the bind matrix undone by the mesh's own).
      skinned.matrixAutoUpdate = false;
      skinned.matrix.copy(BIND);
      bindAtRest(skinned, rig.joints)(matrices);
      if (caster === 'dqs') skin = useDualQuaternionSkinning(skinned);
      mesh = skinned;
    }
    mesh.frustumCulled = false;
    mesh.castShadow = true;
    mesh.layers.set(1);
    const scene = new THREE.Scene();
    const sun = new THREE.DirectionalLight(0xffffff, 3);
    sun.position.copy(centre).add(new THREE.Vector3(0, reach, 0));
    sun.target.position.copy(centre);
    sun.castShadow = true;
    sun.shadow.mapSize.set(1024, 1024);
    Object.assign(sun.shadow.camera, { left: -reach, right: reach, top: reach, bottom: -reach, near: 0.01, far: 3 * reach });
    sun.shadow.camera.updateProjectionMatrix();
    sun.shadow.camera.layers.enable(1);
    const floor = new THREE.Mesh(new THREE.PlaneGeometry(4 * reach, 4 * reach), new THREE.MeshLambertMaterial());
    floor.rotation.x = -Math.PI / 2;
    floor.position.set(centre.x, box.min.y - 0.02, centre.z);
    floor.receiveShadow = true;
    scene.add(mesh, sun, sun.target, floor);
    const camera = new THREE.OrthographicCamera(-reach, reach, reach, -reach, 0.01, 4 * reach);
    camera.position.copy(centre).add(new THREE.Vector3(0, 2 * reach, 0));
    camera.lookAt(centre);
    const target = new THREE.RenderTarget(size, size);
    renderer.setRenderTarget(target);
    renderer.setClearColor(0x000000, 1);
    renderer.render(scene, camera);
    const pixels = (await renderer.readRenderTargetPixelsAsync(target, 0, 0, size, size)) as Uint8Array;
    renderer.setRenderTarget(null);
    target.dispose();
    skin?.dispose();
    sun.shadow.map?.dispose();
    // Lit floor is bright; shadowed floor is dark (no ambient light).
    return Uint8Array.from({ length: size * size }, (_, k) => (pixels[4 * k] < 64 ? 1 : 0));
  };
  const reference = await picture('reference');
  const differing = (mask: Uint8Array) => mask.reduce((n, m, k) => n + (m !== reference[k] ? 1 : 0), 0);
  return { shadowed: reference.reduce((n, m) => n + m, 0), dqs: differing(await picture('dqs')), three: differing(await picture('three')) };
}
