// The three.js scene: up to four hands side by side (one per skinning method), lit so that
// creases and volume read, with optional heat map, wireframe and skeleton overlays; or, with a
// manipulation scene, one hand (or a server's two) among the objects in their common world. Geometry comes from
// the engine; this file only draws it.

import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { disposeLook, type Look } from './look';
import { SceneObjects } from './objects';
import { type Frame, type HelloScene, type Method, METHODS, type SceneMessage, type Side, type Topology } from './protocol';

const SKIN = new THREE.Color(0xe0a98f);
/** Distortion that maps to the top of the heat scale (30 % mean edge-length change). */
export const HEAT_MAX = 0.3;

/** Heat colour of a distortion value: neutral blue-grey at 0, yellow at half, red at HEAT_MAX. */
export function heatColor(value: number, out: THREE.Color): THREE.Color {
  const t = Math.min(Math.max(value / HEAT_MAX, 0), 1);
  if (t < 0.5) return out.setRGB(0.55 + 0.9 * t, 0.6 + 0.6 * t, 0.75 - 1.3 * t);
  const s = (t - 0.5) * 2;
  return out.setRGB(1.0, 0.9 - 0.8 * s, 0.1 - 0.05 * s);
}

/**
 * The engine's frame (WebXR: fingers along −Z, back of the hand +Y) turned for viewing:
 * fingers up, palm toward the default camera.
 */
const PRESENT = new THREE.Quaternion().setFromEuler(new THREE.Euler(Math.PI / 2, Math.PI, 0, 'YXZ'));
/** The engine's frame as it is: hands in the world (a scene's, or where the user's is). */
const UNTURNED = new THREE.Quaternion();

class HandView {
  /** Placed side by side in the scene (mirrored by `HandScene.place` for a left hand in the world). */
  readonly group = new THREE.Group();
  /** Engine coordinates inside (turned for viewing or not by `HandScene.place`). */
  readonly oriented = new THREE.Group();
  /** The skin, its vertex arrays rewritten by each frame; drawn in its look's materials, or the plain one. */
  readonly mesh: THREE.Mesh<THREE.BufferGeometry, THREE.Material | THREE.Material[]>;
  /** One skin-coloured material: before the look arrives, for a model without one, and under the heat map. */
  private readonly plain: THREE.MeshPhysicalMaterial;
  private look: Look | null = null;
  private lookShown = true;
  /** The skeleton overlay: one segment from each joint to its parent. */
  readonly bones: THREE.LineSegments<THREE.BufferGeometry, THREE.LineBasicMaterial>;
  /** The skeleton overlay: a dot on each joint. */
  readonly jointDots: THREE.Points<THREE.BufferGeometry, THREE.PointsMaterial>;
  method: Method | null = null;

  constructor(readonly topology: Topology) {
    const n = topology.vertexCount;
    const geometry = new THREE.BufferGeometry();
    geometry.setIndex(new THREE.BufferAttribute(topology.indices, 1));
    for (const [name, size] of [['position', 3], ['normal', 3], ['color', 3]] as const) {
      const attribute = new THREE.BufferAttribute(new Float32Array(n * size), size);
      attribute.setUsage(THREE.DynamicDrawUsage);
      geometry.setAttribute(name, attribute);
    }
    this.plain = new THREE.MeshPhysicalMaterial({
      color: SKIN, roughness: 0.55, metalness: 0, sheen: 0.5, sheenRoughness: 0.5,
      sheenColor: new THREE.Color(0xff8f7a), clearcoat: 0.08, clearcoatRoughness: 0.5,
    });
    this.mesh = new THREE.Mesh(geometry, this.plain);
    this.mesh.castShadow = true;
    this.mesh.receiveShadow = true;
    this.mesh.frustumCulled = false;
    const pairs = Array.from(topology.parents).filter((p) => p >= 0).length;
    const lines = new THREE.BufferGeometry();
    lines.setAttribute('position', new THREE.BufferAttribute(new Float32Array(pairs * 6), 3));
    this.bones = new THREE.LineSegments(lines, new THREE.LineBasicMaterial({ color: 0x1d6fe0, depthTest: false }));
    const dots = new THREE.BufferGeometry();
    dots.setAttribute('position', new THREE.BufferAttribute(new Float32Array(topology.parents.length * 3), 3));
    this.jointDots = new THREE.Points(dots, new THREE.PointsMaterial({ color: 0x0b3d91, size: 6, sizeAttenuation: false, depthTest: false }));
    for (const o of [this.bones, this.jointDots]) {
      o.renderOrder = 10;
      o.frustumCulled = false;
    }
    this.oriented.add(this.mesh, this.bones, this.jointDots);
    this.group.add(this.oriented);
  }

  update(frame: Frame, index: number, parents: Int32Array, heat: THREE.Color): void {
    const arrays = frame.meshes[index];
    this.method = arrays.method;
    const g = this.mesh.geometry;
    const position = g.getAttribute('position') as THREE.BufferAttribute;
    const normal = g.getAttribute('normal') as THREE.BufferAttribute;
    (position.array as Float32Array).set(arrays.positions);
    (normal.array as Float32Array).set(arrays.normals);
    position.needsUpdate = true;
    normal.needsUpdate = true;
    const material = this.plain;
    const heatOn = arrays.distortion !== null;
    if (heatOn) {
      const color = g.getAttribute('color') as THREE.BufferAttribute;
      const c = color.array as Float32Array;
      arrays.distortion!.forEach((d, v) => {
        heatColor(d, heat);
        c[3 * v] = heat.r;
        c[3 * v + 1] = heat.g;
        c[3 * v + 2] = heat.b;
      });
      color.needsUpdate = true;
    }
    if (material.vertexColors !== heatOn) {
      material.vertexColors = heatOn;
      material.color.set(heatOn ? 0xffffff : SKIN);
      material.sheen = heatOn ? 0 : 0.5;
      material.needsUpdate = true;
      this.drawMaterial();
    }
    const lines = this.bones.geometry.getAttribute('position') as THREE.BufferAttribute;
    const l = lines.array as Float32Array;
    let k = 0;
    parents.forEach((p, j) => {
      if (p < 0) return;
      l.set(frame.joints.subarray(3 * p, 3 * p + 3), k);
      l.set(frame.joints.subarray(3 * j, 3 * j + 3), k + 3);
      k += 6;
    });
    lines.needsUpdate = true;
    const dots = this.jointDots.geometry.getAttribute('position') as THREE.BufferAttribute;
    (dots.array as Float32Array).set(frame.joints);
    dots.needsUpdate = true;
  }

  /** Draws the skin in `look`'s regions and materials (the heat map still in the plain one). */
  setLook(look: Look): void {
    const g = this.mesh.geometry;
    g.setAttribute('uv', look.uv);
    g.clearGroups();
    look.groups.forEach((group, k) => g.addGroup(group.start, group.count, k));
    this.look = look;
    this.setWireframe(this.wireframe);
    this.drawMaterial();
  }

  /** Draws the look, or the plain material (false), where there is a look and no heat map. */
  showLook(on: boolean): void {
    this.lookShown = on;
    this.drawMaterial();
  }

  private wireframe = false;

  private drawMaterial(): void {
    this.mesh.material = this.look && this.lookShown && !this.plain.vertexColors ? this.look.materials : this.plain;
  }

  /** The look's materials by name, in draw-group order, while the skin is drawn in them; null otherwise (none yet, none at all, the heat map, `showLook(false)`). */
  lookNames(): string[] | null {
    return this.look && this.mesh.material === this.look.materials ? this.look.materials.map((m) => m.name) : null;
  }

  setWireframe(on: boolean): void {
    this.wireframe = on;
    for (const m of [this.plain, ...(this.look?.materials ?? [])]) (m as THREE.MeshStandardMaterial).wireframe = on;
  }

  /** Frees the GPU buffers of the skin, bones and joint dots (their geometries and own materials; a look's are its hand's). */
  dispose(): void {
    for (const o of [this.mesh, this.bones, this.jointDots]) o.geometry.dispose();
    for (const m of [this.plain, this.bones.material, this.jointDots.material]) m.dispose();
  }
}

export class HandScene {
  readonly renderer: THREE.WebGLRenderer;
  readonly scene = new THREE.Scene();
  readonly camera = new THREE.PerspectiveCamera(35, 1, 0.005, 20);
  readonly controls: OrbitControls;
  private readonly key: THREE.DirectionalLight;
  private readonly ground: THREE.Mesh;
  private views: HandView[] = [];
  /** Each hand's look, drawn by its views: freed when they are replaced. */
  private readonly applied: [Look | null, Look | null] = [null, null];
  /** What every view is drawn with: wireframe, and the look or the plain material. */
  private wireframe = false;
  private lookShown = true;
  private parents: Int32Array = new Int32Array(0);
  /** The second hand of a server driving two (its topology's hand 1), and its skeleton's parents; drawn in the world beside the first. */
  private second: { view: HandView; parents: Int32Array } | null = null;
  private spacing = 0.15;
  private framed = false;
  private shownCount = 0;
  private readonly heat = new THREE.Color();
  /** Centre and size of the hand at the first frame (with a scene: of the objects and the room above them), for camera presets. */
  readonly bounds = new THREE.Box3();
  /** The manipulation scene, or null: then hands are turned for viewing (PRESENT); with one, they stay in the world the objects are in. */
  objects: SceneObjects | null = null;
  /** One hand in the world, mirrored back (left) or not, while the page's own input drives it; null: not. */
  private world: Side | null = null;
  /** The camera of an XR session: three.js moves the camera it renders with to the headset's pose, so not the desktop's. */
  private readonly xrCamera = new THREE.PerspectiveCamera(70, 1, 0.01, 20);
  showSkeleton = false;
  lastFrame: Frame | null = null;
  /** The second hand's latest frame shown, null without one. */
  secondFrame: Frame | null = null;
  /** The second hand is left out of the picture (the tests' hook, to see what it draws). */
  private secondHidden = false;

  constructor(readonly canvas: HTMLCanvasElement) {
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
    this.renderer.shadowMap.enabled = true;
    this.renderer.shadowMap.type = THREE.PCFShadowMap;
    this.renderer.toneMapping = THREE.ACESFilmicToneMapping;
    this.renderer.toneMappingExposure = 1.05;
    this.scene.background = new THREE.Color(0xf2f1ee);
    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.enableDamping = true;

    this.scene.add(new THREE.HemisphereLight(0xfdfbf7, 0x9a8a80, 1.3));
    this.key = new THREE.DirectionalLight(0xfff4e8, 2.4);
    this.key.castShadow = true;
    this.key.shadow.mapSize.set(2048, 2048);
    this.key.shadow.radius = 6;
    this.key.shadow.blurSamples = 16;
    this.key.shadow.bias = -0.0004;
    this.key.shadow.normalBias = 0.002;
    this.scene.add(this.key, this.key.target);
    const fill = new THREE.DirectionalLight(0xdde8ff, 0.7);
    fill.position.set(-1, 0.4, -0.6);
    this.scene.add(fill);
    this.ground = new THREE.Mesh(new THREE.PlaneGeometry(4, 4), new THREE.ShadowMaterial({ opacity: 0.22 }));
    this.ground.rotation.x = -Math.PI / 2;
    this.ground.receiveShadow = true;
    this.scene.add(this.ground);
  }

  /**
   * Draws hand `topology.hand` in `look` (its file's, for that topology: a look that arrives
   * after another session's topology replaced it is dropped).
   */
  setLook(topology: Topology, look: Look): void {
    const views = (topology.hand === 1 ? (this.second ? [this.second.view] : []) : this.views).filter((v) => v.topology === topology);
    if (views.length === 0) return disposeLook(look);
    this.dropLook(topology.hand);
    this.applied[topology.hand] = look;
    for (const v of views) v.setLook(look);
  }

  /** Frees hand `hand`'s look (its materials and their maps), its views replaced. */
  private dropLook(hand: number): void {
    const look = this.applied[hand];
    this.applied[hand] = null;
    if (look) disposeLook(look);
  }

  /** Draws every hand in its look (true) or in the plain skin material, as before the look (the figures' before and after). */
  showLook(on: boolean): void {
    this.lookShown = on;
    for (const v of this.hands()) v.showLook(on);
  }

  /** A new view drawn as the others are: wireframe or not, the look shown or not. */
  private styled(view: HandView): HandView {
    view.setWireframe(this.wireframe);
    view.showLook(this.lookShown);
    return view;
  }

  /** Each hand's look (`HandView.lookNames`): the first's, then the second's where there is one. */
  looks(): (string[] | null)[] {
    return [this.views[0]?.lookNames() ?? null, ...(this.second ? [this.second.view.lookNames()] : [])];
  }

  setTopology(topology: Topology): void {
    this.dropLook(1);
    if (topology.hand === 0) this.dropLook(0);
    if (this.second) {
      // A new session (its first hand's topology) or the second hand's replaced.
      this.scene.remove(this.second.view.group);
      this.second.view.dispose();
      this.second = null;
      this.secondFrame = null;
    }
    if (topology.hand === 1) {
      this.second = { view: this.styled(new HandView(topology)), parents: topology.parents };
      this.second.view.group.visible = false; // until its first frame
      this.place(this.second.view);
      this.scene.add(this.second.view.group);
      return;
    }
    for (const v of this.views) {
      this.scene.remove(v.group);
      v.dispose();
    }
    this.views = METHODS.map(() => this.styled(new HandView(topology)));
    for (const v of this.views) {
      this.place(v);
      this.scene.add(v.group);
    }
    this.parents = topology.parents;
    this.framed = false;
  }

  /**
   * Sets the hello's scene (null: none): its table and objects are drawn once a scene message
   * places them, and the hands are drawn in the world beside them (a hello comes before the
   * topology that builds the hands).
   */
  setScene(scene: HelloScene | null): void {
    if (this.objects) {
      this.scene.remove(this.objects.group);
      this.objects.dispose();
    }
    this.objects = scene && new SceneObjects(scene);
    if (this.objects) this.scene.add(this.objects.group);
    for (const v of this.hands()) this.place(v);
    this.framed = false;
  }

  /** Every hand view: the first hand's three, and the second hand's. */
  private hands(): HandView[] {
    return this.second ? [...this.views, this.second.view] : this.views;
  }

  /**
   * Draws one hand (DQB) in the engine's world, where the user's tracked hand is (an XR
   * session, the camera), or turned for viewing again (off). `left`: the engine mirrored the
   * tracked hand onto its own (x → −x about the world's origin), so it is mirrored back.
   */
  setWorld(on: boolean, side: Side): void {
    this.world = on ? side : null;
    for (const v of this.hands()) this.place(v);
  }

  /** Turns and mirrors a hand for the scene, the world or viewing. */
  private place(v: HandView): void {
    v.oriented.quaternion.copy(this.objects || this.world ? UNTURNED : PRESENT);
    v.group.scale.x = this.world === 'left' ? -1 : 1;
  }

  /** Shows a scene message; the first frames the camera on the objects (the floor's shadow at y = 0). */
  showScene(message: SceneMessage): void {
    if (!this.objects) return;
    this.objects.update(message);
    if (!this.framed) {
      this.framed = true;
      this.objects.frame(this.bounds);
      this.ground.position.y = 0;
      this.setView('default');
    }
  }

  /**
   * Shows a frame: one hand per mesh in it, side by side; with a scene or in the world one
   * hand (DQB in a split view: four hands side by side would not be where the objects are).
   */
  showFrame(frame: Frame): void {
    if (frame.header.second) return this.showSecond(frame);
    if (this.views.length === 0 || frame.header.vertexCount !== this.views[0].mesh.geometry.getAttribute('position').count) return;
    this.lastFrame = frame;
    const world = this.objects !== null || this.world !== null || this.second !== null;
    const count = world ? 1 : frame.meshes.length;
    const first = world ? Math.max(0, frame.header.methods.indexOf('dqb')) : 0;
    this.views.forEach((view, i) => {
      view.group.visible = i < count;
      if (i >= count) return;
      view.update(frame, first + i, this.parents, this.heat);
      view.group.position.x = (i - (count - 1) / 2) * this.spacing;
      view.bones.visible = view.jointDots.visible = this.showSkeleton;
    });
    if (!this.framed && !world) {
      this.framed = true;
      const first = this.views[0];
      first.mesh.geometry.computeBoundingBox();
      this.bounds.copy(first.mesh.geometry.boundingBox!).applyMatrix4(new THREE.Matrix4().makeRotationFromQuaternion(PRESENT));
      const size = this.bounds.getSize(new THREE.Vector3());
      this.spacing = Math.max(size.x, 0.6 * size.z) * 1.2;
      this.ground.position.y = this.bounds.min.y - 0.03;
    }
    if (count !== this.shownCount) {
      this.shownCount = count;
      this.setView('default');
    }
  }

  /** Shows the second hand's frame (DQB, or its one method), placed as the first hand is in the world. */
  private showSecond(frame: Frame): void {
    const second = this.second;
    if (!second || frame.header.vertexCount !== second.view.mesh.geometry.getAttribute('position').count) return;
    this.secondFrame = frame;
    second.view.update(frame, Math.max(0, frame.header.methods.indexOf('dqb')), second.parents, this.heat);
    second.view.group.visible = !this.secondHidden;
    second.view.bones.visible = second.view.jointDots.visible = this.showSkeleton;
  }

  /** Draws the second hand or leaves it out (the tests' hook). */
  showSecondHand(on: boolean): void {
    this.secondHidden = !on;
    if (this.second && this.secondFrame) this.second.view.group.visible = on;
  }

  /** Visible hands and their methods, left to right. */
  visibleMethods(): (Method | null)[] {
    return this.views.filter((v) => v.group.visible).map((v) => v.method);
  }

  setWireframe(on: boolean): void {
    this.wireframe = on;
    for (const v of this.hands()) v.setWireframe(on);
  }

  /**
   * Camera: from the front (`default`), from the index finger's side (`side`) or along a
   * given direction, at the whole scene or close on a point.
   */
  setView(preset: 'default' | 'side' | [number, number, number], focus?: THREE.Vector3, distance?: number): void {
    const center = focus ?? this.bounds.getCenter(new THREE.Vector3());
    const count = Math.max(1, this.visibleMethods().length);
    const size = this.bounds.getSize(new THREE.Vector3()).length();
    const d = distance ?? size * (1.5 + 0.55 * (count - 1));
    const direction = Array.isArray(preset)
      ? new THREE.Vector3(...preset)
      : preset === 'side' ? new THREE.Vector3(1, 0.15, 0.2) : new THREE.Vector3(0.3, 0.35, 1);
    this.controls.target.copy(center);
    this.camera.position.copy(center).addScaledVector(direction.normalize(), d);
    this.key.position.copy(center).add(new THREE.Vector3(0.35, 1.0, 0.6));
    this.key.target.position.copy(center);
    const s = this.key.shadow.camera;
    const reach = Math.max(0.4, 0.6 * size);
    s.left = s.bottom = -reach;
    s.right = s.top = reach;
    s.near = 0.1;
    s.far = 3;
    s.updateProjectionMatrix();
    this.controls.update();
  }

  /** Where the first visible hand's joint `index` is in the world (for zoomed figures). */
  jointPosition(index: number): THREE.Vector3 | null {
    const f = this.lastFrame;
    if (!f || 3 * index + 2 >= f.joints.length) return null;
    const first = this.views.find((v) => v.group.visible) ?? this.views[0];
    first.group.updateMatrixWorld();
    return first.oriented.localToWorld(new THREE.Vector3(f.joints[3 * index], f.joints[3 * index + 1], f.joints[3 * index + 2]));
  }

  /** Where each joint of the first visible hand is drawn, as fractions of the canvas from its top left (to grade a tracker run on the canvas). */
  jointsOnScreen(): [number, number][] {
    const joints = (this.lastFrame?.joints.length ?? 0) / 3;
    return Array.from({ length: joints }, (_, i) => {
      const p = this.jointPosition(i)!.project(this.camera);
      return [(p.x + 1) / 2, (1 - p.y) / 2] as [number, number];
    });
  }

  /** Screen position (CSS pixels) of each visible hand's centre, for the method labels. */
  labelPositions(): { method: Method | null; x: number; y: number }[] {
    const rect = this.canvas.getBoundingClientRect();
    const top = new THREE.Vector3();
    return this.views
      .filter((v) => v.group.visible)
      .map((v) => {
        top.set(0, this.bounds.max.y + 0.02, 0).add(this.bounds.getCenter(new THREE.Vector3()).setY(0)).add(v.group.position);
        top.project(this.camera);
        return { method: v.method, x: ((top.x + 1) / 2) * rect.width, y: ((1 - top.y) / 2) * rect.height };
      });
  }

  render(): void {
    if (this.renderer.xr.isPresenting) return this.renderer.render(this.scene, this.xrCamera);
    const { clientWidth: w, clientHeight: h } = this.canvas;
    if (this.canvas.width !== Math.floor(w * this.renderer.getPixelRatio()) || this.canvas.height !== Math.floor(h * this.renderer.getPixelRatio())) {
      this.renderer.setSize(w, h, false);
      this.camera.aspect = w / Math.max(h, 1);
      this.camera.updateProjectionMatrix();
    }
    this.controls.update();
    this.renderer.render(this.scene, this.camera);
  }
}
