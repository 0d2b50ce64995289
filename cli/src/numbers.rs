//! Whole-number flags (`--granules`, `--seed`, `-j`, …): a value parser
//! whose rejection says what is allowed, where the standard integer
//! parsers say "invalid digit found in string" for `-3`, `1.5` or `1e3`;
//! the number flags' parser ([`real`]), which refuses what the standard
//! one reads as something else (`1e400` as infinity, `1e-400` as 0) and
//! says how to write a number it cannot read (`1mm`, `0,5`); and the comma
//! lists of distinct values of `--types` and `--seeds`.

/// A clap value parser of whole numbers `lo..=hi` written in digits; a
/// rejection (clap prefixes the flag and the value) gives the range.
pub fn whole<T>(
    lo: u64,
    hi: u64,
) -> impl Fn(&str) -> Result<T, String> + Clone + Send + Sync + 'static
where
    T: TryFrom<u64> + Clone + Send + Sync + 'static,
{
    move |text: &str| {
        let allowed = format!("allowed: whole numbers {lo}..={hi}");
        let Ok(n) = text.trim().parse::<i128>() else {
            return Err(format!("not a whole number ({allowed})"));
        };
        u64::try_from(n)
            .ok()
            .filter(|n| (lo..=hi).contains(n))
            .and_then(|n| T::try_from(n).ok())
            .ok_or_else(|| format!("out of range ({allowed})"))
    }
}

/// The clap value parser of every number flag (`--diameter-mm`,
/// `--yield-stress-pa`, …). It reads what Rust's `f64` parser reads —
/// `inf` and `nan` included, which each flag's own check then allows or
/// refuses with its range — but refuses a written number the double cannot
/// hold instead of reading it as another: one beyond about 1.8e308 (read as
/// infinity) or a nonzero one below about 4.9e-324 (read as 0). A value it
/// cannot read gets a hint: a comma (`0,5`, `30,000`: a decimal point, no
/// thousands separators) or a unit after the number (`1mm`, `30kPa`: the
/// unit is in the flag's name).
pub fn real(text: &str) -> Result<f64, String> {
    let t = text.trim();
    let Ok(x) = t.parse::<f64>() else {
        let number_part = t.trim_end_matches(|c: char| c.is_alphabetic() || c == '%' || c == ' ');
        return Err(
            if t.contains(',') && t.replace(',', "").parse::<f64>().is_ok() {
                // `0,5` or `30,000`: which one the comma meant is not ours
                // to guess.
                "not a number: no commas, a decimal point for a fraction (`0.5`) and no \
                 thousands separators (`30000`)"
                    .to_owned()
            } else if number_part != t
                && !number_part.is_empty()
                && number_part.parse::<f64>().is_ok()
            {
                format!(
                    "not a number: write the number alone (`{number_part}`); the flag's name gives its unit"
                )
            } else {
                "not a number (write e.g. 0.5, 2e-3 or 30000)".to_owned()
            },
        );
    };
    let mantissa = t.split(['e', 'E']).next().unwrap_or(t);
    let spelled_infinite = t
        .trim_start_matches(['+', '-'])
        .to_ascii_lowercase()
        .starts_with("inf");
    if x.is_infinite() && !spelled_infinite {
        return Err(
            "beyond the largest double (about 1.8e308); it would be read as infinity".to_owned(),
        );
    }
    if x == 0.0 && mantissa.chars().any(|c| ('1'..='9').contains(&c)) {
        return Err("below the smallest double (about 4.9e-324); it would be read as 0".to_owned());
    }
    Ok(x)
}

/// The comma list `text` parsed item by item (items trimmed) with
/// `parse`, each item at most once. A rejection names the item: "`x`:
/// what `parse` said", "`x` is listed twice".
pub fn distinct_list<T: PartialEq>(
    text: &str,
    parse: impl Fn(&str) -> Result<T, String>,
) -> Result<Vec<T>, String> {
    let mut items = Vec::new();
    for item in text.split(',').map(str::trim) {
        let value = parse(item).map_err(|e| format!("`{item}`: {e}"))?;
        if items.contains(&value) {
            return Err(format!("`{item}` is listed twice"));
        }
        items.push(value);
    }
    Ok(items)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits_for_tables() {
        let cases = [
            (0.300_001_234_5, "0.3000"),
            (123.456, "123.5"),
            (123_456.7, "123457"),
            (9.9996, "10.00"),
            (999_999.9, "1.000e6"),
            (1.23e-7, "1.230e-7"),
            (0.001_234_56, "0.001235"),
            (-0.000_999_96, "-0.001000"),
            (-0.000_099_996, "-1.000e-4"),
            (-42.0, "-42.00"),
            (0.0, "0.000"),
            (f64::NAN, "n/a"),
            (f64::NEG_INFINITY, "-∞"),
            (-0.0, "0.000"),
        ];
        for (x, text) in cases {
            assert_eq!(significant(x, 4), text, "{x}");
        }
        assert_eq!(significant(0.5, 0), "0.5");
        assert_eq!(significant(2.0 / 3.0, 2), "0.67");
    }

    /// Numbers are read as Rust reads them, `inf` and `nan` included; a
    /// written number the double cannot hold is refused, not read as
    /// infinity or 0; a unit or a decimal comma gets a hint.
    #[test]
    fn real_refuses_what_a_double_would_misread() {
        for (text, x) in [
            ("0.5", 0.5),
            (" 30000 ", 30_000.0),
            ("2e-3", 2e-3),
            ("-0", -0.0),
            ("0e5", 0.0),
            ("0.000", 0.0),
            ("1e308", 1e308),
            ("5e-324", 5e-324),
            ("inf", f64::INFINITY),
            ("-Infinity", f64::NEG_INFINITY),
        ] {
            assert_eq!(real(text).map(f64::to_bits), Ok(x.to_bits()), "{text}");
        }
        assert!(real("nan").unwrap().is_nan());
        let refused = |text: &str, says: &str| {
            let e = real(text).unwrap_err();
            assert!(e.contains(says), "{text}: {e}");
        };
        refused("1e400", "largest double");
        refused("-2e309", "largest double");
        refused("1e-400", "smallest double");
        refused("0,5", "no commas, a decimal point for a fraction (`0.5`)");
        refused("30,000", "no thousands separators (`30000`)");
        refused("1mm", "the number alone (`1`)");
        refused("30 kPa", "the number alone (`30`)");
        refused("12%", "the number alone (`12`)");
        refused("abc", "not a number (write");
        refused("", "not a number (write");
    }

    #[test]
    fn distinct_list_names_the_item_it_refuses() {
        let parse = |t: &str| t.parse::<u8>().map_err(|_| "not a byte".to_owned());
        assert_eq!(distinct_list(" 1, 2,3", parse), Ok(vec![1, 2, 3]));
        assert_eq!(
            distinct_list("1,x", parse),
            Err("`x`: not a byte".to_owned())
        );
        assert_eq!(
            distinct_list("1, 2, 01", parse),
            Err("`01` is listed twice".to_owned())
        );
        assert_eq!(distinct_list("", parse), Err("``: not a byte".to_owned()));
    }

    #[test]
    fn rejections_give_the_range() {
        let parse = whole::<usize>(1, 100_000);
        assert_eq!(parse("30"), Ok(30));
        assert_eq!(parse(" 100000 "), Ok(100_000));
        for bad in ["-3", "0", "100001", "99999999999999999999999999"] {
            let e = parse(bad).unwrap_err();
            assert!(
                e.contains("out of range") && e.contains("1..=100000"),
                "{bad}: {e}"
            );
        }
        for bad in ["1.5", "1e3", "abc", ""] {
            let e = parse(bad).unwrap_err();
            assert!(
                e.contains("not a whole number") && e.contains("1..=100000"),
                "{bad}: {e}"
            );
        }
        let seed = whole::<u64>(0, u64::MAX);
        assert_eq!(seed(&u64::MAX.to_string()), Ok(u64::MAX));
        assert!(seed("-1").unwrap_err().contains("0..=18446744073709551615"));
        let small = whole::<u32>(1, 10);
        assert_eq!(small("10"), Ok(10));
        assert!(small("11").is_err());
    }
}

pub use granbed_host::text::short;

/// `x` rounded to `digits` significant digits (at least 1) for a table a
/// reader scans: plain decimals for 10⁻³ ≤ |x| < 10⁶ (`0.3000`, `123.5`,
/// `123457`), scientific notation outside (`1.230e-7`), "n/a" for NaN and
/// "∞"/"-∞" for infinities. The full value stays in the machine-readable
/// output (`summary.json`, CSV); this is for pages and tables only.
pub fn significant(x: f64, digits: usize) -> String {
    if x.is_nan() {
        return "n/a".to_owned();
    }
    if x.is_infinite() {
        return if x > 0.0 { "∞" } else { "-∞" }.to_owned();
    }
    // -0.0 (a zero from round-off below zero) prints as 0.
    let x = if x == 0.0 { 0.0 } else { x };
    let digits = digits.max(1);
    // The exponent after rounding: 9.9996 to four digits is 1.000e1.
    let scientific = format!("{:.*e}", digits - 1, x);
    let exponent: i32 = scientific
        .rsplit_once('e')
        .and_then(|(_, e)| e.parse().ok())
        .unwrap_or(0);
    if x == 0.0 || (-3..6).contains(&exponent) {
        let decimals = (digits as i32 - 1 - exponent).max(0) as usize;
        format!("{x:.decimals$}")
    } else {
        scientific
    }
}

/// A value as a message shows it: a float [`short`], anything else as
/// it displays.
pub trait Shown {
    /// The text of the value.
    fn shown(&self) -> String;
}

impl Shown for f64 {
    fn shown(&self) -> String {
        short(*self)
    }
}

impl<T: Shown + ?Sized> Shown for &T {
    fn shown(&self) -> String {
        (**self).shown()
    }
}

/// [`Shown`] as [`ToString`] for the types that are not floats.
macro_rules! shown_as_displayed {
    ($($t:ty),*) => {
        $(impl Shown for $t {
            fn shown(&self) -> String {
                self.to_string()
            }
        })*
    };
}

shown_as_displayed!(
    u32,
    u64,
    usize,
    bool,
    str,
    String,
    granbed_kernel::material::GranuleType,
    crate::model::MeshLevel
);

#[cfg(test)]
mod short_tests {
    #[test]
    fn a_value_is_shown_short() {
        assert_eq!(super::Shown::shown(&&1e300), "1e300");
        assert_eq!(super::Shown::shown("one-point"), "one-point");
    }
}
