// A skinned glTF (public/hand.glb, or ?model=URL) with its fingers bent 70° at every knuckle,
// drawn with dual quaternion skinning; ?mode=lbs draws three.js's own linear skinning instead.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { useDualQuaternionSkinning } from 'three-dqs';

const query = new URLSearchParams(location.search);
const mode = query.get('mode') === 'lbs' ? 'lbs' : 'dqs';
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setSize(innerWidth, innerHeight);
renderer.domElement.id = 'view';
document.body.append(renderer.domElement);
const scene = new THREE.Scene();
scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 2), new THREE.DirectionalLight(0xffffff, 2));
const camera = new THREE.PerspectiveCamera(40, innerWidth / innerHeight, 0.01, 10);

const gltf = await new GLTFLoader().loadAsync(query.get('model') ?? './hand.glb');
scene.add(gltf.scene);
const meshes = [];
const phalanges = [];
gltf.scene.traverse((o) => {
  if (o.isSkinnedMesh) meshes.push(o);
  if (o.isBone && /phalanx/.test(o.name) && !/distal$/.test(o.name)) phalanges.push(o);
});
// Bend every finger joint but the metacarpals' by 70° towards the palm: about the axis across
// the hand (index knuckle to little knuckle), whatever way the model's bones are oriented.
gltf.scene.updateMatrixWorld(true);
const at = (name) => gltf.scene.getObjectByName(name)?.getWorldPosition(new THREE.Vector3());
const across = at('pinky-finger-phalanx-proximal')?.sub(at('index-finger-phalanx-proximal')).normalize() ?? new THREE.Vector3(1, 0, 0);
for (const bone of phalanges) {
  const local = across.clone().applyQuaternion(bone.getWorldQuaternion(new THREE.Quaternion()).invert());
  bone.rotateOnAxis(local, /thumb/.test(bone.name) ? 0.6 : 1.2);
}
for (const mesh of meshes) {
  mesh.material = new THREE.MeshStandardMaterial({ color: 0xe0a98f, roughness: 0.6 });
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
// From the little finger's side: the fingers' profile, where linear skinning thins the knuckles.
camera.position.copy(centre).addScaledVector(across, size * 1.4);
camera.lookAt(centre);
renderer.render(scene, camera);

window.example = {
  mode,
  meshes: meshes.length,
  bones: meshes.reduce((n, m) => n + m.skeleton.bones.length, 0),
  programs: renderer.info.programs.map((p) => p.cacheKey),
  box: box.getSize(new THREE.Vector3()).toArray(),
};
document.title = 'drawn';
