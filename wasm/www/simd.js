// Whether this browser's WebAssembly has SIMD, which the page's module is
// built with (.cargo/config.toml): asked when the module does not load, to
// say why.

// A module of one function returning a v128 (i32.const 0; i8x16.splat):
// valid only where WebAssembly has SIMD.
export const SIMD_PROBE = new Uint8Array([
  0, 97, 115, 109, 1, 0, 0, 0, // "\0asm", version 1
  1, 5, 1, 96, 0, 1, 123, // type section: () -> v128
  3, 2, 1, 0, // function section: one function of that type
  10, 8, 1, 6, 0, 65, 0, 253, 15, 11, // code: i32.const 0, i8x16.splat, end
]);

export function hasSimd() {
  return WebAssembly.validate(SIMD_PROBE);
}
