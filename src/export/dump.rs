//! Writing a pose dump (`docs/pose-dump.md`) a time at a time: what `inspect --format dump` writes of bonescope's
//! own evaluation, so that a dump reads back as the rig it came from, and a runtime's can be checked against it.
//!
//! Numbers are written in Rust's shortest round-trip form, so a dump read back gives the very `f64`s written.

use std::io::{self, Write};

use glam::DMat4;

use crate::import::dump::{CSV_COLUMNS, DumpHeader, FORMAT_ID, Syntax, VERSION};
use crate::model::{Choice, Skeleton};

/// A pose dump being written: the header and bones first ([`DumpWriter::new`]), then one time after another
/// ([`DumpWriter::frame`]), then [`DumpWriter::finish`].
pub struct DumpWriter<'s, W: Write> {
    out: W,
    syntax: Syntax,
    header: DumpHeader,
    skeleton: &'s Skeleton,
    frames: usize,
}

impl<'s, W: Write> DumpWriter<'s, W> {
    /// Writes the header and the bones of `skeleton` (refused where two bones share a name: a dump pairs by name).
    pub fn new(mut out: W, syntax: Syntax, header: DumpHeader, skeleton: &'s Skeleton) -> io::Result<Self> {
        let names = skeleton.bones().iter().map(|b| b.name.as_str());
        if let Some(name) = repeated(names) {
            let message = format!("two bones are named `{name}`: a pose dump names each bone once");
            return Err(io::Error::new(io::ErrorKind::InvalidData, message));
        }
        match syntax {
            Syntax::Json => json_head(&mut out, &header, skeleton)?,
            Syntax::Csv => csv_head(&mut out, &header)?,
        }
        Ok(DumpWriter { out, syntax, header, skeleton, frames: 0 })
    }

    /// Writes the matrices of every bone at `time` (one per bone, in bone order; times increasing).
    pub fn frame(&mut self, time: f64, matrices: &[DMat4]) -> io::Result<()> {
        let finite = time.is_finite() && matrices.iter().all(DMat4::is_finite);
        if !finite || matrices.len() != self.skeleton.len() {
            let message = format!("the pose at t = {time} is not finite, or not one matrix per bone");
            return Err(io::Error::new(io::ErrorKind::InvalidData, message));
        }
        let numbers = |m: &DMat4| self.header.order.numbers(m).map(|n| format!("{n:?}")).join(",");
        match self.syntax {
            Syntax::Json => {
                let separator = if self.frames == 0 { "" } else { "," };
                write!(self.out, "{separator}\n  {{\"time\": {time:?}, \"matrices\": [")?;
                for (i, m) in matrices.iter().enumerate() {
                    write!(self.out, "{}[{}]", if i == 0 { "" } else { ", " }, numbers(m))?;
                }
                write!(self.out, "]}}")?;
            }
            Syntax::Csv => {
                for (bone, m) in self.skeleton.bones().iter().zip(matrices) {
                    let parent = bone.parent.map_or("", |p| self.skeleton.bone(p).name.as_str());
                    writeln!(self.out, "{time:?},{},{},{}", csv_field(&bone.name), csv_field(parent), numbers(m))?;
                }
            }
        }
        self.frames += 1;
        Ok(())
    }

    /// Ends the document; the writer back.
    pub fn finish(mut self) -> io::Result<W> {
        if self.syntax == Syntax::Json {
            writeln!(self.out, "\n]}}")?;
        }
        Ok(self.out)
    }
}

/// The JSON document up to its first frame.
fn json_head(out: &mut impl Write, header: &DumpHeader, skeleton: &Skeleton) -> io::Result<()> {
    let quoted = |text: &str| serde_json::to_string(text).unwrap_or_default();
    write!(out, "{{\"format\": \"{FORMAT_ID}\", \"version\": {VERSION}, ")?;
    write!(out, "\"space\": \"{}\", \"order\": \"{}\"", header.space.id(), header.order.id())?;
    if let Some(unit) = header.unit {
        write!(out, ", \"unit\": {:?}", unit.in_metres())?;
    }
    if let Some(up) = header.up {
        write!(out, ", \"up\": \"{}\"", up.id())?;
    }
    if let Some(clip) = &header.clip {
        write!(out, ", \"clip\": {}", quoted(clip))?;
    }
    if let Some(source) = &header.source {
        write!(out, ", \"source\": {}", quoted(source))?;
    }
    write!(out, ",\n\"bones\": [")?;
    for (i, bone) in skeleton.bones().iter().enumerate() {
        let parent = bone.parent.map_or_else(|| "null".to_owned(), |p| quoted(&skeleton.bone(p).name));
        let separator = if i == 0 { "" } else { "," };
        write!(out, "{separator}\n  {{\"name\": {}, \"parent\": {parent}}}", quoted(&bone.name))?;
    }
    write!(out, "\n],\n\"frames\": [")
}

/// The CSV header line and the columns' names.
fn csv_head(out: &mut impl Write, header: &DumpHeader) -> io::Result<()> {
    write!(out, "# {FORMAT_ID} {VERSION}; space={}; order={}", header.space.id(), header.order.id())?;
    if let Some(unit) = header.unit {
        write!(out, "; unit={:?}", unit.in_metres())?;
    }
    if let Some(up) = header.up {
        write!(out, "; up={}", up.id())?;
    }
    for (key, value) in [("clip", &header.clip), ("source", &header.source)] {
        if let Some(value) = value {
            // A `;` would start another pair, a line break end the header.
            write!(out, "; {key}={}", value.replace(';', ",").replace(['\r', '\n'], " "))?;
        }
    }
    writeln!(out, "\n{}", CSV_COLUMNS.join(","))
}

/// A CSV field, quoted where it holds a comma, a quote or a line break.
fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n', '\r']) { format!("\"{}\"", text.replace('"', "\"\"")) } else { text.to_owned() }
}

/// The first name that comes twice.
fn repeated<'a>(names: impl Iterator<Item = &'a str>) -> Option<&'a str> {
    let mut seen = std::collections::HashSet::new();
    names.into_iter().find(|name| !seen.insert(*name))
}
