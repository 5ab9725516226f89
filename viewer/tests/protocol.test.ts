// The page's side of the wire format, on the golden vectors the Rust tests write and check
// (crates/dqhand/tests/stream.rs): the two sides stay byte-compatible.

import { readFileSync } from 'node:fs';
import { describe, expect, test } from 'vitest';
import { heldText, InputLog, learningText, LOG_LENGTH } from '../src/input';
import {
  binaryKind, decodeFrame, decodeText, decodeTopology, encodeCommand, frameByteLength, type Hello, type InputMessage, MAX_SCENE_CONTACTS,
  MAX_SCENE_TRIANGLES, type LearningMessage, ProtocolError, type SceneMessage,
} from '../src/protocol';

const fixture = (name: string): ArrayBuffer => {
  const bytes = readFileSync(new URL(`./fixtures/${name}`, import.meta.url));
  return bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
};

describe('frame', () => {
  test('decodes every field of the golden frame', () => {
    const buffer = fixture('frame-v2.bin');
    expect(binaryKind(buffer)).toBe('frame');
    const f = decodeFrame(buffer);
    expect(f.header).toMatchObject({
      sequence: 7, vertexCount: 2, jointCount: 2, dofCount: 3, methods: ['lb', 'dqb'], distortion: true,
      engineUs: 123.5, engineFps: 120, time: 1.25, duration: 21, playing: true, limits: true, second: false,
    });
    expect(Array.from(f.header.wrist)).toEqual([0.1, 0.2, 0.3, 0, 0, 0, 1].map(Math.fround));
    expect(Array.from(f.angles)).toEqual([0.5, -0.25, 1]);
    expect(f.joints[5]).toBeCloseTo(-0.05, 7);
    expect(f.meshes.map((m) => m.method)).toEqual(['lb', 'dqb']);
    expect(Array.from(f.meshes[1].positions)).toEqual([20, 21, 22, 23, 24, 25]);
    expect(Array.from(f.meshes[0].normals)).toEqual([0, 1, 0, 0, 0, 1]);
    expect(Array.from(f.meshes[1].distortion!)).toEqual([0.25, 0]);
    expect(frameByteLength(f.header)).toBe(buffer.byteLength);
  });

  test('refuses truncated, padded, foreign and future frames', () => {
    const buffer = fixture('frame-v2.bin');
    const bytes = new Uint8Array(buffer);
    const variant = (edit: (b: Uint8Array) => Uint8Array) => edit(bytes.slice()).buffer as ArrayBuffer;
    const cases: [ArrayBuffer, RegExp][] = [
      [buffer.slice(0, buffer.byteLength - 4), /header announces/],
      [variant((b) => { const c = new Uint8Array(b.length + 4); c.set(b); return c; }), /header announces/],
      [buffer.slice(0, 20), /truncated/],
      [variant((b) => ((b[0] = 0x58), b)), /wrong magic/],
      [variant((b) => ((b[4] = 9), b)), /version 9/],
      [variant((b) => ((b[4] = 1), b)), /version 1, this page knows 2/],
      [variant((b) => ((b[25] = 7), b)), /mesh 1: method code 7/],
      [variant((b) => ((b[24] = 255), b)), /no meshes/],
      [variant((b) => ((b[7] = 1), b)), /unknown to version 2/],
      [variant((b) => ((b[25] = b[24]), b)), /given twice/],
      [variant((b) => ((b[27] = 0), b)), /mesh 3: method code 0 after the last mesh \(2\)/],
      // Codes before repeats, as the reference (crates/dqhand-stream/tests/stream.rs).
      [variant((b) => (b.set([0, 0, 255, 1], 24), b)), /mesh 3: method code 1 after the last mesh \(2\)/],
    ];
    for (const [b, message] of cases) expect(() => decodeFrame(b)).toThrow(message);
    expect(() => decodeFrame(buffer.slice(0, 20))).toThrow(ProtocolError);
  });

  test('flag bit 1 marks the second hand\'s frame', () => {
    const bytes = new Uint8Array(fixture('frame-v2.bin')).slice();
    bytes[6] |= 2;
    expect(decodeFrame(bytes.buffer).header).toMatchObject({ second: true, distortion: true, sequence: 7 });
  });
});

describe('topology', () => {
  test('decodes the golden topology', () => {
    const buffer = fixture('topology-v2.bin');
    expect(binaryKind(buffer)).toBe('topology');
    const t = decodeTopology(buffer);
    expect(t.vertexCount).toBe(4);
    expect(Array.from(t.indices)).toEqual([0, 1, 2, 2, 1, 3]);
    expect(Array.from(t.parents)).toEqual([-1, 0, 1]);
    expect(t.hand).toBe(0);
  });

  test('the second hand\'s topology says hand 1; any other hand is refused', () => {
    const bytes = new Uint8Array(fixture('topology-v2.bin')).slice();
    bytes[6] = 1;
    expect(decodeTopology(bytes.slice().buffer).hand).toBe(1);
    bytes[6] = 2;
    expect(() => decodeTopology(bytes.buffer)).toThrow(/unknown to version 2/);
  });

  test('refuses an index past the vertices and a joint that is its own parent', () => {
    const bytes = new Uint8Array(fixture('topology-v2.bin'));
    const badIndex = bytes.slice();
    new DataView(badIndex.buffer).setUint32(20, 4, true);
    expect(() => decodeTopology(badIndex.buffer)).toThrow(/index 4 with 4 vertices/);
    const selfParent = bytes.slice();
    new DataView(selfParent.buffer).setInt32(20 + 24 + 4, 1, true);
    expect(() => decodeTopology(selfParent.buffer)).toThrow(/joint 1: parent 1/);
    expect(() => decodeTopology(bytes.slice(0, 30).buffer)).toThrow(/announces/);
  });
});

describe('text messages and commands', () => {
  test('hello and error are recognised, anything else refused', () => {
    expect(decodeText('{"type":"error","message":"x"}')).toEqual({ type: 'error', message: 'x' });
    expect(decodeText('{"type":"hello","version":1}').type).toBe('hello');
    expect(() => decodeText('{"type":"other"}')).toThrow(/unknown text message type/);
    expect(() => decodeText('not json')).toThrow(/not JSON/);
    expect(binaryKind(new ArrayBuffer(2))).toBeNull();
  });

  test('commands are the JSON the engine parses', () => {
    expect(encodeCommand({ type: 'angle', dof: 'index-finger-phalanx-intermediate.flex', deg: 90 })).toBe(
      '{"type":"angle","dof":"index-finger-phalanx-intermediate.flex","deg":90}',
    );
    expect(JSON.parse(encodeCommand({ type: 'view', methods: ['lb', 'qb', 'dqb'] }))).toEqual({ type: 'view', methods: ['lb', 'qb', 'dqb'] });
  });
});

describe('live input', () => {
  const good = {
    type: 'input', tracking: 'tracking', gesture: 'fist',
    events: [{ t: 1.25, event: 'start', gesture: 'fist' }, { t: 1.0, event: 'end', gesture: 'open_palm' }],
    actions: [{ t: 1.8, gesture: 'thumbs_up', action: 'next_method' }],
    accepted: 1234, rejected: 5, side: 'left', mirrored: true,
  };
  const text = (edit: Record<string, unknown> = {}) => JSON.stringify({ ...good, ...edit });

  test('an input message is parsed with every field', () => {
    expect(decodeText(text())).toEqual({ ...good, events: good.events.map((e) => ({ ...e, hand: null })), hands: null });
    const quiet = decodeText(text({ tracking: 'lost', gesture: null, events: [], actions: [] })) as InputMessage;
    expect(quiet).toMatchObject({ tracking: 'lost', gesture: null, events: [], actions: [], accepted: 1234 });
    // An older server says nothing of the side: none, not mirrored.
    expect(decodeText(text({ side: undefined, mirrored: undefined }))).toMatchObject({ side: null, mirrored: false });
  });

  test('with two hands, each hand\'s state and the hand of each event are parsed, and logged', () => {
    const hands = [{ side: 'right', tracking: 'tracking', gesture: 'fist' }, { side: 'left', tracking: 'lost', gesture: null }];
    const events = [{ t: 2, event: 'start', gesture: 'fist', hand: 'right' }, { t: 2.5, event: 'start', gesture: 'hands_together', hand: 'both' }];
    const m = decodeText(text({ hands, events, actions: [] })) as InputMessage;
    expect(m.hands).toEqual(hands);
    expect(m.events).toEqual(events);
    const log = new InputLog();
    log.add(m);
    expect(log.lines).toEqual(['2.50  both start hands_together', '2.00  right start fist']);
    for (const [edit, message] of [
      [{ hands: [hands[0]] }, /hands/],
      [{ hands: [hands[0], { ...hands[1], side: 'middle' }] }, /hands/],
      [{ hands: [hands[0], { ...hands[1], tracking: 'gone' }] }, /hands/],
      [{ hands: [hands[0], { ...hands[0], gesture: null }] }, /hands/],
      [{ events: [{ ...events[0], hand: 'third' }] }, /events\[0\]/],
    ] as const) {
      expect(() => decodeText(text(edit))).toThrow(message);
    }
  });

  test('a recording message is parsed, and a malformed one refused naming the field', () => {
    const recording = { type: 'recording', on: false, path: 'recordings/live-1.jsonl', records: 412, failed: false };
    expect(decodeText(JSON.stringify(recording))).toEqual(recording);
    expect(decodeText(JSON.stringify({ ...recording, path: null, records: 0 }))).toEqual({ ...recording, path: null, records: 0 });
    for (const [edit, message] of [[{ on: 'yes' }, /on "yes"/], [{ path: 3 }, /path 3/], [{ records: -2 }, /records -2/], [{ failed: 1 }, /failed 1/]] as const) {
      expect(() => decodeText(JSON.stringify({ ...recording, ...edit }))).toThrow(message);
    }
    expect(JSON.parse(encodeCommand({ type: 'record', on: true }))).toEqual({ type: 'record', on: true });
  });

  test('a learning message is parsed with its report, a malformed one refused naming the field, and the panel words it', () => {
    // As crates/dqhand-cli/src/live_learning.rs writes it.
    const wire = {
      type: 'learning', state: 'learned', name: 'gun', not: false, seconds: 4, path: 'recordings/gestures-learned.json', error: null,
      report: { frames: 160, not_frames: 0, recall: 0.98, checked: 70, not_rate: null, overlap: [{ gesture: 'point', rate: 0.012 }, { gesture: 'none', rate: 0 }],
        already: null, separable: true, verdict: 'separable from the others' },
    };
    const parsed = decodeText(JSON.stringify(wire)) as LearningMessage;
    expect(parsed.report).toEqual({ frames: 160, notFrames: 0, recall: 0.98, checked: 70, notRate: null, overlap: wire.report.overlap, already: null, separable: true, verdict: 'separable from the others' });
    expect(learningText(parsed)).toBe('learned gun: recognised on 98 % of its frames held back; other gestures taken for it: point 1.2 %, none 0 %; separable from the others; saved to recordings/gestures-learned.json');
    const recording = { type: 'learning', state: 'recording', name: 'gun', not: true, seconds: 4, report: null, path: null, error: null };
    expect(learningText(decodeText(JSON.stringify(recording)) as LearningMessage)).toBe('show what is not gun, for 4 s…');
    const idle = { ...recording, state: 'idle', name: null, not: false, seconds: null };
    expect(learningText(decodeText(JSON.stringify(idle)) as LearningMessage)).toBe('');
    const cases: [object, RegExp][] = [
      [{ state: 'thinking' }, /state "thinking"/],
      [{ name: 7 }, /name 7/],
      [{ seconds: -1 }, /seconds -1/],
      [{ report: { ...wire.report, recall: 1.5 } }, /report.recall 1.5/],
      [{ report: { ...wire.report, overlap: [{ gesture: 'point' }] } }, /report.overlap/],
      [{ report: { ...wire.report, separable: 'yes' } }, /report.separable "yes"/],
      [{ report: { ...wire.report, already: { gesture: 'point', rate: 2 } } }, /report.already/],
      [{ report: { ...wire.report, verdict: undefined } }, /report.verdict undefined/],
    ];
    for (const [edit, message] of cases) expect(() => decodeText(JSON.stringify({ ...wire, ...edit }))).toThrow(message);
    expect(JSON.parse(encodeCommand({ type: 'learn', name: 'gun', not: true }))).toEqual({ type: 'learn', name: 'gun', not: true });
  });

  test('a malformed input message is refused, naming the field', () => {
    const cases: [string, RegExp][] = [
      [text({ tracking: 'searching' }), /tracking "searching"/],
      [text({ tracking: undefined }), /tracking undefined/],
      [text({ gesture: 3 }), /gesture 3/],
      [text({ events: null }), /events null/],
      [text({ events: [{ t: 1, event: 'begin', gesture: 'fist' }] }), /events\[0\]/],
      [text({ events: [{ t: '1', event: 'start', gesture: 'fist' }] }), /events\[0\]/],
      [text({ actions: [{ t: 1, gesture: 'fist', action: 'explode' }] }), /actions\[0\]/],
      [text({ actions: undefined }), /actions undefined/],
      [text({ accepted: -1 }), /accepted -1/],
      [text({ rejected: 1.5 }), /rejected 1.5/],
      [text({ side: 'both' }), /side "both"/],
      [text({ mirrored: 'no' }), /mirrored "no"/],
    ];
    for (const [t, message] of cases) {
      expect(() => decodeText(t)).toThrow(ProtocolError);
      expect(() => decodeText(t)).toThrow(message);
    }
  });

  test('the hello\'s second hand is null, absent (an older server: null) or its side and mesh', () => {
    const second = { side: 'left', description: 'built-in left hand', vertices: 100, triangles: 196 };
    expect(decodeText(JSON.stringify({ type: 'hello', version: 1 }))).toMatchObject({ second_hand: null });
    expect(decodeText(JSON.stringify({ type: 'hello', version: 1, second_hand: second }))).toMatchObject({ second_hand: second });
    for (const bad of [{ ...second, side: 'both' }, { ...second, vertices: -1 }, 'left']) {
      expect(() => decodeText(JSON.stringify({ type: 'hello', version: 1, second_hand: bad }))).toThrow(/second_hand/);
    }
  });

  test('the hello\'s input is null, absent (an older server: null) or a source and gesture names', () => {
    const hello = (input: unknown) => JSON.stringify({ type: 'hello', version: 1, ...(input === undefined ? {} : { input }) });
    expect(decodeText(hello(undefined))).toMatchObject({ input: null });
    expect(decodeText(hello(null))).toMatchObject({ input: null });
    const input = { source: 'udp 127.0.0.1:9000', gestures: ['open_palm', 'fist'] };
    expect(decodeText(hello(input))).toMatchObject({ input });
    expect(() => decodeText(hello({ source: 'x' }))).toThrow(/hello: input/);
    expect(() => decodeText(hello({ source: 1, gestures: [] }))).toThrow(/hello: input/);
    expect(() => decodeText(hello('udp'))).toThrow(/hello: input/);
  });

  test('the event log puts the newest first, an action after the event that caused it', () => {
    const log = new InputLog();
    log.add({ events: [{ t: 0.5, event: 'start', gesture: 'open_palm' }], actions: [] });
    log.add({
      events: [{ t: 1.8, event: 'start', gesture: 'thumbs_up' }, { t: 1.75, event: 'end', gesture: 'open_palm' }],
      actions: [{ t: 1.8, gesture: 'thumbs_up', action: 'next_method' }],
    });
    expect(log.lines).toEqual([
      '1.80  thumbs_up → next_method',
      '1.80  start thumbs_up',
      '1.75  end open_palm',
      '0.50  start open_palm',
    ]);
    log.add({ events: [], actions: [] });
    expect(log.lines).toHaveLength(4);
  });

  test('the event log keeps the latest 30 entries', () => {
    const log = new InputLog();
    expect(LOG_LENGTH).toBe(30);
    for (let i = 0; i < 25; i++) log.add({ events: [{ t: i, event: 'start', gesture: 'fist' }], actions: [] });
    log.add({ events: Array.from({ length: 10 }, (_, k) => ({ t: 25 + k, event: 'end' as const, gesture: 'fist' })), actions: [] });
    expect(log.lines).toHaveLength(30);
    expect(log.lines[0]).toBe('34.00  end fist');
    expect(log.lines[29]).toBe('5.00  start fist');
    log.clear();
    expect(log.lines).toEqual([]);
  });
});

describe('scene', () => {
  const scene = {
    table: { height: 0.75, centre: [0, -0.35], half: [0.6, 0.4] },
    objects: [
      { name: 'ball', shape: 'sphere', radius: 0.04 },
      { name: 'cube', shape: 'box', size: [0.06, 0.06, 0.06] },
      { name: 'mug', shape: 'cylinder', radius: 0.04, height: 0.1 },
      { name: 'tri', shape: 'mesh', positions: [0, 0, 0, 1, 0, 0, 0, 1, 0], indices: [0, 1, 2], simplified: false },
    ],
  };
  const hello = (s: unknown) => JSON.stringify({ type: 'hello', version: 1, input: null, scene: s });
  const withObject = (o: object) => ({ ...scene, objects: [o] });

  test('the hello\'s scene: null, absent (an older server: null), or the table and every kind of object, meshes as typed arrays', () => {
    expect(decodeText(JSON.stringify({ type: 'hello', version: 1 }))).toMatchObject({ scene: null });
    expect(decodeText(hello(null))).toMatchObject({ scene: null });
    const h = decodeText(hello(scene)) as Hello;
    expect(h.scene!.table).toEqual(scene.table);
    expect(h.scene!.objects.slice(0, 3)).toEqual(scene.objects.slice(0, 3));
    const mesh = h.scene!.objects[3];
    expect(mesh.shape === 'mesh' && [mesh.positions, mesh.indices, mesh.simplified]).toEqual([new Float32Array([0, 0, 0, 1, 0, 0, 0, 1, 0]), new Uint32Array([0, 1, 2]), false]);
    expect((decodeText(hello({ ...scene, table: null })) as Hello).scene!.table).toBeNull();
  });

  test('a malformed scene in the hello is refused, naming the field', () => {
    const tri = scene.objects[3];
    const cases: [unknown, RegExp][] = [
      ['ball', /hello: scene "ball"/],
      [{ ...scene, table: { height: 0.75 } }, /scene table/],
      [{ ...scene, table: { ...scene.table, half: [0.6, -1] } }, /scene table/],
      [{ ...scene, objects: null }, /scene objects null/],
      [withObject({ name: 'ball', shape: 'sphere', radius: 0 }), /objects\[0\]\.radius 0/],
      [withObject({ name: 'ball', shape: 'cone', radius: 1 }), /objects\[0\]\.shape "cone"/],
      [withObject({ name: '', shape: 'sphere', radius: 1 }), /objects\[0\]\.name ""/],
      [withObject({ name: 'x'.repeat(65), shape: 'sphere', radius: 1 }), /objects\[0\]\.name/],
      [{ ...scene, objects: [scene.objects[0], scene.objects[0]] }, /objects\[1\]\.name "ball"/],
      [withObject({ name: 'b', shape: 'box', size: [1, 1] }), /objects\[0\]\.size/],
      [withObject({ name: 'c', shape: 'cylinder', radius: 1 }), /objects\[0\]\.height/],
      [withObject({ ...tri, indices: [0, 1, 3] }), /objects\[0\]\.indices/],
      [withObject({ ...tri, indices: [0, 1] }), /objects\[0\]\.indices/],
      [withObject({ ...tri, positions: [0, 0, 0, 1, 0, 0, 0, 1] }), /objects\[0\]\.positions/],
      [withObject({ ...tri, positions: [0, 0, 0, 1, 0, 0, 0, 1, null] }), /objects\[0\]\.positions/],
      [withObject({ ...tri, simplified: 'no' }), /objects\[0\]\.simplified/],
      [withObject({ ...tri, indices: Array(3 * (MAX_SCENE_TRIANGLES + 1)).fill(0) }), /triangles in all/],
      [{ ...scene, objects: Array.from({ length: 257 }, (_, k) => ({ name: `o${k}`, shape: 'sphere', radius: 1 })) }, /scene objects/],
    ];
    for (const [s, message] of cases) {
      expect(() => decodeText(hello(s))).toThrow(ProtocolError);
      expect(() => decodeText(hello(s))).toThrow(message);
    }
  });

  const good: SceneMessage = {
    type: 'scene', held: 'ball', holding: null,
    objects: { ball: { p: [0.1, 0.9, -0.3], q: [0, 0, 0, 1] }, teapot: { p: [0.15, 0.75, -0.35], q: [0, 0.383, 0, 0.924] } },
    contacts: [{ bone: 'thumb-tip', object: 'ball', p: [0.1, 0.93, -0.3], n: [0, 1, 0], hand: null }],
  };
  const message = (edit: Record<string, unknown> = {}) => JSON.stringify({ ...good, ...edit });

  test('a scene message is parsed with every field', () => {
    expect(decodeText(message())).toEqual(good);
    expect(decodeText(message({ held: null, contacts: [] }))).toMatchObject({ held: null, contacts: [] });
    expect(heldText(good)).toBe('ball');
  });

  test('with two hands, what each hand holds and the hand of each contact are parsed and shown', () => {
    const contacts = [{ ...good.contacts[0], hand: 'left' }];
    const both = decodeText(message({ holding: { left: 'ball', right: 'ball' }, contacts })) as SceneMessage;
    expect(both.holding).toEqual({ left: 'ball', right: 'ball' });
    expect(both.contacts[0].hand).toBe('left');
    expect(heldText(both)).toBe('ball in both hands');
    expect(heldText({ held: 'ball', holding: { left: null, right: 'ball' } })).toBe('left: —, right: ball');
    expect(heldText({ held: null, holding: { left: null, right: null } })).toBe('—');
    expect(() => decodeText(message({ holding: { middle: 'ball' } }))).toThrow(/holding/);
    expect(() => decodeText(message({ holding: { left: 3 } }))).toThrow(/holding/);
    expect(() => decodeText(message({ holding: {} }))).toThrow(/holding/);
    expect(() => decodeText(message({ holding: { left: 'ball' } }))).toThrow(/holding/);
    expect(() => decodeText(message({ contacts: [{ ...good.contacts[0], hand: 'both' }] }))).toThrow(/contacts\[0\]/);
  });

  test('a malformed scene message is refused, naming the field', () => {
    const contact = good.contacts[0];
    const cases: [string, RegExp][] = [
      [message({ held: 3 }), /held 3/],
      [message({ held: undefined }), /held undefined/],
      [message({ objects: [] }), /objects \[\]/],
      [message({ objects: { ball: { p: [0, 1], q: [0, 0, 0, 1] } } }), /objects\.ball/],
      [message({ objects: { ball: { p: [0, 1, 0], q: [0, 0, 0, 'w'] } } }), /objects\.ball/],
      [message({ contacts: null }), /contacts null/],
      [message({ contacts: [{ ...contact, n: [0, 1] }] }), /contacts\[0\]/],
      [message({ contacts: [{ ...contact, bone: 7 }] }), /contacts\[0\]/],
      [message({ contacts: Array(MAX_SCENE_CONTACTS + 1).fill(contact) }), /contacts \[/],
    ];
    for (const [t, m] of cases) {
      expect(() => decodeText(t)).toThrow(ProtocolError);
      expect(() => decodeText(t)).toThrow(m);
    }
  });

  test('the scene\'s reset is an action of the input log', () => {
    const input = JSON.stringify({ type: 'input', tracking: 'tracking', gesture: 'open_palm', events: [], actions: [{ t: 3, gesture: 'open_palm', action: 'reset' }], accepted: 1, rejected: 0 });
    expect((decodeText(input) as InputMessage).actions).toEqual([{ t: 3, gesture: 'open_palm', action: 'reset' }]);
  });
});
