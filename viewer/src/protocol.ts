// The stream's wire format, version 2 (crates/dqhand-stream/src/frame.rs is the reference):
// a topology message once, then binary frames; JSON text for hello, input state, scene state, errors and commands.
// Arrays are 4-byte aligned, so they are read as typed-array views without copying.

export const VERSION = 2;
export const FRAME_MAGIC = 0x46485144; // "DQHF" little-endian
export const TOPOLOGY_MAGIC = 0x54485144; // "DQHT"
export const FRAME_HEADER_BYTES = 76;
export const TOPOLOGY_HEADER_BYTES = 20;
export const FLAG_DISTORTION = 1;
/** Frame flag: the frame is of the second hand (the hello's `second_hand`). */
export const FLAG_SECOND_HAND = 2;
export const STATE_PLAYING = 1;
export const STATE_LIMITS = 2;
export const METHODS = ['lb', 'qb', 'dqb', 'cor'] as const;
export type Method = (typeof METHODS)[number];
/** How the page names each method. */
export const METHOD_LABELS: Record<Method, string> = { lb: 'LB', qb: 'QB', dqb: 'DQB', cor: 'CoR' };
/** Mesh slots of a frame (bytes 24-27), fixed by the format's version: a fifth method fails this type check rather than change the layout. */
const MESH_SLOTS = METHODS.length satisfies 4;

export class ProtocolError extends Error {}

export interface FrameHeader {
  sequence: number;
  vertexCount: number;
  jointCount: number;
  dofCount: number;
  methods: Method[];
  distortion: boolean;
  /** The frame is of the second hand (a server driving two). */
  second: boolean;
  engineUs: number;
  engineFps: number;
  time: number;
  duration: number;
  playing: boolean;
  limits: boolean;
  /** World translation xyz (m), rotation xyzw: the pose's wrist, or the rig's rest wrist when none is set. */
  wrist: Float32Array;
}

export interface MeshArrays {
  method: Method;
  positions: Float32Array;
  normals: Float32Array;
  /** Per-vertex mean edge-length change against rest; null unless the heat map is on. */
  distortion: Float32Array | null;
}

export interface Frame {
  header: FrameHeader;
  /** Radians, one per DOF of the hello's joint model. */
  angles: Float32Array;
  /** World joint positions, xyz per joint. */
  joints: Float32Array;
  meshes: MeshArrays[];
  byteLength: number;
}

export interface Topology {
  /** Which hand: 0 the first, 1 the second (the hello's `second_hand`). */
  hand: number;
  vertexCount: number;
  indices: Uint32Array;
  /** Parent joint index, -1 for a root. */
  parents: Int32Array;
}

export interface Dof {
  name: string;
  joint: string;
  min_deg: number;
  max_deg: number;
}

export interface Hello {
  type: 'hello';
  version: number;
  description: string;
  vertices: number;
  triangles: number;
  joints: string[];
  joint_model: string;
  joint_models: string[];
  dofs: Dof[];
  gestures: string[];
  sequence: { name: string; duration: number };
  methods: Method[];
  gesture_seconds: number;
  max_message_bytes: number;
  /** The live input driving the hand, or null when the demo has none (an older server omits it: null). */
  input: HelloInput | null;
  /** The scene the hand manipulates (`dqhand demo --scene`), or null (an older server omits it: null). */
  scene: HelloScene | null;
  /** The second hand, when the live input drives two (`dqhand demo --hands 2`), else null (an older server omits it: null). */
  second_hand: SecondHand | null;
}

/** The hello's second hand: of the other side than the first, following the live input's hand of its side. */
export interface SecondHand {
  side: Side;
  description: string;
  vertices: number;
  triangles: number;
}

/** Bounds of the scene messages (crates/dqhand-stream/src/frame.rs): larger ones are refused. */
export const MAX_SCENE_OBJECTS = 256;
export const MAX_SCENE_TRIANGLES = 50_000;
export const MAX_SCENE_CONTACTS = 64;
export const MAX_NAME_BYTES = 64;

export type Vec3 = [number, number, number];

/** The table's top: the plane y = height, a rectangle about (centre x, centre z) of the half sizes along x and z. Metres. */
export interface SceneTable {
  height: number;
  centre: [number, number];
  half: [number, number];
}

/** An object's shape in its own frame (metres; a cylinder's axis is +Y; a mesh is scaled as the physics has it). */
export type ObjectShape =
  | { shape: 'sphere'; radius: number }
  | { shape: 'box'; size: Vec3 }
  | { shape: 'cylinder'; radius: number; height: number }
  /** `simplified`: the mesh did not fit the hello's triangle budget and is its bounding box. */
  | { shape: 'mesh'; positions: Float32Array; indices: Uint32Array; simplified: boolean };

export type SceneObject = { name: string } & ObjectShape;

/** The hello's scene: the table (null: none) and the objects, in scene order. */
export interface HelloScene {
  table: SceneTable | null;
  objects: SceneObject[];
}

/** A point of the rendered hand's bone touching an object, with the object's normal there (toward the hand). World, metres. */
export interface Contact {
  bone: string;
  object: string;
  p: Vec3;
  n: Vec3;
  /** The hand touching, with two hands; null with one. */
  hand: Side | null;
}

/** The scene's state, sent at once on a grasp or release and at a bounded rate while it moves. */
export interface SceneMessage {
  type: 'scene';
  /** The object held (with two hands, by the first hand in the engine's order that holds one), or null. */
  held: string | null;
  /** With two hands, what each holds (null: nothing); null with one hand. */
  holding: Record<Side, string | null> | null;
  /** Every object's world pose: translation and rotation xyzw. */
  objects: Record<string, { p: Vec3; q: [number, number, number, number] }>;
  contacts: Contact[];
}

/** The hello's description of the live input (`dqhand demo --input FILE` or `--udp PORT`). */
export interface HelloInput {
  /** Where the records come from, for display: a recording's path, or e.g. `udp 127.0.0.1:9000`. */
  source: string;
  /** The gestures the recogniser knows, by name. */
  gestures: string[];
}

export const TRACKING_STATES = ['waiting', 'tracking', 'lost'] as const;
/** The input's tracking: no record yet, records arriving, or none for longer than the grace period. */
export type Tracking = (typeof TRACKING_STATES)[number];
/** The viewer's actions, and a scene's (`reset`: every object back where the scene file puts it). */
export const INPUT_ACTIONS = ['next_method', 'split_view', 'toggle_heatmap', 'reset'] as const;
export type InputAction = (typeof INPUT_ACTIONS)[number];

/** A recognised gesture starting or ending, at `t` seconds of the input's clock. */
export interface GestureEvent {
  t: number;
  event: 'start' | 'end';
  gesture: string;
  /** With two hands, the hand whose gesture it is, or `both` for a gesture of both hands; null with one (the parser always sets it). */
  hand?: Side | 'both' | null;
}

/** One hand of two in an input message: our hand's side, its tracking and its gesture now. */
export interface HandState {
  side: Side;
  tracking: Tracking;
  gesture: string | null;
}

/** An action the server applied because of a gesture, at `t` seconds of the input's clock. */
export interface ActionEvent {
  t: number;
  gesture: string;
  action: InputAction;
}

/** The input's state, sent when something in it changes (at most once per frame). */
export interface InputMessage {
  type: 'input';
  tracking: Tracking;
  /** The gesture recognised now, or null. */
  gesture: string | null;
  /** Gesture starts and ends since the previous input message. */
  events: GestureEvent[];
  /** Actions applied since the previous input message. */
  actions: ActionEvent[];
  /** Records accepted since the input started (a running total). */
  accepted: number;
  /** Records refused since the input started (a running total). */
  rejected: number;
  /** The tracked hand's side, null before the first record (an older server omits it: null). */
  side: Side | null;
  /** Our hand, of the other side, shows the tracked one mirrored (x → −x in the world). */
  mirrored: boolean;
  /** With two hands, each one's state, the first hand's first; null with one. */
  hands: HandState[] | null;
}

/** A hand's side. */
export type Side = 'left' | 'right';

/**
 * The viewers' recording of the live input, sent to every viewer when it changes (a `record`
 * command) and to one arriving while there is one: on (the file being written) or off (the
 * last file written), the records in it then, and whether writing failed (a full disk).
 */
export interface RecordingMessage {
  type: 'recording';
  on: boolean;
  /** The file, as the server names it; null before any recording. */
  path: string | null;
  records: number;
  /** Writing failed; the records before the failure are kept (an older server omits it: false). */
  failed: boolean;
}

/** How learning a gesture stands (crates/dqhand-cli/src/live_learning.rs). */
export const LEARNING_STATES = ['idle', 'recording', 'training', 'noted', 'learned', 'failed'] as const;
export type LearningState = (typeof LEARNING_STATES)[number];

/** How separable a learned gesture is: shares of frames held back that were taken for it. */
export interface LearningReport {
  /** Frames of the gesture trained on, and of what must not trigger it. */
  frames: number;
  notFrames: number;
  /** Share of the gesture's own held-back frames taken for it, and how many were checked. */
  recall: number;
  checked: number;
  /** Share of the held-back counter-example frames taken for it; null without any. */
  notRate: number | null;
  /** The built-in gestures most often taken for it, most first (share of their held-out frames). */
  overlap: { gesture: string; rate: number }[];
  /** The gesture the gestures recognised now show most on its frames (share of them); null: none. */
  already: { gesture: string; rate: number } | null;
  separable: boolean;
  /** What to do about it, or that it stands apart, in words. */
  verdict: string;
}

/**
 * The viewers' gesture learning (a `learn` command), sent to every viewer when it changes:
 * recording the hand, training, `noted` (counter-examples kept), `learned` (with the report
 * and where the definitions were saved) or `failed` (with the error).
 */
export interface LearningMessage {
  type: 'learning';
  state: LearningState;
  name: string | null;
  not: boolean;
  seconds: number | null;
  report: LearningReport | null;
  path: string | null;
  error: string | null;
}

export type ServerText = Hello | InputMessage | SceneMessage | RecordingMessage | LearningMessage | { type: 'error'; message: string };

/** Which binary message this is, from its magic; null if neither. */
export function binaryKind(buffer: ArrayBuffer): 'frame' | 'topology' | null {
  if (buffer.byteLength < 4) return null;
  const magic = new DataView(buffer).getUint32(0, true);
  return magic === FRAME_MAGIC ? 'frame' : magic === TOPOLOGY_MAGIC ? 'topology' : null;
}

/** Checks magic and version and returns the flags; bits other than `known` are refused (a later version may use them to change the layout). */
function checkStart(view: DataView, magic: number, what: string, known: number): number {
  if (view.byteLength < 8 || view.getUint32(0, true) !== magic) throw new ProtocolError(`not a ${what} (wrong magic)`);
  const version = view.getUint16(4, true);
  if (version !== VERSION) throw new ProtocolError(`${what} version ${version}, this page knows ${VERSION}`);
  const flags = view.getUint16(6, true);
  if ((flags & ~known) !== 0) throw new ProtocolError(`${what} flags ${flags}: bits ${flags & ~known} are unknown to version ${VERSION}`);
  return flags;
}

/** Bytes a frame with this header occupies. */
export function frameByteLength(h: Pick<FrameHeader, 'vertexCount' | 'jointCount' | 'dofCount' | 'methods' | 'distortion'>): number {
  const perMesh = 6 * h.vertexCount + (h.distortion ? h.vertexCount : 0);
  return FRAME_HEADER_BYTES + 4 * (h.dofCount + 3 * h.jointCount + h.methods.length * perMesh);
}

/** Method code of a mesh slot a frame does not use. */
const UNUSED_METHOD = 255;

export function decodeFrame(buffer: ArrayBuffer): Frame {
  const view = new DataView(buffer);
  if (buffer.byteLength < FRAME_HEADER_BYTES) throw new ProtocolError(`frame of ${buffer.byteLength} bytes is truncated`);
  const flags = checkStart(view, FRAME_MAGIC, 'frame', FLAG_DISTORTION | FLAG_SECOND_HAND);
  // Bytes 24-27: one method code per mesh, 255 past the last.
  const codes = Array.from({ length: MESH_SLOTS }, (_, i) => view.getUint8(24 + i));
  const meshCount = codes.includes(UNUSED_METHOD) ? codes.indexOf(UNUSED_METHOD) : codes.length;
  if (meshCount === 0) throw new ProtocolError('no meshes (method code 255 in the first slot)');
  // In the reference's order: each code, then repeats.
  const methods: Method[] = [];
  codes.forEach((code, i) => {
    if (i >= meshCount) {
      if (code !== UNUSED_METHOD) throw new ProtocolError(`mesh ${i}: method code ${code} after the last mesh (${meshCount})`);
      return;
    }
    const m = METHODS[code];
    if (m === undefined) throw new ProtocolError(`mesh ${i}: method code ${code}`);
    methods.push(m);
  });
  const repeated = methods.find((m, i) => methods.indexOf(m) !== i);
  if (repeated !== undefined) throw new ProtocolError(`method "${repeated}" given twice`);
  const state = view.getUint32(44, true);
  const header: FrameHeader = {
    sequence: view.getUint32(8, true),
    vertexCount: view.getUint32(12, true),
    jointCount: view.getUint32(16, true),
    dofCount: view.getUint32(20, true),
    methods,
    distortion: (flags & FLAG_DISTORTION) !== 0,
    second: (flags & FLAG_SECOND_HAND) !== 0,
    engineUs: view.getFloat32(28, true),
    engineFps: view.getFloat32(32, true),
    time: view.getFloat32(36, true),
    duration: view.getFloat32(40, true),
    playing: (state & STATE_PLAYING) !== 0,
    limits: (state & STATE_LIMITS) !== 0,
    wrist: new Float32Array(buffer, 48, 7),
  };
  const expected = frameByteLength(header);
  if (expected !== buffer.byteLength) throw new ProtocolError(`frame of ${buffer.byteLength} bytes, its header announces ${expected}`);
  let at = FRAME_HEADER_BYTES;
  const floats = (n: number) => {
    const a = new Float32Array(buffer, at, n);
    at += 4 * n;
    return a;
  };
  const angles = floats(header.dofCount);
  const joints = floats(3 * header.jointCount);
  const n = header.vertexCount;
  const meshes = methods.map((method) => ({
    method,
    positions: floats(3 * n),
    normals: floats(3 * n),
    distortion: header.distortion ? floats(n) : null,
  }));
  return { header, angles, joints, meshes, byteLength: buffer.byteLength };
}

export function decodeTopology(buffer: ArrayBuffer): Topology {
  const view = new DataView(buffer);
  // The hand field is read as flags: 0 or 1, any other value refused.
  const hand = checkStart(view, TOPOLOGY_MAGIC, 'topology', 1);
  if (buffer.byteLength < TOPOLOGY_HEADER_BYTES) throw new ProtocolError('topology truncated');
  const vertexCount = view.getUint32(8, true);
  const indexCount = view.getUint32(12, true);
  const jointCount = view.getUint32(16, true);
  const expected = TOPOLOGY_HEADER_BYTES + 4 * (indexCount + jointCount);
  if (expected !== buffer.byteLength) throw new ProtocolError(`topology of ${buffer.byteLength} bytes, its header announces ${expected}`);
  const indices = new Uint32Array(buffer, TOPOLOGY_HEADER_BYTES, indexCount);
  const parents = new Int32Array(buffer, TOPOLOGY_HEADER_BYTES + 4 * indexCount, jointCount);
  for (const i of indices) if (i >= vertexCount) throw new ProtocolError(`index ${i} with ${vertexCount} vertices`);
  parents.forEach((p, j) => {
    if (p < -1 || p >= jointCount || p === j) throw new ProtocolError(`joint ${j}: parent ${p} is not another joint`);
  });
  return { hand, vertexCount, indices, parents };
}

/** Parses a text message from the server. */
export function decodeText(text: string): ServerText {
  let value: unknown;
  try {
    value = JSON.parse(text);
  } catch (e) {
    throw new ProtocolError(`text message is not JSON: ${(e as Error).message}`);
  }
  const type = (value as { type?: unknown } | null)?.type;
  if (type === 'hello') return checkHello(value as Record<string, unknown>);
  if (type === 'input') return checkInput(value as Record<string, unknown>);
  if (type === 'scene') return checkSceneMessage(value as Record<string, unknown>);
  if (type === 'recording') return checkRecording(value as Record<string, unknown>);
  if (type === 'learning') return checkLearning(value as Record<string, unknown>);
  if (type !== 'error') throw new ProtocolError(`unknown text message type ${JSON.stringify(type)}`);
  return value as ServerText;
}

const isObject = (v: unknown): v is Record<string, unknown> => typeof v === 'object' && v !== null && !Array.isArray(v);
const isString = (v: unknown): v is string => typeof v === 'string';
const isCount = (v: unknown): v is number => typeof v === 'number' && Number.isSafeInteger(v) && v >= 0;
const isTime = (v: unknown): v is number => typeof v === 'number' && Number.isFinite(v);
const oneOf = <T extends string>(values: readonly T[], v: unknown): v is T => values.includes(v as T);
const isSize = (v: unknown): v is number => isTime(v) && v > 0;
const isVector = (v: unknown, n: number): boolean => Array.isArray(v) && v.length === n && v.every(isTime);
const isSide = (v: unknown): v is Side => v === 'left' || v === 'right';
const isName = (v: unknown): v is string => isString(v) && v.length > 0 && new TextEncoder().encode(v).length <= MAX_NAME_BYTES;
/** A value for an error message, cut short: a bad mesh may be megabytes. */
const show = (v: unknown) => {
  const text = JSON.stringify(v) ?? String(v);
  return text.length > 120 ? `${text.slice(0, 120)}…` : text;
};

/** The hello with its `input` and `scene` checked (the rest is trusted, as before). */
function checkHello(value: Record<string, unknown>): Hello {
  const input = value.input ?? null;
  if (input !== null && !(isObject(input) && isString(input.source) && Array.isArray(input.gestures) && input.gestures.every(isString))) {
    throw new ProtocolError(`hello: input ${JSON.stringify(input)} is neither null nor {source, gestures}`);
  }
  const scene = value.scene == null ? null : checkHelloScene(value.scene);
  const second = value.second_hand ?? null;
  if (second !== null && !(isObject(second) && isSide(second.side) && isString(second.description) && isCount(second.vertices) && isCount(second.triangles))) {
    throw new ProtocolError(`hello: second_hand ${show(second)} is neither null nor {side, description, vertices, triangles}`);
  }
  return { ...value, input, scene, second_hand: second } as unknown as Hello;
}

/** Checks the hello's scene field by field (the error names the first bad one) and turns meshes into typed arrays. */
function checkHelloScene(v: unknown): HelloScene {
  const bad = (field: string, value: unknown) => new ProtocolError(`hello: scene ${field && `${field} `}${show(value)}`);
  if (!isObject(v)) throw bad('', v);
  const table = v.table ?? null;
  if (table !== null && !(isObject(table) && isTime(table.height) && isVector(table.centre, 2) && isVector(table.half, 2) && (table.half as number[]).every(isSize))) {
    throw bad('table', table);
  }
  if (!Array.isArray(v.objects) || v.objects.length > MAX_SCENE_OBJECTS) throw bad('objects', v.objects);
  const names = new Set<string>();
  let triangles = 0;
  const objects = v.objects.map((o: unknown, i): SceneObject => {
    const field = `objects[${i}]`;
    if (!isObject(o) || !isName(o.name) || names.has(o.name)) throw bad(`${field}.name`, isObject(o) ? o.name : o);
    names.add(o.name);
    const name = o.name;
    switch (o.shape) {
      case 'sphere':
        if (!isSize(o.radius)) throw bad(`${field}.radius`, o.radius);
        return { name, shape: 'sphere', radius: o.radius };
      case 'box':
        if (!(isVector(o.size, 3) && (o.size as number[]).every(isSize))) throw bad(`${field}.size`, o.size);
        return { name, shape: 'box', size: o.size as Vec3 };
      case 'cylinder':
        if (!isSize(o.radius)) throw bad(`${field}.radius`, o.radius);
        if (!isSize(o.height)) throw bad(`${field}.height`, o.height);
        return { name, shape: 'cylinder', radius: o.radius, height: o.height };
      case 'mesh': {
        const { positions, indices } = o;
        if (!(Array.isArray(positions) && positions.length % 3 === 0 && positions.every(isTime))) throw bad(`${field}.positions`, positions);
        const vertices = positions.length / 3;
        if (!(Array.isArray(indices) && indices.length % 3 === 0 && indices.every((k) => isCount(k) && k < vertices))) throw bad(`${field}.indices`, indices);
        triangles += indices.length / 3;
        if (triangles > MAX_SCENE_TRIANGLES) throw bad(`${field}.indices`, `${triangles} triangles in all (at most ${MAX_SCENE_TRIANGLES})`);
        if (typeof o.simplified !== 'boolean') throw bad(`${field}.simplified`, o.simplified);
        return { name, shape: 'mesh', positions: Float32Array.from(positions), indices: Uint32Array.from(indices), simplified: o.simplified };
      }
      default:
        throw bad(`${field}.shape`, o.shape);
    }
  });
  return { table: table as SceneTable | null, objects };
}

/** Checks every field of a scene message; the message names the first bad one. */
function checkSceneMessage(v: Record<string, unknown>): SceneMessage {
  const bad = (field: string, value: unknown) => new ProtocolError(`scene message: ${field} ${show(value)}`);
  if (v.held !== null && !isName(v.held)) throw bad('held', v.held);
  const holding = v.holding ?? null;
  const heldBy = (o: unknown) => o === null || isName(o);
  if (holding !== null && !(isObject(holding) && Object.keys(holding).length === 2 && heldBy(holding.left) && heldBy(holding.right))) throw bad('holding', holding);
  if (!isObject(v.objects) || Object.keys(v.objects).length > MAX_SCENE_OBJECTS) throw bad('objects', v.objects);
  const objects: SceneMessage['objects'] = {};
  for (const [name, pose] of Object.entries(v.objects)) {
    if (!isName(name) || !(isObject(pose) && isVector(pose.p, 3) && isVector(pose.q, 4))) throw bad(`objects.${name}`, pose);
    objects[name] = { p: pose.p as Vec3, q: pose.q as [number, number, number, number] };
  }
  if (!Array.isArray(v.contacts) || v.contacts.length > MAX_SCENE_CONTACTS) throw bad('contacts', v.contacts);
  const contacts = v.contacts.map((c: unknown, i): Contact => {
    const hand = isObject(c) ? c.hand ?? null : null;
    if (!(isObject(c) && isString(c.bone) && isName(c.object) && isVector(c.p, 3) && isVector(c.n, 3) && (hand === null || isSide(hand)))) throw bad(`contacts[${i}]`, c);
    return { bone: c.bone, object: c.object, p: c.p as Vec3, n: c.n as Vec3, hand };
  });
  const holds = holding && { left: holding.left as string | null, right: holding.right as string | null };
  return { type: 'scene', held: v.held as string | null, holding: holds, objects, contacts };
}

/** Checks every field of an input message; the message names the first bad one. */
function checkInput(v: Record<string, unknown>): InputMessage {
  const bad = (field: string, value: unknown) => new ProtocolError(`input message: ${field} ${JSON.stringify(value)}`);
  if (!oneOf(TRACKING_STATES, v.tracking)) throw bad('tracking', v.tracking);
  if (v.gesture !== null && !isString(v.gesture)) throw bad('gesture', v.gesture);
  if (!Array.isArray(v.events)) throw bad('events', v.events);
  v.events.forEach((e: unknown, i) => {
    const hand = isObject(e) ? e.hand ?? null : null;
    if (!(isObject(e) && isTime(e.t) && (e.event === 'start' || e.event === 'end') && isString(e.gesture) && (hand === null || hand === 'both' || isSide(hand)))) throw bad(`events[${i}]`, e);
  });
  if (!Array.isArray(v.actions)) throw bad('actions', v.actions);
  v.actions.forEach((a: unknown, i) => {
    if (!(isObject(a) && isTime(a.t) && isString(a.gesture) && oneOf(INPUT_ACTIONS, a.action))) throw bad(`actions[${i}]`, a);
  });
  if (!isCount(v.accepted)) throw bad('accepted', v.accepted);
  if (!isCount(v.rejected)) throw bad('rejected', v.rejected);
  const side = v.side ?? null;
  if (side !== null && side !== 'left' && side !== 'right') throw bad('side', v.side);
  const mirrored = v.mirrored ?? false;
  if (typeof mirrored !== 'boolean') throw bad('mirrored', v.mirrored);
  const hands = v.hands ?? null;
  const handState = (h: unknown) => isObject(h) && isSide(h.side) && oneOf(TRACKING_STATES, h.tracking) && (h.gesture === null || isString(h.gesture));
  if (hands !== null && !(Array.isArray(hands) && hands.length === 2 && hands.every(handState) && hands[0].side !== hands[1].side)) {
    throw bad('hands', hands);
  }
  const events = v.events as GestureEvent[];
  const actions = v.actions as ActionEvent[];
  return {
    type: 'input', tracking: v.tracking, gesture: v.gesture as string | null,
    events: events.map(({ t, event, gesture, hand }) => ({ t, event, gesture, hand: hand ?? null })),
    actions: actions.map(({ t, gesture, action }) => ({ t, gesture, action })),
    accepted: v.accepted, rejected: v.rejected, side, mirrored,
    hands: hands && (hands as HandState[]).map(({ side, tracking, gesture }) => ({ side, tracking, gesture })),
  };
}

/** Checks a recording message; the message names the first bad field. */
function checkRecording(v: Record<string, unknown>): RecordingMessage {
  const bad = (field: string, value: unknown) => new ProtocolError(`recording message: ${field} ${show(value)}`);
  if (typeof v.on !== 'boolean') throw bad('on', v.on);
  if (v.path !== null && !isString(v.path)) throw bad('path', v.path);
  if (!isCount(v.records)) throw bad('records', v.records);
  const failed = v.failed ?? false;
  if (typeof failed !== 'boolean') throw bad('failed', v.failed);
  return { type: 'recording', on: v.on, path: v.path, records: v.records, failed };
}

/** Checks a learning message; the message names the first bad field. */
function checkLearning(v: Record<string, unknown>): LearningMessage {
  const bad = (field: string, value: unknown) => new ProtocolError(`learning message: ${field} ${show(value)}`);
  const share = (x: unknown): x is number => isTime(x) && x >= 0 && x <= 1;
  const nullOr = <T>(x: unknown, is: (x: unknown) => x is T): x is T | null => x === null || is(x);
  if (!oneOf(LEARNING_STATES, v.state)) throw bad('state', v.state);
  if (!nullOr(v.name, isName)) throw bad('name', v.name);
  if (typeof v.not !== 'boolean') throw bad('not', v.not);
  if (!nullOr(v.seconds, isSize)) throw bad('seconds', v.seconds);
  if (!nullOr(v.path, isString)) throw bad('path', v.path);
  if (!nullOr(v.error, isString)) throw bad('error', v.error);
  let report: LearningReport | null = null;
  if (v.report !== null) {
    const r = v.report;
    if (!isObject(r)) throw bad('report', r);
    if (!isCount(r.frames)) throw bad('report.frames', r.frames);
    if (!isCount(r.not_frames)) throw bad('report.not_frames', r.not_frames);
    if (!isCount(r.checked)) throw bad('report.checked', r.checked);
    // An empty check gives no share (NaN, sent as null).
    const recall = r.recall ?? Number.NaN;
    if (!(share(recall) || Number.isNaN(recall))) throw bad('report.recall', r.recall);
    if (!nullOr(r.not_rate, share)) throw bad('report.not_rate', r.not_rate);
    if (typeof r.separable !== 'boolean') throw bad('report.separable', r.separable);
    if (!Array.isArray(r.overlap) || !r.overlap.every((o) => isObject(o) && isName(o.gesture) && share(o.rate))) throw bad('report.overlap', r.overlap);
    const overlap = (r.overlap as { gesture: string; rate: number }[]).map(({ gesture, rate }) => ({ gesture, rate }));
    const already = r.already ?? null;
    if (!(already === null || (isObject(already) && isName(already.gesture) && share(already.rate)))) throw bad('report.already', r.already);
    if (!isString(r.verdict)) throw bad('report.verdict', r.verdict);
    report = {
      frames: r.frames, notFrames: r.not_frames, recall: recall as number, checked: r.checked, notRate: r.not_rate, overlap,
      already: already && { gesture: already.gesture as string, rate: already.rate as number }, separable: r.separable, verdict: r.verdict,
    };
  }
  return { type: 'learning', state: v.state, name: v.name, not: v.not, seconds: v.seconds, report, path: v.path, error: v.error };
}

/** The commands the engine accepts (crates/dqhand-stream/src/command.rs). */
export type Command =
  | { type: 'ack'; seq: number }
  | { type: 'view'; methods: Method[] }
  | { type: 'joint_model'; name: string }
  | { type: 'angle'; dof: string; deg: number }
  | { type: 'wrist'; translation: [number, number, number]; rotation_deg: [number, number, number] }
  | { type: 'gesture'; name: string; seconds?: number }
  | { type: 'play' }
  | { type: 'pause' }
  | { type: 'seek'; time: number }
  | { type: 'heatmap'; on: boolean }
  | { type: 'limits'; on: boolean }
  | { type: 'rest' }
  | { type: 'record'; on: boolean }
  | { type: 'learn'; name: string; seconds?: number; not?: boolean };

export function encodeCommand(command: Command): string {
  return JSON.stringify(command);
}
