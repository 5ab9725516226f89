// dqhand in the page: a realistic virtual hand (dual quaternion skinning), driven by WebXR hand
// tracking or MediaPipe, recognising gestures and grasping objects, in WebAssembly, for three.js.

export { Engine, Hands, PosedHand, fetchModel, loadEngine } from './engine.js';
export type { Build, HandEvent, HandsOptions, LoadOptions, Method, ObjectShape, PosedHandOptions, SceneObject, SceneSpec, SkinSource } from './engine.js';
export { HandMesh, SKIN_COLOUR } from './hand_mesh.js';
export { disposeLook, lookOf, type Look, type LookTarget } from './look.js';
export { SceneObjects } from './scene_objects.js';
export { placeLandmarks, userSide, type Point, type Side, type Vec3 } from './landmarks.js';
export { simdSupported } from './simd.js';
