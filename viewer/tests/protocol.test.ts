// The page's side of the wire format, on the golden vectors the Rust tests write and check
// (crates/dqhand/tests/stream.rs): the two sides stay byte-compatible.

import { readFileSync } from 'node:fs';
import { describe, expect, test } from 'vitest';
import { InputLog, LOG_LENGTH } from '../src/input';
import { binaryKind, decodeFrame, decodeText, decodeTopology, encodeCommand, frameByteLength, type InputMessage, ProtocolError } from '../src/protocol';

const fixture = (name: string): ArrayBuffer => {
  const bytes = readFileSync(new URL(`./fixtures/${name}`, import.meta.url));
  return bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
};

describe('frame', () => {
  test('decodes every field of the golden frame', () => {
    const buffer = fixture('frame-v1.bin');
    expect(binaryKind(buffer)).toBe('frame');
    const f = decodeFrame(buffer);
    expect(f.header).toMatchObject({
      sequence: 7, vertexCount: 2, jointCount: 2, dofCount: 3, methods: ['lb', 'dqb'], distortion: true,
      engineUs: 123.5, engineFps: 120, time: 1.25, duration: 21, playing: true, limits: true,
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
    const buffer = fixture('frame-v1.bin');
    const bytes = new Uint8Array(buffer);
    const variant = (edit: (b: Uint8Array) => Uint8Array) => edit(bytes.slice()).buffer as ArrayBuffer;
    const cases: [ArrayBuffer, RegExp][] = [
      [buffer.slice(0, buffer.byteLength - 4), /header announces/],
      [variant((b) => { const c = new Uint8Array(b.length + 4); c.set(b); return c; }), /header announces/],
      [buffer.slice(0, 20), /truncated/],
      [variant((b) => ((b[0] = 0x58), b)), /wrong magic/],
      [variant((b) => ((b[4] = 9), b)), /version 9/],
      [variant((b) => ((b[26] = 7), b)), /method code 7/],
      [variant((b) => ((b[24] = 0), b)), /0 meshes/],
      [variant((b) => ((b[7] = 1), b)), /unknown to version 1/],
      [variant((b) => ((b[26] = b[25]), b)), /given twice/],
      [variant((b) => ((b[27] = 0), b)), /method code 0 with 2 meshes/],
    ];
    for (const [b, message] of cases) expect(() => decodeFrame(b)).toThrow(message);
    expect(() => decodeFrame(buffer.slice(0, 20))).toThrow(ProtocolError);
  });
});

describe('topology', () => {
  test('decodes the golden topology', () => {
    const buffer = fixture('topology-v1.bin');
    expect(binaryKind(buffer)).toBe('topology');
    const t = decodeTopology(buffer);
    expect(t.vertexCount).toBe(4);
    expect(Array.from(t.indices)).toEqual([0, 1, 2, 2, 1, 3]);
    expect(Array.from(t.parents)).toEqual([-1, 0, 1]);
  });

  test('refuses an index past the vertices and a joint that is its own parent', () => {
    const bytes = new Uint8Array(fixture('topology-v1.bin'));
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
    accepted: 1234, rejected: 5,
  };
  const text = (edit: Record<string, unknown> = {}) => JSON.stringify({ ...good, ...edit });

  test('an input message is parsed with every field', () => {
    expect(decodeText(text())).toEqual(good);
    const quiet = decodeText(text({ tracking: 'lost', gesture: null, events: [], actions: [] })) as InputMessage;
    expect(quiet).toMatchObject({ tracking: 'lost', gesture: null, events: [], actions: [], accepted: 1234 });
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
    ];
    for (const [t, message] of cases) {
      expect(() => decodeText(t)).toThrow(ProtocolError);
      expect(() => decodeText(t)).toThrow(message);
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
