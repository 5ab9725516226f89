// The figure page: a limb-sized cylinder on two bones, twisted 150° (a wrist turned against its
// forearm) or bent 120° (a finger's knuckle), drawn with three.js's linear skinning or with this
// package (`make figures`: docs/figures/dqs-twist-bend.png). Linear skinning pinches the twist into a candy wrapper and
// collapses the bend's inside; dual quaternions keep the limb's thickness.

import * as THREE from 'three';
import { useDualQuaternionSkinning } from '../src/index';

const LENGTH = 0.3;
const RADIUS = 0.035;
/** Half the width of the band around the joint where the two bones share the skin (m). */
const BLEND = 0.04;

/** A capped-less cylinder along y from 0 to LENGTH, skinned to a bone at 0 and one at its middle. */
function limb(): THREE.BufferGeometry {
  const geometry = new THREE.CylinderGeometry(RADIUS, RADIUS, LENGTH, 48, 96, true);
  geometry.translate(0, LENGTH / 2, 0);
  const position = geometry.attributes.position;
  const index = new Uint16Array(4 * position.count);
  const weight = new Float32Array(4 * position.count);
  for (let v = 0; v < position.count; v++) {
    // The second bone's share rises smoothly across the band around the joint.
    const t = THREE.MathUtils.clamp((position.getY(v) - LENGTH / 2 + BLEND) / (2 * BLEND), 0, 1);
    const second = t * t * (3 - 2 * t);
    index.set([0, 1, 0, 0], 4 * v);
    weight.set([1 - second, second, 0, 0], 4 * v);
  }
  geometry.setAttribute('skinIndex', new THREE.BufferAttribute(index, 4));
  geometry.setAttribute('skinWeight', new THREE.BufferAttribute(weight, 4));
  return geometry;
}

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

/** Draws one limb, `kind` twisted 150° or bent 120°, with dual quaternions or three.js's skinning, into a `size`-pixel square canvas (#view). */
export function figure(kind: 'twist' | 'bend', dual: boolean, size: number): void {
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
  scene.add(light);
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
