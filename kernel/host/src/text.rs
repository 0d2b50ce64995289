//! Numbers as messages show them, shared by the command line and the
//! browser, so that both say a rejected value alike.

use alloc::format;
use alloc::string::{String, ToString};

/// `x` short, for messages: Rust's shortest round-trip decimal, or the
/// same digits in scientific notation where that is more than three
/// characters shorter (`1e300`, not 301 digits; `0.001` and `100000` stay).
pub fn short(x: f64) -> String {
    let (plain, scientific) = (x.to_string(), format!("{x:e}"));
    if scientific.len() + 3 < plain.len() {
        scientific
    } else {
        plain
    }
}

#[cfg(test)]
mod tests {
    use super::short;

    #[test]
    fn long_numbers_go_scientific() {
        assert_eq!(short(0.5), "0.5");
        assert_eq!(short(1e300), "1e300");
        assert_eq!(short(1e-12), "1e-12");
        assert_eq!(short(-2.5e-9), "-2.5e-9");
        assert_eq!(short(f64::NAN), "NaN");
        assert_eq!(short(1234.5678), "1234.5678");
        assert_eq!(short(0.001), "0.001");
        assert_eq!(short(100000.0), "100000");
        assert_eq!(short(1e6), "1e6");
    }
}
