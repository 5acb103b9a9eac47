//! A SkelAnimation's translations, rotations, scales or blend-shape weights as USD reads them at any time code: held
//! before the first sample and after the last, a sample's own at its time, and between two samples of the same length
//! interpolated with the arithmetic of Pixar's `Gf` types, which rounds every step to the attribute's precision:
//! `GfLerp` is `(1 − t)·a + t·b` with both products and their sum rounded (a `half3` held between two equal samples
//! reads a half step off), `GfSlerp` turns by `θ = acos(cos θ)` where `1 − cos θ > 10⁻⁵` and mixes linearly below,
//! neither normalised. The `openusd` crate rounds once and normalises a near-linear slerp: the same within the
//! precision of a `float`, not to the bit UsdSkel computes.
//!
//! A channel is read value by value as the layer decodes it (a value several samples share comes once, with all of
//! them) and kept by element (joint or blend shape): an element whose value never changes is kept once, one that
//! moves as its column of values, one per sample. So a clip's samples are never all in memory at once, and a moving
//! joint's column is its track.

use std::sync::Arc;

use glam::{DQuat, DVec3, Quat, Vec3};
use half::slice::HalfFloatSliceExt;
use openusd::gf::f16;
use openusd::sdf::{TimeSample, Value};
use openusd::usd::{Attribute, Stage};

use super::{charge, said};

/// One channel's samples, sorted by time code, in the precision the file stores them in.
pub enum Channel {
    Vectors(Columns<Vec3>),
    DoubleVectors(Columns<DVec3>),
    Rotations(Columns<Quat>),
    DoubleRotations(Columns<DQuat>),
    Numbers(Columns<f32>),
}

/// Per element, its values at the clip's time codes.
#[derive(Debug, PartialEq)]
pub enum Keys<T> {
    /// The same at every sample: the value read at the first time code.
    Held(T),
    /// One value per time code.
    Moving(Arc<[T]>),
}

impl Channel {
    /// The attribute's time samples, else its default value (held throughout), for arrays of `len` elements;
    /// `None` where it has neither or its samples are not all one array type.
    pub fn read(stage: &Stage, attribute: &Attribute, len: usize) -> Result<Option<Channel>, String> {
        let mut reading = Reading { channel: None, mixed: false, refused: None, len, widened: Vec::new() };
        stage.visit_time_samples(attribute.path().clone(), |sample| reading.add(sample)).map_err(said)?;
        if reading.channel.is_none() && !reading.mixed && reading.refused.is_none() {
            let Some(value) = attribute.get::<Value>().map_err(said)? else { return Ok(None) };
            reading.add(TimeSample { at: vec![(0, 0.0)], value, count: 1 });
        }
        reading.finish()
    }

    /// The time codes of its samples.
    pub fn codes(&self) -> &[f64] {
        each!(self, c => &c.codes)
    }

    /// Each element's vectors at `codes`, `identity` where a sample there is not an array of the channel's length
    /// and throughout a channel of rotations or numbers; an error where the keys made anew would pass the reading's
    /// budget.
    pub fn vectors(self, codes: &[f64], identity: Vec3) -> Result<Vec<Keys<Vec3>>, String> {
        match self {
            Channel::Vectors(c) => c.keys(codes, identity, |v| v, Ok),
            Channel::DoubleVectors(c) => c.keys(codes, identity, DVec3::as_vec3, Err),
            other => each!(other, c => c.keys(codes, identity, |_| identity, Err)),
        }
    }

    /// Each element's rotations at `codes`, as stored: not normalised, as UsdSkel makes a matrix of them (and as
    /// glTF's keys are read); `identity` where a sample there is not an array of the channel's length and throughout
    /// a channel of vectors or numbers; an error where the keys made anew would pass the reading's budget.
    pub fn rotations(self, codes: &[f64], identity: Quat) -> Result<Vec<Keys<Quat>>, String> {
        let single = |q: DQuat| Quat::from_xyzw(q.x as f32, q.y as f32, q.z as f32, q.w as f32);
        match self {
            Channel::Rotations(c) => c.keys(codes, identity, |q| q, Ok),
            Channel::DoubleRotations(c) => c.keys(codes, identity, single, Err),
            other => each!(other, c => c.keys(codes, identity, |_| identity, Err)),
        }
    }

    /// The numbers at each of `codes`, one per element; `None` at a code where the sample is not an array of the
    /// channel's length, and for a channel of vectors or rotations (the caller charges them to the reading's budget).
    pub fn numbers(&self, codes: &[f64]) -> Option<Vec<Option<Vec<f32>>>> {
        let Channel::Numbers(c) = self else { return None };
        let reads = c.reads(codes);
        Some(reads.iter().map(|&read| (0..c.len).map(|e| c.read(e, read)).collect()).collect())
    }
}

/// `$body` with `$c` bound to the columns of whichever type `$channel` holds.
macro_rules! each {
    ($channel:expr, $c:ident => $body:expr) => {
        match $channel {
            Channel::Vectors($c) => $body,
            Channel::DoubleVectors($c) => $body,
            Channel::Rotations($c) => $body,
            Channel::DoubleRotations($c) => $body,
            Channel::Numbers($c) => $body,
        }
    };
}
use each;

/// A channel as its samples arrive.
struct Reading {
    channel: Option<Channel>,
    /// A sample was of another type than the first, or of none a channel holds: the attribute is no channel.
    mixed: bool,
    /// Why the channel cannot be read: its columns would take more memory than the reading may use.
    refused: Option<String>,
    len: usize,
    /// A half-precision sample's numbers, widened.
    widened: Vec<f32>,
}

impl Reading {
    /// Takes a value with the samples that hold it (none at a time code that is not finite).
    fn add(&mut self, sample: TimeSample) {
        let TimeSample { mut at, value, count: of } = sample;
        at.retain(|(_, code)| code.is_finite());
        if at.is_empty() || self.mixed || self.refused.is_some() {
            return;
        }
        let len = Length { len: self.len, of };
        let at = &at;
        let added = match value {
            Value::Vec3hVec(a) => {
                let values = widen(&mut self.widened, bytemuck::cast_slice(&a))
                    .chunks_exact(3)
                    .map(|v| Vec3::new(v[0], v[1], v[2]));
                push(&mut self.channel, Channel::Vectors, Precision::Half, len, at, a.len(), values)
            }
            Value::Vec3fVec(a) => {
                let values = a.iter().map(|v| Vec3::new(v.x, v.y, v.z));
                push(&mut self.channel, Channel::Vectors, Precision::Float, len, at, a.len(), values)
            }
            Value::Vec3dVec(a) => {
                let values = a.iter().map(|v| DVec3::new(v.x, v.y, v.z));
                push(&mut self.channel, Channel::DoubleVectors, Precision::Double, len, at, a.len(), values)
            }
            Value::QuathVec(a) => {
                // Stored (w, x, y, z).
                let values = widen(&mut self.widened, bytemuck::cast_slice(&a))
                    .chunks_exact(4)
                    .map(|q| Quat::from_xyzw(q[1], q[2], q[3], q[0]));
                push(&mut self.channel, Channel::Rotations, Precision::Half, len, at, a.len(), values)
            }
            Value::QuatfVec(a) => {
                let values = a.iter().map(|q| Quat::from_xyzw(q.x, q.y, q.z, q.w));
                push(&mut self.channel, Channel::Rotations, Precision::Float, len, at, a.len(), values)
            }
            Value::QuatdVec(a) => {
                let values = a.iter().map(|q| DQuat::from_xyzw(q.x, q.y, q.z, q.w));
                push(&mut self.channel, Channel::DoubleRotations, Precision::Double, len, at, a.len(), values)
            }
            Value::FloatVec(a) => {
                let values = a.iter().copied();
                push(&mut self.channel, Channel::Numbers, Precision::Float, len, at, a.len(), values)
            }
            _ => Ok(false),
        };
        match added {
            Ok(added) => self.mixed = !added,
            Err(refused) => self.refused = Some(refused),
        }
    }

    /// The channel read; `None` where the attribute is no channel, an error where it could not be read.
    fn finish(self) -> Result<Option<Channel>, String> {
        if let Some(refused) = self.refused {
            return Err(refused);
        }
        let Some(mut channel) = self.channel.filter(|_| !self.mixed) else { return Ok(None) };
        each!(&mut channel, c => c.finish())?;
        Ok(Some(channel))
    }
}

/// The length of the arrays a channel reads, and how many samples it has.
#[derive(Clone, Copy)]
struct Length {
    len: usize,
    of: usize,
}

/// `halves` widened into `into`, a slice at a time (one instruction for several, where the processor has it).
fn widen<'a>(into: &'a mut Vec<f32>, halves: &[f16]) -> &'a [f32] {
    into.resize(halves.len(), 0.0);
    halves.convert_to_f32_slice(into);
    into
}

/// Adds a value of `count` `values` held at the samples `at` (each one's index among the channel's samples, and its
/// time code) to `channel`, which it starts as `variant` where it is `None`; `false` where the channel holds another
/// type or precision. Starting it charges the reading's budget for what it keeps besides the columns (which are
/// charged as they are made): a time code per sample, the first sample's values and the samples staged.
fn push<V: Stored>(
    channel: &mut Option<Channel>,
    variant: fn(Columns<V>) -> Channel,
    precision: Precision,
    length: Length,
    at: &[(usize, f64)],
    count: usize,
    values: impl Iterator<Item = V>,
) -> Result<bool, String> {
    if channel.is_none() {
        charge::<f64>(length.of)?;
        charge::<bool>(length.of)?;
        charge::<V>(length.len.saturating_mul(STAGED + 1))?;
        charge::<(usize, usize)>(length.of)?;
        *channel = Some(variant(Columns::new(precision, length)));
    }
    match channel.as_mut().and_then(V::columns) {
        Some(c) if c.precision == precision => c.push(at, count, values).map(|()| true),
        _ => Ok(false),
    }
}

/// How a file stores a channel's numbers, which decides the rounding of a value read between two samples.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Precision {
    Half,
    Float,
    Double,
}

/// How many values are staged before they are written into the columns.
const STAGED: usize = 256;

/// How many columns are written together: the values of neighbouring elements share the staged rows' cache lines.
const WRITTEN_TOGETHER: usize = 4;

/// A channel's samples by element, sorted by time code.
pub struct Columns<V> {
    precision: Precision,
    /// The length an array must have to be read.
    len: usize,
    /// Per sample (as many as its layer says it has), its time code (NaN for one not read: at no finite time code,
    /// dropped once all are read).
    codes: Vec<f64>,
    /// Per sample, whether its array has `len` elements.
    fits: Vec<bool>,
    /// The first fitting sample's values; an element without a column has this value in every fitting sample.
    first: Option<Vec<V>>,
    /// Per element, its value at each sample, from the first sample that differs from `first` on (`first`'s value
    /// stands in for it at a sample that does not fit, and at those not written yet). Made as large as the layer
    /// says at once: a moving joint's column becomes its track as it is.
    columns: Vec<Option<Arc<[V]>>>,
    /// Values of fitting samples not yet written into the columns, one after the other (each differing from `first`
    /// in some bit), and each of their samples as (value, sample).
    staged: Vec<V>,
    staged_at: Vec<(usize, usize)>,
}

/// How a value at one time code is read from the samples.
#[derive(Clone, Copy)]
enum Read {
    /// A sample's own.
    Sample(usize),
    /// Between two fitting samples, at `t` from the first to the second.
    Mix(usize, usize, f64),
    /// From no sample, or from one whose array does not fit: the identity.
    Nothing,
}

impl<V: Stored> Columns<V> {
    fn new(precision: Precision, Length { len, of }: Length) -> Self {
        let columns = (0..len).map(|_| None).collect();
        let (codes, fits) = (vec![f64::NAN; of], vec![false; of]);
        Columns { precision, len, codes, fits, first: None, columns, staged: Vec::new(), staged_at: Vec::new() }
    }

    /// A column holding `value` at every sample, charged to the reading's budget before it is made.
    fn column(&self, value: V) -> Result<Arc<[V]>, String> {
        charge::<V>(self.codes.len())?;
        Ok(std::iter::repeat_n(value, self.codes.len()).collect())
    }

    /// Adds the `count` `values` held at the samples `at` (values come in any order, each sample once); an error
    /// where a column it starts would pass the reading's budget.
    fn push(&mut self, at: &[(usize, f64)], count: usize, values: impl Iterator<Item = V>) -> Result<(), String> {
        let of = self.codes.len();
        let mut read = false;
        for &(sample, code) in at.iter().filter(|&&(sample, _)| sample < of) {
            self.codes[sample] = code;
            self.fits[sample] = count == self.len;
            read = true;
        }
        if !read || count != self.len {
            return Ok(());
        }
        let Some(first) = &self.first else {
            let first: Vec<V> = values.collect();
            // A value unequal to itself (NaN) is never held.
            for (e, v) in first.iter().enumerate().filter(|(_, v)| v.is_nan()) {
                self.columns[e] = Some(self.column(*v)?);
            }
            self.first = Some(first);
            return Ok(());
        };
        let row = self.staged.len() / self.len;
        self.staged.extend(values);
        // A column holds `first`'s value wherever nothing is written: a value the same to the bit needs no writing.
        if V::same_bits(&self.staged[row * self.len..], first) {
            self.staged.truncate(row * self.len);
            return Ok(());
        }
        self.staged_at.extend(at.iter().filter(|&&(sample, _)| sample < of).map(|&(sample, _)| (row, sample)));
        if row + 1 == STAGED {
            self.flush()?;
        }
        Ok(())
    }

    /// Writes the staged values into the columns of their samples, starting the column of an element where a value
    /// differs from the first.
    fn flush(&mut self) -> Result<(), String> {
        let Some(first) = &self.first else { return Ok(()) };
        let mut columns = std::mem::take(&mut self.columns);
        // The elements that start to move, found row by row: a row is contiguous, and most rows of a channel that
        // mostly holds equal the first sample's.
        for row in self.staged.chunks_exact(self.len).filter(|row| *row != first.as_slice()) {
            for ((column, v), held) in columns.iter_mut().zip(row).zip(first) {
                if column.is_none() && v != held {
                    *column = Some(self.column(*held)?);
                }
            }
        }
        // The moving elements' values, a few columns at a time: each staged row is read from memory once per few
        // columns, and each column reached for writing once per flush.
        let mut moving: Vec<(usize, &mut [V])> =
            columns.iter_mut().enumerate().filter_map(|(e, c)| Some((e, Arc::make_mut(c.as_mut()?)))).collect();
        for together in moving.chunks_mut(WRITTEN_TOGETHER) {
            for &(row, sample) in &self.staged_at {
                let row = &self.staged[row * self.len..][..self.len];
                together.iter_mut().for_each(|(e, column)| column[sample] = row[*e]);
            }
        }
        self.columns = columns;
        self.staged.clear();
        self.staged_at.clear();
        Ok(())
    }

    /// Writes what is staged, drops the samples not read and puts the others in order of time code, the stored
    /// order among equal ones.
    fn finish(&mut self) -> Result<(), String> {
        self.flush()?;
        if self.codes.iter().all(|c| c.is_finite()) && self.codes.is_sorted_by(|a, b| a.total_cmp(b).is_le()) {
            return Ok(());
        }
        let mut order: Vec<usize> = (0..self.codes.len()).filter(|&i| self.codes[i].is_finite()).collect();
        order.sort_by(|&a, &b| self.codes[a].total_cmp(&self.codes[b]));
        self.codes = order.iter().map(|&i| self.codes[i]).collect();
        self.fits = order.iter().map(|&i| self.fits[i]).collect();
        for column in self.columns.iter_mut().flatten() {
            *column = order.iter().map(|&i| column[i]).collect();
        }
        Ok(())
    }

    /// How the value at each of `codes` is read.
    fn reads(&self, codes: &[f64]) -> Vec<Read> {
        let read = |code: f64| {
            let next = self.codes.partition_point(|c| *c <= code);
            match (next.checked_sub(1), (next < self.codes.len()).then_some(next)) {
                (Some(a), Some(b)) if self.codes[a] != code && self.fits[a] && self.fits[b] => {
                    Read::Mix(a, b, (code - self.codes[a]) / (self.codes[b] - self.codes[a]))
                }
                (Some(a), _) | (None, Some(a)) if self.fits[a] => Read::Sample(a),
                _ => Read::Nothing,
            }
        };
        codes.iter().map(|&code| read(code)).collect()
    }

    /// Whether element `e`, the same in every sample, reads the same at every one of `reads`: a half-precision value
    /// read between two samples of it can read a half step off ([`mix_half`]), as USD reads it.
    fn reads_alike(&self, e: usize, reads: &[Read]) -> bool {
        let held = reads.first().map(|&read| self.read(e, read));
        self.precision != Precision::Half || reads.iter().all(|&read| self.read(e, read) == held.flatten())
    }

    /// Element `e`'s value as `read` reads it; `None` for the identity.
    fn read(&self, e: usize, read: Read) -> Option<V> {
        let at = |sample: usize| {
            self.columns[e].as_ref().map_or_else(|| self.first.as_ref().map(|f| f[e]), |c| Some(c[sample]))
        };
        match read {
            Read::Sample(sample) => at(sample),
            Read::Mix(a, b, t) => Some(V::mix(at(a)?, at(b)?, t, self.precision)),
            Read::Nothing => None,
        }
    }

    /// Each element's keys at `codes`, made `T`s: held where every sample fits and holds its value, else one per
    /// code (`identity` where nothing fits there). A column whose samples are `codes` is its keys where it already
    /// holds `T`s (`same` gives it back as such, else back as it is); any other is made anew, charged to the reading's budget first.
    fn keys<T: Copy>(
        mut self,
        codes: &[f64],
        identity: T,
        into: impl Fn(V) -> T,
        same: impl Fn(Arc<[V]>) -> Result<Arc<[T]>, Arc<[V]>>,
    ) -> Result<Vec<Keys<T>>, String> {
        let reads = self.reads(codes);
        let all_fit = self.fits.iter().all(|f| *f);
        let own = all_fit && codes == self.codes;
        let made = |values: &mut dyn Iterator<Item = T>| -> Result<Keys<T>, String> {
            charge::<T>(codes.len())?;
            Ok(Keys::Moving(values.collect()))
        };
        (0..self.len)
            .map(|e| match self.columns[e].take_if(|_| own) {
                Some(column) => match same(column) {
                    Ok(keys) => Ok(Keys::Moving(keys)),
                    Err(column) => made(&mut column.iter().map(|v| into(*v))),
                },
                None if all_fit && self.columns[e].is_none() && self.reads_alike(e, &reads) => {
                    Ok(Keys::Held(self.read(e, reads[0]).map_or(identity, &into)))
                }
                None => made(&mut reads.iter().map(|&read| self.read(e, read).map_or(identity, &into))),
            })
            .collect()
    }
}

/// A value as a channel keeps it: the numbers stored, exactly (half and float widen to `f32` without loss).
pub trait Stored: bytemuck::Pod + PartialEq {
    /// Its columns, where `channel` holds values of its type.
    fn columns(channel: &mut Channel) -> Option<&mut Columns<Self>>;

    /// The value between `a` and `b` at `t`, as Pixar's `Gf` computes it in `precision`.
    fn mix(a: Self, b: Self, t: f64, precision: Precision) -> Self;

    /// Whether a number of it is NaN: it is unequal to itself.
    fn is_nan(self) -> bool;

    /// Whether `a` and `b` hold the same numbers to the bit (`==` takes −0 for 0 and NaN for no number).
    fn same_bits(a: &[Self], b: &[Self]) -> bool {
        bytemuck::cast_slice::<Self, u8>(a) == bytemuck::cast_slice::<Self, u8>(b)
    }
}

/// The part of [`Stored`] alike for every type: the channel variant that holds `$type`, and NaN as `$type` finds it.
macro_rules! of_channel {
    ($type:ty, $variant:ident) => {
        fn columns(channel: &mut Channel) -> Option<&mut Columns<Self>> {
            match channel {
                Channel::$variant(c) => Some(c),
                _ => None,
            }
        }

        fn is_nan(self) -> bool {
            <$type>::is_nan(self)
        }
    };
}

/// `half(half(a·(1 − t)) + half(b·t))` with weights `(1 − t, t)` = `(w0, w1)`: `GfVec3h`'s scaling and sum, each
/// rounded to half precision.
fn mix_half(a: f32, b: f32, w0: f64, w1: f64) -> f32 {
    let scaled = |x: f32, s: f64| f16::from_f32(x * s as f32).to_f32();
    f16::from_f32(scaled(a, w0) + scaled(b, w1)).to_f32()
}

/// `float(float(a·w0) + float(b·w1))`: `GfVec3f`'s scaling and sum, each rounded to single precision.
fn mix_float(a: f32, b: f32, w0: f64, w1: f64) -> f32 {
    (f64::from(a) * w0) as f32 + (f64::from(b) * w1) as f32
}

impl Stored for Vec3 {
    of_channel!(Vec3, Vectors);

    fn mix(a: Self, b: Self, t: f64, precision: Precision) -> Self {
        let mix = if precision == Precision::Half { mix_half } else { mix_float };
        Vec3::new(mix(a.x, b.x, 1.0 - t, t), mix(a.y, b.y, 1.0 - t, t), mix(a.z, b.z, 1.0 - t, t))
    }
}

impl Stored for DVec3 {
    of_channel!(DVec3, DoubleVectors);

    fn mix(a: Self, b: Self, t: f64, _: Precision) -> Self {
        let lerp = |a: f64, b: f64| (1.0 - t) * a + t * b;
        DVec3::new(lerp(a.x, b.x), lerp(a.y, b.y), lerp(a.z, b.z))
    }
}

/// `GfLerp` of two `float`s: computed in double precision, rounded once.
impl Stored for f32 {
    of_channel!(f32, Numbers);

    fn mix(a: Self, b: Self, t: f64, _: Precision) -> Self {
        ((1.0 - t) * f64::from(a) + t * f64::from(b)) as f32
    }
}

/// `GfSlerp`'s weights of the two quaternions `(w, x, y, z)` at `t`: the angle between them found in `f32` (as for
/// `GfQuatf` and `GfQuath`) or in `f64`, the shorter way round.
fn slerp_weights(a: [f64; 4], b: [f64; 4], t: f64, single: bool) -> (f64, f64) {
    let dot = if single {
        // The imaginary parts' dot product and the real parts' product, in single precision.
        let [a, b] = [a, b].map(|q| q.map(|c| c as f32));
        f64::from(a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[0] * b[0])
    } else {
        a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[0] * b[0]
    };
    let (cos, flip) = if dot < 0.0 { (-dot, true) } else { (dot, false) };
    let (w0, w1) = if 1.0 - cos > 1e-5 {
        let (theta, sin) = if single {
            let theta = cos.acos() as f32;
            (f64::from(theta), f64::from(theta.sin()))
        } else {
            (cos.acos(), cos.acos().sin())
        };
        (((1.0 - t) * theta).sin() / sin, (t * theta).sin() / sin)
    } else {
        (1.0 - t, t)
    };
    (w0, if flip { -w1 } else { w1 })
}

impl Stored for Quat {
    of_channel!(Quat, Rotations);

    fn mix(a: Self, b: Self, t: f64, precision: Precision) -> Self {
        let wide = |q: Quat| [q.w, q.x, q.y, q.z].map(f64::from);
        let (w0, w1) = slerp_weights(wide(a), wide(b), t, true);
        let mix = if precision == Precision::Half { mix_half } else { mix_float };
        let c = |x: f32, y: f32| mix(x, y, w0, w1);
        Quat::from_xyzw(c(a.x, b.x), c(a.y, b.y), c(a.z, b.z), c(a.w, b.w))
    }
}

impl Stored for DQuat {
    of_channel!(DQuat, DoubleRotations);

    fn mix(a: Self, b: Self, t: f64, _: Precision) -> Self {
        let (w0, w1) = slerp_weights([a.w, a.x, a.y, a.z], [b.w, b.x, b.y, b.z], t, false);
        let c = |x: f64, y: f64| x * w0 + y * w1;
        DQuat::from_xyzw(c(a.x, b.x), c(a.y, b.y), c(a.z, b.z), c(a.w, b.w))
    }
}

#[cfg(test)]
mod tests {
    use openusd::gf;

    use super::*;

    /// The samples (index, time code, x of the second element) of a channel of two vectors: the first element
    /// holds (1, 1, 1), the second is at (x, 0, 0); an `x` of `None` is an array of one element, which does not fit.
    fn channel(samples: &[(usize, f64, Option<f32>)]) -> Channel {
        let mut reading = Reading { channel: None, mixed: false, refused: None, len: 2, widened: Vec::new() };
        for &(index, time, x) in samples {
            let moving = x.map(|x| gf::vec3f(x, 0.0, 0.0));
            let array = [Some(gf::vec3f(1.0, 1.0, 1.0)), moving].into_iter().flatten().collect();
            reading.add(TimeSample { at: vec![(index, time)], value: Value::Vec3fVec(array), count: samples.len() });
        }
        reading.finish().expect("within the budget").expect("one type throughout")
    }

    fn x(x: f32) -> Vec3 {
        Vec3::new(x, 0.0, 0.0)
    }

    #[test]
    fn samples_in_any_order_are_read_as_in_time_order() {
        let samples = [(0, 0.0, Some(0.0)), (1, 1.0, Some(1.0)), (2, 2.0, Some(3.0))];
        let codes = [0.0, 0.5, 1.0, 2.0, 3.0];
        let in_order = channel(&samples).vectors(&codes, Vec3::ZERO).unwrap();
        let [a, b, c] = samples;
        assert_eq!(channel(&[c, a, b]).vectors(&codes, Vec3::ZERO).unwrap(), in_order);
        // Held before the first sample and after the last, mixed between (exact in `float` at these values).
        let moving: Arc<[Vec3]> = [x(0.0), x(0.5), x(1.0), x(3.0), x(3.0)].into();
        assert_eq!(in_order, vec![Keys::Held(Vec3::ONE), Keys::Moving(moving)]);
    }

    #[test]
    fn a_value_several_samples_share_is_read_at_each_of_them_to_the_bit() {
        // Handed on as a binary layer hands them: each value once, with every sample that holds it. The second
        // element moves (0 → 5 → 5 → 0 → −0); −0 equals the first sample's 0 but is kept as stored.
        let value = |x: f32| Value::Vec3fVec(vec![gf::vec3f(1.0, 1.0, 1.0), gf::vec3f(x, 0.0, 0.0)]);
        let mut reading = Reading { channel: None, mixed: false, refused: None, len: 2, widened: Vec::new() };
        for (at, x) in [(vec![(0, 0.0), (3, 3.0)], 0.0), (vec![(2, 2.0), (1, 1.0)], 5.0), (vec![(4, 4.0)], -0.0)] {
            reading.add(TimeSample { at, value: value(x), count: 5 });
        }
        let codes = [0.0, 1.0, 2.0, 3.0, 4.0];
        let shared = reading.finish().unwrap().expect("a channel").vectors(&codes, Vec3::ZERO).unwrap();
        let one_by_one = [(0, 0.0, Some(0.0)), (1, 1.0, Some(5.0)), (2, 2.0, Some(5.0)), (3, 3.0, Some(0.0))];
        let one_by_one = channel(&[one_by_one.as_slice(), &[(4, 4.0, Some(-0.0))]].concat());
        assert_eq!(shared, one_by_one.vectors(&codes, Vec3::ZERO).unwrap());
        let Keys::Moving(moving) = &shared[1] else { panic!("the second element moves: {shared:?}") };
        let xs: Vec<u32> = moving.iter().map(|v| v.x.to_bits()).collect();
        assert_eq!(xs, [0.0f32, 5.0, 5.0, 0.0, -0.0].map(f32::to_bits));
    }

    #[test]
    fn a_sample_at_no_finite_time_is_dropped_and_one_that_does_not_fit_reads_as_the_identity() {
        // Stored unsorted: index 1 is the last in time.
        let samples = [(0, 0.0, Some(0.0)), (1, 3.0, None), (2, f64::NAN, Some(9.0)), (3, 2.0, Some(2.0))];
        let channel = channel(&samples);
        assert_eq!(channel.codes(), [0.0, 2.0, 3.0]);
        let keys = channel.vectors(&[0.0, 1.0, 2.5, 3.0], Vec3::ZERO).unwrap();
        // Between a fitting sample and one that does not, the earlier is held; at the one that does not fit, nothing
        // is read; every element then moves.
        let held: Arc<[Vec3]> = [Vec3::ONE, Vec3::ONE, Vec3::ONE, Vec3::ZERO].into();
        let moving: Arc<[Vec3]> = [x(0.0), x(1.0), x(2.0), Vec3::ZERO].into();
        assert_eq!(keys, vec![Keys::Moving(held), Keys::Moving(moving)]);
    }

    #[test]
    fn a_half_precision_sample_is_widened_exactly_and_a_second_type_is_no_channel() {
        let half = |x: f32| gf::Vec3h { x: f16::from_f32(x), y: f16::ZERO, z: f16::from_f32(-x) };
        let mut reading = Reading { channel: None, mixed: false, refused: None, len: 1, widened: Vec::new() };
        reading.add(TimeSample { at: vec![(0, 0.0)], value: Value::Vec3hVec(vec![half(0.1)]), count: 1 });
        let widened = f16::from_f32(0.1).to_f32();
        let keys = reading.finish().unwrap().expect("a channel").vectors(&[0.0], Vec3::ZERO).unwrap();
        assert_eq!(keys, vec![Keys::Held(Vec3::new(widened, 0.0, -widened))]);

        let mut reading = Reading { channel: None, mixed: false, refused: None, len: 1, widened: Vec::new() };
        reading.add(TimeSample { at: vec![(0, 0.0)], value: Value::Vec3hVec(vec![half(0.1)]), count: 2 });
        reading.add(TimeSample {
            at: vec![(1, 1.0)],
            value: Value::Vec3fVec(vec![gf::vec3f(0.1, 0.0, 0.0)]),
            count: 2,
        });
        assert!(matches!(reading.finish(), Ok(None)));
    }

    #[test]
    fn a_channel_is_refused_once_the_columns_made_would_pass_the_budget() {
        // Two samples of a hundred joints, every joint moving between them, in a layer that says it has 65,536
        // samples (sharing those two values, say): the layer decodes two arrays, each column takes 786 kB.
        let (samples, joints) = (1 << 16, 100);
        let sample = |index: usize, x: f32| {
            let value = Value::Vec3fVec(vec![gf::vec3f(x, 0.0, 0.0); joints]);
            TimeSample { at: vec![(index, index as f64)], value, count: samples }
        };
        let column = samples * size_of::<Vec3>();
        let read = |budget: usize| {
            let mut reading = Reading { channel: None, mixed: false, refused: None, len: joints, widened: Vec::new() };
            let (finished, peak) = openusd::usdc::budget::within(budget as u64, || {
                reading.add(sample(0, 0.0));
                reading.add(sample(1, 1.0));
                reading.finish()
            });
            (finished.map(|channel| channel.is_some()), peak as usize)
        };
        // Room for 8 columns: refused at the one that does not fit, having made no more than fit.
        let (refused, peak) = read(8 * column);
        let refused = refused.expect_err("refused");
        assert!(refused.contains(&format!("over the reader's budget of {}", 8 * column)), "{refused}");
        assert!(peak <= 9 * column, "{peak} bytes charged");
        // Room for every column and what the reading keeps besides: read.
        let (read, peak) = read(joints * column + (1 << 24));
        assert_eq!(read, Ok(true));
        assert!(peak >= joints * column, "every column charged: {peak} bytes");
    }
}
