// The conformance page: the package's GPU skinning read back from a float render target and
// compared with dqhand's native output of the same frame (`dqhand export-skinning`: rig.json and
// rig.bin beside this page) and, over random poses, with a reference written here from the
// definitions (double precision; it shares no code with the package).

import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { loadRig, type Rig } from './rig';
import { useDualQuaternionSkinning, type SkinningMode } from '../src/index';

const renderer = new THREE.WebGLRenderer();
const camera = new THREE.OrthographicCamera();

/**
 * A SkinnedMesh whose every vertex is drawn as a tiny triangle over its own pixel of a float
 * target: the fragment holds the skinned position (or normal), as the material's skinning
 * chunks computed it.
 */
function readbackMesh(rig: Rig, bones: THREE.Bone[], width: number, output: 'position' | 'normal', blend?: (v: number) => number): THREE.SkinnedMesh {
  const n = rig.vertices;
  const geometry = new THREE.BufferGeometry();
  const corners = [-0.4, -0.4, 0.8, -0.4, -0.4, 0.8];
  const position = new Float32Array(9 * n);
  const normal = new Float32Array(9 * n);
  const skinIndex = new Uint16Array(12 * n);
  const skinWeight = new Float32Array(12 * n);
  const corner = new Float32Array(6 * n);
  const slot = new Float32Array(3 * n);
  for (let v = 0; v < n; v++) {
    for (let c = 0; c < 3; c++) {
      const k = 3 * v + c;
      position.set(rig.rest.subarray(3 * v, 3 * v + 3), 3 * k);
      normal.set(rig.restNormals.subarray(3 * v, 3 * v + 3), 3 * k);
      skinIndex.set(rig.joint.subarray(4 * v, 4 * v + 4), 4 * k);
      skinWeight.set(rig.weight.subarray(4 * v, 4 * v + 4), 4 * k);
      corner.set(corners.slice(2 * c, 2 * c + 2), 2 * k);
      slot[k] = v;
    }
  }
  geometry.setAttribute('position', new THREE.BufferAttribute(position, 3));
  geometry.setAttribute('normal', new THREE.BufferAttribute(normal, 3));
  geometry.setAttribute('skinIndex', new THREE.BufferAttribute(skinIndex, 4));
  geometry.setAttribute('skinWeight', new THREE.BufferAttribute(skinWeight, 4));
  geometry.setAttribute('corner', new THREE.BufferAttribute(corner, 2));
  geometry.setAttribute('slot', new THREE.BufferAttribute(slot, 1));
  if (blend) geometry.setAttribute('dqsBlend', new THREE.BufferAttribute(slot.map(blend), 1));
  const material = new THREE.ShaderMaterial({
    defines: output === 'normal' ? { OUTPUT_NORMAL: '' } : {},
    uniforms: { size: { value: new THREE.Vector2(width, Math.ceil(n / width)) } },
    vertexShader: /* glsl */ `
      #include <common>
      #include <skinning_pars_vertex>
      attribute vec2 corner;
      attribute float slot;
      uniform vec2 size;
      varying vec3 vValue;
      void main() {
        vec3 objectNormal = vec3( normal );
        #include <skinbase_vertex>
        #include <skinnormal_vertex>
        vec3 transformed = vec3( position );
        #include <skinning_vertex>
        #ifdef OUTPUT_NORMAL
          vValue = normalize( objectNormal );
        #else
          vValue = transformed;
        #endif
        vec2 pixel = vec2( mod( slot, size.x ), floor( slot / size.x ) ) + 0.5 + corner;
        gl_Position = vec4( pixel / size * 2.0 - 1.0, 0.0, 1.0 );
      }`,
    fragmentShader: /* glsl */ `
      varying vec3 vValue;
      void main() { gl_FragColor = vec4( vValue, 1.0 ); }`,
  });
  const mesh = new THREE.SkinnedMesh(geometry, material);
  mesh.frustumCulled = false;
  mesh.bind(new THREE.Skeleton(bones, bones.map(() => new THREE.Matrix4())), new THREE.Matrix4());
  return mesh;
}

/** Bones whose skinning matrices are `matrices` (16 per joint, column-major): their world matrices, with identity inverses. */
function bonesOf(matrices: ArrayLike<number>, joints: number): THREE.Bone[] {
  return Array.from({ length: joints }, (_, j) => {
    const bone = new THREE.Bone();
    bone.matrixAutoUpdate = false;
    bone.matrixWorldAutoUpdate = false;
    bone.matrixWorld.fromArray(Array.from(matrices).slice(16 * j, 16 * j + 16));
    return bone;
  });
}

/** The mesh's skinned positions or normals as the GPU computes them, 3 floats per vertex. */
function readBack(rig: Rig, matrices: ArrayLike<number>, mode: SkinningMode | 'three', output: 'position' | 'normal', breakAlignment = false): Float32Array {
  const width = 128;
  const height = Math.ceil(rig.vertices / width);
  const mesh = readbackMesh(rig, bonesOf(matrices, rig.joints), width, output, mode === 'blend' ? blendOf : undefined);
  if (mode !== 'three') {
    useDualQuaternionSkinning(mesh, { mode });
    if (breakAlignment) {
      // The mistake this package avoids, injected: no sign alignment at all.
      const material = mesh.material as THREE.ShaderMaterial;
      const compile = material.onBeforeCompile;
      material.onBeforeCompile = (shader, r) => {
        compile.call(material, shader, r);
        shader.vertexShader = shader.vertexShader.replace(/dot\( dqsReal\d, dqsPivot \) < 0\.0/g, 'false');
      };
      material.customProgramCacheKey = () => 'broken-alignment';
    }
  }
  const target = new THREE.WebGLRenderTarget(width, height, { type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: false });
  const scene = new THREE.Scene();
  scene.add(mesh);
  renderer.setRenderTarget(target);
  renderer.setClearColor(0x000000, 0);
  renderer.clear();
  renderer.render(scene, camera);
  const pixels = new Float32Array(4 * width * height);
  renderer.readRenderTargetPixels(target, 0, 0, width, height, pixels);
  renderer.setRenderTarget(null);
  target.dispose();
  const out = new Float32Array(3 * rig.vertices);
  for (let v = 0; v < rig.vertices; v++) out.set(pixels.subarray(4 * v, 4 * v + 3), 3 * v);
  return out;
}

/** The `dqsBlend` of vertex `v` in mode 'blend': 0 (linear) for even vertices, 1 (dual quaternion) for odd ones. */
const blendOf = (v: number) => v % 2;

/** Positions that are `even`'s on even vertices and `odd`'s on odd ones. */
function alternate(even: ArrayLike<number>, odd: ArrayLike<number>): Float32Array {
  return Float32Array.from({ length: even.length }, (_, i) => (Math.floor(i / 3) % 2 ? odd[i] : even[i]));
}

/** The package's CPU path (applyBoneTransform) for every vertex. */
function cpuPositions(rig: Rig, matrices: ArrayLike<number>): Float32Array {
  const mesh = readbackMesh(rig, bonesOf(matrices, rig.joints), 128, 'position');
  useDualQuaternionSkinning(mesh);
  const out = new Float32Array(3 * rig.vertices);
  const p = new THREE.Vector3();
  for (let v = 0; v < rig.vertices; v++) {
    // Vertex 3v of the read-back geometry is vertex v of the rig.
    mesh.getVertexPosition(3 * v, p);
    out.set([p.x, p.y, p.z], 3 * v);
  }
  return out;
}

// ---- The reference, from the definitions (Kavan et al. 2008), in double precision. ----

/** A rotation matrix's unit quaternion (x, y, z, w), Shepperd's method, from a column-major 4×4. */
function quaternionOf(m: ArrayLike<number>, o: number): number[] {
  const r = (row: number, col: number) => m[o + 4 * col + row];
  const trace = r(0, 0) + r(1, 1) + r(2, 2);
  const candidates = [trace, r(0, 0), r(1, 1), r(2, 2)];
  const k = candidates.indexOf(Math.max(...candidates));
  let q: number[];
  if (k === 0) {
    const s = 2 * Math.sqrt(1 + trace);
    q = [(r(2, 1) - r(1, 2)) / s, (r(0, 2) - r(2, 0)) / s, (r(1, 0) - r(0, 1)) / s, s / 4];
  } else if (k === 1) {
    const s = 2 * Math.sqrt(1 + r(0, 0) - r(1, 1) - r(2, 2));
    q = [s / 4, (r(0, 1) + r(1, 0)) / s, (r(0, 2) + r(2, 0)) / s, (r(2, 1) - r(1, 2)) / s];
  } else if (k === 2) {
    const s = 2 * Math.sqrt(1 + r(1, 1) - r(0, 0) - r(2, 2));
    q = [(r(0, 1) + r(1, 0)) / s, s / 4, (r(1, 2) + r(2, 1)) / s, (r(0, 2) - r(2, 0)) / s];
  } else {
    const s = 2 * Math.sqrt(1 + r(2, 2) - r(0, 0) - r(1, 1));
    q = [(r(0, 2) + r(2, 0)) / s, (r(1, 2) + r(2, 1)) / s, s / 4, (r(1, 0) - r(0, 1)) / s];
  }
  return q;
}

/** Hamilton product of quaternions (x, y, z, w). */
function mul(a: number[], b: number[]): number[] {
  return [
    a[3] * b[0] + a[0] * b[3] + a[1] * b[2] - a[2] * b[1],
    a[3] * b[1] - a[0] * b[2] + a[1] * b[3] + a[2] * b[0],
    a[3] * b[2] + a[0] * b[1] - a[1] * b[0] + a[2] * b[3],
    a[3] * b[3] - a[0] * b[0] - a[1] * b[1] - a[2] * b[2],
  ];
}

/**
 * Reference DQB positions and normals: per vertex, dual quaternions aligned with the heaviest
 * influence, blended, normalised, applied as q v q* + t; with `scales` (a symmetric 3×3 per
 * joint, column-major, the bone's matrix being its rigid `matrices` one times it), the vertex is
 * first moved by the weighted sum of the scales, and the normal by that sum's inverse transpose.
 */
function reference(rig: Rig, matrices: ArrayLike<number>, scales?: number[][]): { positions: Float64Array; normals: Float64Array } {
  const duals = Array.from({ length: rig.joints }, (_, j) => {
    const q = quaternionOf(matrices, 16 * j);
    const t = [matrices[16 * j + 12], matrices[16 * j + 13], matrices[16 * j + 14], 0];
    return { q, d: mul(t, q).map((x) => x / 2) };
  });
  const positions = new Float64Array(3 * rig.vertices);
  const normals = new Float64Array(3 * rig.vertices);
  for (let v = 0; v < rig.vertices; v++) {
    const w = Array.from(rig.weight.subarray(4 * v, 4 * v + 4));
    const ids = Array.from(rig.joint.subarray(4 * v, 4 * v + 4));
    const pivot = duals[ids[w.indexOf(Math.max(...w))]].q;
    const real = [0, 0, 0, 0];
    const dual = [0, 0, 0, 0];
    for (let k = 0; k < 4; k++) {
      const { q, d } = duals[ids[k]];
      const s = q.reduce((a, x, i) => a + x * pivot[i], 0) < 0 ? -w[k] : w[k];
      for (let i = 0; i < 4; i++) {
        real[i] += s * q[i];
        dual[i] += s * d[i];
      }
    }
    const length = Math.hypot(...real);
    const q = real.map((x) => x / length);
    const d = dual.map((x) => x / length);
    const conj = [-q[0], -q[1], -q[2], q[3]];
    const turn = (x: ArrayLike<number>) => mul(mul(q, [x[0], x[1], x[2], 0]), conj);
    const t = mul(d, conj).map((x) => 2 * x);
    let rest: ArrayLike<number> = rig.rest.subarray(3 * v, 3 * v + 3);
    let restNormal: ArrayLike<number> = rig.restNormals.subarray(3 * v, 3 * v + 3);
    if (scales) {
      const m = [0, 0, 0, 0, 0, 0, 0, 0, 0];
      for (let k = 0; k < 4; k++) for (let i = 0; i < 9; i++) m[i] += w[k] * scales[ids[k]][i];
      const times = (x: ArrayLike<number>) => [0, 1, 2].map((r) => m[r] * x[0] + m[3 + r] * x[1] + m[6 + r] * x[2]);
      // The inverse transpose, up to its (positive) determinant: solve mᵀ y = n by Cramer's rule.
      const col = (c: number) => [m[3 * c], m[3 * c + 1], m[3 * c + 2]];
      const cross = (a: number[], b: number[]) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
      const cof = [cross(col(1), col(2)), cross(col(2), col(0)), cross(col(0), col(1))];
      const n0 = restNormal;
      restNormal = [0, 1, 2].map((r) => cof[0][r] * n0[0] + cof[1][r] * n0[1] + cof[2][r] * n0[2]);
      rest = times(rest);
    }
    const p = turn(rest);
    const n = turn(restNormal);
    const nl = Math.hypot(n[0], n[1], n[2]);
    for (let i = 0; i < 3; i++) {
      positions[3 * v + i] = p[i] + t[i];
      normals[3 * v + i] = n[i] / nl;
    }
  }
  return { positions, normals };
}

/** Largest distance between two position arrays, and largest angle between two normal arrays (rad). */
function worst(a: ArrayLike<number>, b: ArrayLike<number>, angles = false): number {
  let most = 0;
  for (let v = 0; v < a.length / 3; v++) {
    const [x, y, z] = [a[3 * v], a[3 * v + 1], a[3 * v + 2]];
    const [u, s, t] = [b[3 * v], b[3 * v + 1], b[3 * v + 2]];
    const value = angles ? Math.acos(Math.min(1, (x * u + y * s + z * t) / (Math.hypot(x, y, z) * Math.hypot(u, s, t)))) : Math.hypot(x - u, y - s, z - t);
    most = Math.max(most, value);
  }
  return most;
}

/** Numbers in [0, 1) from a linear congruential generator started at `seed`: the same poses every run. */
function seeded(seed: number): () => number {
  let state = seed;
  return () => (state = (state * 1664525 + 1013904223) >>> 0) / 2 ** 32;
}

/** Random rigid skinning matrices: the whole hand turned up to 180° about a random axis, each joint by up to 60° more, and moved. */
function randomPose(rig: Rig, seed: number): Float32Array {
  const random = seeded(seed);
  const axis = () => new THREE.Vector3(random() - 0.5, random() - 0.5, random() - 0.5).normalize();
  const whole = new THREE.Quaternion().setFromAxisAngle(axis(), Math.PI * (0.5 + 0.5 * random()));
  const out = new Float32Array(16 * rig.joints);
  const m = new THREE.Matrix4();
  for (let j = 0; j < rig.joints; j++) {
    const own = new THREE.Quaternion().setFromAxisAngle(axis(), (Math.PI / 3) * random());
    m.compose(new THREE.Vector3(random() * 0.1, random() * 0.1, random() * 0.1), whole.clone().multiply(own), new THREE.Vector3(1, 1, 1));
    out.set(m.elements, 16 * j);
  }
  return out;
}

/**
 * A random pose whose bones also scale and shear: each joint's matrix is a rigid one (as
 * {@link randomPose}) times a symmetric positive matrix U diag(s) Uᵀ, s from 0.7 to 1.4 along a
 * random frame U. Returns the matrices and the scales, which the reference takes as given.
 */
function scaledPose(rig: Rig, seed: number): { matrices: Float32Array; rigid: Float32Array; scales: number[][] } {
  const rigid = randomPose(rig, seed);
  const random = seeded(seed * 7919);
  const matrices = new Float32Array(rigid.length);
  const scales: number[][] = [];
  for (let j = 0; j < rig.joints; j++) {
    const u = new THREE.Matrix4().makeRotationFromQuaternion(new THREE.Quaternion(random() - 0.5, random() - 0.5, random() - 0.5, random() - 0.5).normalize());
    const d = new THREE.Matrix4().makeScale(0.7 + 0.7 * random(), 0.7 + 0.7 * random(), 0.7 + 0.7 * random());
    const s = u.clone().multiply(d).multiply(u.clone().transpose());
    const e = s.elements;
    scales.push([e[0], e[1], e[2], e[4], e[5], e[6], e[8], e[9], e[10]]);
    matrices.set(new THREE.Matrix4().fromArray(Array.from(rigid.subarray(16 * j, 16 * j + 16))).multiply(s).elements, 16 * j);
  }
  return { matrices, rigid, scales };
}

/**
 * The WebXR generic hand (hand.glb beside the page: a skinned glTF from the WebXR input
 * profiles, made elsewhere) as a rig: its vertices and normals carried into its skeleton's
 * space by its bind matrix, its own influences; and its bones' matrices in three poses, the
 * hand turned up to 180° and every joint up to 90° about a random axis.
 */
async function outsideHand(): Promise<{ rig: Rig; poses: Float32Array[] }> {
  const gltf = await new GLTFLoader().loadAsync('hand.glb');
  let mesh: THREE.SkinnedMesh | undefined;
  gltf.scene.traverse((o) => {
    if ((o as THREE.SkinnedMesh).isSkinnedMesh) mesh = o as THREE.SkinnedMesh;
  });
  if (!mesh) throw new Error('hand.glb: no skinned mesh');
  const { geometry, skeleton, bindMatrix } = mesh;
  const n = geometry.attributes.position.count;
  const rest = new Float32Array(3 * n);
  const restNormals = new Float32Array(3 * n);
  const joint = new Uint32Array(4 * n);
  const weight = new Float32Array(4 * n);
  const normalMatrix = new THREE.Matrix3().getNormalMatrix(bindMatrix);
  const v = new THREE.Vector3();
  for (let i = 0; i < n; i++) {
    v.fromBufferAttribute(geometry.attributes.position, i).applyMatrix4(bindMatrix).toArray(rest, 3 * i);
    v.fromBufferAttribute(geometry.attributes.normal, i).applyMatrix3(normalMatrix).normalize().toArray(restNormals, 3 * i);
    for (let k = 0; k < 4; k++) {
      joint[4 * i + k] = geometry.attributes.skinIndex.getComponent(i, k);
      weight[4 * i + k] = geometry.attributes.skinWeight.getComponent(i, k);
    }
  }
  const empty = new Float32Array(0);
  const rig: Rig = { vertices: n, joints: skeleton.bones.length, rest, restNormals, joint, weight, triangles: new Uint32Array(0), skinning: empty, lb: empty, dqb: empty, dqbNormals: empty };
  const poses = [21, 22, 23].map((seed) => {
    const random = seeded(seed);
    const axis = () => new THREE.Vector3(random() - 0.5, random() - 0.5, random() - 0.5).normalize();
    skeleton.pose();
    skeleton.bones.forEach((bone, j) => bone.quaternion.multiply(new THREE.Quaternion().setFromAxisAngle(axis(), (j === 0 ? Math.PI : Math.PI / 2) * random())));
    gltf.scene.updateMatrixWorld(true);
    skeleton.update();
    return new Float32Array(skeleton.boneMatrices!);
  });
  return { rig, poses };
}

/**
 * Everything the test asserts, measured in one go. `exports` names more frames of the same hand
 * that dqhand exported in other poses (`name`.json, `name`.bin), each compared with dqhand's own
 * DQB of it.
 */
export async function conformance(exports: string[] = []) {
  const rig = await loadRig();
  const size = (() => {
    const box = new THREE.Box3().setFromArray(rig.rest);
    return box.getSize(new THREE.Vector3()).length();
  })();
  const exported = {
    three: worst(readBack(rig, rig.skinning, 'three', 'position'), rig.lb),
    lbs: worst(readBack(rig, rig.skinning, 'lbs', 'position'), rig.lb),
    dqs: worst(readBack(rig, rig.skinning, 'dqs', 'position'), rig.dqb),
    dqsNormals: worst(readBack(rig, rig.skinning, 'dqs', 'normal'), rig.dqbNormals, true),
    cpu: worst(cpuPositions(rig, rig.skinning), rig.dqb),
    blend: worst(readBack(rig, rig.skinning, 'blend', 'position'), alternate(rig.lb, rig.dqb)),
  };
  const native = [];
  for (const name of exports) {
    const other = await loadRig(name);
    native.push({
      name,
      dqs: worst(readBack(other, other.skinning, 'dqs', 'position'), other.dqb),
      dqsNormals: worst(readBack(other, other.skinning, 'dqs', 'normal'), other.dqbNormals, true),
      cpu: worst(cpuPositions(other, other.skinning), other.dqb),
    });
  }
  const random = [];
  for (let seed = 1; seed <= 6; seed++) {
    const pose = randomPose(rig, seed);
    const ref = reference(rig, pose);
    random.push({
      seed,
      dqs: worst(readBack(rig, pose, 'dqs', 'position'), ref.positions),
      dqsNormals: worst(readBack(rig, pose, 'dqs', 'normal'), ref.normals, true),
      cpu: worst(cpuPositions(rig, pose), ref.positions),
      unaligned: worst(readBack(rig, pose, 'dqs', 'position', true), ref.positions),
    });
  }
  const scaled = [];
  for (let seed = 11; seed <= 13; seed++) {
    const pose = scaledPose(rig, seed);
    const ref = reference(rig, pose.rigid, pose.scales);
    scaled.push({
      seed,
      dqs: worst(readBack(rig, pose.matrices, 'dqs', 'position'), ref.positions),
      dqsNormals: worst(readBack(rig, pose.matrices, 'dqs', 'normal'), ref.normals, true),
      cpu: worst(cpuPositions(rig, pose.matrices), ref.positions),
    });
  }
  const outside = await outsideHand();
  const outsideSize = new THREE.Box3().setFromArray(outside.rig.rest).getSize(new THREE.Vector3()).length();
  const generic = outside.poses.map((pose, k) => {
    const ref = reference(outside.rig, pose);
    return {
      seed: 21 + k,
      dqs: worst(readBack(outside.rig, pose, 'dqs', 'position'), ref.positions),
      dqsNormals: worst(readBack(outside.rig, pose, 'dqs', 'normal'), ref.normals, true),
      cpu: worst(cpuPositions(outside.rig, pose), ref.positions),
    };
  });
  return { size, vertices: rig.vertices, exported, native, random, scaled, outside: { size: outsideSize, vertices: outside.rig.vertices, poses: generic } };
}
