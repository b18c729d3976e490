//! Numbers in messages: an error or a tolerance printed with two significant digits, `0` for
//! zero, without padding (`1.2e-15`, `1e-9`, `0`), the same in every solver's message and in
//! the Python layer's (`coulomb._readable`).

use std::fmt::{self, Write};

/// `x` with two significant digits in scientific notation, trailing `.0` dropped, and `0` for
/// zero (`Readable(0.0)` is `0`, `Readable(1.23e-15)` is `1.2e-15`, `Readable(1e-9)` is
/// `1e-9`); infinities and NaN as Rust prints them.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Readable(pub f64);

impl Readable {
    /// appends the text to `out` (what `Display` prints), without the formatting machinery
    /// for the common case: a solve's message prints at least one number.
    pub(crate) fn push_to(self, out: &mut String) {
        match fast_digits(self.0) {
            Some((negative, digits, exponent)) => {
                if negative {
                    out.push('-');
                }
                out.push(char::from(b'0' + digits / 10));
                if digits % 10 != 0 {
                    out.push('.');
                    out.push(char::from(b'0' + digits % 10));
                }
                out.push('e');
                push_int(out, exponent);
            }
            None => {
                // the exact path; a String's fmt::Write cannot fail
                let _ = write!(out, "{self}");
            }
        }
    }
}

/// `x`'s two significant digits `d` (10..=99) and exponent `e` with `|x|` = d.d x 10^e to
/// two digits, when they are certain from f64 arithmetic: `None` for 0, non-finite values,
/// magnitudes outside 1e-290..1e290 and values within 1e-9 (relative) of a rounding tie,
/// which the exact formatter decides.
fn fast_digits(x: f64) -> Option<(bool, u8, i32)> {
    let a = x.abs();
    if !(1e-290..=1e290).contains(&a) {
        return None;
    }
    // log10's estimate of the exponent may be one off near a power of ten: corrected below
    let mut e = a.log10().floor() as i32;
    let mut m = a * 10f64.powi(1 - e);
    if m < 10.0 {
        e -= 1;
        m *= 10.0;
    } else if m >= 100.0 {
        e += 1;
        m /= 10.0;
    }
    let below = m.floor();
    let frac = m - below;
    // m carries a few ulps of error from the power and the product: a value this close to
    // a tie (or to 10 or 100) is left to the exact formatter
    if (frac - 0.5).abs() < 1e-9 || !(10.0 + 1e-9..100.0 - 1e-9).contains(&m) {
        return None;
    }
    let mut digits = below as u32 + u32::from(frac > 0.5);
    if digits == 100 {
        digits = 10;
        e += 1;
    }
    Some((x < 0.0, digits as u8, e))
}

/// appends the decimal digits of `v`, with its sign.
fn push_int(out: &mut String, v: i32) {
    if v < 0 {
        out.push('-');
    }
    push_count(out, v.unsigned_abs() as usize);
}

/// appends the decimal digits of `v` (a count in a message).
pub(crate) fn push_count(out: &mut String, v: usize) {
    let mut u = v;
    let mut buf = [0u8; 20];
    let mut at = buf.len();
    loop {
        at -= 1;
        buf[at] = b'0' + (u % 10) as u8;
        u /= 10;
        if u == 0 {
            break;
        }
    }
    for &b in &buf[at..] {
        out.push(char::from(b));
    }
}

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

    #[test]
    fn the_fast_path_prints_what_the_exact_formatter_prints() {
        let pushed = |x: f64| {
            let mut s = String::new();
            Readable(x).push_to(&mut s);
            s
        };
        // every decade, values at and around the ties d.d5 and the powers of ten, and a
        // dense sweep of mantissas (xorshift: deterministic)
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        let mut checked = 0;
        for e in -320..=308 {
            let p = 10f64.powi(e);
            let mut values = vec![p, p * 0.999_999_999_999, p * 1.000_000_000_001];
            for d in 10..100 {
                let tie = (d as f64 + 0.5) / 10.0 * p;
                values.extend([tie, tie.next_up(), tie.next_down(), d as f64 / 10.0 * p]);
            }
            for _ in 0..200 {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                values.push((1.0 + (state >> 11) as f64 / (1u64 << 53) as f64 * 9.0) * p);
            }
            for v in values.into_iter().filter(|v| v.is_finite() && *v != 0.0) {
                for v in [v, -v] {
                    assert_eq!(pushed(v), Readable(v).to_string(), "{v:e}");
                    checked += 1;
                }
            }
        }
        for v in [
            0.0,
            -0.0,
            f64::INFINITY,
            f64::NAN,
            f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
        ] {
            assert_eq!(pushed(v), Readable(v).to_string(), "{v:e}");
        }
        assert!(checked > 400_000, "{checked}");
    }
}
