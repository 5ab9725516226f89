// three.js's CPU skinning on the frame `dqhand export-skinning` wrote to RIG (make bench-peers).
//
//   node three.mjs RIG [FRAMES]
//
// Builds a THREE.SkinnedMesh whose skeleton reproduces the exported skinning matrices (bind
// matrix and bone inverses identity, each bone's matrixWorld = its skinning matrix, so
// matrixWorld · boneInverse is exactly what dqhand blends), then times
// SkinnedMesh.applyBoneTransform over every vertex per frame: positions alone, and positions
// with normals, which it transforms as three.js's shader does (skinnormal_vertex: the blended
// matrix itself, w = 0, then normalised; applyBoneTransform takes such a Vector4). Writes
// RIG/three.json (medians, µs) and RIG/three.bin (float32 positions, then normals, #V×3 each).

import { readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import * as THREE from 'three';

const [rigDir, framesArg = '2000'] = process.argv.slice(2);
if (!rigDir) throw new Error('usage: node three.mjs RIG [FRAMES]');
const frames = Number(framesArg);
const rig = JSON.parse(readFileSync(join(rigDir, 'rig.json'), 'utf8'));
const bin = readFileSync(join(rigDir, 'rig.bin'));
const array = (name) => {
  const { dtype, shape, offset } = rig.arrays[name];
  const Type = { float32: Float32Array, uint32: Uint32Array }[dtype];
  // Copied out of the file's buffer: the typed array needs its own 4-byte aligned one.
  return new Type(bin.buffer.slice(bin.byteOffset + offset, bin.byteOffset + offset + shape[0] * shape[1] * 4));
};

const geometry = new THREE.BufferGeometry();
geometry.setAttribute('position', new THREE.BufferAttribute(array('rest_positions'), 3));
geometry.setAttribute('normal', new THREE.BufferAttribute(array('rest_normals'), 3));
// Uint16 joint indices, as three.js's GLTFLoader gives them.
geometry.setAttribute('skinIndex', new THREE.Uint16BufferAttribute(Uint16Array.from(array('joints')), 4));
geometry.setAttribute('skinWeight', new THREE.BufferAttribute(array('weights'), 4));
geometry.setIndex(new THREE.BufferAttribute(array('triangles'), 1));

const skinning = array('skinning');
const bones = Array.from({ length: rig.joints }, (_, j) => {
  const bone = new THREE.Bone();
  bone.matrixWorld.fromArray(skinning, 16 * j);
  return bone;
});
const mesh = new THREE.SkinnedMesh(geometry);
mesh.bind(new THREE.Skeleton(bones, bones.map(() => new THREE.Matrix4())), new THREE.Matrix4());

const n = rig.vertices;
const positions = new Float32Array(n * 3);
const normals = new Float32Array(n * 3);
const position = geometry.attributes.position;
const normal = geometry.attributes.normal;
const p = new THREE.Vector3();
const d = new THREE.Vector4();

function skinPositions() {
  for (let i = 0; i < n; i++) {
    mesh.applyBoneTransform(i, p.fromBufferAttribute(position, i));
    p.toArray(positions, 3 * i);
  }
}

function skinPositionsAndNormals() {
  skinPositions();
  for (let i = 0; i < n; i++) {
    mesh.applyBoneTransform(i, d.set(normal.getX(i), normal.getY(i), normal.getZ(i), 0));
    p.set(d.x, d.y, d.z).normalize().toArray(normals, 3 * i);
  }
}

/** Median µs per call over `frames` calls, after 100 untimed ones (JIT, caches). */
function medianUs(fn) {
  for (let f = 0; f < 100; f++) fn();
  const samples = new Float64Array(frames);
  for (let f = 0; f < frames; f++) {
    const t = process.hrtime.bigint();
    fn();
    samples[f] = Number(process.hrtime.bigint() - t) / 1e3;
  }
  return samples.sort()[Math.floor(frames / 2)];
}

const report = {
  three: THREE.REVISION,
  node: process.version,
  frames,
  positions_us: medianUs(skinPositions),
  positions_normals_us: medianUs(skinPositionsAndNormals),
};
writeFileSync(join(rigDir, 'three.json'), JSON.stringify(report, null, 2));
writeFileSync(join(rigDir, 'three.bin'), Buffer.concat([Buffer.from(positions.buffer), Buffer.from(normals.buffer)]));
console.log(`three.js r${report.three}: ${report.positions_us.toFixed(0)} µs positions, ${report.positions_normals_us.toFixed(0)} µs with normals`);
