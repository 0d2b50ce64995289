//! Every transcendental or rounding-sensitive scalar function the kernel uses.
//!
//! All of them go through `libm`, never through the platform's `f64` methods
//! (unavailable in `core` anyway) and never through fused multiply-add, so that
//! native and wasm32 builds give the same bits for the same input.

use crate::Real;

/// Square root (correctly rounded, IEEE 754).
///
/// On x86-64 through the SSE2 intrinsic, not `libm`: `libm::sqrt` is inline
/// assembly (`sqrtsd`), which keeps its legacy SSE encoding inside the AVX2
/// element loop, and a legacy SSE instruction after 256-bit code pays the
/// SSE/AVX transition penalty. On one machine of this project (Xeon, model
/// 167) that made the AVX2 element 2.8x slower than the scalar one
/// (BENCHMARKS.md, "The AVX2 element and libm's square root"). The intrinsic
/// is LLVM's `sqrt`, encoded `vsqrtsd` where AVX is on; both are IEEE's
/// correctly rounded square root, so the bits are the same. On WebAssembly
/// with SIMD, the instruction `f64x2.sqrt` on one lane, correctly rounded
/// as well.
#[inline]
pub fn sqrt(x: Real) -> Real {
    #[cfg(target_arch = "x86_64")]
    {
        use core::arch::x86_64::{_mm_cvtsd_f64, _mm_set_sd, _mm_sqrt_pd};
        // SAFETY: SSE2 is part of every x86-64 processor (the target's
        // baseline); the intrinsics touch registers only.
        #[allow(unsafe_code)]
        unsafe {
            _mm_cvtsd_f64(_mm_sqrt_pd(_mm_set_sd(x)))
        }
    }
    // WebAssembly has the instruction (f64.sqrt), but core exposes it on
    // stable Rust only as a SIMD lane; libm's software square root took a
    // fifth of the browser's run (BENCHMARKS.md, "The browser's module
    // with SIMD and the square root instruction").
    #[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
    {
        use core::arch::wasm32::{f64x2_extract_lane, f64x2_splat, f64x2_sqrt};
        f64x2_extract_lane::<0>(f64x2_sqrt(f64x2_splat(x)))
    }
    #[cfg(not(any(
        target_arch = "x86_64",
        all(target_arch = "wasm32", target_feature = "simd128")
    )))]
    {
        libm::sqrt(x)
    }
}

/// Cube root of any real number (negative arguments give negative roots).
#[inline]
pub fn cbrt(x: Real) -> Real {
    libm::cbrt(x)
}

/// Natural logarithm.
#[inline]
pub fn ln(x: Real) -> Real {
    libm::log(x)
}

/// ln(1 + x), accurate for small x (the Heckel ordinate ln(1/(1 − D)) is
/// −ln_1p(−D)).
#[inline]
pub fn ln_1p(x: Real) -> Real {
    libm::log1p(x)
}

/// e^x − 1, accurate for small x.
#[inline]
pub fn exp_m1(x: Real) -> Real {
    libm::expm1(x)
}

/// Absolute value.
#[inline]
pub fn abs(x: Real) -> Real {
    libm::fabs(x)
}

/// Sine (radians).
#[inline]
pub fn sin(x: Real) -> Real {
    libm::sin(x)
}

/// Cosine (radians).
#[inline]
pub fn cos(x: Real) -> Real {
    libm::cos(x)
}

/// Arc cosine (radians), for x in [−1, 1].
#[inline]
pub fn acos(x: Real) -> Real {
    libm::acos(x)
}

/// Tangent (radians).
#[inline]
pub fn tan(x: Real) -> Real {
    libm::tan(x)
}

/// Larger of two numbers; a NaN argument yields the other one (IEEE
/// `maxNum`). Written out (libm's `fmax` is an out-of-line call in the hot
/// loops); deterministic on every target.
#[inline]
pub fn max(a: Real, b: Real) -> Real {
    if a.is_nan() || b > a { b } else { a }
}

/// Smaller of two numbers; a NaN argument yields the other one (IEEE
/// `minNum`).
#[inline]
pub fn min(a: Real, b: Real) -> Real {
    if a.is_nan() || b < a { b } else { a }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The intrinsic square root has libm's bits (both are IEEE's correctly
    /// rounded one) on a spread of normal numbers and on the special cases:
    /// it catches a wrong lane or conversion in the intrinsic form (on
    /// targets without it both sides are libm).
    #[test]
    fn sqrt_has_libms_bits() {
        let mut x: Real = 1.0e-310; // subnormal
        while x < 1.0e300 {
            for y in [x, x * 1.000_000_7, x * 3.3] {
                assert_eq!(sqrt(y).to_bits(), libm::sqrt(y).to_bits(), "sqrt({y:e})");
            }
            x *= 1.37;
        }
        for y in [0.0, -0.0, Real::INFINITY, Real::MIN_POSITIVE, Real::MAX] {
            assert_eq!(sqrt(y).to_bits(), libm::sqrt(y).to_bits(), "sqrt({y:e})");
        }
        for y in [-1.0, Real::NEG_INFINITY, Real::NAN] {
            assert!(sqrt(y).is_nan(), "sqrt({y:e})");
        }
    }
}
