//! Where the bytes of a glTF file are: in memory ([`crate::import::load_bytes`]), or in a file on disk, read as they
//! are needed ([`crate::import::load`]).
//!
//! Read from disk, a binary glTF is never copied into memory whole: the GLB framing and the JSON are read, and then
//! only the bytes of the accessors bonescope decodes, each just before it is decoded. For a large file that halves
//! the memory the process touches (fresh pages cost the kernel a fault each, which for a 20 MB animation was a
//! third of the loading time), and a file's unused parts (textures, say) are not read at all.

use std::borrow::Cow;
use std::fs::File;
use std::ops::Range;

/// The whole file, in memory or on disk.
#[derive(Clone, Copy, Debug)]
pub(super) enum Source<'a> {
    Memory(&'a [u8]),
    /// An open file of `len` bytes (its length when it was opened).
    File {
        file: &'a File,
        len: usize,
    },
}

impl<'a> Source<'a> {
    /// The file's length in bytes.
    pub fn len(&self) -> usize {
        match self {
            Source::Memory(bytes) => bytes.len(),
            Source::File { len, .. } => *len,
        }
    }

    /// The bytes in `range`, which must lie within [`Source::len`]: borrowed from memory, or read from the file
    /// (which fails if the file has shrunk since it was opened).
    pub fn read(&self, range: Range<usize>) -> std::io::Result<Cow<'a, [u8]>> {
        match self {
            Source::Memory(bytes) => bytes.get(range).map(Cow::Borrowed).ok_or_else(|| outside(bytes.len())),
            Source::File { file, len } => {
                if range.end > *len {
                    return Err(outside(*len));
                }
                let mut bytes = vec![0; range.len()];
                read_at(file, &mut bytes, range.start as u64)?;
                Ok(Cow::Owned(bytes))
            }
        }
    }
}

/// Fills `bytes` from `file` at `offset`, leaving the file's own position alone: accessors are read on several
/// threads at once.
#[cfg(unix)]
fn read_at(file: &File, bytes: &mut [u8], offset: u64) -> std::io::Result<()> {
    std::os::unix::fs::FileExt::read_exact_at(file, bytes, offset)
}

#[cfg(windows)]
fn read_at(file: &File, mut bytes: &mut [u8], mut offset: u64) -> std::io::Result<()> {
    while !bytes.is_empty() {
        match std::os::windows::fs::FileExt::seek_read(file, bytes, offset)? {
            0 => return Err(std::io::ErrorKind::UnexpectedEof.into()),
            read => (bytes, offset) = (&mut bytes[read..], offset + read as u64),
        }
    }
    Ok(())
}

fn outside(len: usize) -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::UnexpectedEof, format!("beyond the end of the file ({len} bytes)"))
}

/// Part of a [`Source`]: the GLB `BIN` chunk.
#[derive(Clone, Copy, Debug)]
pub(super) struct Region<'a> {
    pub source: Source<'a>,
    pub start: usize,
    pub len: usize,
}

impl<'a> Region<'a> {
    /// The bytes in `range`, relative to the region's start; `range` must lie within `len`.
    pub fn read(&self, range: Range<usize>) -> std::io::Result<Cow<'a, [u8]>> {
        if range.end > self.len {
            return Err(outside(self.len));
        }
        self.source.read(self.start + range.start..self.start + range.end)
    }
}
