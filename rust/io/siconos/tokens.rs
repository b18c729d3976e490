//! the file as a stream of whitespace-separated tokens, as the C readers see it with
//! `fscanf`.

use std::fmt::Display;

use super::ReadError;
use super::Result;

struct Token<'a> {
    text: &'a str,
    line: usize,
}

/// the file as whitespace-separated tokens, with a cursor.
pub(super) struct Tokens<'a> {
    toks: Vec<Token<'a>>,
    pub(super) pos: usize,
    origin: &'a str,
}

impl<'a> Tokens<'a> {
    pub(super) fn new(text: &'a str, origin: &'a str) -> Self {
        let toks = text
            .lines()
            .enumerate()
            .flat_map(|(i, line)| {
                line.split_whitespace()
                    .map(move |text| Token { text, line: i + 1 })
            })
            .collect();
        Self {
            toks,
            pos: 0,
            origin,
        }
    }

    pub(super) fn remaining(&self) -> usize {
        self.toks.len().saturating_sub(self.pos)
    }

    pub(super) fn peek(&self) -> Option<&'a str> {
        self.text_at(self.pos)
    }

    pub(super) fn text_at(&self, index: usize) -> Option<&'a str> {
        self.toks.get(index).map(|t| t.text)
    }

    /// whether the rest is empty or a single integer: Siconos FC writers append one unused
    /// flag, so this is what "the whole file was consumed" looks like.
    pub(super) fn only_flag_left(&self) -> bool {
        match self.remaining() {
            0 => true,
            1 => self.peek().is_some_and(|s| s.parse::<i64>().is_ok()),
            _ => false,
        }
    }

    pub(super) fn error_at(&self, index: usize, message: impl Display) -> ReadError {
        let place = match self.toks.get(index) {
            Some(tok) => format!("token {index} (line {})", tok.line),
            None => format!("token {index} (end of input)"),
        };
        ReadError::Format {
            path: self.origin.to_string(),
            message: format!("{message}, at {place}"),
        }
    }

    pub(super) fn next(&mut self, what: &str) -> Result<&'a str> {
        self.next_with(|| what.to_string())
    }

    pub(super) fn next_with(&mut self, what: impl FnOnce() -> String) -> Result<&'a str> {
        match self.toks.get(self.pos) {
            Some(tok) => {
                self.pos += 1;
                Ok(tok.text)
            }
            None => Err(self.error_at(
                self.pos,
                format_args!("expected {}, found end of input", what()),
            )),
        }
    }

    /// fails unless `count` more tokens exist; called before allocating for them.
    pub(super) fn ensure(&self, count: usize, what: impl FnOnce() -> String) -> Result<()> {
        let left = self.remaining();
        if left < count {
            return Err(self.error_at(
                self.toks.len(),
                format_args!(
                    "expected {count} {}, but only {left} tokens remain (truncated file?)",
                    what()
                ),
            ));
        }
        Ok(())
    }

    pub(super) fn literal(&mut self, expected: &str) -> Result<()> {
        let at = self.pos;
        let tok = self.next_with(|| format!("`{expected}`"))?;
        if tok != expected {
            return Err(self.error_at(at, format_args!("expected `{expected}`, found `{tok}`")));
        }
        Ok(())
    }

    pub(super) fn usize(&mut self, what: &str) -> Result<usize> {
        self.usize_with(|| what.to_string())
    }

    pub(super) fn usize_with(&mut self, what: impl Fn() -> String) -> Result<usize> {
        let at = self.pos;
        let tok = self.next_with(&what)?;
        tok.parse().map_err(|_| {
            self.error_at(
                at,
                format_args!(
                    "expected {} (a non-negative integer), found `{tok}`",
                    what()
                ),
            )
        })
    }

    /// an integer printed as `K,` inside a CSparse header.
    pub(super) fn usize_comma(&mut self, what: &str) -> Result<usize> {
        let at = self.pos;
        let tok = self.next(what)?;
        tok.trim_end_matches(',').parse().map_err(|_| {
            self.error_at(
                at,
                format_args!("expected {what} (a non-negative integer), found `{tok}`"),
            )
        })
    }

    /// an integer that must be below `bound`.
    pub(super) fn index(&mut self, bound: usize, what: impl Fn() -> String) -> Result<usize> {
        let at = self.pos;
        let i = self.usize_with(&what)?;
        if i >= bound {
            return Err(self.error_at(
                at,
                format_args!("{} = {i} is out of range (must be < {bound})", what()),
            ));
        }
        Ok(i)
    }

    pub(super) fn f64_with(&mut self, what: impl Fn() -> String) -> Result<f64> {
        let at = self.pos;
        let tok = self.next_with(&what)?;
        match tok.parse::<f64>() {
            // nan/inf would poison every solver downstream; treat them as corrupt data
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.error_at(
                at,
                format_args!("expected {} (a finite number), found `{tok}`", what()),
            )),
        }
    }

    pub(super) fn f64_vec(&mut self, n: usize, name: &str) -> Result<Vec<f64>> {
        self.ensure(n, || format!("entries of {name}"))?;
        (0..n)
            .map(|k| self.f64_with(|| format!("{name}[{k}]")))
            .collect()
    }

    pub(super) fn usize_vec(&mut self, n: usize, name: &str) -> Result<Vec<usize>> {
        self.ensure(n, || format!("entries of {name}"))?;
        (0..n)
            .map(|k| self.usize_with(|| format!("{name}[{k}]")))
            .collect()
    }
}
