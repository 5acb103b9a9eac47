//! A pose dump written as CSV (see `docs/pose-dump.md`): a header line, the columns' names, then one row per time
//! and bone, every time listing the bones in the first time's order.

use std::io::BufRead;

use glam::DMat4;

use super::{Dump, DumpHeader, Syntax, check_format, choice, first_bad_time};
use crate::import::failure::{Failure, Result};
use crate::model::{Unit, UpAxis};

/// The line of the first row of numbers: after the header line and the columns' names.
pub(super) const FIRST_ROW_LINE: usize = 3;

/// The columns' names, in order.
pub const COLUMNS: [&str; 19] = [
    "time", "bone", "parent", "m0", "m1", "m2", "m3", "m4", "m5", "m6", "m7", "m8", "m9", "m10", "m11", "m12", "m13",
    "m14", "m15",
];

fn on_line(line: usize, message: impl Into<String>) -> Failure {
    Failure::at(format!("line {line}"), message)
}

/// Parses the dump from `reader`, a line at a time.
pub(super) fn read(mut reader: impl BufRead) -> Result<Dump> {
    let mut text = String::new();
    let mut next_line = |text: &mut String| -> Result<bool> {
        text.clear();
        let read = reader.read_line(text).map_err(|e| Failure::whole(format!("cannot read the file: {e}")))?;
        Ok(read > 0)
    };
    next_line(&mut text)?;
    let header = header(text.trim_start_matches('\u{feff}').trim_end()).map_err(|why| on_line(1, why))?;
    next_line(&mut text)?;
    if split(text.trim_end()) != COLUMNS {
        return Err(on_line(2, format!("the columns must be named {}", COLUMNS.join(","))));
    }
    let (mut rows, mut line, mut blank) = (Rows::default(), FIRST_ROW_LINE, None);
    while next_line(&mut text)? {
        // Blank lines may end the file; between rows they would hide which line a time and bone is on.
        if text.trim().is_empty() {
            blank = blank.or(Some(line));
        } else if let Some(blank) = blank {
            return Err(on_line(blank, "an empty line between rows"));
        } else {
            rows.push(&split(text.trim_end()), &header).map_err(|why| on_line(line, why))?;
        }
        line += 1;
    }
    rows.finish(header)
}

/// The header line: `# bonescope-pose-dump 1; space=world; order=column-major`, then optionally `unit=`, `up=`,
/// `clip=` and `source=`, each pair after a `;` (values may hold spaces, not `;`).
fn header(line: &str) -> std::result::Result<DumpHeader, String> {
    let rest = line.strip_prefix('#').unwrap_or(line);
    let mut parts = rest.split(';').map(str::trim);
    let mut words = parts.next().unwrap_or_default().split_whitespace();
    let (format, version) = (words.next().unwrap_or_default(), words.next().unwrap_or_default());
    let version = version.parse().map_err(|_| format!("`{version}` is not a version number"))?;
    check_format(format, version)?;
    let mut header = DumpHeader::default();
    let (mut space, mut order) = (false, false);
    for part in parts.filter(|p| !p.is_empty()) {
        let (key, value) = part.split_once('=').ok_or_else(|| format!("`{part}` is not key=value"))?;
        let value = value.trim();
        match key.trim() {
            "space" => (header.space, space) = (choice(value, "the space")?, true),
            "order" => (header.order, order) = (choice(value, "the order")?, true),
            "unit" => header.unit = Some(value.parse::<Unit>().map_err(|e| e.to_string())?),
            "up" => header.up = Some(choice::<UpAxis>(value, "the up axis")?),
            "clip" => header.clip = Some(value.to_owned()),
            "source" => header.source = Some(value.to_owned()),
            key => return Err(format!("unknown key `{key}` (expected space, order, unit, up, clip, source)")),
        }
    }
    if !(space && order) {
        return Err("the header must state space= and order=".to_owned());
    }
    Ok(header)
}

/// The fields of a CSV row: split at commas, a field in double quotes keeping its commas (`""` is a quote).
fn split(row: &str) -> Vec<String> {
    let mut fields = vec![String::new()];
    let (mut quoted, mut chars) = (false, row.chars().peekable());
    while let Some(c) = chars.next() {
        let field = fields.last_mut().expect("one field at least");
        match c {
            '"' if quoted && chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            '"' => quoted = !quoted,
            ',' if !quoted => fields.push(String::new()),
            c => field.push(c),
        }
    }
    fields
}

/// The rows read so far, grouped by time.
#[derive(Default)]
struct Rows {
    bones: Vec<(String, Option<String>)>,
    times: Vec<f64>,
    frames: Vec<Vec<DMat4>>,
}

impl Rows {
    /// Adds the row `fields` on `line`.
    fn push(&mut self, fields: &[String], header: &DumpHeader) -> std::result::Result<(), String> {
        if fields.len() != COLUMNS.len() {
            return Err(format!("{} fields, expected 19 (time, bone, parent and 16 numbers)", fields.len()));
        }
        let number = |i: usize| {
            let text = fields[i].trim();
            text.parse::<f64>().map_err(|_| format!("{}: `{text}` is not a number", COLUMNS[i]))
        };
        let time = number(0)?;
        if !time.is_finite() {
            return Err(format!("the time {time} is not finite"));
        }
        let mut numbers = [0.0; 16];
        for (k, n) in numbers.iter_mut().enumerate() {
            *n = number(3 + k)?;
        }
        let (name, parent) = (fields[1].as_str(), Some(fields[2].as_str()).filter(|p| !p.is_empty()));
        if self.times.last() != Some(&time) {
            self.close_frame()?;
            self.times.push(time);
            self.frames.push(Vec::with_capacity(self.bones.len()));
        }
        let (first_time, frame) = (self.times.len() == 1, self.frames.last_mut().expect("a frame was opened"));
        if first_time {
            self.bones.push((name.to_owned(), parent.map(str::to_owned)));
        } else {
            let Some((expected, expected_parent)) = self.bones.get(frame.len()) else {
                return Err(format!("time {time} lists more bones than the first time ({})", self.bones.len()));
            };
            if expected != name || expected_parent.as_deref() != parent {
                return Err(format!(
                    "bone `{name}` (parent `{}`) where the first time has `{expected}` (parent `{}`): every time \
                     lists the bones, with their parents, in the first time's order",
                    parent.unwrap_or_default(),
                    expected_parent.as_deref().unwrap_or_default()
                ));
            }
        }
        frame.push(header.order.matrix(&numbers));
        Ok(())
    }

    /// Checks that the time just read listed every bone.
    fn close_frame(&self) -> std::result::Result<(), String> {
        match self.frames.last() {
            Some(frame) if frame.len() != self.bones.len() => Err(format!(
                "the time before ({}) lists {} bones, the first time {}",
                self.times.last().copied().unwrap_or_default(),
                frame.len(),
                self.bones.len()
            )),
            _ => Ok(()),
        }
    }

    fn finish(self, header: DumpHeader) -> Result<Dump> {
        let line_of = |t: usize| FIRST_ROW_LINE + t * self.bones.len();
        self.close_frame().map_err(|why| on_line(line_of(self.times.len().saturating_sub(1)), why))?;
        if self.bones.is_empty() {
            return Err(Failure::whole("a pose dump needs at least one bone and one time"));
        }
        if let Some((t, why)) = first_bad_time(&self.times) {
            return Err(on_line(line_of(t), why));
        }
        let Rows { bones, times, frames } = self;
        Ok(Dump { header, bones, times, frames, syntax: Syntax::Csv })
    }
}
