// The speed page: N skinned hands (dqhand's built-in hand, from rig.json/rig.bin beside this
// page) drawn with three.js's linear skinning and with this package's dual quaternion skinning,
// their bones moving every frame. Frames of the two alternate in blocks, so both see the same
// machine; each frame is timed to the GPU's end (a one-pixel read-back).

import * as THREE from 'three';
import { loadRig, type Rig } from './rig';
import { BoneDualQuaternions, useDualQuaternionSkinning } from '../src/index';

/** One hand: the rig's mesh on its own skeleton, whose bones are moved by hand each frame. */
function hand(rig: Rig, geometry: THREE.BufferGeometry, material: THREE.Material, k: number): THREE.SkinnedMesh {
  const bones = Array.from({ length: rig.joints }, () => {
    const b = new THREE.Bone();
    b.matrixAutoUpdate = false;
    b.matrixWorldAutoUpdate = false;
    return b;
  });
  const mesh = new THREE.SkinnedMesh(geometry, material);
  mesh.bind(new THREE.Skeleton(bones, bones.map(() => new THREE.Matrix4())), new THREE.Matrix4());
  mesh.frustumCulled = false;
  const columns = 10;
  mesh.position.set(((k % columns) - columns / 2) * 0.25, Math.floor(k / columns) * 0.25 - 1, 0);
  return mesh;
}

/** The exported pose's matrices, each turned a little about its own origin by `t` (s). */
function move(mesh: THREE.SkinnedMesh, rig: Rig, t: number, turn: THREE.Matrix4): void {
  mesh.skeleton.bones.forEach((bone, j) => {
    turn.makeRotationAxis(new THREE.Vector3(1, 0, 0), 0.3 * Math.sin(2 * t + j));
    bone.matrixWorld.fromArray(rig.skinning, 16 * j).multiply(turn);
  });
}

export async function bench(counts: number[], frames: number) {
  const rig = await loadRig();
  const renderer = new THREE.WebGLRenderer();
  renderer.setSize(640, 400);
  document.body.append(renderer.domElement);
  const gl = renderer.getContext();
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(rig.rest, 3));
  geometry.setAttribute('normal', new THREE.BufferAttribute(rig.restNormals, 3));
  geometry.setAttribute('skinIndex', new THREE.BufferAttribute(Uint16Array.from(rig.joint), 4));
  geometry.setAttribute('skinWeight', new THREE.BufferAttribute(rig.weight, 4));
  geometry.setIndex(new THREE.BufferAttribute(rig.triangles, 1));
  const camera = new THREE.PerspectiveCamera(50, 640 / 400, 0.1, 20);
  camera.position.set(0, 0, 4);
  const pixel = new Uint8Array(4);
  const turn = new THREE.Matrix4();
  const results = [];
  for (const n of counts) {
    const scenes = { lbs: new THREE.Scene(), dqs: new THREE.Scene() };
    const meshes = { lbs: [] as THREE.SkinnedMesh[], dqs: [] as THREE.SkinnedMesh[] };
    for (const mode of ['lbs', 'dqs'] as const) {
      scenes[mode].add(new THREE.HemisphereLight(0xffffff, 0x404040, 2));
      for (let k = 0; k < n; k++) {
        const mesh = hand(rig, geometry, new THREE.MeshStandardMaterial({ color: 0xe0a98f }), k);
        if (mode === 'dqs') useDualQuaternionSkinning(mesh, { shareMaterials: true });
        meshes[mode].push(mesh);
        scenes[mode].add(mesh);
      }
    }
    const times = { lbs: [] as number[], dqs: [] as number[] };
    const frame = (mode: 'lbs' | 'dqs', t: number) => {
      const start = performance.now();
      for (const mesh of meshes[mode]) move(mesh, rig, t, turn);
      renderer.render(scenes[mode], camera);
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel);
      return performance.now() - start;
    };
    // Compile and warm both, then alternate blocks of 5 frames.
    for (let i = 0; i < 3; i++) for (const mode of ['lbs', 'dqs'] as const) frame(mode, i);
    for (let i = 0; i < frames; i += 5) {
      for (const mode of ['lbs', 'dqs'] as const) for (let k = 0; k < 5; k++) times[mode].push(frame(mode, (i + k) / 60));
    }
    const stat = (xs: number[]) => {
      const s = [...xs].sort((a, b) => a - b);
      return { median: s[Math.floor(s.length / 2)], p95: s[Math.floor(0.95 * (s.length - 1))] };
    };
    const [lbs, dqs] = [stat(times.lbs), stat(times.dqs)];
    results.push({ hands: n, frames: times.lbs.length, lbs, dqs, ratio: dqs.median / lbs.median });
    for (const mode of ['lbs', 'dqs'] as const) for (const mesh of meshes[mode]) (mesh.material as THREE.Material).dispose();
  }
  // The CPU side: the per-bone split into dual quaternion and scale–shear, timed alone.
  // Two poses in turn: an update that finds the bones unchanged does nothing.
  const probe = hand(rig, geometry, new THREE.MeshBasicMaterial(), 0);
  const poses = [0, 0.5].map((t) => {
    move(probe, rig, t, turn);
    probe.skeleton.update();
    return { boneMatrices: Float32Array.from(probe.skeleton.boneMatrices!) } as unknown as THREE.Skeleton;
  });
  const bones = new BoneDualQuaternions(rig.joints);
  const repeats = 2000;
  const start = performance.now();
  for (let i = 0; i < repeats; i++) bones.update(poses[i % 2]);
  const perBoneMicroseconds = ((performance.now() - start) * 1000) / (repeats * rig.joints);
  return { vertices: rig.vertices, bones: rig.joints, results, perBoneMicroseconds, renderer: gl.getParameter(gl.getExtension('WEBGL_debug_renderer_info')?.UNMASKED_RENDERER_WEBGL ?? gl.RENDERER) };
}
