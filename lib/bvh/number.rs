//! Decimal text -> f64, fast and exactly rounded.
//!
//! Frame data is almost all short decimals like `-171.350895`. For those, Clinger's fast path
//! is exact: when the digits fit in a u64 below 2^53 and the power of ten is at most 22, one
//! IEEE multiplication or division of two exactly representable numbers rounds correctly.
//! Everything else (long mantissas, big exponents) goes to the standard library, which is also
//! correctly rounded, so the result never depends on which path ran. Measured in BENCHMARKS.md.

const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Parse a BVH number: optional sign, digits with an optional `.`, optional exponent.
/// Returns `None` for anything else, including `nan`, `inf` and empty text, because a
/// non-finite channel value is never meaningful in a BVH file.
pub fn parse_f64(s: &[u8]) -> Option<f64> {
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
    let mut mantissa: u64 = 0;
    let mut digits = 0usize; // significant digits accumulated into mantissa
    let mut any_digit = false;
    let mut exp10: i64 = 0;
    let mut overflow = false;
    while i < s.len() && s[i].is_ascii_digit() {
        any_digit = true;
        if digits < 19 {
            mantissa = mantissa * 10 + (s[i] - b'0') as u64;
            if mantissa != 0 {
                digits += 1;
            }
        } else {
            overflow = true;
            exp10 += 1;
        }
        i += 1;
    }
    if i < s.len() && s[i] == b'.' {
        i += 1;
        while i < s.len() && s[i].is_ascii_digit() {
            any_digit = true;
            if digits < 19 {
                mantissa = mantissa * 10 + (s[i] - b'0') as u64;
                if mantissa != 0 {
                    digits += 1;
                }
                exp10 -= 1;
            } else {
                overflow = true;
            }
            i += 1;
        }
    }
    if !any_digit {
        return None;
    }
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
    if i != s.len() {
        return None;
    }
    if !overflow && mantissa < (1u64 << 53) && exp10.abs() <= 22 {
        let m = mantissa as f64;
        let v = if exp10 >= 0 { m * POW10[exp10 as usize] } else { m / POW10[(-exp10) as usize] };
        return Some(if neg { -v } else { v });
    }
    // Slow but correctly rounded; the text is ASCII by construction here.
    let text = std::str::from_utf8(s).ok()?;
    let v: f64 = text.parse().ok()?;
    v.is_finite().then_some(v)
}

#[cfg(test)]
mod tests {
    use super::parse_f64;

    #[test]
    fn agrees_with_std_on_awkward_numbers() {
        let cases = [
            "0", "-0", "1", "-171.350895", "0.1", "1e-5", "-1.5E+3", "123456789012345678901234",
            "0.000000000000000000000001", "9007199254740993", "1.7976931348623157e308",
            "4.9e-324", "2.2250738585072014e-308", ".5", "5.", "+3.25", "0.30000000000000004",
            "1234567.8901234567", "-0.000005",
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
