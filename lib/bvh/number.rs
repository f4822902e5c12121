//! Decimal text -> f64, fast and exactly rounded.
//!
//! Frame data is almost all short decimals like `-171.350895`. For those, Clinger's fast path
//! is exact: when the digits fit in a u64 below 2^53 and the power of ten is at most 22, one
//! IEEE multiplication or division of two exactly representable numbers rounds correctly.
//! Everything else (long mantissas, big exponents) goes to the standard library, which is also
//! correctly rounded, so the result never depends on which path ran. Measured in BENCHMARKS.md.

const POW10: [f64; 23] = [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22];

/// Parse a BVH number: optional sign, digits with an optional `.`, optional exponent.
/// Returns `None` for anything else, including `nan`, `inf` and empty text, because a
/// non-finite channel value is never meaningful in a BVH file.
pub fn parse_f64(s: &[u8]) -> Option<f64> {
    match parse_f64_prefix(s) {
        Some((v, len)) if len == s.len() => Some(v),
        _ => None,
    }
}

/// Parse the number that starts `s`: its value and how many bytes its text takes. The scan is
/// the one `parse_f64` uses, stopping where the number's text ends instead of requiring that to
/// be the end of `s`, so `parse_f64(t) == Some(v)` exactly when this returns `Some((v, t.len()))`.
/// It lets the frame reader find and parse a value in a single pass over the bytes.
pub(super) fn parse_f64_prefix(s: &[u8]) -> Option<(f64, usize)> {
    let mut i = 0;
    let neg = match s.first() {
        Some(b'-') => {
            i = 1;
            true
        }
        Some(b'+') => {
            i = 1;
            false
        }
        _ => false,
    };
    // Digits on both sides of the point go into one integer, with one test per byte: the count
    // of digits comes from positions, not from per-digit bookkeeping, since this loop is most of
    // the frame section's parse time. Past 19 digits the sum may wrap; that case is sorted out
    // below, before the mantissa is trusted.
    let digits_start = i;
    let mut mantissa: u64 = 0;
    while let Some(d) = s.get(i).map(|c| c.wrapping_sub(b'0')).filter(|&d| d <= 9) {
        mantissa = mantissa.wrapping_mul(10).wrapping_add(d as u64);
        i += 1;
    }
    let int_digits = i - digits_start;
    let mut frac_digits = 0;
    if s.get(i) == Some(&b'.') {
        i += 1;
        let frac_start = i;
        while let Some(d) = s.get(i).map(|c| c.wrapping_sub(b'0')).filter(|&d| d <= 9) {
            mantissa = mantissa.wrapping_mul(10).wrapping_add(d as u64);
            i += 1;
        }
        frac_digits = i - frac_start;
    }
    if int_digits + frac_digits == 0 {
        return None;
    }
    // Leading zeros (`0.000012`) add nothing to the sum, so it is exact unless there are more
    // than 19 significant digits (10^19 < 2^64). Only long numbers pay for counting them.
    let exact = int_digits + frac_digits <= 19 || s[digits_start..i].iter().filter(|&&c| c != b'.').skip_while(|&&c| c == b'0').count() <= 19;
    let mut exp10 = -(frac_digits as i64);
    if i < s.len() && (s[i] == b'e' || s[i] == b'E') {
        i += 1;
        let mut eneg = false;
        if i < s.len() && (s[i] == b'-' || s[i] == b'+') {
            eneg = s[i] == b'-';
            i += 1;
        }
        let start = i;
        let mut e: i64 = 0;
        while i < s.len() && s[i].is_ascii_digit() {
            if e < 100_000 {
                e = e * 10 + (s[i] - b'0') as i64;
            }
            i += 1;
        }
        if i == start {
            return None;
        }
        exp10 += if eneg { -e } else { e };
    }
    if exact && mantissa < (1u64 << 53) && exp10.abs() <= 22 {
        let m = mantissa as f64;
        let v = if exp10 >= 0 { m * POW10[exp10 as usize] } else { m / POW10[(-exp10) as usize] };
        return Some((if neg { -v } else { v }, i));
    }
    // Slow but correctly rounded; the text is ASCII by construction here.
    let text = std::str::from_utf8(&s[..i]).ok()?;
    let v: f64 = text.parse().ok()?;
    v.is_finite().then_some((v, i))
}

#[cfg(test)]
mod tests {
    use super::parse_f64;

    #[test]
    fn agrees_with_std_on_awkward_numbers() {
        let cases = [
            "0",
            "-0",
            "1",
            "-171.350895",
            "0.1",
            "1e-5",
            "-1.5E+3",
            "123456789012345678901234",
            "0.000000000000000000000001",
            "9007199254740993",
            "1.7976931348623157e308",
            "4.9e-324",
            "2.2250738585072014e-308",
            ".5",
            "5.",
            "+3.25",
            "0.30000000000000004",
            "1234567.8901234567",
            "-0.000005",
        ];
        for c in cases {
            let ours = parse_f64(c.as_bytes()).unwrap_or_else(|| panic!("rejected {c}"));
            let std: f64 = c.parse().unwrap();
            assert_eq!(ours.to_bits(), std.to_bits(), "{c}");
        }
    }

    #[test]
    fn rejects_garbage_and_non_finite() {
        for c in ["", "-", ".", "e5", "1e", "1.2.3", "nan", "NaN", "inf", "-inf", "1e999", "1x", "--1", "0x10"] {
            assert!(parse_f64(c.as_bytes()).is_none(), "accepted {c:?}");
        }
    }
}
