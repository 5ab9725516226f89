// The scene the hand manipulates (`dqhand demo --scene`): the table, the objects at their
// streamed poses (the one held tinted), and the contacts as dots with short normal lines.
// All in the engine's world (metres, +Y up), the frame the hand's vertices come in.

import * as THREE from 'three';
import { type HelloScene, MAX_SCENE_CONTACTS, type ObjectShape, type SceneMessage } from './protocol';

/** Object colours, in scene order (blues and greens: apart from the skin and the table). */
const COLOURS = [0x2e6fd8, 0x3b9b6b, 0x6d5bd0, 0x1f9bb0, 0x4f6f8f];
/** The held object's colour. */
export const HELD_COLOUR = 0xff7a1a;
const TABLE_COLOUR = 0xb8926a;
/** The table's slab, as thick as the physics has it (m). */
const TABLE_THICKNESS = 0.05;
/** Length of a contact's normal line (m). */
const NORMAL_LENGTH = 0.02;
/** Above the objects, the room the hand works in, for framing the camera (m). */
const REACH = 0.35;

function shapeGeometry(o: ObjectShape): THREE.BufferGeometry {
  switch (o.shape) {
    case 'sphere':
      return new THREE.SphereGeometry(o.radius, 32, 16);
    case 'box':
      return new THREE.BoxGeometry(...o.size);
    case 'cylinder':
      return new THREE.CylinderGeometry(o.radius, o.radius, o.height, 32);
    case 'mesh': {
      const g = new THREE.BufferGeometry();
      g.setAttribute('position', new THREE.BufferAttribute(o.positions, 3));
      g.setIndex(new THREE.BufferAttribute(o.indices, 1));
      g.computeVertexNormals();
      return g;
    }
  }
}

type Solid = THREE.Mesh<THREE.BufferGeometry, THREE.MeshStandardMaterial>;

export class SceneObjects {
  readonly group = new THREE.Group();
  private readonly objects = new Map<string, Solid>();
  private readonly table: Solid | null = null;
  private readonly dots: THREE.Points<THREE.BufferGeometry, THREE.PointsMaterial>;
  private readonly normals: THREE.LineSegments<THREE.BufferGeometry, THREE.LineBasicMaterial>;
  /** The object held, as the latest scene message says. */
  held: string | null = null;
  /** What the tint shows: the objects held (their names, or empty for none) one per line. */
  private tinted = '';
  contacts = 0;
  /** Scene messages shown. */
  updates = 0;

  constructor(scene: HelloScene) {
    if (scene.table) {
      const { height, centre, half } = scene.table;
      this.table = new THREE.Mesh(
        new THREE.BoxGeometry(2 * half[0], TABLE_THICKNESS, 2 * half[1]),
        new THREE.MeshStandardMaterial({ color: TABLE_COLOUR, roughness: 0.8 }),
      );
      this.table.position.set(centre[0], height - TABLE_THICKNESS / 2, centre[1]);
      this.table.receiveShadow = true;
      this.group.add(this.table);
    }
    scene.objects.forEach((o, i) => {
      // A mesh may be open (the Utah teapot): its inside shows through the gaps.
      const material = new THREE.MeshStandardMaterial({ color: COLOURS[i % COLOURS.length], roughness: 0.45, side: o.shape === 'mesh' ? THREE.DoubleSide : THREE.FrontSide });
      const solid = new THREE.Mesh(shapeGeometry(o), material);
      solid.castShadow = solid.receiveShadow = true;
      solid.visible = false; // until a scene message places it
      solid.userData.colour = material.color.getHex();
      this.objects.set(o.name, solid);
      this.group.add(solid);
    });
    const dots = new THREE.BufferGeometry();
    dots.setAttribute('position', new THREE.BufferAttribute(new Float32Array(3 * MAX_SCENE_CONTACTS), 3));
    this.dots = new THREE.Points(dots, new THREE.PointsMaterial({ color: 0xd01c1c, size: 7, sizeAttenuation: false, depthTest: false }));
    const lines = new THREE.BufferGeometry();
    lines.setAttribute('position', new THREE.BufferAttribute(new Float32Array(6 * MAX_SCENE_CONTACTS), 3));
    this.normals = new THREE.LineSegments(lines, new THREE.LineBasicMaterial({ color: 0xd01c1c, depthTest: false }));
    for (const o of [this.dots, this.normals]) {
      o.renderOrder = 10;
      o.frustumCulled = false;
      o.geometry.setDrawRange(0, 0);
      this.group.add(o);
    }
  }

  /** Moves the objects to a scene message's poses, tints the ones held and draws the contacts (objects the hello did not name are ignored). */
  update(m: SceneMessage): void {
    for (const [name, { p, q }] of Object.entries(m.objects)) {
      const solid = this.objects.get(name);
      if (!solid) continue;
      solid.position.set(...p);
      solid.quaternion.set(...q);
      solid.visible = true;
    }
    // With two hands, each one's object is tinted.
    const held = m.holding ? [m.holding.left, m.holding.right] : [m.held];
    const tinted = held.join('\n');
    if (tinted !== this.tinted) {
      for (const [name, solid] of this.objects) solid.material.color.setHex(held.includes(name) ? HELD_COLOUR : solid.userData.colour);
      this.tinted = tinted;
    }
    this.held = m.held;
    const dots = this.dots.geometry.getAttribute('position') as THREE.BufferAttribute;
    const lines = this.normals.geometry.getAttribute('position') as THREE.BufferAttribute;
    const d = dots.array as Float32Array;
    const l = lines.array as Float32Array;
    m.contacts.forEach(({ p, n }, i) => {
      d.set(p, 3 * i);
      l.set(p, 6 * i);
      for (let k = 0; k < 3; k++) l[6 * i + 3 + k] = p[k] + NORMAL_LENGTH * n[k];
    });
    dots.needsUpdate = lines.needsUpdate = true;
    this.contacts = m.contacts.length;
    this.dots.geometry.setDrawRange(0, this.contacts);
    this.normals.geometry.setDrawRange(0, 2 * this.contacts);
    this.updates++;
  }

  /** Where the camera should look: the placed objects and the room above them where the hand reaches. */
  frame(out: THREE.Box3): THREE.Box3 {
    out.makeEmpty();
    for (const solid of this.objects.values()) if (solid.visible) out.expandByObject(solid);
    if (out.isEmpty() && this.table) out.expandByObject(this.table);
    out.max.y += REACH;
    return out;
  }

  /** Objects drawn now (placed by a scene message), by name. */
  drawn(): string[] {
    return [...this.objects].filter(([, solid]) => solid.visible).map(([name]) => name);
  }

  /** Frees the GPU buffers of the table, the objects and the contact overlays. */
  dispose(): void {
    for (const o of [this.table, ...this.objects.values(), this.dots, this.normals]) {
      o?.geometry.dispose();
      o?.material.dispose();
    }
  }
}
