//! bonescope: a crate file read through a few blocks of it kept in memory, instead of whole into memory first.

use std::io::{self, Read, Seek, SeekFrom};

/// The size of a block, and the most read at once through them (larger reads go straight to the file).
const BLOCK: usize = 1 << 16;

/// How many blocks are kept: a crate file's deduplicated values send the reader back and forth between a few
/// regions of the file, value after value.
const KEPT: usize = 32;

/// A reader over `R` that keeps the [`KEPT`] blocks of it used last: reading a layer whole first took fresh pages
/// for all of it, and one buffered window was read again at every jump between regions.
pub struct Blocks<R> {
    inner: R,
    len: u64,
    position: u64,
    /// Each kept block's index (`u64::MAX` for none), buffer and when it was last used.
    kept: Vec<(u64, Box<[u8]>, u64)>,
    clock: u64,
}

impl<R: Read + Seek> Blocks<R> {
    pub fn new(mut inner: R) -> io::Result<Self> {
        let len = inner.seek(SeekFrom::End(0))?;
        Ok(Blocks { inner, len, position: 0, kept: Vec::new(), clock: 0 })
    }

    /// Block `index`, read from the file unless it is kept (into the buffer of the one used longest ago: a fresh
    /// buffer per read cost more than the read).
    fn block(&mut self, index: u64) -> io::Result<&[u8]> {
        self.clock += 1;
        let slot = match self.kept.iter().position(|(i, ..)| *i == index) {
            Some(slot) => slot,
            None => {
                let slot = if self.kept.len() < KEPT {
                    self.kept.push((index, vec![0; BLOCK].into_boxed_slice(), 0));
                    self.kept.len() - 1
                } else {
                    (0..KEPT).min_by_key(|&slot| self.kept[slot].2).expect("blocks are kept")
                };
                let (start, len) = self.extent(index);
                // Marked unread until the read succeeds: a failed read leaves no block that seems to hold it.
                self.kept[slot].0 = u64::MAX;
                self.inner.seek(SeekFrom::Start(start))?;
                self.inner.read_exact(&mut self.kept[slot].1[..len])?;
                self.kept[slot].0 = index;
                slot
            }
        };
        self.kept[slot].2 = self.clock;
        let (_, len) = self.extent(index);
        Ok(&self.kept[slot].1[..len])
    }

    /// Where block `index` starts in the file, and its length (shorter at the end of the file).
    fn extent(&self, index: u64) -> (u64, usize) {
        let start = index * BLOCK as u64;
        (start, (self.len - start).min(BLOCK as u64) as usize)
    }
}

impl<R: Read + Seek> Read for Blocks<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if self.position >= self.len || buf.is_empty() {
            return Ok(0);
        }
        let read = if buf.len() >= BLOCK {
            self.inner.seek(SeekFrom::Start(self.position))?;
            self.inner.read(buf)?
        } else {
            let offset = (self.position % BLOCK as u64) as usize;
            let block = self.block(self.position / BLOCK as u64)?;
            let read = (block.len() - offset).min(buf.len());
            buf[..read].copy_from_slice(&block[offset..offset + read]);
            read
        };
        self.position += read as u64;
        Ok(read)
    }
}

impl<R> Seek for Blocks<R> {
    fn seek(&mut self, to: SeekFrom) -> io::Result<u64> {
        let target = match to {
            SeekFrom::Start(target) => Some(target),
            SeekFrom::Current(offset) => self.position.checked_add_signed(offset),
            SeekFrom::End(offset) => self.len.checked_add_signed(offset),
        };
        self.position = target.ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "a seek before the file"))?;
        Ok(self.position)
    }

    fn stream_position(&mut self) -> io::Result<u64> {
        Ok(self.position)
    }
}
