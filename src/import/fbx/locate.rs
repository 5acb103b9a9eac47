//! Where a broken FBX file breaks, for error messages.
//!
//! ufbx says what went wrong ("Truncated file") but, as built by its crate, not where. When it fails, this module
//! walks the file's structure itself, without allocating more than the nesting depth: binary node records (each
//! states where it ends; arrays state their sizes) or ASCII braces. The first record that overruns the file or its
//! parent, or the block the text ends in, is the place. Nothing found (a file broken inside a value) means no place.

/// Where the structure of `bytes` first breaks, if it visibly does.
pub(super) fn locate(bytes: &[u8]) -> Option<String> {
    if bytes.starts_with(super::BINARY_MAGIC) { binary(bytes) } else { ascii(bytes) }
}

/// Little-endian integer of `width` bytes at `pos`, if the file holds it.
fn int(bytes: &[u8], pos: usize, width: usize) -> Option<u64> {
    let slice = bytes.get(pos..pos.checked_add(width)?)?;
    Some(slice.iter().rev().fold(0u64, |acc, &b| (acc << 8) | u64::from(b)))
}

/// An open record: where it ends (the file's end for a record that claims more), its name, what it claims.
struct Open {
    end: u64,
    name: String,
    claimed_end: u64,
}

/// The names of the open records, outermost first, then `name`, for messages; a path deeper than a reader can
/// take in keeps its outermost and innermost names and counts the ones between.
fn path(stack: &[Open], name: &str) -> String {
    const OUTER: usize = 3;
    const INNER: usize = 3;
    let mut parts: Vec<&str> = stack.iter().map(|o| o.name.as_str()).collect();
    parts.push(name);
    if parts.len() <= OUTER + INNER {
        return parts.join(" > ");
    }
    let (outer, inner) = (parts[..OUTER].join(" > "), parts[parts.len() - INNER..].join(" > "));
    format!("{outer} > ({} more) > {inner}", parts.len() - OUTER - INNER)
}

/// How deep ufbx reads nested records or blocks.
const MAX_DEPTH: usize = 32;

fn binary(bytes: &[u8]) -> Option<String> {
    const HEADER: u64 = 27;
    let Some(version) = int(bytes, 23, 4) else {
        return Some(format!("byte {}: the file ends inside the 27-byte header", bytes.len()));
    };
    let width = if version >= 7500 { 8 } else { 4 };
    let mut walk = Walk { bytes, width, pos: HEADER, stack: Vec::new() };
    loop {
        if let Err(problem) = walk.leave_finished() {
            return Some(problem);
        }
        match walk.record() {
            Ok(true) => {}
            Ok(false) => return None,
            Err(problem) => return Some(problem),
        }
    }
}

/// A walk through a binary file's records: where it is, and the records it is inside.
struct Walk<'b> {
    bytes: &'b [u8],
    /// The width of a record header's integers: 8 bytes from version 7500, else 4.
    width: usize,
    pos: u64,
    stack: Vec<Open>,
}

impl Walk<'_> {
    fn len(&self) -> u64 {
        self.bytes.len() as u64
    }

    /// Leaves the records that end where the walk is; one that ends inside its last child, or past the file's end,
    /// is the problem.
    fn leave_finished(&mut self) -> Result<(), String> {
        let len = self.len();
        while let Some(open) = self.stack.last() {
            if self.pos < open.end {
                break;
            }
            let outer = &self.stack[..self.stack.len() - 1];
            if open.claimed_end > len {
                let (here, claimed) = (path(outer, &open.name), open.claimed_end);
                return Err(format!(
                    "byte {len}: the file ends inside node `{here}`, which claims to end at byte {claimed}"
                ));
            }
            if self.pos > open.end {
                return Err(format!(
                    "byte {}: node `{}` ends inside its last child",
                    open.end,
                    path(outer, &open.name)
                ));
            }
            self.stack.pop();
        }
        Ok(())
    }

    /// Reads the record where the walk is: a null record closes a list of children (`false` at the top level: the
    /// end of the nodes), any other is checked and entered.
    fn record(&mut self) -> Result<bool, String> {
        let (at, width, len) = (self.pos as usize, self.width, self.len());
        let (Some(end), Some(count), Some(list_len), Some(name_len)) = (
            int(self.bytes, at, width),
            int(self.bytes, at + width, width),
            int(self.bytes, at + 2 * width, width),
            int(self.bytes, at + 3 * width, 1),
        ) else {
            return Err(match self.stack.split_last() {
                Some((open, outer)) => format!("byte {len}: the file ends inside node `{}`", path(outer, &open.name)),
                None => format!("byte {len}: the file ends before the end of the top-level node list"),
            });
        };
        let header = (3 * width + 1) as u64;
        if end == 0 && count == 0 && list_len == 0 && name_len == 0 {
            self.pos += header;
            return Ok(!self.stack.is_empty());
        }
        let name_start = self.pos + header;
        let name = self
            .bytes
            .get(name_start as usize..(name_start + name_len) as usize)
            .map(crate::import::text::printable_bytes)
            .unwrap_or_else(|| "(name cut off)".to_owned());
        self.enter(Record { end, count, list_len, properties: name_start + name_len, name })?;
        Ok(true)
    }

    /// Checks a record's extent and properties against its parent and the file, and enters its children.
    fn enter(&mut self, record: Record) -> Result<(), String> {
        let (pos, len, Record { end, count, list_len, properties, name }) = (self.pos, self.len(), record);
        // Only a message needs the path: built per record, it made a deep file's walk quadratic.
        let here = || path(&self.stack, &name);
        if let Some(parent) = self.stack.last()
            && end > parent.claimed_end
        {
            let parent_end = parent.claimed_end;
            return Err(format!(
                "byte {pos}: node `{}` ends at byte {end}, after its parent (byte {parent_end})",
                here()
            ));
        }
        if end < properties {
            return Err(format!("byte {pos}: node `{}` claims to end at byte {end}, inside its own header", here()));
        }
        // A record that claims more than the file holds is walked up to the file's end: the innermost one is the place.
        let reachable = end.min(len);
        let Some(children) = properties.checked_add(list_len).filter(|&c| c <= reachable) else {
            if end > len {
                return Err(format!("byte {len}: the file ends inside the properties of node `{}`", here()));
            }
            return Err(format!(
                "byte {pos}: node `{}` has {list_len} bytes of properties, more than fit before its end (byte {end})",
                here()
            ));
        };
        if let Some(problem) = check_properties(self.bytes, properties, children, count) {
            return Err(format!("node `{}`: {problem}", here()));
        }
        if self.stack.len() == MAX_DEPTH {
            return Err(format!("byte {pos}: node `{}` is nested deeper than FBX readers go ({MAX_DEPTH})", here()));
        }
        self.pos = children;
        self.stack.push(Open { end: reachable, name, claimed_end: end });
        Ok(())
    }
}

/// A record's header, as read.
struct Record {
    /// Where it claims to end.
    end: u64,
    /// How many properties it has, in how many bytes, from where.
    count: u64,
    list_len: u64,
    properties: u64,
    name: String,
}

/// Checks that `count` properties fit between `start` and `end`, array sizes included.
fn check_properties(bytes: &[u8], start: u64, end: u64, count: u64) -> Option<String> {
    let mut pos = start;
    for index in 0..count {
        if pos >= end {
            return Some(format!("byte {pos}: property {index} of {count} starts past the property list"));
        }
        let at = pos as usize;
        let code = *bytes.get(at)?;
        let size: u64 = match code {
            b'C' | b'B' => 1,
            b'Y' => 2,
            b'I' | b'F' => 4,
            b'D' | b'L' => 8,
            b'S' | b'R' => 4 + int(bytes, at + 1, 4)?,
            b'f' | b'i' => array(bytes, at, 4)?,
            b'd' | b'l' => array(bytes, at, 8)?,
            b'b' | b'c' => array(bytes, at, 1)?,
            other => return Some(format!("byte {pos}: unknown property type {:?}", other as char)),
        };
        pos = pos.saturating_add(1).saturating_add(size);
        if pos > end {
            let kind = code as char;
            return Some(format!(
                "property {index} (type {kind}) needs {size} bytes, more than the node holds (up to byte {end})"
            ));
        }
    }
    None
}

/// The bytes an array property takes after its type code: the 12-byte header and its (compressed) data.
fn array(bytes: &[u8], at: usize, element: u64) -> Option<u64> {
    let length = int(bytes, at + 1, 4)?;
    let encoding = int(bytes, at + 5, 4)?;
    let stored = int(bytes, at + 9, 4)?;
    // Uncompressed data must be exactly `length` elements; a claim that cannot match is the overrun to report.
    let data = if encoding == 0 { length.saturating_mul(element).max(stored) } else { stored };
    Some(12 + data)
}

/// Where the blocks of an ASCII file first fail to balance: a `}` without its `{`, or the end inside a block or a
/// string.
pub(super) fn ascii(bytes: &[u8]) -> Option<String> {
    let mut line = 1usize;
    // Open blocks: the key before the `{` and the line it is on.
    let mut stack: Vec<(String, usize)> = Vec::new();
    let mut key = String::new();
    let mut word = String::new();
    let mut i = 0;
    while i < bytes.len() {
        let b = bytes[i];
        match b {
            b'\n' => {
                line += 1;
                key.clear();
                word.clear();
            }
            b';' => {
                while i < bytes.len() && bytes[i] != b'\n' {
                    i += 1;
                }
                continue;
            }
            b'"' => {
                let start = line;
                i += 1;
                while i < bytes.len() && bytes[i] != b'"' {
                    line += usize::from(bytes[i] == b'\n');
                    i += 1;
                }
                if i >= bytes.len() {
                    return Some(format!("line {start}: a string that never ends"));
                }
            }
            b':' => key = std::mem::take(&mut word),
            b'{' if stack.len() == MAX_DEPTH => {
                return Some(format!("line {line}: blocks nested deeper than FBX readers go ({MAX_DEPTH})"));
            }
            b'{' => stack.push((std::mem::take(&mut key), line)),
            b'}' => {
                if stack.pop().is_none() {
                    return Some(format!("line {line}: `}}` without a `{{`"));
                }
            }
            b if b.is_ascii_alphanumeric() || b == b'_' => word.push(b as char),
            _ => word.clear(),
        }
        i += 1;
    }
    let (name, opened) = stack.last()?;
    let name = if name.is_empty() { "a block".to_owned() } else { format!("`{name}`") };
    Some(format!("line {line}: the file ends inside {name} (opened on line {opened}, {} blocks deep)", stack.len()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_places() {
        assert_eq!(ascii(b"; comment {\nA: {\n  B: 1 {\n}\n}\n"), None);
        assert_eq!(
            ascii(b"Objects:  {\n\tModel: 1, \"x{\" {\n"),
            Some("line 3: the file ends inside `Model` (opened on line 2, 2 blocks deep)".to_owned())
        );
        assert_eq!(ascii(b"A: {\n}\n}\n"), Some("line 3: `}` without a `{`".to_owned()));
        assert_eq!(ascii(b"A: \"abc\n"), Some("line 1: a string that never ends".to_owned()));
    }

    /// A binary FBX 7.4 record: end offset, property count, property bytes, name, properties, children.
    fn record(start: usize, name: &str, properties: &[u8], count: u32, children: &[u8]) -> Vec<u8> {
        let end = start + 13 + name.len() + properties.len() + children.len();
        let mut r = Vec::new();
        r.extend((end as u32).to_le_bytes());
        r.extend(count.to_le_bytes());
        r.extend((properties.len() as u32).to_le_bytes());
        r.push(name.len() as u8);
        r.extend(name.as_bytes());
        r.extend(properties);
        r.extend(children);
        r
    }

    fn file(records: &[u8]) -> Vec<u8> {
        let mut f = b"Kaydara FBX Binary  \0\x1a\0".to_vec();
        f.extend(7400u32.to_le_bytes());
        f.extend(records);
        f.extend([0u8; 13]);
        f
    }

    #[test]
    fn binary_places() {
        // One record `A` with an i32 property and an array of 2 doubles.
        let mut props = vec![b'I', 7, 0, 0, 0, b'd'];
        props.extend(2u32.to_le_bytes());
        props.extend(0u32.to_le_bytes());
        props.extend(16u32.to_le_bytes());
        props.extend([0u8; 16]);
        let good = file(&record(27, "A", &props, 2, &[]));
        assert_eq!(binary(&good), None);
        // Cut inside the array.
        let cut = &good[..good.len() - 20];
        assert!(binary(cut).unwrap().contains("the file ends inside the properties of node `A`"), "{:?}", binary(cut));
        // An array claiming 2³² − 1 doubles.
        let mut huge = good.clone();
        let at = 27 + 13 + 1 + 5 + 1;
        huge[at..at + 4].copy_from_slice(&u32::MAX.to_le_bytes());
        assert!(binary(&huge).unwrap().contains("property 1 (type d) needs 34359738372 bytes"), "{:?}", binary(&huge));
        assert!(binary(&good[..20]).unwrap().contains("header"));
    }
}
