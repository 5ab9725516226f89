// Reads the instructions of a WebAssembly module's function bodies (the binary format of the
// WebAssembly core specification, 5.4, with the SIMD, bulk-memory, reference-types and
// sign-extension proposals): how many SIMD instructions (the 0xFD prefix) a module holds,
// counted at instruction boundaries, not by byte (0xFD also occurs in immediates). An opcode it
// does not know is an error, never skipped.

/** A cursor over the bytes. */
class Reader {
  constructor(bytes, at = 0) {
    this.b = bytes;
    this.at = at;
  }
  byte() {
    if (this.at >= this.b.length) throw new Error(`wasm: read past the end at ${this.at}`);
    return this.b[this.at++];
  }
  u32() {
    let result = 0;
    let shift = 0;
    for (;;) {
      const b = this.byte();
      result += (b & 0x7f) * 2 ** shift;
      if (!(b & 0x80)) return result;
      shift += 7;
    }
  }
  /** A signed LEB128 of any width, skipped. */
  sleb() {
    while (this.byte() & 0x80);
  }
  skip(n) {
    this.at += n;
  }
}

const VALUE_TYPES = new Set([0x7f, 0x7e, 0x7d, 0x7c, 0x7b, 0x70, 0x6f, 0x40]);

/** Skips a block type: empty, a value type, or a type index (signed LEB128). */
function blockType(r) {
  if (VALUE_TYPES.has(r.b[r.at])) r.skip(1);
  else r.sleb();
}

function memarg(r) {
  const align = r.u32();
  if (align & 0x40) r.u32(); // a memory index (multi-memory)
  r.u32();
}

/** Skips the immediates of one 0xFD (SIMD) instruction. */
function simd(r) {
  const op = r.u32();
  if (op <= 11 || op === 92 || op === 93) memarg(r);
  else if (op === 12 || op === 13) r.skip(16);
  else if (op >= 21 && op <= 34) r.skip(1);
  else if (op >= 84 && op <= 91) {
    memarg(r);
    r.skip(1);
  }
}

/** Skips the immediates of one 0xFC instruction. */
function misc(r) {
  const op = r.u32();
  if (op <= 7) return;
  const immediates = { 8: 'u1', 9: 'u', 10: '11', 11: '1', 12: 'uu', 13: 'u', 14: 'uu', 15: 'u', 16: 'u', 17: 'u' }[op];
  if (immediates === undefined) throw new Error(`wasm: unknown 0xFC opcode ${op} at ${r.at}`);
  for (const kind of immediates) (kind === 'u' ? r.u32() : r.skip(Number(kind)));
}

/** Decodes one instruction; returns whether it is a SIMD instruction. */
function instruction(r) {
  const op = r.byte();
  if (op === 0xfd) {
    simd(r);
    return true;
  }
  if (op === 0xfc) misc(r);
  else if (op >= 0x02 && op <= 0x04) blockType(r);
  else if (op === 0x0c || op === 0x0d || op === 0x10 || op === 0x12 || (op >= 0x20 && op <= 0x26) || op === 0xd2) r.u32();
  else if (op === 0x0e) {
    for (let n = r.u32(); n > 0; n--) r.u32();
    r.u32();
  } else if (op === 0x11 || op === 0x13) {
    r.u32();
    r.u32();
  } else if (op === 0x1c) r.skip(r.u32());
  else if (op >= 0x28 && op <= 0x3e) memarg(r);
  else if (op === 0x3f || op === 0x40 || op === 0xd0) r.skip(1);
  else if (op === 0x41 || op === 0x42) r.sleb();
  else if (op === 0x43) r.skip(4);
  else if (op === 0x44) r.skip(8);
  else if (!(op <= 0x01 || op === 0x05 || op === 0x0b || op === 0x0f || op === 0x1a || op === 0x1b || (op >= 0x45 && op <= 0xc4) || op === 0xd1)) {
    throw new Error(`wasm: unknown opcode 0x${op.toString(16)} at ${r.at - 1}`);
  }
  return false;
}

/** How many instructions, and how many of them SIMD, the module's function bodies hold. */
export function countInstructions(bytes) {
  const r = new Reader(bytes, 8);
  let total = 0;
  let simdCount = 0;
  while (r.at < bytes.length) {
    const id = r.byte();
    const size = r.u32();
    const end = r.at + size;
    if (id === 10) {
      for (let n = r.u32(); n > 0; n--) {
        const bodyEnd = r.u32() + r.at;
        for (let groups = r.u32(); groups > 0; groups--) {
          r.u32();
          r.skip(1);
        }
        while (r.at < bodyEnd) {
          total++;
          if (instruction(r)) simdCount++;
        }
        if (r.at !== bodyEnd) throw new Error(`wasm: a function body overran by ${r.at - bodyEnd} bytes`);
      }
    }
    r.at = end;
  }
  return { total, simd: simdCount };
}
