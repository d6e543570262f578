//! How dressform words a problem: one line per problem, at most [`MAX_LINE`] characters,
//! control characters escaped, long lists cut to their first few items ("and N more"), numbers
//! in a readable precision. Whatever a file or a flag contains, the message stays readable and
//! cannot move the cursor, recolour the terminal or fill the screen.

use std::fmt::{self, Display};

/// The longest line a message may have (characters): two lines of a terminal.
pub const MAX_LINE: usize = 200;

/// The most lines one message may have ("one line per problem"; more are summarised).
pub const MAX_LINES: usize = 20;

/// How many items of a long list a message shows.
pub const LIST_ITEMS: usize = 5;

/// `text` as it may appear inside a message: control and bidirectional-formatting characters
/// escaped (`\n`, `\u{1b}`), invalid UTF-8 shown as `\xNN`, and cut after `max` characters
/// with "...".
pub fn quote(text: &[u8], max: usize) -> String {
    let mut out = String::new();
    let mut shown = 0;
    for chunk in text.utf8_chunks() {
        let invalid = chunk.invalid().iter().map(|b| Piece::Byte(*b));
        for piece in chunk.valid().chars().map(Piece::Char).chain(invalid) {
            if shown == max {
                out.push_str("...");
                return out;
            }
            shown += 1;
            match piece {
                Piece::Char(c) if needs_escape(c) => out.extend(c.escape_default()),
                Piece::Char(c) => out.push(c),
                Piece::Byte(b) => out.push_str(&format!("\\x{b:02x}")),
            }
        }
    }
    out
}

/// How many characters of a path a message shows.
pub const PATH_SHOWN: usize = 120;

/// A path as a message shows it: escaped like [`quote`]; a very long one keeps its start and
/// its end (the file name).
pub fn path(path: &std::path::Path) -> String {
    let text = path.as_os_str().as_encoded_bytes();
    let full = quote(text, usize::MAX);
    let chars: Vec<char> = full.chars().collect();
    if chars.len() <= PATH_SHOWN {
        return full;
    }
    let half = PATH_SHOWN / 2;
    let start: String = chars[..half].iter().collect();
    let end: String = chars[chars.len() - half..].iter().collect();
    format!("{start}...{end}")
}

enum Piece {
    Char(char),
    Byte(u8),
}

/// Control characters, and the invisible ones that reorder or hide text on a terminal.
fn needs_escape(c: char) -> bool {
    c.is_control()
        || matches!(c, '\u{200b}'..='\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

/// The first [`LIST_ITEMS`] of `items`, comma-separated, then "and N more".
pub fn list<T: Display>(items: impl IntoIterator<Item = T>) -> String {
    let mut shown = Vec::new();
    let mut more = 0usize;
    for item in items {
        if shown.len() < LIST_ITEMS {
            shown.push(item.to_string());
        } else {
            more += 1;
        }
    }
    let mut s = shown.join(", ");
    if more > 0 {
        s.push_str(&format!(" and {more} more"));
    }
    s
}

/// A number as a message shows it: up to 6 significant digits, in exponent form when very
/// large or small (`1e300`, not three hundred digits).
pub fn number(x: f64) -> Number {
    Number(x)
}

/// See [`number`].
#[derive(Debug, Clone, Copy)]
pub struct Number(pub f64);

impl Display for Number {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        // Plain notation covers body sizes in any unit, from 0.001 mm to 10 km.
        if x == 0.0 || !x.is_finite() || (1e-3..1e7).contains(&x.abs()) {
            let digits = 5usize.saturating_sub(x.abs().log10().floor().max(0.0) as usize);
            let s = format!("{x:.digits$}");
            let s =
                if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.') } else { &s };
            f.write_str(if s == "-0" { "0" } else { s })
        } else {
            let s = format!("{x:.5e}");
            let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
            let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
            write!(f, "{mantissa}e{exponent}")
        }
    }
}

/// `message` made safe to print: each line escaped (see [`quote`]) and cut to [`MAX_LINE`]
/// characters, at most [`MAX_LINES`] lines. The command line passes every error and warning
/// through this, whatever produced it.
pub fn bounded(message: &str) -> String {
    let lines: Vec<&str> = message.lines().collect();
    let mut out: Vec<String> = lines
        .iter()
        .take(MAX_LINES)
        .map(|line| {
            let chars = line.chars().count();
            let q = quote(line.as_bytes(), MAX_LINE);
            if chars > MAX_LINE { format!("{q} ({} more characters)", chars - MAX_LINE) } else { q }
        })
        .collect();
    if lines.len() > MAX_LINES {
        out.push(format!("... and {} more lines", lines.len() - MAX_LINES));
    }
    out.join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_and_invalid_bytes_are_escaped() {
        assert_eq!(quote(b"act\x1b[31mred", 50), "act\\u{1b}[31mred");
        assert_eq!(quote(b"a\nb\tc", 50), "a\\nb\\tc");
        assert_eq!(quote(b"ok\xff\xfe", 50), "ok\\xff\\xfe");
        assert_eq!(quote("x\u{202e}y".as_bytes(), 50), "x\\u{202e}y");
        assert_eq!(quote(b"abcdef", 3), "abc...");
        assert_eq!(quote("é€".as_bytes(), 50), "é€");
    }

    #[test]
    fn paths_are_escaped_and_keep_their_file_name() {
        assert_eq!(path(std::path::Path::new("a/b\x1b.obj")), "a/b\\u{1b}.obj");
        let long = format!("/{}/scan.ply", "d".repeat(500));
        let shown = path(std::path::Path::new(&long));
        assert!(shown.len() < PATH_SHOWN + 10 && shown.ends_with("d/scan.ply"), "{shown}");
    }

    #[test]
    fn long_lists_show_the_first_few() {
        assert_eq!(list(["a", "b"]), "a, b");
        assert_eq!(list(0..100_000), "0, 1, 2, 3, 4 and 99995 more");
    }

    #[test]
    fn numbers_are_short() {
        let shown: Vec<String> = [0.0, -0.0, 1.7, 1700.0, 1234.56789, 0.0125, 1e300, -2.5e-9, 1e7]
            .map(|x| number(x).to_string())
            .into();
        assert_eq!(
            shown,
            ["0", "0", "1.7", "1700", "1234.57", "0.0125", "1e300", "-2.5e-9", "1e7"]
        );
        assert_eq!(number(f64::NAN).to_string(), "NaN");
        assert_eq!(number(f64::NEG_INFINITY).to_string(), "-inf");
    }

    #[test]
    fn bounded_messages_are_short_escaped_lines() {
        let long = "x".repeat(10_000);
        let b = bounded(&format!("first\u{1b}]0;title\u{7}\n{long}"));
        let lines: Vec<&str> = b.lines().collect();
        assert_eq!(lines[0], "first\\u{1b}]0;title\\u{7}");
        assert!(lines[1].len() < MAX_LINE + 40 && lines[1].ends_with("(9800 more characters)"));
        let many = (0..100).map(|i| i.to_string()).collect::<Vec<_>>().join("\n");
        let b = bounded(&many);
        assert_eq!(b.lines().count(), MAX_LINES + 1);
        assert!(b.ends_with("and 80 more lines"));
    }
}
