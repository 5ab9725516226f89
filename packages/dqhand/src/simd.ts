// Which build of the engine to load: the package holds it twice, with WebAssembly's 128-bit
// SIMD (the simd128 skinning kernel) and without, because a module cannot detect features at
// run time and an engine without SIMD rejects a module that holds one SIMD instruction. The
// engine is asked to validate a tiny module holding one (`v128.const`), and the SIMD build is
// loaded where it passes.

/**
 * A module of one function returning a `v128.const` of zeros (type () -> v128): valid only
 * where the engine has SIMD.
 */
export const SIMD_PROBE = Uint8Array.from([
  0x00, 0x61, 0x73, 0x6d, 0x01, 0x00, 0x00, 0x00, // "\0asm", version 1
  0x01, 0x05, 0x01, 0x60, 0x00, 0x01, 0x7b, // type section: one type, () -> v128
  0x03, 0x02, 0x01, 0x00, // function section: one function of type 0
  0x0a, 0x16, 0x01, 0x14, 0x00, // code section: one body of 20 bytes, no locals
  0xfd, 0x0c, ...new Array<number>(16).fill(0), // v128.const 0
  0x0b, // end
]);

/** Whether this engine runs WebAssembly SIMD. */
export function simdSupported(): boolean {
  return typeof WebAssembly === 'object' && WebAssembly.validate(SIMD_PROBE);
}
