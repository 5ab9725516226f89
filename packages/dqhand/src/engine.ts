// The engine in the page: loading the WebAssembly build this browser runs, and the two things
// it makes, hands driven by tracking (`Hands`: both of the paper's loops, gestures and
// manipulation) and a hand posed by joint angles (`PosedHand`). Skins and object poses are
// read from the module's memory through views that are made again only when that memory grows
// (which detaches every view of it), so a frame allocates nothing.

import init, { Hand, Interaction, wasmMemory } from '../wasm/dqhand_wasm.js';
import { simdSupported } from './simd.js';
import { type Point, type Side, type Vec3, placeLandmarks, SideFilter, userSide } from './landmarks.js';
import { XRJoints } from './xr.js';

/**
 * A skinning method: linear (LB), quaternion (QB) or dual quaternion blending (DQB, the default),
 * or optimized centres of rotation (CoR, Le and Hodgins 2016; its centres are computed when first set).
 */
export type Method = 'lb' | 'qb' | 'dqb' | 'cor';

/** Which build to load: `'auto'` picks the SIMD one where the browser validates SIMD. */
export type Build = 'auto' | 'simd' | 'plain';

export interface LoadOptions {
  build?: Build;
  /** Where the `.wasm` files are (a folder URL ending in `/`); default: beside this package's files. */
  wasmBase?: string | URL;
  /** The chosen build's `.wasm` itself, bytes or compiled (where there is no fetch of files: Node, workers). */
  module?: BufferSource | WebAssembly.Module;
}

/** Anything with a skinned mesh in the engine's memory: what a `HandMesh` draws. */
export interface SkinSource {
  /** The hand's vertex count. */
  vertexCount(hand: number): number;
  /** Its triangles, three vertex indices each. */
  indices(hand: number): Uint32Array;
  /**
   * A view of the skinned positions (x y z per vertex, world metres) in the engine's memory,
   * valid until the next call into the engine; the same view each frame unless the memory grew.
   */
  positions(hand: number): Float32Array;
  /** A view of the skinned normals, as `positions`. */
  normals(hand: number): Float32Array;
}

/** What `step` reports: a gesture begun or ended (`hand` `'both'` for a gesture of both hands), an object grasped or let go. */
export type HandEvent =
  | { t: number; hand: Side | 'both'; event: 'start' | 'end'; gesture: string }
  | { t: number; hand: Side; event: 'grasp'; object: string }
  | { t: number; hand: Side; event: 'release'; object: string; linvel: Vec3; angvel: Vec3 };

/** A scene object's shape in its own frame (metres; a cylinder's axis is +Y). */
export type ObjectShape =
  | { shape: 'sphere'; radius: number }
  | { shape: 'box'; size: Vec3 }
  | { shape: 'cylinder'; radius: number; height: number }
  | { shape: 'mesh'; positions: number[]; indices: number[]; simplified: boolean };

/** An object to put in a scene: docs/formats.md's scene object (shapes, not mesh files). */
export type SceneObject = { name: string; position: Vec3; rotation?: [number, number, number, number]; mass: number; friction?: number; restitution?: number } & (
  | { shape: 'sphere'; radius: number }
  | { shape: 'box'; size: Vec3 }
  | { shape: 'cylinder'; radius: number; height: number }
);

/** A scene: a table's top at `height` (m, +Y up) and objects; or a built-in scene's name (`'grasp'`, `'objects'`, `'two-hands'`). */
export type SceneSpec = string | { table?: { height: number }; objects: SceneObject[]; actions?: { gesture: string; hold_s?: number; action: 'reset' }[] };

export interface HandsOptions {
  /** Which of the user's hands the engine drives (each built as itself); default `'right'`. */
  hands?: Side | 'both';
  /** The scene the hands manipulate; default none (gestures only). */
  scene?: SceneSpec | null;
  /** Wrist crease to middle fingertip (m), default 0.19; breadth across the knuckles (m), default 0.085. */
  length?: number;
  breadth?: number;
  /**
   * Skinned glTF 2.0 hands to drive instead of built-in ones: `.glb` bytes (or `.gltf` JSON
   * with its buffers embedded) whose skeleton has the 25 WebXR hand joints, such as a hand
   * written by `dqhand hand --out right.glb` or the WebXR input profiles' generic hands. The
   * sides given are the hands driven (`hands`, if set, must agree); `length` and `breadth` do
   * not apply. Loading a written built-in hand takes milliseconds where generating it takes
   * seconds: see `fetchModel`.
   */
  models?: { right?: Uint8Array | ArrayBuffer; left?: Uint8Array | ArrayBuffer };
}

export interface PosedHandOptions {
  side?: Side;
  length?: number;
  breadth?: number;
  /** `'full'` (23 angles) or `'paper'` (18, the paper's Table 1). */
  jointModel?: 'full' | 'paper';
}

/** The loaded engine: makes hands. One per page (the module is loaded once). */
export class Engine {
  private constructor(
    /** Whether the SIMD build (the simd128 kernel) was loaded. */
    readonly simd: boolean,
  ) {}

  /** @internal */
  static async load(options: LoadOptions = {}): Promise<Engine> {
    const simd = options.build === 'simd' || (options.build !== 'plain' && simdSupported());
    const file = simd ? 'dqhand_wasm_simd_bg.wasm' : 'dqhand_wasm_bg.wasm';
    const url = options.wasmBase ? new URL(file, new URL(options.wasmBase, import.meta.url)) : simd ? new URL('../wasm/dqhand_wasm_simd_bg.wasm', import.meta.url) : new URL('../wasm/dqhand_wasm_bg.wasm', import.meta.url);
    await init({ module_or_path: options.module ?? url });
    return new Engine(simd);
  }

  /** Hands driven by tracked hands, in a scene or none. Throws an `Error` of one line for bad options. */
  hands(options: HandsOptions = {}): Hands {
    return new Hands(options);
  }

  /** The built-in hand posed by joint angles. Throws an `Error` of one line for bad options. */
  posedHand(options: PosedHandOptions = {}): PosedHand {
    return new PosedHand(options);
  }
}

/**
 * The bytes of the hand model at `url` (a `.glb`), for `HandsOptions.models`. Throws an `Error`
 * of one line naming the URL when it cannot be fetched.
 */
export async function fetchModel(url: string | URL): Promise<Uint8Array> {
  const answer = await fetch(url).catch((e: unknown) => {
    throw new Error(`${String(url)}: ${(e as Error).message}`);
  });
  if (!answer.ok) throw new Error(`${String(url)}: HTTP ${answer.status} ${answer.statusText}`.trim());
  return new Uint8Array(await answer.arrayBuffer());
}

let loading: Promise<Engine> | null = null;

/** Loads the engine (once per page; later calls get the same one, whatever their options). */
export function loadEngine(options: LoadOptions = {}): Promise<Engine> {
  loading ??= Engine.load(options).catch((e: unknown) => {
    loading = null; // a later call tries again
    throw e;
  });
  return loading;
}

/** A view of `count` floats at `ptr` in the module's memory, made again only when the memory has grown. */
class MemoryView {
  private buffer: ArrayBuffer | null = null;
  private view = new Float32Array(0);
  private at = -1;

  get(ptr: number, count: number): Float32Array {
    const buffer = wasmMemory().buffer as ArrayBuffer;
    if (buffer !== this.buffer || ptr !== this.at || count !== this.view.length) {
      [this.buffer, this.at, this.view] = [buffer, ptr, new Float32Array(buffer, ptr, count)];
    }
    return this.view;
  }
}

const NO_EVENTS: readonly HandEvent[] = Object.freeze([]);
const NO_HANDS: readonly Point[][] = Object.freeze([]);

/**
 * One or two hands driven by the user's tracked hands: per frame, push what the trackers give
 * (`pushXRFrame`, `pushLandmarks`, `pushMediaPipe`, `pushLine`), then `step(t)`. With a
 * scene, the rendered hands stop on the objects and on each other, grasp, carry and let go,
 * and the objects fall and roll. Hand 0 is the left one of two.
 */
export class Hands implements SkinSource {
  private inner: Interaction;
  private readonly spec: HandsOptions;
  private views: { positions: MemoryView; normals: MemoryView }[] = [];
  private readonly poseView = new MemoryView();
  private readonly xr = new XRJoints();
  private readonly landmarks = new Float32Array(63);
  private readonly sideFilter = new SideFilter();
  private shapes: ({ name: string } & ObjectShape)[] | null = null;
  /** The scene's table top, null without one. */
  private tableTop: { height: number; centre: [number, number]; half: [number, number] } | null = null;
  /** Each hand's side (read once: the engine's answer is a new string each time). */
  private readonly sides: Side[];

  /** @internal Use `Engine.hands`. */
  constructor(options: HandsOptions) {
    this.spec = { ...options };
    this.inner = Hands.make(this.spec);
    this.views = Array.from({ length: this.inner.handCount }, () => ({ positions: new MemoryView(), normals: new MemoryView() }));
    this.sides = this.views.map((_, k) => this.inner.side(k) as Side);
  }

  private static make(o: HandsOptions): Interaction {
    const scene = o.scene == null ? '' : typeof o.scene === 'string' ? o.scene : JSON.stringify(o.scene);
    if (!o.models) return new Interaction(o.hands ?? 'right', scene, o.length, o.breadth);
    const { right, left } = o.models;
    const given = right && left ? 'both' : left ? 'left' : 'right';
    if (o.hands !== undefined && o.hands !== given) throw new Error(`models: ${right || left ? given : 'none'} given for hands ${JSON.stringify(o.hands)}`);
    const bytes = (b?: Uint8Array | ArrayBuffer) => (b === undefined || b instanceof Uint8Array ? b : new Uint8Array(b));
    return Interaction.withModels(scene, bytes(right), bytes(left));
  }

  /** How many hands (1 or 2). */
  get count(): number {
    return this.inner.handCount;
  }

  /** Hand `k`'s side. */
  side(k: number): Side {
    return this.sides[Math.min(k, this.sides.length - 1)];
  }

  /** The hand of `side` (its index), or −1 when the engine drives none of that side. */
  handOf(side: Side): number {
    for (let k = 0; k < this.count; k++) if (this.side(k) === side) return k;
    return -1;
  }

  vertexCount(k: number): number {
    return this.inner.vertexCount(k);
  }

  indices(k: number): Uint32Array {
    return this.inner.indices(k);
  }

  positions(k: number): Float32Array {
    return this.views[k].positions.get(this.inner.positionsPtr(k), 3 * this.inner.vertexCount(k));
  }

  normals(k: number): Float32Array {
    return this.views[k].normals.get(this.inner.normalsPtr(k), 3 * this.inner.vertexCount(k));
  }

  /** Skins with `method` from now on. */
  setMethod(method: Method): void {
    this.inner.setMethod(method);
  }

  /**
   * Pushes every hand of `frame`'s session the engine drives and the headset tracks in full
   * (all 25 joints), posed in `space` (the scene's reference space, e.g. `'local-floor'`), at
   * `t` seconds (default: the frame's time). Returns how many were pushed. A hand the tracker
   * refuses is counted by the engine (`counts`), not thrown.
   */
  pushXRFrame(frame: XRFrame, space: XRReferenceSpace, t?: number): number {
    let pushed = 0;
    const sources = frame.session.inputSources;
    for (let i = 0; i < sources.length; i++) {
      const source = sources[i];
      const side = source.handedness;
      if (!source.hand || (side !== 'left' && side !== 'right') || (this.count === 1 && this.side(0) !== side)) continue;
      if (!this.xr.read(frame, source.hand, space)) continue;
      try {
        this.inner.pushJoints(side, t ?? frame.predictedDisplayTime / 1000, this.xr.matrices, this.xr.radii);
        pushed++;
      } catch {
        // Refused (counted by the engine); the hand keeps its last pose.
      }
    }
    return pushed;
  }

  /** Pushes `side`'s 21 world landmarks (x y z each, m, the engine's axes: +Y up) at `t` s. Throws an `Error` of one line when refused. */
  pushLandmarks(side: Side, t: number, landmarks: Float32Array): void {
    this.inner.pushLandmarks(side, t, landmarks);
  }

  /**
   * Pushes the hands of one MediaPipe Hands result (`multiHandWorldLandmarks`,
   * `multiHandLandmarks`, `multiHandedness`) at `t` s, placed before the camera with the hand's
   * middle `anchor` m in the world at half a metre from it (the camera facing the user; the
   * image not mirrored). A lone hand's label is steadied over frames (`SideFilter`: MediaPipe
   * flips it now and then, which would mirror the hand across the world); of two hands
   * labelled alike only the first drives. Returns how many hands were pushed.
   */
  pushMediaPipe(
    results: { multiHandWorldLandmarks?: Point[][]; multiHandLandmarks?: Point[][]; multiHandedness?: { label: string }[] },
    t: number,
    aspect: number,
    anchor: Vec3 = [0, 1.2, -0.3],
  ): number {
    const world = results.multiHandWorldLandmarks ?? NO_HANDS;
    const image = results.multiHandLandmarks ?? NO_HANDS;
    if (world.length !== 1) this.sideFilter.reset(); // none, or hands told apart by their labels
    let pushed = 0;
    let seen = 0;
    for (let i = 0; i < world.length; i++) {
      const labelled = userSide(results.multiHandedness?.[i]?.label === 'Left' ? 'Left' : 'Right');
      const side = world.length === 1 ? this.sideFilter.update(labelled) : labelled;
      // Two hands labelled alike are one hand seen twice as far as anyone can tell: only the first drives.
      const bit = side === 'left' ? 1 : 2;
      if (seen & bit) continue;
      seen |= bit;
      if ((this.count === 1 && this.side(0) !== side) || !image[i] || !placeLandmarks(world[i], image[i], aspect, anchor, this.landmarks)) continue;
      try {
        this.inner.pushLandmarks(side, t, this.landmarks);
        pushed++;
      } catch {
        // Refused (counted); the hand keeps its last pose.
      }
    }
    return pushed;
  }

  /** Pushes one line of a recording (docs/formats.md). Throws an `Error` of one line when refused. */
  pushLine(line: string): void {
    this.inner.pushLine(line);
  }

  /**
   * Advances to `t` s (the records' clock): the hands follow, grasp and carry; the physics
   * steps; the skins are deformed. Returns the events of the frame (a shared empty array when
   * there are none).
   */
  step(t: number): readonly HandEvent[] {
    if (this.inner.step(t) === 0) return NO_EVENTS;
    return this.inner
      .takeEvents()
      .trim()
      .split('\n')
      .map((l) => JSON.parse(l) as HandEvent);
  }

  /** Hand `k`'s tracking: `'waiting'` (nothing yet), `'tracking'` or `'lost'`. */
  tracking(k: number): 'waiting' | 'tracking' | 'lost' {
    return this.inner.tracking(k) as 'waiting' | 'tracking' | 'lost';
  }

  /** Hand `k`'s gesture now, or null. */
  gesture(k: number): string | null {
    return this.inner.gesture(k) ?? null;
  }

  /** The name of the object hand `k` holds, or null. */
  held(k: number): string | null {
    const i = this.inner.held(k);
    return i < 0 ? null : this.objects()[i].name;
  }

  /** The scene's objects' shapes, in the order of `poses`. */
  objects(): readonly ({ name: string } & ObjectShape)[] {
    this.readScene();
    return this.shapes!;
  }

  /** The scene's table top (centre and half sizes along x and z), or null. */
  table(): { height: number; centre: [number, number]; half: [number, number] } | null {
    this.readScene();
    return this.tableTop;
  }

  private readScene(): void {
    if (this.shapes) return;
    const scene = JSON.parse(this.inner.scene());
    [this.shapes, this.tableTop] = [scene.objects, scene.table];
  }

  /** The objects' poses: 7 floats each, position x y z (m), rotation x y z w; a view, valid until the next call into the engine. */
  poses(): Float32Array {
    return this.poseView.get(this.inner.posesPtr(), 7 * this.inner.objectCount);
  }

  /**
   * Adds `object` to the scene. The engine is made again around the scene with the other
   * objects where they are now (and at rest): a hand's tracking starts over (at its next
   * record), and an object held is let go. Make a new `SceneObjects` to draw the new object.
   */
  addObject(object: SceneObject): void {
    const base = typeof this.spec.scene === 'string' ? null : this.spec.scene;
    if (typeof this.spec.scene === 'string' && this.spec.scene !== '') {
      throw new Error(`addObject: the scene is the built-in ${JSON.stringify(this.spec.scene)}; give the scene as objects to add to it`);
    }
    const poses = this.poses();
    const objects = (base?.objects ?? []).map((o, i) => ({ ...o, position: [poses[7 * i], poses[7 * i + 1], poses[7 * i + 2]] as Vec3, rotation: [poses[7 * i + 3], poses[7 * i + 4], poses[7 * i + 5], poses[7 * i + 6]] as [number, number, number, number] }));
    const scene = { ...(base ?? {}), objects: [...objects, object] };
    const next = Hands.make({ ...this.spec, scene });
    this.inner.free();
    [this.inner, this.spec.scene, this.shapes] = [next, scene, null];
  }

  /** Every object back where the scene puts it, at rest (at the next `step`). */
  reset(): void {
    this.inner.reset();
  }

  /** Records taken and refused so far, over every hand. */
  counts(): { accepted: number; refused: number } {
    const [accepted, refused] = this.inner.counts();
    return { accepted, refused };
  }

  /** Frees the engine's memory of these hands; they cannot be used after. */
  dispose(): void {
    this.inner.free();
  }
}

/** The built-in hand posed by joint angles (radians, in `dofNames` order), skinned with DQB unless told. */
export class PosedHand implements SkinSource {
  private readonly inner: Hand;
  private readonly views = { positions: new MemoryView(), normals: new MemoryView() };

  /** @internal Use `Engine.posedHand`. */
  constructor(o: PosedHandOptions) {
    this.inner = Hand.builtin(o.length ?? 0.19, o.breadth ?? 0.085, o.side ?? 'right', o.jointModel ?? 'full');
  }

  /** The angles' names, `'<bone>.<flex|abd>'`. */
  dofNames(): string[] {
    return this.inner.dofNames();
  }

  /** Poses `angles` (clamped to the hand's limits) and skins. Throws an `Error` of one line for a wrong count or a non-finite angle. */
  setAngles(angles: Float32Array): void {
    this.inner.step(angles);
  }

  /** The next `setAngles` does not follow the last one (each call otherwise does, as frames of one motion: a joint twisted past 180° stays the way it turned): for a pose unrelated to the last. */
  forgetPreviousFrame(): void {
    this.inner.forgetPreviousFrame();
  }

  setMethod(method: Method): void {
    this.inner.setMethod(method);
  }

  vertexCount(): number {
    return this.inner.vertexCount;
  }

  indices(): Uint32Array {
    return this.inner.indices();
  }

  positions(): Float32Array {
    return this.views.positions.get(this.inner.positionsPtr(), 3 * this.inner.vertexCount);
  }

  normals(): Float32Array {
    return this.views.normals.get(this.inner.normalsPtr(), 3 * this.inner.vertexCount);
  }

  dispose(): void {
    this.inner.free();
  }
}
