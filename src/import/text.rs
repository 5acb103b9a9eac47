//! Text from a file made safe to print: a bone name, a URI or a record name is data, and must neither act on the
//! terminal (`ESC ] 0;…` retitles it, `ESC [2J` clears it), nor break the one line an error takes, nor make a
//! report that XML cannot hold (XML 1.0 forbids most control characters), nor fill a screen.

use std::borrow::Cow;
use std::fmt::Write as _;

/// The most characters of a name from a file that are kept: far beyond any real bone or clip name, short enough
/// for a table row.
pub const NAME_CHARS: usize = 200;

/// `text` with every control character (C0, DEL, C1) escaped as `\x1b` (`\u{9b}` above ASCII), so it prints as the
/// characters it holds and on one line.
pub fn printable(text: &str) -> Cow<'_, str> {
    if !text.chars().any(char::is_control) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        push_escaped(&mut out, c);
    }
    Cow::Owned(out)
}

/// Bytes that should be UTF-8 as printable text: invalid bytes escaped as `\xff`, control characters as in
/// [`printable`].
pub fn printable_bytes(bytes: &[u8]) -> String {
    let mut out = String::with_capacity(bytes.len());
    for chunk in bytes.utf8_chunks() {
        for c in chunk.valid().chars() {
            push_escaped(&mut out, c);
        }
        for byte in chunk.invalid() {
            write!(out, "\\x{byte:02x}").unwrap_or_default();
        }
    }
    out
}

/// A name read from a file as bonescope keeps it: [`printable`], and cut to [`NAME_CHARS`] characters.
pub fn name(text: &str) -> String {
    printable_cut(text, NAME_CHARS)
}

/// [`printable`], cut to `max` characters (marked by a trailing `…`).
pub fn printable_cut(text: &str, max: usize) -> String {
    let printable = printable(text);
    match printable.char_indices().nth(max) {
        None => printable.into_owned(),
        Some((cut, _)) => format!("{}…", &printable[..cut]),
    }
}

fn push_escaped(out: &mut String, c: char) {
    match c as u32 {
        _ if !c.is_control() => out.push(c),
        code @ 0..=0x7f => write!(out, "\\x{code:02x}").unwrap_or_default(),
        code => write!(out, "\\u{{{code:x}}}").unwrap_or_default(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_are_escaped() {
        assert_eq!(printable("plain name é"), "plain name é");
        assert!(matches!(printable("plain"), Cow::Borrowed(_)));
        assert_eq!(
            printable("\u{1b}]0;x\u{7}\u{1b}[2J\0a\nb\r\u{7f}\u{9b}"),
            "\\x1b]0;x\\x07\\x1b[2J\\x00a\\x0ab\\x0d\\x7f\\u{9b}"
        );
    }

    #[test]
    fn invalid_utf8_is_escaped_byte_by_byte() {
        assert_eq!(printable_bytes(b"ok \xff\xfe\x1b[2J \xc3\xa9"), "ok \\xff\\xfe\\x1b[2J é");
    }

    #[test]
    fn names_are_cut_to_a_readable_length() {
        let long = "é".repeat(NAME_CHARS + 10);
        let cut = name(&long);
        assert_eq!(cut.chars().count(), NAME_CHARS + 1);
        assert!(cut.ends_with('…'));
        assert_eq!(name(&"a".repeat(NAME_CHARS)), "a".repeat(NAME_CHARS), "a name of exactly the limit stays whole");
    }
}
