// A skinned glTF (public/hand.glb, or ?model=URL) with its fingers bent 70° at every knuckle,
// drawn with dual quaternion skinning and casting its shadow; ?mode=lbs draws three.js's own
// linear skinning instead. ?renderer=webgpu draws with WebGPURenderer and three-dqs/webgpu;
// ?view=shadow draws the floor and the hand's shadow without the hand.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';

const query = new URLSearchParams(location.search);
const mode = query.get('mode') === 'lbs' ? 'lbs' : 'dqs';
const webgpu = query.get('renderer') === 'webgpu';
const { useDualQuaternionSkinning } = webgpu ? await import('three-dqs/webgpu') : await import('three-dqs');
const renderer = webgpu
  ? new (await import('three/webgpu')).WebGPURenderer({ antialias: true })
  : new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
if (webgpu) await renderer.init();
renderer.setSize(innerWidth, innerHeight);
renderer.domElement.id = 'view';
document.body.append(renderer.domElement);
renderer.shadowMap.enabled = true;
const scene = new THREE.Scene();
const sun = new THREE.DirectionalLight(0xffffff, 2);
sun.castShadow = true;
scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 2), sun);
const camera = new THREE.PerspectiveCamera(40, innerWidth / innerHeight, 0.01, 10);

const gltf = await new GLTFLoader().loadAsync(query.get('model') ?? './hand.glb');
scene.add(gltf.scene);
const meshes = [];
gltf.scene.traverse((o) => {
  if (o.isSkinnedMesh) meshes.push(o);
});
// Bend each finger's knuckles towards the palm, about the axis across the hand (index knuckle to
// little knuckle). A joint turns everything beyond it on its finger: glTF hands may keep their
// joints side by side under one parent (the WebXR generic hand does), so the turn is applied to
// the joint and to every later one, about the joint, in their parent's frame.
gltf.scene.updateMatrixWorld(true);
const joint = (name) => gltf.scene.getObjectByName(name);
const at = (name) => joint(name)?.getWorldPosition(new THREE.Vector3());
const across = at('pinky-finger-phalanx-proximal')?.sub(at('index-finger-phalanx-proximal')).normalize() ?? new THREE.Vector3(1, 0, 0);
const fingers = [
  { chain: ['thumb-phalanx-proximal', 'thumb-phalanx-distal', 'thumb-tip'], bends: [0.5, 0.5] },
  ...['index', 'middle', 'ring', 'pinky'].map((f) => ({ chain: ['proximal', 'intermediate', 'distal'].map((p) => `${f}-finger-phalanx-${p}`).concat(`${f}-finger-tip`), bends: [1.2, 1.2, 0.4] })),
];
for (const { chain, bends } of fingers) {
  const joints = chain.map(joint);
  if (joints.some((j) => !j)) continue;
  bends.forEach((angle, k) => {
    const pivot = joints[k].position.clone();
    const parent = joints[k].parent;
    const axis = across.clone().applyQuaternion(parent.getWorldQuaternion(new THREE.Quaternion()).invert());
    const turn = new THREE.Quaternion().setFromAxisAngle(axis, -angle);
    // Joints deeper than this one in the chain, whichever node holds them.
    for (const j of joints.slice(k)) {
      if (j.parent !== parent && j !== joints[k]) continue;
      if (j !== joints[k]) j.position.sub(pivot).applyQuaternion(turn).add(pivot);
      j.quaternion.premultiply(turn);
    }
  });
}
const shadowOnly = query.get('view') === 'shadow';
// (The hand on a layer the camera does not see and the sun's shadow camera does.)
if (shadowOnly) sun.shadow.camera.layers.enable(1);
for (const mesh of meshes) {
  mesh.material = new THREE.MeshStandardMaterial({ color: 0xe0a98f, roughness: 0.6 });
  mesh.castShadow = true;
  if (shadowOnly) mesh.layers.set(1);
  if (mode === 'dqs') useDualQuaternionSkinning(mesh);
}
gltf.scene.updateMatrixWorld(true);
// Frame what is drawn: the bounding box from the skinned vertices (the CPU path).
const box = new THREE.Box3();
for (const mesh of meshes) {
  mesh.skeleton.update();
  mesh.computeBoundingBox();
  box.union(mesh.boundingBox.clone().applyMatrix4(mesh.matrixWorld));
}
const centre = box.getCenter(new THREE.Vector3());
const size = box.getSize(new THREE.Vector3()).length();
// From the little finger's side and a little behind: the bent fingers, where linear skinning thins the knuckles.
camera.position.copy(centre).addScaledVector(across, size).add(new THREE.Vector3(size, size * 0.4, 0));
camera.lookAt(centre);
// The light shines over the hand onto a floor beneath it: the hand's shadow is drawn with its
// skinning too.
sun.position.copy(centre).add(new THREE.Vector3(0, 2, 0.4));
sun.target.position.copy(centre);
scene.add(sun.target);
const floor = new THREE.Mesh(new THREE.PlaneGeometry(4 * size, 4 * size), new THREE.MeshStandardMaterial({ color: 0x808890 }));
floor.rotation.x = -Math.PI / 2;
floor.position.copy(centre).y -= size / 2;
floor.receiveShadow = true;
scene.add(floor);
// (WebGPURenderer compiles its pipelines asynchronously: wait for them, errors included.)
if (webgpu) await renderer.compileAsync(scene, camera);
renderer.render(scene, camera);

window.example = {
  mode,
  meshes: meshes.length,
  bones: meshes.reduce((n, m) => n + m.skeleton.bones.length, 0),
  renderer: webgpu ? (renderer.backend.isWebGPUBackend ? 'webgpu' : 'webgl2') : 'webgl',
  programs: webgpu ? [] : renderer.info.programs.map((p) => p.cacheKey),
  box: box.getSize(new THREE.Vector3()).toArray(),
};
document.title = 'drawn';
