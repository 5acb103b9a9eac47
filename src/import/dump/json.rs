//! A pose dump written as one JSON document (see `docs/pose-dump.md`).

use std::io::BufRead;

use glam::DMat4;

use super::{Dump, DumpHeader, MatrixOrder, Syntax, check_format, choice, first_bad_time};
use crate::import::failure::{Failure, Result};
use crate::model::{Unit, UnknownUnit, UpAxis};

/// The document as serde reads it.
#[derive(serde::Deserialize)]
struct Document {
    format: String,
    version: u32,
    space: String,
    order: String,
    #[serde(default)]
    unit: Option<UnitValue>,
    #[serde(default)]
    up: Option<String>,
    #[serde(default)]
    clip: Option<String>,
    #[serde(default)]
    source: Option<String>,
    bones: Vec<DumpBone>,
    frames: Vec<Frame>,
}

/// A unit as a length in metres (`0.01`) or by id (`"cm"`).
#[derive(serde::Deserialize)]
#[serde(untagged)]
enum UnitValue {
    Metres(f64),
    Named(String),
}

#[derive(serde::Deserialize)]
struct DumpBone {
    name: String,
    #[serde(default)]
    parent: Option<String>,
}

#[derive(serde::Deserialize)]
struct Frame {
    time: f64,
    matrices: Vec<[f64; 16]>,
}

/// Parses the document from `reader` (streamed: the file is never held whole).
pub(super) fn read(reader: impl BufRead) -> Result<Dump> {
    let mut deserializer = serde_json::Deserializer::from_reader(reader);
    let document: Document = serde_path_to_error::deserialize(&mut deserializer).map_err(|e| {
        let place = e.path().to_string();
        let message = e.into_inner().to_string();
        if place == "." { Failure::whole(message) } else { Failure::at(place, message) }
    })?;
    dump(document)
}

/// The dump the document describes, its header and shape checked.
fn dump(document: Document) -> Result<Dump> {
    check_format(&document.format, document.version).map_err(|why| Failure::at("format", why))?;
    let header = header(&document)?;
    if document.bones.is_empty() || document.frames.is_empty() {
        return Err(Failure::whole("a pose dump needs at least one bone and one frame"));
    }
    let times: Vec<f64> = document.frames.iter().map(|f| f.time).collect();
    if let Some((i, why)) = first_bad_time(&times) {
        return Err(Failure::at(format!("frames[{i}].time"), why));
    }
    let bones: Vec<(String, Option<String>)> = document.bones.into_iter().map(|b| (b.name, b.parent)).collect();
    let mut frames = Vec::with_capacity(document.frames.len());
    for (t, frame) in document.frames.into_iter().enumerate() {
        if frame.matrices.len() != bones.len() {
            let (count, expected) = (frame.matrices.len(), bones.len());
            return Err(Failure::at(format!("frames[{t}].matrices"), format!("{count} matrices for {expected} bones")));
        }
        frames.push(frame.matrices.iter().map(|numbers| header.order.matrix(numbers)).collect::<Vec<DMat4>>());
    }
    Ok(Dump { header, bones, times, frames, syntax: Syntax::Json })
}

/// The header members, parsed.
fn header(document: &Document) -> Result<DumpHeader> {
    let space = choice(&document.space, "the space").map_err(|why| Failure::at("space", why))?;
    let order = choice::<MatrixOrder>(&document.order, "the order").map_err(|why| Failure::at("order", why))?;
    let unit = match &document.unit {
        None => None,
        Some(UnitValue::Metres(metres)) => Some(Unit::metres(*metres).ok_or_else(|| UnknownUnit(metres.to_string()))),
        Some(UnitValue::Named(name)) => Some(name.parse::<Unit>()),
    };
    let unit = unit.transpose().map_err(|e| Failure::at("unit", e.to_string()))?;
    let up = document.up.as_deref().map(|up| choice::<UpAxis>(up, "the up axis")).transpose();
    let up = up.map_err(|why| Failure::at("up", why))?;
    Ok(DumpHeader { space, order, unit, up, clip: document.clip.clone(), source: document.source.clone() })
}
