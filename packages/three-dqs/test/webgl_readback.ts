// The conformance page's WebGL side: the package's shader chunks run by WebGLRenderer and read
// back from a float render target.

import * as THREE from 'three';
import { useDualQuaternionSkinning, type SkinningMode } from '../src/index';
import type { Backend } from './conformance';
import { bindAtRest, blendOf, cpuSkinned, drawAlone, readbackGeometry, toSkeletonSpace } from './poses';
import type { Rig } from './rig';

const renderer = new THREE.WebGLRenderer();
const camera = new THREE.OrthographicCamera();

/**
 * A SkinnedMesh whose every vertex is drawn as a tiny triangle over its own pixel of a float
 * target: the fragment holds the skinned position (or normal), as the material's skinning
 * chunks computed it.
 */
function readbackMesh(rig: Rig, width: number, output: 'position' | 'normal', blend?: (v: number) => number): { mesh: THREE.SkinnedMesh; pose: (matrices: ArrayLike<number>) => void } {
  const geometry = readbackGeometry(rig, blend);
  const n = rig.vertices;
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
  return { mesh, pose: bindAtRest(mesh, rig.joints) };
}

/**
 * The mesh's skinned positions or normals as the GPU computes them, 3 floats per vertex, in the
 * skeleton's space: drawn once at rest, then posed and drawn again (the bone data must follow).
 */
function readBack(rig: Rig, matrices: ArrayLike<number>, mode: SkinningMode | 'three', output: 'position' | 'normal', unaligned = false): Float32Array {
  const width = 128;
  const height = Math.ceil(rig.vertices / width);
  const { mesh, pose } = readbackMesh(rig, width, output, mode === 'blend' ? blendOf : undefined);
  const skin = mode === 'three' ? null : useDualQuaternionSkinning(mesh, { mode });
  if (unaligned) {
    // The mistake this package avoids, injected: no sign alignment at all.
    const material = mesh.material as THREE.ShaderMaterial;
    const compile = material.onBeforeCompile;
    material.onBeforeCompile = (shader, r) => {
      compile.call(material, shader, r);
      shader.vertexShader = shader.vertexShader.replace(/dot\( dqsReal\d, dqsPivot \) < 0\.0/g, 'false');
    };
    material.customProgramCacheKey = () => 'broken-alignment';
  }
  const target = new THREE.WebGLRenderTarget(width, height, { type: THREE.FloatType, format: THREE.RGBAFormat, depthBuffer: false });
  drawAlone(renderer, target, mesh, camera);
  pose(matrices);
  drawAlone(renderer, target, mesh, camera);
  const pixels = new Float32Array(4 * width * height);
  renderer.readRenderTargetPixels(target, 0, 0, width, height, pixels);
  renderer.setRenderTarget(null);
  target.dispose();
  skin?.dispose();
  const out = new Float32Array(3 * rig.vertices);
  for (let v = 0; v < rig.vertices; v++) out.set(pixels.subarray(4 * v, 4 * v + 3), 3 * v);
  return toSkeletonSpace(out, output === 'normal');
}

/** The package's CPU path (applyBoneTransform) for every vertex. */
function cpuPositions(rig: Rig, matrices: ArrayLike<number>): Float32Array {
  const { mesh, pose } = readbackMesh(rig, 128, 'position');
  const skin = useDualQuaternionSkinning(mesh);
  const out = cpuSkinned(mesh, pose, matrices, rig.vertices);
  skin.dispose();
  return out;
}


export const webgl: Backend = {
  readBack: async (rig, matrices, mode, output, unaligned) => readBack(rig, matrices, mode, output, unaligned),
  cpuPositions,
};
