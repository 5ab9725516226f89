// A frame `dqhand export-skinning` writes (rig.json and rig.bin beside the page, or another name): the
// built-in hand's rest mesh, influences and triangles, each joint's skinning matrix, and
// dqhand's own LB and DQB of it.

export interface Rig {
  vertices: number;
  joints: number;
  rest: Float32Array;
  restNormals: Float32Array;
  joint: Uint32Array;
  weight: Float32Array;
  triangles: Uint32Array;
  /** 16 floats per joint, column-major. */
  skinning: Float32Array;
  lb: Float32Array;
  dqb: Float32Array;
  dqbNormals: Float32Array;
}

/** The frame written as `name`.json and `name`.bin. */
export async function loadRig(name = 'rig'): Promise<Rig> {
  const meta = await (await fetch(`${name}.json`)).json();
  const bin = await (await fetch(`${name}.bin`)).arrayBuffer();
  const view = <T>(make: new (b: ArrayBuffer, o: number, n: number) => T, name: string) => new make(bin, meta.arrays[name].offset, meta.arrays[name].shape.reduce((a: number, b: number) => a * b, 1));
  return {
    vertices: meta.vertices,
    joints: meta.joints,
    rest: view(Float32Array, 'rest_positions'),
    restNormals: view(Float32Array, 'rest_normals'),
    joint: view(Uint32Array, 'joints'),
    weight: view(Float32Array, 'weights'),
    triangles: view(Uint32Array, 'triangles'),
    skinning: view(Float32Array, 'skinning'),
    lb: view(Float32Array, 'lb_positions'),
    dqb: view(Float32Array, 'dqb_positions'),
    dqbNormals: view(Float32Array, 'dqb_normals'),
  };
}
