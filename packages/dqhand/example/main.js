// dqhand in a three.js page: on the desktop, the built-in hand posed by joint angles (its
// fingers closing and opening); in a VR or AR session with hand tracking, both of the user's
// hands, tracked, skinned with dual quaternion blending, grasping a ball on a table.
import * as THREE from 'three';
import { HandMesh, SceneObjects, loadEngine } from 'dqhand';

const status = document.getElementById('status');
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setSize(window.innerWidth, window.innerHeight);
renderer.xr.enabled = true;
renderer.xr.setReferenceSpaceType('local-floor'); // the engine's world: metres, +Y up, floor at 0
renderer.domElement.id = 'view';
document.body.append(renderer.domElement);

const scene = new THREE.Scene();
scene.background = new THREE.Color(0x20242b);
scene.add(new THREE.HemisphereLight(0xffffff, 0x404050, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 1.5);
sun.position.set(1, 2, 1.5);
scene.add(sun);
const camera = new THREE.PerspectiveCamera(40, window.innerWidth / window.innerHeight, 0.01, 20);

const engine = await loadEngine();

// The desktop: a posed hand, its camera on it.
const posed = engine.posedHand({ side: 'right' });
const names = posed.dofNames();
const angles = new Float32Array(names.length);
const flexes = names.map((n, i) => (n.endsWith('.flex') && !n.startsWith('thumb') ? i : -1)).filter((i) => i >= 0);
const desktopHand = new HandMesh(posed);
scene.add(desktopHand);
desktopHand.geometry.computeBoundingSphere();
const { center, radius } = desktopHand.geometry.boundingSphere;
camera.position.copy(center).addScaledVector(new THREE.Vector3(1, 0.15, 0.2).normalize(), 3.2 * radius); // from the index finger's side
camera.lookAt(center);

// In XR: the user's two hands and a ball on a table in front of them.
const hands = engine.hands({
  hands: 'both',
  scene: { table: { height: 0.75 }, objects: [{ name: 'ball', shape: 'sphere', radius: 0.04, position: [0, 0.79, -0.35], mass: 0.15 }] },
});
const xrHands = [0, 1].map((k) => new HandMesh(hands, k));
const objects = new SceneObjects(hands);
const world = new THREE.Group();
world.add(...xrHands, objects);
world.visible = false;
scene.add(world);

/** What the tests read (window.dqhand.state()). */
const state = { simd: engine.simd, mode: null, pushed: 0, tracking: ['waiting', 'waiting'], held: [null, null], events: [], drawn: 0 };
window.dqhand = { state: () => ({ ...state, centres: xrHands.map((m) => m.geometry.boundingSphere.center.toArray()) }) };
status.textContent = `dqhand ${engine.simd ? 'SIMD' : 'scalar'} build`;

for (const [id, mode] of [['enter-vr', 'immersive-vr'], ['enter-ar', 'immersive-ar']]) {
  const button = document.getElementById(id);
  navigator.xr?.isSessionSupported(mode).then((yes) => (button.hidden = !yes), () => {});
  button.addEventListener('click', async () => {
    try {
      const session = await navigator.xr.requestSession(mode, { requiredFeatures: ['local-floor', 'hand-tracking'] });
      session.addEventListener('end', () => {
        state.mode = null;
        world.visible = false;
        desktopHand.visible = true;
      });
      await renderer.xr.setSession(session);
      state.mode = mode;
      world.visible = true;
      desktopHand.visible = false;
    } catch (e) {
      status.textContent = `${button.textContent}: ${e.message}`;
    }
  });
}

renderer.setAnimationLoop((time, frame) => {
  const t = time / 1000;
  if (frame && state.mode) {
    state.pushed += hands.pushXRFrame(frame, renderer.xr.getReferenceSpace(), t);
    for (const e of hands.step(t)) state.events.push(e);
    xrHands.forEach((m) => m.update());
    objects.update();
    state.tracking = [0, 1].map((k) => hands.tracking(k));
    state.held = [0, 1].map((k) => hands.held(k));
  } else {
    const closed = 0.5 - 0.5 * Math.cos(t * 1.5);
    for (const i of flexes) angles[i] = 1.3 * closed;
    posed.setAngles(angles);
    desktopHand.update();
  }
  renderer.render(scene, camera);
  state.drawn++;
});

window.addEventListener('resize', () => {
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(window.innerWidth, window.innerHeight);
});
