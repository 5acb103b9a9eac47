//! A SkelAnimation's translations, rotations, scales or blend-shape weights as USD reads them at any time code: held before the first
//! sample and after the last, a sample's own at its time, and between two samples of the same length interpolated
//! with the arithmetic of Pixar's `Gf` types, which rounds every step to the attribute's precision: `GfLerp` is
//! `(1 − t)·a + t·b` with both products and their sum rounded (a `half3` held between two equal samples reads a
//! half step off), `GfSlerp` turns by `θ = acos(cos θ)` where `1 − cos θ > 10⁻⁵` and mixes linearly below, neither
//! normalised. The `openusd` crate rounds once and normalises a near-linear slerp: the same within the
//! precision of a `float`, not to the bit UsdSkel computes.

use std::borrow::Cow;

use glam::{Quat, Vec3};
use openusd::gf::{self, f16};
use openusd::sdf::Value;
use openusd::usd::{Attribute, Stage};

use super::said;

/// One channel's samples, by time code, in the type the file stores them in.
pub enum Channel {
    Half3(Samples<gf::Vec3h>),
    Float3(Samples<gf::Vec3f>),
    Double3(Samples<gf::Vec3d>),
    Quath(Samples<gf::Quath>),
    Quatf(Samples<gf::Quatf>),
    Quatd(Samples<gf::Quatd>),
    Float(Samples<f32>),
}

/// Time codes and the array at each, sorted by time code.
pub struct Samples<T>(Vec<(f64, Vec<T>)>);

impl Channel {
    /// The attribute's time samples, else its default value (held throughout); `None` where it has neither or
    /// holds another type.
    pub fn read(stage: &Stage, attribute: &Attribute) -> Result<Option<Channel>, String> {
        let mut samples = stage.time_samples(attribute.path().clone()).map_err(said)?.unwrap_or_default();
        samples.retain(|(code, _)| code.is_finite());
        if samples.is_empty() {
            let Some(default) = attribute.get::<Value>().map_err(said)? else { return Ok(None) };
            samples.push((0.0, default));
        }
        samples.sort_by(|a, b| a.0.total_cmp(&b.0));
        Ok(Channel::of(samples))
    }

    /// The channel of `samples`, all of one array type.
    fn of(samples: Vec<(f64, Value)>) -> Option<Channel> {
        macro_rules! typed {
            ($variant:ident, $channel:ident) => {
                samples
                    .into_iter()
                    .map(|(code, value)| match value {
                        Value::$variant(array) => Some((code, array)),
                        _ => None,
                    })
                    .collect::<Option<Vec<_>>>()
                    .map(|s| Channel::$channel(Samples(s)))
            };
        }
        match samples.first()?.1 {
            Value::Vec3hVec(_) => typed!(Vec3hVec, Half3),
            Value::Vec3fVec(_) => typed!(Vec3fVec, Float3),
            Value::Vec3dVec(_) => typed!(Vec3dVec, Double3),
            Value::QuathVec(_) => typed!(QuathVec, Quath),
            Value::QuatfVec(_) => typed!(QuatfVec, Quatf),
            Value::QuatdVec(_) => typed!(QuatdVec, Quatd),
            Value::FloatVec(_) => typed!(FloatVec, Float),
            _ => None,
        }
    }

    /// The vectors at time code `code` of the elements `picked`, where its array there has `len` elements (`None`
    /// otherwise, and for a rotation channel).
    pub fn vectors(&self, code: f64, len: usize, picked: &[usize]) -> Option<Vec<Vec3>> {
        match self {
            Channel::Half3(s) => s.picked(code, len, picked, |v| Vec3::new(v.x.into(), v.y.into(), v.z.into())),
            Channel::Float3(s) => s.picked(code, len, picked, |v| Vec3::new(v.x, v.y, v.z)),
            Channel::Double3(s) => s.picked(code, len, picked, |v| Vec3::new(v.x as f32, v.y as f32, v.z as f32)),
            _ => None,
        }
    }

    /// The numbers at time code `code` (`None` for a vector or rotation channel).
    pub fn numbers(&self, code: f64) -> Option<Vec<f32>> {
        match self {
            Channel::Float(s) => Some(s.at(code).into_owned()),
            _ => None,
        }
    }

    /// The rotations at time code `code` of the elements `picked`, as stored: not normalised, as UsdSkel makes a
    /// matrix of them (and as glTF's keys are read). `None` where its array there has not `len` elements, and for a
    /// vector channel.
    pub fn rotations(&self, code: f64, len: usize, picked: &[usize]) -> Option<Vec<Quat>> {
        let quat = |w: f64, x: f64, y: f64, z: f64| Quat::from_xyzw(x as f32, y as f32, z as f32, w as f32);
        let half = |h: f16| f64::from(h.to_f32());
        match self {
            Channel::Quath(s) => s.picked(code, len, picked, |q| quat(half(q.w), half(q.x), half(q.y), half(q.z))),
            Channel::Quatf(s) => s.picked(code, len, picked, |q| quat(q.w.into(), q.x.into(), q.y.into(), q.z.into())),
            Channel::Quatd(s) => s.picked(code, len, picked, |q| quat(q.w, q.x, q.y, q.z)),
            _ => None,
        }
    }

    /// The time codes of its samples.
    pub fn codes(&self) -> Vec<f64> {
        each!(self, s => s.0.iter().map(|(c, _)| *c).collect())
    }

    /// Per element of arrays of length `len`, whether every sample's array has that length and holds the same
    /// value there: held throughout.
    pub fn held(&self, len: usize) -> Vec<bool> {
        each!(self, s => s.held(len))
    }
}

/// `$body` with `$s` bound to the samples of whichever type `$channel` holds.
macro_rules! each {
    ($channel:expr, $s:ident => $body:expr) => {
        match $channel {
            Channel::Half3($s) => $body,
            Channel::Float3($s) => $body,
            Channel::Double3($s) => $body,
            Channel::Quath($s) => $body,
            Channel::Quatf($s) => $body,
            Channel::Quatd($s) => $body,
            Channel::Float($s) => $body,
        }
    };
}
use each;

impl<T: PartialEq> Samples<T> {
    fn held(&self, len: usize) -> Vec<bool> {
        let Some((_, first)) = self.0.first().filter(|(_, a)| a.len() == len) else { return vec![false; len] };
        let mut held = vec![true; len];
        // Sample by sample, each array read in order, while some element may still be held.
        for (_, array) in &self.0 {
            if array.len() != len {
                return vec![false; len];
            }
            if !held.contains(&true) {
                continue;
            }
            held.iter_mut().zip(array.iter().zip(first)).for_each(|(h, (v, f))| *h &= v == f);
        }
        held
    }
}

impl<T: Mix> Samples<T> {
    /// The elements `picked` of the array at `code`, each made a `U`, where the array has `len` elements.
    fn picked<U>(&self, code: f64, len: usize, picked: &[usize], into: impl Fn(&T) -> U) -> Option<Vec<U>> {
        let array = self.at(code);
        (array.len() == len).then(|| picked.iter().map(|&i| into(&array[i])).collect())
    }

    /// The array at time code `code`: a sample's own (borrowed) at its time and outside the samples, else mixed.
    fn at(&self, code: f64) -> Cow<'_, [T]> {
        let samples = &self.0;
        let next = samples.partition_point(|(c, _)| *c <= code);
        match (next.checked_sub(1).map(|i| &samples[i]), samples.get(next)) {
            (Some((c0, a)), Some((c1, b))) if *c0 != code && a.len() == b.len() => {
                let t = (code - c0) / (c1 - c0);
                Cow::Owned(a.iter().zip(b).map(|(a, b)| T::mix(a, b, t)).collect())
            }
            (Some((_, a)), _) | (None, Some((_, a))) => Cow::Borrowed(a),
            (None, None) => Cow::Borrowed(&[]),
        }
    }
}

/// A value between two samples at `t`, as Pixar's `Gf` computes it.
pub trait Mix: Clone {
    fn mix(a: &Self, b: &Self, t: f64) -> Self;
}

/// `half(half(a·(1 − t)) + half(b·t))`: `GfVec3h`'s scaling and sum, each rounded to half precision.
fn lerp_half(a: f16, b: f16, t: f64) -> f16 {
    let scaled = |h: f16, s: f64| f16::from_f32(h.to_f32() * s as f32);
    f16::from_f32(scaled(a, 1.0 - t).to_f32() + scaled(b, t).to_f32())
}

/// `float(float(a·(1 − t)) + float(b·t))`: `GfVec3f`'s scaling and sum, each rounded to single precision.
fn lerp_float(a: f32, b: f32, t: f64) -> f32 {
    (f64::from(a) * (1.0 - t)) as f32 + (f64::from(b) * t) as f32
}

/// `GfLerp` of two `float`s: computed in double precision, rounded once.
impl Mix for f32 {
    fn mix(a: &Self, b: &Self, t: f64) -> Self {
        ((1.0 - t) * f64::from(*a) + t * f64::from(*b)) as f32
    }
}

impl Mix for gf::Vec3h {
    fn mix(a: &Self, b: &Self, t: f64) -> Self {
        gf::vec3h(lerp_half(a.x, b.x, t), lerp_half(a.y, b.y, t), lerp_half(a.z, b.z, t))
    }
}

impl Mix for gf::Vec3f {
    fn mix(a: &Self, b: &Self, t: f64) -> Self {
        gf::vec3f(lerp_float(a.x, b.x, t), lerp_float(a.y, b.y, t), lerp_float(a.z, b.z, t))
    }
}

impl Mix for gf::Vec3d {
    fn mix(a: &Self, b: &Self, t: f64) -> Self {
        let lerp = |a: f64, b: f64| (1.0 - t) * a + t * b;
        gf::Vec3d { x: lerp(a.x, b.x), y: lerp(a.y, b.y), z: lerp(a.z, b.z) }
    }
}

/// `GfSlerp`'s weights of the two quaternions `(w, x, y, z)` at `t`: the angle between them found in `f32` (as for
/// `GfQuatf`), the shorter way round.
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

impl Mix for gf::Quatf {
    fn mix(a: &Self, b: &Self, t: f64) -> Self {
        let (pa, pb) = ([a.w, a.x, a.y, a.z].map(f64::from), [b.w, b.x, b.y, b.z].map(f64::from));
        let (w0, w1) = slerp_weights(pa, pb, t, true);
        let c = |x: f32, y: f32| (f64::from(x) * w0) as f32 + (f64::from(y) * w1) as f32;
        gf::quatf(c(a.w, b.w), c(a.x, b.x), c(a.y, b.y), c(a.z, b.z))
    }
}

impl Mix for gf::Quath {
    fn mix(a: &Self, b: &Self, t: f64) -> Self {
        let wide = |q: &gf::Quath| [q.w, q.x, q.y, q.z].map(|h| f64::from(h.to_f32()));
        let (w0, w1) = slerp_weights(wide(a), wide(b), t, true);
        let c = |x: f16, y: f16| {
            let scaled = |h: f16, s: f64| f16::from_f32(h.to_f32() * s as f32);
            f16::from_f32(scaled(x, w0).to_f32() + scaled(y, w1).to_f32())
        };
        gf::Quath { w: c(a.w, b.w), x: c(a.x, b.x), y: c(a.y, b.y), z: c(a.z, b.z) }
    }
}

impl Mix for gf::Quatd {
    fn mix(a: &Self, b: &Self, t: f64) -> Self {
        let (w0, w1) = slerp_weights([a.w, a.x, a.y, a.z], [b.w, b.x, b.y, b.z], t, false);
        let c = |x: f64, y: f64| x * w0 + y * w1;
        gf::Quatd { w: c(a.w, b.w), x: c(a.x, b.x), y: c(a.y, b.y), z: c(a.z, b.z) }
    }
}
