//! Numbers in messages: an error or a tolerance printed with two significant digits, `0` for
//! zero, without padding (`1.2e-15`, `1e-9`, `0`), the same in every solver's message and in
//! the Python layer's (`coulomb._readable`).

use std::fmt;

/// `x` with two significant digits in scientific notation, trailing `.0` dropped, and `0` for
/// zero (`Readable(0.0)` is `0`, `Readable(1.23e-15)` is `1.2e-15`, `Readable(1e-9)` is
/// `1e-9`); infinities and NaN as Rust prints them.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Readable(pub f64);

impl fmt::Display for Readable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        if x == 0.0 {
            return f.write_str("0");
        }
        if !x.is_finite() {
            return write!(f, "{x}");
        }
        let text = format!("{x:.1e}");
        match text.split_once('e') {
            Some((mantissa, exponent)) => {
                let mantissa = mantissa.strip_suffix(".0").unwrap_or(mantissa);
                write!(f, "{mantissa}e{exponent}")
            }
            None => f.write_str(&text),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Readable;

    #[test]
    fn zero_prints_as_zero_and_others_with_two_significant_digits() {
        let cases = [
            (0.0, "0"),
            (-0.0, "0"),
            (1.23e-15, "1.2e-15"),
            (1e-9, "1e-9"),
            (-2.5e3, "-2.5e3"),
            (0.5, "5e-1"),
            (9.96e-3, "1e-2"),
            (f64::INFINITY, "inf"),
        ];
        for (x, text) in cases {
            assert_eq!(Readable(x).to_string(), text, "{x:e}");
        }
        assert_eq!(Readable(f64::NAN).to_string(), "NaN");
    }
}
