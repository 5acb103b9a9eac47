//! BVH motion capture (Biovision Hierarchy), read by hand: no well-kept crate exists.
//!
//! The hierarchy is read line by line (`ROOT`/`JOINT` name, `{`, `OFFSET x y z`, `CHANNELS n …`, `End Site`, `}`,
//! keywords in any case, several roots allowed), then `MOTION`, `Frames:`, `Frame Time:` and one line of numbers per
//! frame. Lines may end in LF, CRLF or CR; spaces and tabs separate tokens, as many as a file likes.
//!
//! What the numbers mean (the usual reading, the one Blender's exporter and importer agree on):
//! - a joint's local transform is `T(translation)·R`, with the translation its `OFFSET`, except for the components a
//!   position channel names, which the channel replaces (Blender writes `offset + location` there);
//! - rotation channels are Euler angles in degrees composed in the order the channels are listed, intrinsically:
//!   `Zrotation Xrotation Yrotation` is `R = Rz·Rx·Ry`; position and rotation channels may be interleaved;
//! - an `End Site` becomes a bone named `<parent>_end` with its offset as translation and no channels, in the role of
//!   an end site (the tip of its parent's bone);
//! - frame `k` is at `k · Frame Time` seconds (the frame time is kept at full precision), one LINEAR key per frame.
//!
//! Hostile files: counts are checked against what the file holds (a header claiming 2³² frames fails at the end of
//! the file, having allocated no more than the file's numbers need), there is no recursion, and every error names
//! the line.

use std::path::Path;
use std::sync::Arc;

use glam::{DQuat, DVec3, Quat, Vec3};

use super::failure::{Failure, Result};
use super::{ImportError, budget, text};
use crate::model::{Bone, BoneTracks, Clip, InheritMode, Interpolation, NodeRole, Rig, Skeleton, Track, Transform};

/// Reads a BVH file whose bytes are in memory.
pub fn load(path: &Path, bytes: &[u8]) -> std::result::Result<Rig, ImportError> {
    read(bytes).map_err(|f| f.with_path(path))
}

/// A problem on one line.
fn on_line(line: usize, message: impl Into<String>) -> Failure {
    Failure::at(format!("line {line}"), message)
}

/// One degree of freedom a joint reads from each frame.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Channel {
    Position(usize),
    Rotation(usize),
}

impl Channel {
    fn parse(name: &str) -> Option<Channel> {
        let name = name.to_ascii_lowercase();
        let (axis, kind) = name.split_at_checked(1)?;
        let axis = match axis {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return None,
        };
        match kind {
            "position" => Some(Channel::Position(axis)),
            "rotation" => Some(Channel::Rotation(axis)),
            _ => None,
        }
    }

    fn name(self) -> String {
        let (axis, kind) = match self {
            Channel::Position(a) => (a, "position"),
            Channel::Rotation(a) => (a, "rotation"),
        };
        format!("{}{kind}", ["X", "Y", "Z"][axis])
    }
}

/// A joint or end site as the hierarchy declares it.
#[derive(Debug)]
struct Joint {
    name: String,
    parent: Option<usize>,
    /// `None` until the `OFFSET` line.
    offset: Option<DVec3>,
    channels: Vec<Channel>,
    end_site: bool,
    /// Where the joint was declared, for messages.
    line: usize,
}

impl Joint {
    fn has_rotation(&self) -> bool {
        self.channels.iter().any(|c| matches!(c, Channel::Rotation(_)))
    }

    fn has_position(&self) -> bool {
        self.channels.iter().any(|c| matches!(c, Channel::Position(_)))
    }

    /// The local translation and rotation for this joint's slice of one frame (degrees for rotations).
    fn pose(&self, offset: DVec3, values: &[f64]) -> (DVec3, DQuat) {
        let mut translation = offset;
        let mut rotation = DQuat::IDENTITY;
        for (&channel, &value) in self.channels.iter().zip(values) {
            match channel {
                Channel::Position(axis) => translation[axis] = value,
                Channel::Rotation(axis) => {
                    let angle = value.to_radians();
                    let step = match axis {
                        0 => DQuat::from_rotation_x(angle),
                        1 => DQuat::from_rotation_y(angle),
                        _ => DQuat::from_rotation_z(angle),
                    };
                    // Intrinsic: each later channel turns about the axes already turned.
                    rotation *= step;
                }
            }
        }
        (translation, rotation)
    }
}

/// Lines of the file, numbered from 1, ending at LF, CRLF or a lone CR.
struct Lines<'a> {
    text: &'a [u8],
    number: usize,
}

impl<'a> Iterator for Lines<'a> {
    type Item = (usize, &'a [u8]);

    fn next(&mut self) -> Option<Self::Item> {
        if self.text.is_empty() {
            return None;
        }
        self.number += 1;
        let end = self.text.iter().position(|&b| b == b'\n' || b == b'\r').unwrap_or(self.text.len());
        let line = &self.text[..end];
        let mut rest = &self.text[end..];
        if rest.starts_with(b"\r\n") {
            rest = &rest[2..];
        } else if !rest.is_empty() {
            rest = &rest[1..];
        }
        self.text = rest;
        Some((self.number, line))
    }
}

/// The whitespace-separated words of a line, printable (invalid UTF-8 and control characters escaped: names and
/// keywords are echoed in notes and errors).
fn words(line: &[u8]) -> Vec<String> {
    line.split(u8::is_ascii_whitespace).filter(|w| !w.is_empty()).map(text::printable_bytes).collect()
}

fn number(word: &str, line: usize, what: &str) -> Result<f64> {
    match word.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(on_line(line, format!("{what}: `{word}` is not a finite number"))),
    }
}

fn read(bytes: &[u8]) -> Result<Rig> {
    let text = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    check_declared_joints(text)?;
    let mut lines = Lines { text, number: 0 };
    let joints = read_hierarchy(&mut lines)?;
    let (frames, frame_time, header_line) = read_motion_header(&mut lines)?;
    check_budget(&joints, frames, lines.text.len())?;
    let skeleton = skeleton(&joints)?;
    let mut notes = vec![
        "units and axes: as written (BVH states neither; often centimetres, Y-up), no conversion".to_owned(),
        "position channels replace the OFFSET components they name; end sites are bones named <parent>_end".to_owned(),
    ];
    let (values, rows) = read_frames(&mut lines, &joints, frames, header_line)?;
    if rows > frames {
        notes.push(format!(
            "the MOTION section has {rows} rows, {} more than its `Frames: {frames}`: all {rows} are read",
            rows - frames
        ));
    }
    let frames = rows;
    let clips = match values {
        None => {
            notes.push("the MOTION section has 0 frames: no animation".to_owned());
            Vec::new()
        }
        Some(values) => {
            notes.push(format!("rotation orders (as channels list them): {}", rotation_orders(&joints).join(", ")));
            notes.push(format!(
                "motion: {frames} frames, {frame_time} s apart ({:.3} fps), one LINEAR key per frame; rotations \
                 composed in each joint's channel order (R = R_first·R_second·R_third)",
                1.0 / frame_time
            ));
            vec![clip(&joints, &values, frames as usize, frame_time)?]
        }
    };
    Ok(Rig { skeleton, clips, skins: Vec::new(), meshes: Vec::new(), unit: None, notes, tool: None })
}

/// `HIERARCHY` up to and including `MOTION`.
fn read_hierarchy(lines: &mut Lines) -> Result<Vec<Joint>> {
    let mut tree = Tree::default();
    let mut seen_hierarchy = false;
    for (line, text) in lines.by_ref() {
        let words = words(text);
        let Some(keyword) = words.first() else { continue };
        let keyword = keyword.to_ascii_uppercase();
        if !seen_hierarchy {
            if keyword != "HIERARCHY" || words.len() > 1 {
                return Err(on_line(line, "expected `HIERARCHY`"));
            }
            seen_hierarchy = true;
            continue;
        }
        if let Some(joint) = tree.pending
            && keyword != "{"
        {
            return Err(on_line(line, format!("expected `{{` after `{}`", tree.joints[joint].name)));
        }
        match keyword.as_str() {
            "ROOT" | "JOINT" | "END" => tree.declare(&keyword, &words, line)?,
            "{" => tree.open(&words, line)?,
            "}" => tree.close(&words, line)?,
            "OFFSET" => tree.offset(&words, line)?,
            "CHANNELS" => tree.channels(&words, line)?,
            "MOTION" => return tree.finished(line),
            _ => return Err(on_line(line, format!("unexpected `{}` in the hierarchy", words[0]))),
        }
    }
    let place = on_line(lines.number, "the file ends before MOTION");
    Err(if seen_hierarchy { place } else { on_line(lines.number, "empty file: expected `HIERARCHY`") })
}

/// The joints of a hierarchy as far as it is read.
#[derive(Default)]
struct Tree {
    joints: Vec<Joint>,
    /// Joints whose `{` has been read and whose `}` has not, innermost last.
    open: Vec<usize>,
    /// A joint declared on a line before its `{`.
    pending: Option<usize>,
}

impl Tree {
    /// A `ROOT name`, `JOINT name` or `End Site` line (its `{` on it, or on the next line).
    fn declare(&mut self, keyword: &str, words: &[String], line: usize) -> Result<()> {
        let (end_site, opens) = declaration(keyword, words, self.open.is_empty(), line)?;
        let parent = self.open.last().copied();
        if let Some(p) = parent
            && self.joints[p].end_site
        {
            return Err(on_line(line, "an End Site cannot have children"));
        }
        let name = if end_site {
            format!("{}_end", parent.map_or("", |p| self.joints[p].name.as_str()))
        } else {
            let last = if opens { words.len() - 1 } else { words.len() };
            let name = words[1..last].join(" ");
            if name.is_empty() { format!("joint{}", self.joints.len()) } else { name }
        };
        self.joints.push(Joint { name, parent, offset: None, channels: Vec::new(), end_site, line });
        if opens {
            self.open.push(self.joints.len() - 1);
        } else {
            self.pending = Some(self.joints.len() - 1);
        }
        Ok(())
    }

    /// A `{` on a line of its own.
    fn open(&mut self, words: &[String], line: usize) -> Result<()> {
        let Some(joint) = self.pending.take() else {
            return Err(on_line(line, "`{` without a ROOT, JOINT or End Site before it"));
        };
        if words.len() > 1 {
            return Err(on_line(line, format!("unexpected `{}` after `{{`", words[1])));
        }
        self.open.push(joint);
        Ok(())
    }

    fn close(&mut self, words: &[String], line: usize) -> Result<()> {
        let Some(joint) = self.open.pop() else {
            return Err(on_line(line, "`}` without a matching `{`"));
        };
        if self.joints[joint].offset.is_none() {
            return Err(on_line(line, format!("`{}` has no OFFSET", self.joints[joint].name)));
        }
        if words.len() > 1 {
            return Err(on_line(line, format!("unexpected `{}` after `}}`", words[1])));
        }
        Ok(())
    }

    fn offset(&mut self, words: &[String], line: usize) -> Result<()> {
        let joint = current(&self.open, line, "OFFSET")?;
        if self.joints[joint].offset.is_some() {
            return Err(on_line(line, format!("a second OFFSET for `{}`", self.joints[joint].name)));
        }
        if words.len() != 4 {
            return Err(on_line(line, format!("OFFSET needs 3 numbers, found {}", words.len() - 1)));
        }
        let mut offset = DVec3::ZERO;
        for axis in 0..3 {
            offset[axis] = number(&words[axis + 1], line, "OFFSET")?;
        }
        self.joints[joint].offset = Some(offset);
        Ok(())
    }

    fn channels(&mut self, words: &[String], line: usize) -> Result<()> {
        let joint = current(&self.open, line, "CHANNELS")?;
        if self.joints[joint].end_site {
            return Err(on_line(line, "an End Site has no CHANNELS"));
        }
        if !self.joints[joint].channels.is_empty() {
            return Err(on_line(line, format!("a second CHANNELS for `{}`", self.joints[joint].name)));
        }
        self.joints[joint].channels = channels(words, line)?;
        Ok(())
    }

    /// The joints, at `MOTION`: every one closed.
    fn finished(self, line: usize) -> Result<Vec<Joint>> {
        if let Some(&joint) = self.open.last() {
            return Err(on_line(line, format!("MOTION before the `}}` of `{}`", self.joints[joint].name)));
        }
        if self.joints.is_empty() {
            return Err(on_line(line, "MOTION before any ROOT"));
        }
        Ok(self.joints)
    }
}

/// Checks a `ROOT name`, `JOINT name` or `End Site` line: whether it is an end site, and whether it ends in `{`.
fn declaration(keyword: &str, words: &[String], at_top: bool, line: usize) -> Result<(bool, bool)> {
    let opens = words.len() > 1 && words[words.len() - 1] == "{";
    match keyword {
        "ROOT" if !at_top => Err(on_line(line, "ROOT inside another joint")),
        "JOINT" if at_top => Err(on_line(line, "JOINT outside any ROOT")),
        "END" => {
            let site = words.get(1).is_some_and(|w| w.eq_ignore_ascii_case("site"));
            if !site || words.len() > 2 + usize::from(opens) {
                return Err(on_line(line, "expected `End Site`"));
            }
            if at_top {
                return Err(on_line(line, "End Site outside any joint"));
            }
            Ok((true, opens))
        }
        _ => Ok((false, opens)),
    }
}

/// The innermost open joint, which an `OFFSET` or `CHANNELS` line describes.
fn current(open: &[usize], line: usize, what: &str) -> Result<usize> {
    open.last().copied().ok_or_else(|| on_line(line, format!("{what} outside any joint")))
}

/// `CHANNELS n name…`: n names, at most six, none twice.
fn channels(words: &[String], line: usize) -> Result<Vec<Channel>> {
    let count = words.get(1).and_then(|w| w.parse::<usize>().ok());
    let Some(count) = count.filter(|&n| n <= 6) else {
        let found = words.get(1).map_or("nothing", String::as_str);
        return Err(on_line(line, format!("CHANNELS needs a count from 0 to 6, found `{found}`")));
    };
    let names = &words[2..];
    if names.len() != count {
        return Err(on_line(line, format!("CHANNELS {count} names {} channels", names.len())));
    }
    let mut channels = Vec::with_capacity(count);
    for name in names {
        let channel = Channel::parse(name).ok_or_else(|| on_line(line, format!("unknown channel `{name}`")))?;
        if channels.contains(&channel) {
            return Err(on_line(line, format!("channel {} listed twice", channel.name())));
        }
        channels.push(channel);
    }
    Ok(channels)
}

/// `Frames: n` and `Frame Time: seconds`, and the line of the latter.
fn read_motion_header(lines: &mut Lines) -> Result<(u64, f64, usize)> {
    let mut next_field = |name: &str| -> Result<(String, usize)> {
        for (line, text) in lines.by_ref() {
            let text = String::from_utf8_lossy(text);
            let text = text.trim();
            if text.is_empty() {
                continue;
            }
            let (key, value) = text.split_once(':').unwrap_or((text, ""));
            let key: Vec<&str> = key.split_ascii_whitespace().collect();
            if !key.join(" ").eq_ignore_ascii_case(name) {
                return Err(on_line(line, format!("expected `{name}:`")));
            }
            return Ok((value.trim().to_owned(), line));
        }
        Err(on_line(lines.number, format!("the file ends before `{name}:`")))
    };
    let (frames, line) = next_field("Frames")?;
    let frames =
        frames.parse::<u64>().map_err(|_| on_line(line, format!("Frames: `{frames}` is not a whole number ≥ 0")))?;
    let (frame_time, line) = next_field("Frame Time")?;
    let frame_time = number(&frame_time, line, "Frame Time")?;
    if frame_time <= 0.0 {
        return Err(on_line(line, format!("Frame Time must be above 0, found {frame_time}")));
    }
    Ok((frames, frame_time, line))
}

/// Refuses a file that declares more joints than the memory budget holds bones, before any is read: a count of the
/// lines that start with `ROOT`, `JOINT` or `End` up to `MOTION` (a quick pass, where reading the hierarchy of a
/// million joints takes a second).
fn check_declared_joints(text: &[u8]) -> Result<()> {
    let starts = |line: &[u8], word: &[u8]| line.get(..word.len()).is_some_and(|w| w.eq_ignore_ascii_case(word));
    let mut joints = 0u64;
    for (_, line) in (Lines { text, number: 0 }) {
        let line = line.trim_ascii_start();
        if starts(line, b"MOTION") {
            break;
        }
        joints += u64::from(starts(line, b"ROOT") || starts(line, b"JOINT") || starts(line, b"END"));
    }
    budget::check(joints.saturating_mul(budget::BONE_BYTES), None, || format!("{joints} joints"))
}

/// Refuses a file whose joints and frames (as many as the rest of the file, `rest` bytes, can hold) would exceed
/// the memory budget: a joint is a bone, and each frame a translation and a rotation key per joint with channels.
fn check_budget(joints: &[Joint], frames: u64, rest: usize) -> Result<()> {
    const KEY_BYTES: u64 = 8 + 12 + 16;
    let per_frame = joints.iter().map(|j| j.channels.len() as u64).sum::<u64>();
    // A number takes at least two bytes (a digit and a separator); every frame holds at least its line break.
    let frames = frames.min(rest as u64 / (2 * per_frame).max(1));
    let animated = joints.iter().filter(|j| !j.channels.is_empty()).count() as u64;
    let per_frame_bytes = animated.saturating_mul(KEY_BYTES).saturating_add(per_frame.saturating_mul(8));
    let bytes =
        (joints.len() as u64).saturating_mul(budget::BONE_BYTES).saturating_add(frames.saturating_mul(per_frame_bytes));
    budget::check(bytes, None, || format!("{} joints and {frames} frames", joints.len()))
}

/// Every frame's numbers, `rows × channels` of them (`None` when there are none), and the number of rows: those the
/// header declares, or more when the file holds more (a common off-by-one that other readers accept; fewer is an
/// error).
fn read_frames(
    lines: &mut Lines,
    joints: &[Joint],
    frames: u64,
    header_line: usize,
) -> Result<(Option<Vec<f64>>, u64)> {
    let per_frame: usize = joints.iter().map(|j| j.channels.len()).sum();
    // Each number takes at least two bytes (a digit and a separator): never reserve more than the file can hold.
    let room = lines.text.len() / 2 + 1;
    let expected = usize::try_from(frames).unwrap_or(usize::MAX).saturating_mul(per_frame);
    let mut values = Vec::with_capacity(expected.min(room));
    let mut read: u64 = 0;
    let mut last_line = header_line;
    for (line, text) in lines.by_ref() {
        last_line = line;
        // Borrowed, not copied, for text that is valid UTF-8 (the numbers of a frame always are).
        let text = String::from_utf8_lossy(text);
        if text.trim_ascii().is_empty() {
            continue;
        }
        read += 1;
        let frame = read - 1;
        let before = values.len();
        for word in text.split_ascii_whitespace() {
            if values.len() - before == per_frame {
                // Too many numbers: count them all for the message.
                let found = text.split_ascii_whitespace().count();
                return Err(on_line(line, format!("frame {frame}: {found} numbers, expected {per_frame}")));
            }
            match word.parse::<f64>() {
                Ok(v) if v.is_finite() => values.push(v),
                _ => return Err(on_line(line, format!("frame {frame}: `{word}` is not a finite number"))),
            }
        }
        let found = values.len() - before;
        if found != per_frame {
            return Err(on_line(line, format!("frame {frame}: {found} numbers, expected {per_frame}")));
        }
    }
    if read < frames {
        let message = format!("the file ends after {read} frames, but the header declares {frames}");
        return Err(on_line(last_line, message));
    }
    Ok(((read > 0).then_some(values), read))
}

/// The distinct rotation orders of the joints (`ZXY` for `Zrotation Xrotation Yrotation`), in order of appearance.
fn rotation_orders(joints: &[Joint]) -> Vec<String> {
    let mut orders: Vec<String> = Vec::new();
    for joint in joints {
        let order: String = joint
            .channels
            .iter()
            .filter_map(|c| match c {
                Channel::Rotation(axis) => Some(['X', 'Y', 'Z'][*axis]),
                Channel::Position(_) => None,
            })
            .collect();
        if !order.is_empty() && !orders.contains(&order) {
            orders.push(order);
        }
    }
    orders
}

fn skeleton(joints: &[Joint]) -> Result<Skeleton> {
    let bones = joints
        .iter()
        .enumerate()
        .map(|(index, joint)| Bone {
            name: joint.name.clone(),
            node: index,
            parent: joint.parent,
            rest: Transform::from_trs(joint.offset.unwrap_or_default(), DQuat::IDENTITY, DVec3::ONE),
            inherit: InheritMode::Full,
            role: if joint.end_site { NodeRole::EndSite } else { NodeRole::Joint },
        })
        .collect();
    // Cannot fail: a joint is declared after its parent.
    Skeleton::new(bones).map_err(|e| Failure::whole(e.to_string()))
}

/// One clip: a LINEAR translation and/or rotation track per joint with channels, one key per frame.
fn clip(joints: &[Joint], values: &[f64], frames: usize, frame_time: f64) -> Result<Clip> {
    let times: Arc<[f64]> = (0..frames).map(|k| k as f64 * frame_time).collect();
    let per_frame: usize = joints.iter().map(|j| j.channels.len()).sum();
    let mut tracks = Vec::new();
    let mut first = 0;
    for (index, joint) in joints.iter().enumerate() {
        let count = joint.channels.len();
        if count == 0 {
            continue;
        }
        let offset = joint.offset.unwrap_or_default();
        let mut translations = Vec::with_capacity(if joint.has_position() { frames } else { 0 });
        let mut rotations = Vec::with_capacity(if joint.has_rotation() { frames } else { 0 });
        for frame in values.chunks_exact(per_frame) {
            let (t, r) = joint.pose(offset, &frame[first..first + count]);
            if joint.has_position() {
                translations.push(t.as_vec3());
            }
            if joint.has_rotation() {
                rotations.push(r.as_quat());
            }
        }
        first += count;
        let track_error = |e| on_line(joint.line, format!("`{}`: {e}", joint.name));
        let mut bone = BoneTracks::new(index);
        if joint.has_position() {
            bone.translation =
                Some(Track::<Vec3>::new(times.clone(), translations, Interpolation::Linear).map_err(track_error)?);
        }
        if joint.has_rotation() {
            bone.rotation =
                Some(Track::<Quat>::new(times.clone(), rotations, Interpolation::Linear).map_err(track_error)?);
        }
        tracks.push(bone);
    }
    Ok(Clip::new(0, None, tracks, Vec::new()).with_frame_rate(1.0 / frame_time))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(text: &str) -> Vec<(usize, String)> {
        Lines { text: text.as_bytes(), number: 0 }.map(|(n, l)| (n, String::from_utf8_lossy(l).into_owned())).collect()
    }

    #[test]
    fn lines_end_at_lf_crlf_and_cr() {
        let expected: Vec<(usize, String)> =
            vec![(1, "a".into()), (2, "b".into()), (3, "c".into()), (4, "".into()), (5, "d".into())];
        assert_eq!(lines("a\nb\r\nc\r\rd"), expected);
        assert_eq!(lines("a\n"), vec![(1, "a".to_owned())]);
    }

    #[test]
    fn channel_names_in_any_case() {
        assert_eq!(Channel::parse("Xposition"), Some(Channel::Position(0)));
        assert_eq!(Channel::parse("zROTATION"), Some(Channel::Rotation(2)));
        assert_eq!(Channel::parse("Wrotation"), None);
        assert_eq!(Channel::parse(""), None);
        assert_eq!(Channel::Rotation(1).name(), "Yrotation");
    }

    #[test]
    fn rotations_compose_in_channel_order() {
        let joint = Joint {
            name: "j".into(),
            parent: None,
            offset: Some(DVec3::ZERO),
            channels: vec![Channel::Rotation(2), Channel::Position(1), Channel::Rotation(0)],
            end_site: false,
            line: 1,
        };
        let (t, r) = joint.pose(DVec3::new(1.0, 2.0, 3.0), &[90.0, 7.0, 90.0]);
        assert_eq!(t, DVec3::new(1.0, 7.0, 3.0));
        let expected = DQuat::from_rotation_z(90f64.to_radians()) * DQuat::from_rotation_x(90f64.to_radians());
        assert!(r.abs_diff_eq(expected, 1e-15));
    }
}
