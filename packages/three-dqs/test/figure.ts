// The figure page: a limb-sized cylinder on two bones, twisted 150° (a wrist turned against its
// forearm) or bent 120° (a finger's knuckle), and the WebXR generic hand (hand.glb beside the
// page) with its index finger twisted or bent, drawn with three.js's linear skinning or with
// this package (`make figures`: docs/figures/dqs-twist-bend.png and dqs-hand.png). Linear
// skinning pinches the twist into a candy wrapper and collapses the bend's inside; dual
// quaternions keep the limb's thickness.

import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { useDualQuaternionSkinning } from '../src/index';
import { LIMB, limb } from './poses';

const LENGTH = LIMB.length;

/** One limb with its joint turned by `turn`, at `x`, `y`; with dual quaternions or not. */
function posed(turn: THREE.Quaternion, dual: boolean, x: number, y: number): THREE.SkinnedMesh {
  const root = new THREE.Bone();
  const joint = new THREE.Bone();
  joint.position.y = LENGTH / 2;
  root.add(joint);
  const mesh = new THREE.SkinnedMesh(limb(), new THREE.MeshStandardMaterial({ color: 0xe0a98f, roughness: 0.55 }));
  mesh.add(root);
  mesh.bind(new THREE.Skeleton([root, joint]));
  joint.quaternion.copy(turn);
  mesh.position.set(x, y, 0);
  if (dual) useDualQuaternionSkinning(mesh);
  return mesh;
}

/** A renderer drawing into a fresh `size`-pixel square canvas (#view), and a lit scene. */
function stage(size: number): { renderer: THREE.WebGLRenderer; scene: THREE.Scene; light: THREE.DirectionalLight } {
  document.getElementById('view')?.remove();
  const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
  renderer.setSize(size, size);
  renderer.setClearColor(0xffffff);
  renderer.domElement.id = 'view';
  document.body.append(renderer.domElement);
  const scene = new THREE.Scene();
  scene.add(new THREE.HemisphereLight(0xffffff, 0x606060, 1.6));
  const light = new THREE.DirectionalLight(0xffffff, 2.2);
  light.position.set(0.4, 1, 1.2);
  scene.add(light, light.target);
  return { renderer, scene, light };
}

/** Draws one limb, `kind` twisted 150° or bent 120°, with dual quaternions or three.js's skinning, into a `size`-pixel square canvas (#view). */
export function figure(kind: 'twist' | 'bend', dual: boolean, size: number): void {
  const { renderer, scene } = stage(size);
  const turn = kind === 'twist'
    ? new THREE.Quaternion().setFromAxisAngle(new THREE.Vector3(0, 1, 0), (150 * Math.PI) / 180)
    : new THREE.Quaternion().setFromAxisAngle(new THREE.Vector3(0, 0, 1), (120 * Math.PI) / 180);
  const mesh = posed(turn, dual, kind === 'twist' ? 0 : 0.05, kind === 'twist' ? -LENGTH / 2 : -0.1);
  // Tilted a little towards the light: the shading shows the surface's shape.
  mesh.rotation.x = 0.35;
  scene.add(mesh);
  const half = 0.2;
  const camera = new THREE.OrthographicCamera(-half, half, half, -half, 0.01, 10);
  camera.position.set(0, 0, 2);
  renderer.render(scene, camera);
  renderer.dispose();
}

/**
 * Draws the WebXR generic hand (a glTF made elsewhere) with its index finger twisted 150° about
 * its own axis at the knuckle, or bent 30° at the knuckle and 120° at the middle joint, with dual
 * quaternions or three.js's skinning, into a `size`-pixel square canvas (#view). The hand has no
 * forearm to turn the wrist against: the twist is the finger's.
 */
export async function handFigure(kind: 'twist' | 'bend', dual: boolean, size: number): Promise<void> {
  const { renderer, scene, light } = stage(size);
  const gltf = await new GLTFLoader().loadAsync('hand.glb');
  scene.add(gltf.scene);
  gltf.scene.updateMatrixWorld(true);
  const joint = (name: string) => gltf.scene.getObjectByName(name)!;
  const at = (name: string) => joint(name).getWorldPosition(new THREE.Vector3());
  const chain = ['proximal', 'intermediate', 'distal'].map((p) => `index-finger-phalanx-${p}`).concat('index-finger-tip').map(joint);
  const across = at('pinky-finger-phalanx-proximal').sub(at('index-finger-phalanx-proximal')).normalize();
  const along = at('index-finger-phalanx-intermediate').sub(at('index-finger-phalanx-proximal')).normalize();
  const back = new THREE.Vector3().crossVectors(along, across).normalize();
  /** Turns chain joint `k` and every later one (side by side under one parent in this glTF) by `angle` about the world `axis`, about joint `k`. */
  const turn = (k: number, axis: THREE.Vector3, angle: number) => {
    const parent = chain[k].parent!;
    const local = axis.clone().transformDirection(parent.matrixWorld.clone().invert());
    const q = new THREE.Quaternion().setFromAxisAngle(local, angle);
    const pivot = chain[k].position.clone();
    for (const j of chain.slice(k)) {
      if (j !== chain[k]) j.position.sub(pivot).applyQuaternion(q).add(pivot);
      j.quaternion.premultiply(q);
    }
    gltf.scene.updateMatrixWorld(true);
  };
  if (kind === 'twist') turn(0, along, (150 * Math.PI) / 180);
  else {
    turn(0, across, (-30 * Math.PI) / 180);
    turn(1, across, (-120 * Math.PI) / 180);
  }
  gltf.scene.traverse((o) => {
    const mesh = o as THREE.SkinnedMesh;
    if (!mesh.isSkinnedMesh) return;
    mesh.material = new THREE.MeshStandardMaterial({ color: 0xe0a98f, roughness: 0.55 });
    mesh.frustumCulled = false;
    if (dual) useDualQuaternionSkinning(mesh);
  });
  // The finger's knuckle and middle joint in the middle of the picture, seen from the side for
  // the bend and from the back of the hand for the twist.
  const centre = kind === 'twist' ? at('index-finger-phalanx-proximal').lerp(at('index-finger-phalanx-intermediate'), 0.2) : at('index-finger-phalanx-intermediate');
  const from = kind === 'twist' ? back : across.clone().negate();
  const half = 0.03;
  const camera = new THREE.OrthographicCamera(-half, half, half, -half, 0.01, 10);
  camera.position.copy(centre).addScaledVector(from, 1);
  camera.up.copy(kind === 'twist' ? along.clone().negate() : back);
  camera.lookAt(centre);
  light.position.copy(centre).addScaledVector(from, 1).addScaledVector(camera.up, 0.6);
  light.target.position.copy(centre);
  renderer.render(scene, camera);
  renderer.dispose();
}
