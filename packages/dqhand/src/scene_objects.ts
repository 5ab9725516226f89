// A scene's objects (and its table) as three.js meshes, moved to the engine's object poses each
// frame: the shapes once, from the engine's own description; the poses read in place.

import { BoxGeometry, BufferAttribute, BufferGeometry, CylinderGeometry, Group, Mesh, MeshStandardMaterial, SphereGeometry, type Material } from 'three';
import type { Hands, ObjectShape } from './engine.js';

/** The objects' colour, and the held object's. */
export const OBJECT_COLOUR = 0x6f8fb8;
export const HELD_COLOUR = 0xd9a440;
/** The table's colour. */
export const TABLE_COLOUR = 0x8a6f55;

function geometryOf(o: ObjectShape): BufferGeometry {
  switch (o.shape) {
    case 'sphere':
      return new SphereGeometry(o.radius, 32, 16);
    case 'box':
      return new BoxGeometry(...o.size);
    case 'cylinder':
      return new CylinderGeometry(o.radius, o.radius, o.height, 32);
    case 'mesh': {
      const g = new BufferGeometry();
      g.setAttribute('position', new BufferAttribute(Float32Array.from(o.positions), 3));
      g.setIndex(o.indices);
      g.computeVertexNormals();
      return g;
    }
  }
}

/** The objects of `hands`' scene, one mesh each named as the object, and its table. Call `update()` after each `step`. */
export class SceneObjects extends Group {
  private readonly meshes: Mesh<BufferGeometry, MeshStandardMaterial>[];
  private readonly heldNow: (string | null)[] = [];

  constructor(readonly hands: Hands) {
    super();
    this.meshes = hands.objects().map((o) => {
      const mesh = new Mesh(geometryOf(o), new MeshStandardMaterial({ color: OBJECT_COLOUR, roughness: 0.5 }));
      mesh.name = o.name;
      return mesh;
    });
    const table = hands.table();
    if (table) {
      const top = new Mesh(new BoxGeometry(2 * table.half[0], 0.02, 2 * table.half[1]), new MeshStandardMaterial({ color: TABLE_COLOUR, roughness: 0.8 }) as Material);
      top.position.set(table.centre[0], table.height - 0.01, table.centre[1]);
      top.name = 'table';
      this.add(top);
    }
    this.add(...this.meshes);
    this.update();
  }

  /** Moves each object to its pose, and colours the ones a hand holds. */
  update(): void {
    for (let k = 0; k < this.hands.count; k++) this.heldNow[k] = this.hands.held(k);
    const poses = this.hands.poses(); // after the calls above, which may grow the memory
    this.meshes.forEach((m, i) => {
      m.position.fromArray(poses, 7 * i);
      m.quaternion.fromArray(poses, 7 * i + 3);
      m.material.color.setHex(this.heldNow.includes(m.name) ? HELD_COLOUR : OBJECT_COLOUR);
    });
  }
}
