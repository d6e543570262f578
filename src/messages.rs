//! How dressform words a problem: one line per problem, at most [`MAX_LINE`] characters,
//! control characters escaped, long lists cut after an item ("a, b and N more"), numbers
//! short (`1e308`). Whatever a file or a flag contains, the message stays readable and
//! cannot move the cursor, recolour the terminal or fill the screen.

use std::fmt::Display;

/// The longest line a message may have (characters): four lines of a terminal, room for a
/// long path, what was seen and what to do (a measurement held back and why, a stance and the
/// command that takes it); anything longer is an echo of a file's content, cut.
pub const MAX_LINE: usize = 400;

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

/// How many characters a list may take in a message: [`MAX_LINE`] less room for what the
/// message says before it (a file name, a lead-in such as "positions outside the stroke: ").
pub const LIST_CHARS: usize = 130;

/// `items` for a message, comma-separated (see [`separated`]): `a, b, c and 7 more`.
pub fn list<T: Display>(items: impl IntoIterator<Item = T>) -> String {
    separated(items, ", ")
}

/// The first items of `items` joined by `separator`: at most [`LIST_ITEMS`], and no more
/// than fit in [`LIST_CHARS`] (the first always shows), then "and N more" for the rest. A
/// long list ends at an item, never in the middle of one.
pub fn separated<T: Display>(items: impl IntoIterator<Item = T>, separator: &str) -> String {
    let mut shown = String::new();
    let (mut count, mut chars, mut more) = (0, 0, 0usize);
    for item in items {
        if more == 0 && count < LIST_ITEMS {
            let item = item.to_string();
            let sep = if count == 0 { "" } else { separator };
            let width = sep.chars().count() + item.chars().count();
            if count == 0 || chars + width <= LIST_CHARS {
                shown.push_str(sep);
                shown.push_str(&item);
                (count, chars) = (count + 1, chars + width);
                continue;
            }
        }
        more += 1;
    }
    if more > 0 {
        shown.push_str(&format!(" and {more} more"));
    }
    shown
}

/// Numbers as messages show them (`1e308`, not 309 digits): the one formatter of the workspace,
/// in the lowest crate whose messages echo numbers from files (form descriptions).
pub use form_description::{Number, number};

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
        assert_eq!(separated(["a, b", "c"], "; "), "a, b; c");
    }

    #[test]
    fn long_items_end_the_list_at_an_item() {
        let items: Vec<String> = (0..30).map(|i| format!("ring-{i} (1234567 mm wanted)")).collect();
        let shown = list(&items);
        assert_eq!(
            shown,
            format!("{}, {}, {}, {} and 26 more", items[0], items[1], items[2], items[3])
        );
        assert!(shown.chars().count() <= LIST_CHARS + " and 26 more".len());
        // One item longer than the budget still shows, whole.
        let long = "x".repeat(LIST_CHARS + 10);
        assert_eq!(list([long.as_str(), "y"]), format!("{long} and 1 more"));
    }

    #[test]
    fn bounded_messages_are_short_escaped_lines() {
        let long = "x".repeat(10_000);
        let b = bounded(&format!("first\u{1b}]0;title\u{7}\n{long}"));
        let lines: Vec<&str> = b.lines().collect();
        assert_eq!(lines[0], "first\\u{1b}]0;title\\u{7}");
        assert!(lines[1].len() < MAX_LINE + 40 && lines[1].ends_with("(9600 more characters)"));
        let many = (0..100).map(|i| i.to_string()).collect::<Vec<_>>().join("\n");
        let b = bounded(&many);
        assert_eq!(b.lines().count(), MAX_LINES + 1);
        assert!(b.ends_with("and 80 more lines"));
    }
}
