//! Numbers in messages: an error or a tolerance printed with two significant digits, `0` for
//! zero, without padding (`1.2e-15`, `1e-9`, `0`), the same in every solver's message and in
//! the Python layer's (`coulomb._readable`).

use std::fmt::{self, Write};

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
        // formatted on the stack: every solve's message prints its error
        let mut buf = Stack::default();
        if write!(buf, "{x:.1e}").is_err() {
            return write!(f, "{x:.1e}");
        }
        let text = buf.as_str();
        match text.split_once('e') {
            Some((mantissa, exponent)) => {
                f.write_str(mantissa.strip_suffix(".0").unwrap_or(mantissa))?;
                f.write_str("e")?;
                f.write_str(exponent)
            }
            None => f.write_str(text),
        }
    }
}

/// A short text on the stack (`-1.2e-308` is 9 bytes); writing past its end is an error.
#[derive(Default)]
struct Stack {
    bytes: [u8; 32],
    len: usize,
}

impl Stack {
    fn as_str(&self) -> &str {
        // only whole `&str`s are written, so the bytes are UTF-8
        std::str::from_utf8(&self.bytes[..self.len]).unwrap_or("")
    }
}

impl fmt::Write for Stack {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        let end = self.len + s.len();
        let room = self.bytes.get_mut(self.len..end).ok_or(fmt::Error)?;
        room.copy_from_slice(s.as_bytes());
        self.len = end;
        Ok(())
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

    #[test]
    fn the_stack_buffer_prints_what_format_prints() {
        // the heap form it replaced, as the oracle
        let heap = |x: f64| {
            let text = format!("{x:.1e}");
            let (mantissa, exponent) = text.split_once('e').unwrap();
            format!(
                "{}e{exponent}",
                mantissa.strip_suffix(".0").unwrap_or(mantissa)
            )
        };
        let mut x: f64 = 5e-324;
        while x < 1e308 {
            for v in [x, -x, x * 1.05, x * 9.951]
                .into_iter()
                .filter(|v| v.is_finite())
            {
                assert_eq!(Readable(v).to_string(), heap(v), "{v:e}");
            }
            x *= 7.3;
        }
        assert_eq!(Readable(-f64::MAX).to_string(), heap(-f64::MAX));
    }
}
