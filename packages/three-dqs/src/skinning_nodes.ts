/**
 * The same skinning as {@link ./skinning_chunks.ts}, written in TSL for WebGPURenderer (which
 * compiles it to WGSL, or to GLSL on its WebGL 2 fallback): per vertex, in the skeleton's
 * space through the mesh's bind matrix, the four influences' dual quaternions aligned against
 * the **heaviest** influence's, blended and normalised (DQB, Kavan et al. 2008), after the
 * linear blend of their scale–shear matrices (§4).
 */
import type { Skeleton, SkinnedMesh, Texture } from 'three';
import type { Node, NodeFrame } from 'three/webgpu';
import { Fn, OnObjectUpdate, attribute, cross, dot, float, int, ivec2, length, max, mix, normalLocal, positionGeometry, positionLocal, reference, select, sign, tangentLocal, texture, vec3, vec4 } from 'three/tsl';
import { bonesOf } from './dual_quaternion_mesh.js';
import type { SkinningMode } from './skinning_chunks.js';

// TSL's nodes chain methods (`a.mul(b)`) that its type declarations give only in part.
// eslint-disable-next-line @typescript-eslint/no-explicit-any
type N = any;

/** One influence of a vertex: its bone's dual quaternion, scale–shear columns and weight. */
interface Influence {
  real: N;
  dual: N;
  scale: [N, N, N];
  weight: N;
}

/** The frame each skeleton was last updated in: once a frame however many meshes it has. */
const updated = new WeakMap<Skeleton, number>();

/**
 * The bone texture node, following the drawn object's skeleton (a build may serve every mesh
 * of the same material copy and geometry layout), and each skeleton updated once a frame, as three.js's own skinning node
 * does (which this one replaces, so nothing else updates it).
 */
function boneTextureNode(first: Texture): N {
  const node: N = texture(first);
  OnObjectUpdate(({ object, frameId }: NodeFrame) => {
    const skeleton = (object as SkinnedMesh).skeleton;
    if (updated.get(skeleton) !== frameId) {
      updated.set(skeleton, frameId);
      skeleton.update();
    }
    const bones = bonesOf(skeleton);
    if (bones) node.value = bones.texture;
  });
  return node;
}

/** The four influences of the vertex, read from the bone texture (5 texels a row, a row per bone). */
function influences(bones: N): Influence[] {
  const skinIndex: N = attribute('skinIndex', 'uvec4');
  const skinWeight: N = attribute('skinWeight', 'vec4');
  return (['x', 'y', 'z', 'w'] as const).map((c) => {
    const row = int(skinIndex[c]);
    const texel = (k: number) => bones.load(ivec2(k, row)).toVar();
    const real = texel(0);
    const dual = texel(1);
    const first = texel(2);
    // A rigid bone's flag (the first column's w) is 0: its scale–shear is the identity.
    const rigid = first.w.equal(0);
    const column = (k: number, value: N) => select(rigid, vec3(k === 0 ? 1 : 0, k === 1 ? 1 : 0, k === 2 ? 1 : 0), value.xyz).toVar();
    return { real, dual, scale: [column(0, first), column(1, texel(3)), column(2, texel(4))], weight: skinWeight[c] };
  });
}

/** `v` turned by the unit quaternion `q`. */
const rotate = (q: N, v: N): N => v.add(cross(q.xyz, cross(q.xyz, v).add(v.mul(q.w))).mul(2));

/** The translation of the unit dual quaternion (`real`, `dual`): 2 · dual · conj(real). */
const translation = (real: N, dual: N): N => dual.xyz.mul(real.w).sub(real.xyz.mul(dual.w)).add(cross(real.xyz, dual.xyz)).mul(2);

/** The 3×3 matrix with these columns times `v`. */
const times = (columns: N[], v: N): N => columns[0].mul(v.x).add(columns[1].mul(v.y)).add(columns[2].mul(v.z));

/** The blended transform of one vertex: its unit dual quaternion and scale–shear (and S's cofactors, for normals). */
interface Blend {
  real: N;
  dual: N;
  scale: N[];
  normalScale: N[];
}

/**
 * DQB of the influences. With `alignSigns` false the signs are left as they come: the mistake
 * (a vertex blending the long way round) that the conformance test injects to show it fails.
 */
function blend(all: Influence[], alignSigns: boolean): Blend {
  // The heaviest influence's rotation, which the others' signs are aligned against.
  let pivot: N = all[0].real;
  let most: N = all[0].weight;
  for (const influence of all.slice(1)) {
    const heavier = influence.weight.greaterThan(most);
    pivot = select(heavier, influence.real, pivot);
    most = select(heavier, influence.weight, most);
  }
  pivot = pivot.toVar();
  let real: N = vec4(0);
  let dual: N = vec4(0);
  for (const { real: r, dual: d, weight } of all) {
    const w = alignSigns ? select(dot(r, pivot).lessThan(0), weight.negate(), weight) : weight;
    real = real.add(r.mul(w));
    dual = dual.add(d.mul(w));
  }
  // (A vertex with no weight at all keeps a zero transform rather than a division by zero.)
  const norm = max(length(real), float(1e-20)).toVar();
  // (Divided by the weights' sum, as the dual quaternion is normalised: weights that do not add
  // up to 1 scale neither part.)
  const total = max(all.reduce((sum: N, i) => sum.add(i.weight), float(0)), float(1e-20)).toVar();
  const scale = [0, 1, 2].map((k) => all.reduce((sum: N, i) => sum.add(i.scale[k].mul(i.weight)), vec3(0)).div(total).toVar());
  // Normals: the blended scale–shear's inverse transpose (its cofactors, up to the
  // determinant); the determinant's sign keeps a mirrored normal pointing out.
  const cofactors = [cross(scale[1], scale[2]), cross(scale[2], scale[0]), cross(scale[0], scale[1])];
  const flip = sign(dot(scale[0], cofactors[0])).toVar();
  return { real: real.div(norm).toVar(), dual: dual.div(norm).toVar(), scale, normalScale: cofactors.map((c) => c.mul(flip).toVar()) };
}

/** Linear blending of the same per-bone transforms (`point` false for a direction). */
function linear(all: Influence[], v: N, point: boolean): N {
  return all.reduce((sum: N, { real, dual, scale, weight }) => {
    const moved = rotate(real, times(scale, v));
    return sum.add((point ? moved.add(translation(real, dual)) : moved).mul(weight));
  }, vec3(0));
}

/** What the skinning of one vertex needs: its influences, their blend, and the mesh's bind matrices. */
interface Vertex {
  all: Influence[];
  blended: Blend;
  bindMatrix: N;
  bindMatrixInverse: N;
  mode: SkinningMode;
}

/**
 * `v` (a point or a direction) carried into the skeleton's space by the bind matrix, skinned by
 * the mode (`dual` the DQS of it), and back, as three.js's own skinning does.
 */
function skin(vertex: Vertex, v: N, point: boolean, dual: (local: N) => N): N {
  const w = point ? 1 : 0;
  const local = vertex.bindMatrix.mul(vec4(v, w)).xyz.toVar();
  let skinned: N;
  if (vertex.mode === 'dqs') skinned = dual(local);
  else if (vertex.mode === 'lbs') skinned = linear(vertex.all, local, point);
  else skinned = mix(linear(vertex.all, local, point), dual(local), attribute('dqsBlend', 'float'));
  return vertex.bindMatrixInverse.mul(vec4(skinned, w)).xyz;
}

/** A mat4 property of the drawn object (the types ask for an object; three.js's own skinning names none). */
const objectReference = (name: string): N => (reference as N)(name, 'mat4');

/** The vertex's inputs for `mode`, read once. */
function vertexOf(mesh: SkinnedMesh, mode: SkinningMode, alignSigns: boolean): Vertex {
  const bones = bonesOf(mesh.skeleton);
  if (!bones) throw new Error(`${mesh.name || 'mesh'}: drawn with a material that skins with dual quaternions, but its skeleton has none (call useDualQuaternionSkinning on it)`);
  const all = influences(boneTextureNode(bones.texture));
  return { all, blended: blend(all, alignSigns), bindMatrix: objectReference('bindMatrix'), bindMatrixInverse: objectReference('bindMatrixInverse'), mode };
}

/** The skinned position of `position` (a local-space point). */
function skinnedPosition(vertex: Vertex, position: N): N {
  const { real, dual, scale } = vertex.blended;
  return skin(vertex, position, true, (v) => rotate(real, times(scale, v)).add(translation(real, dual)));
}

/**
 * {@link dualQuaternionSkinning} with the sign alignment optional: without it, the mistake (a
 * vertex blending the long way round) that the conformance test injects to show it fails.
 */
export const skinInPlace = (mesh: SkinnedMesh, mode: SkinningMode, alignSigns: boolean): Node =>
  Fn((_: unknown, builder: N) => {
    const vertex = vertexOf(mesh, mode, alignSigns);
    const { real, scale, normalScale } = vertex.blended;
    const skinnedNormal = builder.hasGeometryAttribute('normal') ? skin(vertex, normalLocal, false, (v) => rotate(real, times(normalScale, v))) : null;
    const skinnedTangent = builder.hasGeometryAttribute('tangent') ? skin(vertex, tangentLocal, false, (v) => rotate(real, times(scale, v))) : null;
    (positionLocal as N).assign(skinnedPosition(vertex, positionLocal));
    if (skinnedNormal) (normalLocal as N).assign(skinnedNormal);
    if (skinnedTangent) (tangentLocal as N).assign(skinnedTangent);
  }, 'void')() as Node;

/**
 * Skins `positionLocal`, `normalLocal` and `tangentLocal` in place (where the geometry has
 * them): what three.js's `skinning(mesh)` does, with dual quaternions. Call it where that is
 * called, in a node material's `setupPosition`.
 */
export const dualQuaternionSkinning = (mesh: SkinnedMesh, mode: SkinningMode = 'dqs'): Node => skinInPlace(mesh, mode, true);

/** One node per mode: materials that share it can share their builds. */
const shadowPositions = new Map<SkinningMode, Node>();

/**
 * The skinned position of the drawn mesh's geometry (its own positions: no morph targets,
 * displacement or `positionNode`), as a node: for `castShadowPositionNode`, which shadow maps
 * draw with in place of three.js's skinning. One node per mode, for every mesh.
 */
export function dualQuaternionSkinnedPosition(mode: SkinningMode = 'dqs'): Node {
  let node = shadowPositions.get(mode);
  if (!node) {
    node = Fn((_: unknown, builder: N) => skinnedPosition(vertexOf(builder.object as SkinnedMesh, mode, true), positionGeometry))() as Node;
    shadowPositions.set(mode, node);
  }
  return node;
}
