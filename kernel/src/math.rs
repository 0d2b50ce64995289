//! Every transcendental or rounding-sensitive scalar function the kernel uses.
//!
//! All of them go through `libm`, never through the platform's `f64` methods
//! (unavailable in `core` anyway) and never through fused multiply-add, so that
//! native and wasm32 builds give the same bits for the same input.

use crate::Real;

/// Square root (correctly rounded, IEEE 754).
#[inline]
pub fn sqrt(x: Real) -> Real {
    libm::sqrt(x)
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
