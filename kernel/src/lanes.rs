//! Arithmetic on several values side by side, with the scalar code's bits.
//!
//! [`Num`] is the arithmetic the element and the elastic trial state need
//! (`+ − × ÷`, negation, square root, constants). It is implemented for
//! [`Real`] (one value) and for [`Lanes`] (`W` values, every operation
//! applied lane by lane). Code written once over `T: Num` therefore gives,
//! in every lane of a `Lanes<W>`, exactly the bits the `Real` instance gives
//! for that lane's input: the operations and their order are the same, and
//! IEEE 754 rounds `+ − × ÷ √` correctly whatever the vector width (no fused
//! multiply-add is ever formed — Rust does not contract `a * b + c`).
//!
//! The lane loops are plain array loops; the compiler turns them into vector
//! instructions of the width the enclosing function is compiled for (SSE2:
//! 2 lanes, AVX2: 4 — see [`crate::element::batch`] for the run-time
//! dispatch).

use core::ops::{Add, Div, Mul, Neg, Sub};

use crate::{Real, math};

/// The arithmetic shared by scalars and lane bundles.
pub trait Num:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    /// Number of lanes.
    const LANES: usize;
    /// Every lane set to `v`.
    fn splat(v: Real) -> Self;
    /// Correctly rounded square root of every lane ([`math::sqrt`]).
    fn sqrt(self) -> Self;
    /// Lane `l` (`l < LANES`).
    fn lane(self, l: usize) -> Real;
    /// Lanes built from `f(l)`.
    fn from_fn(f: impl FnMut(usize) -> Real) -> Self;
}

impl Num for Real {
    const LANES: usize = 1;
    #[inline(always)]
    fn splat(v: Real) -> Self {
        v
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        math::sqrt(self)
    }
    #[inline(always)]
    fn lane(self, _l: usize) -> Real {
        self
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> Real) -> Self {
        f(0)
    }
}

/// Whether bit `l` of a lane mask is set: the masks of the lane solvers
/// (`u64`, bit l for lane l, so at most 64 lanes) that say which lanes are
/// still iterating. `false` for `l` ≥ 64 (a shift that far overflowed).
#[inline(always)]
pub fn lane_bit(bits: u64, l: usize) -> bool {
    u32::try_from(l)
        .ok()
        .and_then(|l| bits.checked_shr(l))
        .is_some_and(|b| b & 1 == 1)
}

/// `W` values operated on lane by lane.
///
/// Aligned to 32 bytes, the width of an AVX2 register: four lanes then
/// never straddle a cache line, so with AVX2 the element batch's loads and
/// stores of its lanes (reference data, coordinates, forces, spills) are
/// one access each; the batch's elastic case ran 80 → 76 µs per granule
/// against the 8-byte alignment of `[Real; W]` (BENCHMARKS.md, session
/// 32). Fewer than four lanes are padded to 32 bytes.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C, align(32))]
pub struct Lanes<const W: usize>(pub [Real; W]);

macro_rules! lane_op {
    ($trait:ident, $method:ident, $op_assign:tt) => {
        impl<const W: usize> $trait for Lanes<W> {
            type Output = Self;
            #[inline(always)]
            fn $method(self, other: Self) -> Self {
                let mut out = self.0;
                for (o, b) in out.iter_mut().zip(other.0) {
                    *o $op_assign b;
                }
                Self(out)
            }
        }
    };
}

lane_op!(Add, add, +=);
lane_op!(Sub, sub, -=);
lane_op!(Mul, mul, *=);
lane_op!(Div, div, /=);

impl<const W: usize> Neg for Lanes<W> {
    type Output = Self;
    #[inline(always)]
    fn neg(self) -> Self {
        let mut out = self.0;
        for o in &mut out {
            *o = -*o;
        }
        Self(out)
    }
}

impl<const W: usize> Num for Lanes<W> {
    const LANES: usize = W;
    #[inline(always)]
    fn splat(v: Real) -> Self {
        Self([v; W])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        let mut out = self.0;
        for o in &mut out {
            *o = math::sqrt(*o);
        }
        Self(out)
    }
    #[inline(always)]
    fn lane(self, l: usize) -> Real {
        self.0[l]
    }
    #[inline(always)]
    fn from_fn(mut f: impl FnMut(usize) -> Real) -> Self {
        // A loop rather than `array::from_fn`, which rustc left out of line.
        let mut out = [0.0; W];
        for (l, o) in out.iter_mut().enumerate() {
            *o = f(l);
        }
        Self(out)
    }
}

impl Lanes<4> {
    /// Four scalars as one lane vector, lane l = `v[l]`, the same values as
    /// `Lanes(v)`.
    ///
    /// Where the build targets AVX (every x86-64 Linux build of this
    /// workspace: `.cargo/config.toml`), made with the `_mm256_setr_pd`
    /// intrinsic. Made from the array, the element batch's gather of its
    /// nodes' coordinates stored every scalar on its own into the batch's
    /// scratch (96 8-byte stores per batch, read back as 24 vectors); made
    /// here, it stores them in pairs, and the element in the default bed
    /// took 3 % less time early in the compression (BENCHMARKS.md, session
    /// 37). Elsewhere (wasm32, a baseline x86-64 build) it is `Lanes(v)`.
    #[inline(always)]
    pub fn from_scalars(v: [Real; 4]) -> Self {
        #[cfg(all(target_arch = "x86_64", target_feature = "avx"))]
        {
            use core::arch::x86_64::{__m256d, _mm256_setr_pd};
            // SAFETY: AVX is enabled for the whole build (the `cfg` above),
            // so the intrinsic's instructions exist; it touches registers
            // only. `__m256d` holds four f64 in lane order (`setr`: lane 0
            // first), the layout of `[f64; 4]`, and every bit pattern is
            // valid in both.
            #[allow(unsafe_code)]
            unsafe {
                Self(core::mem::transmute::<__m256d, [Real; 4]>(_mm256_setr_pd(
                    v[0], v[1], v[2], v[3],
                )))
            }
        }
        #[cfg(not(all(target_arch = "x86_64", target_feature = "avx")))]
        {
            Self(v)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `from_scalars` puts `v[l]` in lane l, bit for bit (signed zero, NaN
    /// payload, subnormal), on whichever path the build compiles (the
    /// intrinsic on this workspace's x86-64 builds).
    #[test]
    fn from_scalars_keeps_lane_order_and_bits() {
        let v = core::hint::black_box([-0.0, f64::from_bits(0x7ff8_0000_dead_beef), 5e-324, 1.5]);
        let lanes = Lanes::from_scalars(v);
        for (l, x) in v.iter().enumerate() {
            assert_eq!(lanes.0[l].to_bits(), x.to_bits(), "lane {l}");
        }
    }

    /// A lane mask's bits read in order, and a lane past the mask's 64 is
    /// not set (its shift overflowed).
    #[test]
    fn lane_bits_past_the_mask_are_unset() {
        let bits = 0b1011u64 | 1 << 63;
        let set: [bool; 5] = core::array::from_fn(|l| lane_bit(bits, l));
        assert_eq!(set, [true, true, false, true, false]);
        assert!(lane_bit(bits, 63));
        assert!(!lane_bit(u64::MAX, 64) && !lane_bit(u64::MAX, usize::MAX));
    }

    /// Lane l of every operation equals the scalar operation on lane l.
    #[test]
    fn lanes_give_the_scalar_bits() {
        // black_box: inputs the compiler cannot fold at build time.
        let a = core::hint::black_box(Lanes([1.0 / 3.0, -2.5e-300, 7.0e300, 0.1]));
        let b = core::hint::black_box(Lanes([3.0, 1.0e-10, 0.3, -0.0]));
        type Scalar = fn(Real, Real) -> Real;
        let ops: [(Lanes<4>, Scalar); 4] = [
            (a + b, |x, y| x + y),
            (a - b, |x, y| x - y),
            (a * b, |x, y| x * y),
            (a / b, |x, y| x / y),
        ];
        for (lanes, scalar) in ops {
            for l in 0..4 {
                assert_eq!(lanes.lane(l).to_bits(), scalar(a.0[l], b.0[l]).to_bits());
            }
        }
        for l in 0..4 {
            assert_eq!((-a).lane(l).to_bits(), (-a.0[l]).to_bits());
            assert_eq!(b.sqrt().lane(l).to_bits(), math::sqrt(b.0[l]).to_bits());
        }
    }
}
