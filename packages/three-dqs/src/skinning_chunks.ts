/**
 * GLSL that takes the place of three.js's four skinning chunks in any material's vertex shader
 * (WebGLRenderer): the same `#include` points, so every built-in material and any
 * `ShaderMaterial` that includes them is skinned this way.
 *
 * Per vertex, in the skeleton's space (through the mesh's bind matrix, as three.js does): the
 * four influences' dual quaternions, signs aligned against the **heaviest**
 * influence's (q and −q are one rotation; aligned against a light one, a vertex can blend the
 * long way round), blended and normalised (DQB, Kavan et al. 2008), after the blend of their
 * scale–shear matrices. `DQS_MODE` 0 is DQS, 1 linear blending of the same transforms, 2 a
 * per-vertex mix of the two by the attribute `dqsBlend` (1 = DQS).
 */

/** Replaces `skinning_pars_vertex`: the bone texture (three.js's uniform, holding {@link BoneDualQuaternions}' data) and its reading. */
export const skinningParsVertex = /* glsl */ `
#ifdef USE_SKINNING
	uniform mat4 bindMatrix;
	uniform mat4 bindMatrixInverse;
	uniform highp sampler2D boneTexture;
	#if DQS_MODE == 2
		attribute float dqsBlend;
	#endif
	// Bone i's dual quaternion, and its scale–shear (the identity for a rigid bone, whose flag
	// in the first column's w is 0: two texels fewer).
	bool dqsBone( const in float i, out vec4 real, out vec4 dual, out mat3 scale ) {
		int row = int( i );
		real = texelFetch( boneTexture, ivec2( 0, row ), 0 );
		dual = texelFetch( boneTexture, ivec2( 1, row ), 0 );
		vec4 first = texelFetch( boneTexture, ivec2( 2, row ), 0 );
		if ( first.w == 0.0 ) {
			scale = mat3( 1.0 );
			return false;
		}
		scale = mat3( first.xyz, texelFetch( boneTexture, ivec2( 3, row ), 0 ).xyz, texelFetch( boneTexture, ivec2( 4, row ), 0 ).xyz );
		return true;
	}
	vec3 dqsRotate( const in vec4 q, const in vec3 v ) {
		return v + 2.0 * cross( q.xyz, cross( q.xyz, v ) + q.w * v );
	}
	vec3 dqsTranslation( const in vec4 real, const in vec4 dual ) {
		return 2.0 * ( real.w * dual.xyz - dual.w * real.xyz + cross( real.xyz, dual.xyz ) );
	}
#endif
`;

/** The four influences, unrolled: GLSL arrays indexed per vertex are spilled to memory by software renderers (SwiftShader), which made the blend 1.6 times three.js's. */
const INFLUENCES = [0, 1, 2, 3];
const each = (line: (j: number, c: string) => string) => INFLUENCES.map((j) => line(j, 'xyzw'[j])).join('\n\t');

/** Replaces `skinbase_vertex`: the influences read and blended once per vertex. */
export const skinbaseVertex = /* glsl */ `
#ifdef USE_SKINNING
	${each((j) => `vec4 dqsReal${j}, dqsDual${j};
	mat3 dqsScale${j};`)}
	bool dqsScaled = false;
	${each((j, c) => `dqsScaled = dqsBone( skinIndex.${c}, dqsReal${j}, dqsDual${j}, dqsScale${j} ) || dqsScaled;`)}
	// The heaviest influence's rotation, which the others' signs are aligned against.
	vec4 dqsPivot = dqsReal0;
	float dqsMost = skinWeight.x;
	${each((j, c) => (j === 0 ? '' : `if ( skinWeight.${c} > dqsMost ) { dqsMost = skinWeight.${c}; dqsPivot = dqsReal${j}; }`))}
	vec4 dqsBlendReal = vec4( 0.0 );
	vec4 dqsBlendDual = vec4( 0.0 );
	${each((j, c) => `{ float w = dot( dqsReal${j}, dqsPivot ) < 0.0 ? - skinWeight.${c} : skinWeight.${c}; dqsBlendReal += w * dqsReal${j}; dqsBlendDual += w * dqsDual${j}; }`)}
	// (A vertex with no weight at all keeps a zero transform rather than a division by zero.)
	float dqsLength = max( length( dqsBlendReal ), 1e-20 );
	dqsBlendReal /= dqsLength;
	dqsBlendDual /= dqsLength;
	mat3 dqsScale = mat3( 1.0 );
	mat3 dqsNormalScale = mat3( 1.0 );
	if ( dqsScaled ) {
		// (Divided by the weights' sum, as the dual quaternion is normalised: weights that do not
		// add up to 1 scale neither part.)
		dqsScale = ( skinWeight.x * dqsScale0 + skinWeight.y * dqsScale1 + skinWeight.z * dqsScale2 + skinWeight.w * dqsScale3 ) / max( dot( skinWeight, vec4( 1.0 ) ), 1e-20 );
		// Normals: the blended scale–shear's inverse transpose (its cofactors, up to the determinant).
		// The determinant's sign keeps a mirrored normal pointing out.
		dqsNormalScale = sign( determinant( dqsScale ) ) * mat3( cross( dqsScale[ 1 ], dqsScale[ 2 ] ), cross( dqsScale[ 2 ], dqsScale[ 0 ] ), cross( dqsScale[ 0 ], dqsScale[ 1 ] ) );
	}
#endif
`;

/** Linear blending of the same per-bone transforms, for `DQS_MODE` 1 and 2 (`what` is `1.0` for a point, `0.0` for a direction). */
const linear = (v: string, what: string) => `( ${INFLUENCES.map((j) => `skinWeight.${'xyzw'[j]} * ( dqsRotate( dqsReal${j}, dqsScale${j} * ${v} ) + ${what} * dqsTranslation( dqsReal${j}, dqsDual${j} ) )`).join('\n\t\t+ ')} )`;

/**
 * `v` (a point where `what` is `1.0`, a direction where `0.0`) carried into the skeleton's space
 * by the bind matrix, skinned by each mode (`dual` the DQS expression over `local`), and back,
 * as three.js's own chunks do.
 */
const skin = (target: string, what: string, dual: (local: string) => string) => `{
		vec3 local = ( bindMatrix * vec4( ${target}, ${what} ) ).xyz;
		#if DQS_MODE == 0
			local = ${dual('local')};
		#elif DQS_MODE == 1
			local = ${linear('local', what)};
		#else
			local = mix( ${linear('local', what)}, ${dual('local')}, dqsBlend );
		#endif
		${target} = ( bindMatrixInverse * vec4( local, ${what} ) ).xyz;
	}`;

/** Replaces `skinnormal_vertex`. */
export const skinnormalVertex = /* glsl */ `
#ifdef USE_SKINNING
	${skin('objectNormal', '0.0', (v) => `dqsRotate( dqsBlendReal, dqsNormalScale * ${v} )`)}
	#ifdef USE_TANGENT
		${skin('objectTangent', '0.0', (v) => `dqsRotate( dqsBlendReal, dqsScale * ${v} )`)}
	#endif
#endif
`;

/** Replaces `skinning_vertex`. */
export const skinningVertex = /* glsl */ `
#ifdef USE_SKINNING
	${skin('transformed', '1.0', (v) => `dqsRotate( dqsBlendReal, dqsScale * ${v} ) + dqsTranslation( dqsBlendReal, dqsBlendDual )`)}
#endif
`;

/** The modes' numbers in the shader. */
export const MODES = { dqs: 0, lbs: 1, blend: 2 } as const;

/** A skinning mode: dual quaternion, linear, or a per-vertex mix of the two. */
export type SkinningMode = keyof typeof MODES;

/**
 * `vertexShader` with three.js's skinning chunks replaced by these for `mode`. Throws if it
 * includes none of them (a material that is not skinned the three.js way).
 */
export function patchVertexShader(vertexShader: string, mode: SkinningMode): string {
  const chunks: [string, string][] = [
    ['skinning_pars_vertex', `#define DQS_MODE ${MODES[mode]}\n${skinningParsVertex}`],
    ['skinbase_vertex', skinbaseVertex],
    ['skinnormal_vertex', skinnormalVertex],
    ['skinning_vertex', skinningVertex],
  ];
  let patched = vertexShader;
  for (const [name, glsl] of chunks) patched = patched.replace(`#include <${name}>`, glsl);
  if (patched === vertexShader) throw new Error(`vertex shader: includes none of three.js's skinning chunks, so it cannot be skinned with dual quaternions`);
  return patched;
}
