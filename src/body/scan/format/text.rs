//! Text formats (OBJ, ASCII PLY, ASCII STL) as numbered lines and whitespace-separated words.
//! Lines end at `\n`, `\r\n` or a lone `\r` (old Mac files): every line ending a tool may
//! write reads the same. A UTF-8 byte-order mark is skipped.

use super::ReadError;
use crate::messages::quote;

/// How many characters of a word a message shows.
const WORD_SHOWN: usize = 24;

/// The lines of `bytes`, numbered from 1, without their line endings.
pub(super) fn lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    let mut rest = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    let mut number = 0;
    std::iter::from_fn(move || {
        if rest.is_empty() {
            return None;
        }
        number += 1;
        let end = rest.iter().position(|&b| b == b'\n' || b == b'\r').unwrap_or(rest.len());
        let line = &rest[..end];
        let ending = match rest.get(end..end + 2) {
            Some(b"\r\n") => 2,
            _ => usize::from(end < rest.len()),
        };
        rest = &rest[end + ending..];
        Some((number, line))
    })
}

/// The whitespace-separated words of a line.
pub(super) fn words(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|b| b.is_ascii_whitespace()).filter(|w| !w.is_empty())
}

/// `word` as a message shows it (escaped, cut).
pub(super) fn shown(word: &[u8]) -> String {
    format!("'{}'", quote(word, WORD_SHOWN))
}

/// `word` as a number, or an error naming line `line` and the word.
pub(super) fn number(word: &[u8], line: usize) -> Result<f64, ReadError> {
    std::str::from_utf8(word)
        .ok()
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| ReadError::at(line, format!("{} is not a number", shown(word))))
}

/// `word` as an integer, or an error naming line `line` and the word.
pub(super) fn integer(word: &[u8], line: usize) -> Result<i64, ReadError> {
    std::str::from_utf8(word)
        .ok()
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| ReadError::at(line, format!("{} is not an integer", shown(word))))
}

/// The words of a whole text, one after the other, with the line each is on.
pub(super) struct Words<'a> {
    lines: Box<dyn Iterator<Item = (usize, &'a [u8])> + 'a>,
    line: usize,
    rest: &'a [u8],
}

impl<'a> Words<'a> {
    pub(super) fn new(bytes: &'a [u8]) -> Self {
        Words { lines: Box::new(lines(bytes)), line: 0, rest: &[] }
    }

    /// The line of the word last returned (or of the end of the text).
    pub(super) fn line(&self) -> usize {
        self.line
    }

    /// Drops the rest of the current line.
    pub(super) fn skip_line(&mut self) {
        self.rest = &[];
    }

    /// The next word, or `None` at the end of the text.
    pub(super) fn next_word(&mut self) -> Option<&'a [u8]> {
        loop {
            let start = self.rest.iter().position(|b| !b.is_ascii_whitespace());
            if let Some(start) = start {
                let rest = &self.rest[start..];
                let end = rest.iter().position(u8::is_ascii_whitespace).unwrap_or(rest.len());
                self.rest = &rest[end..];
                return Some(&rest[..end]);
            }
            (self.line, self.rest) = self.lines.next()?;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_line_ending_reads_the_same() {
        for text in ["a b\nc\n\nd", "a b\r\nc\r\n\r\nd", "a b\rc\r\rd", "\u{feff}a b\nc\n\nd\n"] {
            let got: Vec<(usize, &[u8])> = lines(text.as_bytes()).collect();
            assert_eq!(got, [(1, &b"a b"[..]), (2, b"c"), (3, b""), (4, b"d")], "{text:?}");
        }
        let mut w = Words::new(b"x  y\r\n\r\n z");
        assert_eq!((w.next_word(), w.line()), (Some(&b"x"[..]), 1));
        assert_eq!((w.next_word(), w.line()), (Some(&b"y"[..]), 1));
        assert_eq!((w.next_word(), w.line()), (Some(&b"z"[..]), 3));
        assert_eq!(w.next_word(), None);
    }

    #[test]
    fn numbers_name_their_line_and_word() {
        assert_eq!(number(b"-1.5e3", 1).unwrap(), -1500.0);
        let e = number(b"thr\x1bee", 7).unwrap_err().to_string();
        assert_eq!(e, "line 7: 'thr\\u{1b}ee' is not a number");
        assert!(integer(b"1.0", 2).is_err());
    }
}
