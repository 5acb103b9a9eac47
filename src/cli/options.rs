//! Options shared by several commands, defined once.

use anyhow::{Context, anyhow, bail};
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::{Args, ValueEnum};

use crate::analysis::Tolerances;
use crate::import::Format;
use crate::model::{Choice, Clip, InheritMode, ModeChoice, Rig};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum OutputFormat {
    /// Aligned columns for people; flagged bones marked.
    #[default]
    Table,
    /// One JSON document on standard output.
    Json,
}

/// The parser of one of the library's [`Choice`]s: its ids, each listed in `--help` with its description.
pub fn choice<T: Choice>() -> impl TypedValueParser<Value = T> {
    let values = T::ALL.iter().map(|v| PossibleValue::new(v.id()).help(v.description()));
    // Clap lets through only the ids listed, each of which is a value's.
    PossibleValuesParser::new(values).map(|id| T::from_id(&id).expect("an id of a listed value"))
}

/// The clip named `name`, or with index `name`; the error lists the available ones.
pub fn find_clip<'a>(rig: &'a Rig, name: &str) -> anyhow::Result<&'a Clip> {
    rig.clip_named(name).map_err(|why| anyhow!(why))
}

pub fn parse_bone_mode(s: &str) -> Result<(String, InheritMode), String> {
    let (name, mode) = parse_assignment(s)?;
    Ok((name, mode.parse().map_err(|e| format!("{e}"))?))
}

/// `NAME=VALUE` (split at the last `=`: names from files may hold one, values do not).
pub fn parse_assignment(s: &str) -> Result<(String, String), String> {
    let (name, value) = s.rsplit_once('=').ok_or_else(|| format!("expected NAME=VALUE, got `{s}`"))?;
    Ok((name.to_owned(), value.to_owned()))
}

/// An angle in degrees: a finite number ≥ 0.
pub fn parse_angle(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(angle) if angle.is_finite() && angle >= 0.0 => Ok(angle),
        _ => Err(format!("expected a finite number of degrees ≥ 0, got `{s}`")),
    }
}

/// Samples per second: a finite number ≥ 0 (0: the key times alone).
pub fn parse_rate(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(rate) if rate.is_finite() && rate >= 0.0 => Ok(rate),
        _ => Err(format!("expected a finite number of samples per second ≥ 0, got `{s}`")),
    }
}

/// A distance in model units or relative to the rig's size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Distance {
    Units(f64),
    Percent(f64),
}

impl Distance {
    pub fn units(self, rig_size: f64) -> f64 {
        match self {
            Distance::Units(d) => d,
            Distance::Percent(p) => p / 100.0 * rig_size,
        }
    }
}

pub fn parse_distance(s: &str) -> Result<Distance, String> {
    let (number, percent) = match s.trim().strip_suffix('%') {
        Some(number) => (number, true),
        None => (s.trim(), false),
    };
    let value: f64 =
        number.trim().parse().map_err(|_| format!("`{s}` is not a distance (a number, or a number and %)"))?;
    if !(value.is_finite() && value >= 0.0) {
        return Err(format!("the distance must be finite and ≥ 0, got `{s}`"));
    }
    Ok(if percent { Distance::Percent(value) } else { Distance::Units(value) })
}

/// The position in `rig.clips` of the clip `--option` names.
pub fn clip_index(rig: &Rig, option: &str, name: &str) -> anyhow::Result<usize> {
    let clip = find_clip(rig, name).with_context(|| option.to_owned())?;
    rig.clips.iter().position(|c| std::ptr::eq(c, clip)).ok_or_else(|| anyhow!("{option}: no animation `{name}`"))
}

/// `A,B`: two mode choices to compare.
pub fn parse_comparison(s: &str) -> Result<[ModeChoice; 2], String> {
    let (a, b) = s.split_once(',').ok_or_else(|| format!("expected two modes separated by a comma, got `{s}`"))?;
    let parse = |p: &str| p.trim().parse::<ModeChoice>().map_err(|e| e.to_string());
    Ok([parse(a)?, parse(b)?])
}

/// The help of an argument naming animation files: `what`, the formats read ([`Format::listed`]), then `rest` (what
/// more it may name; a help line ends without a full stop).
pub fn files_help(what: &str, rest: &str) -> String {
    format!("{what} ({}; recognised by content){rest}", Format::listed())
}

/// The thresholds of the verdicts.
#[derive(Clone, Debug, Args)]
pub struct ToleranceArgs {
    /// A bone counts as stretched only when max/min of its scale factors exceeds 1 + this.
    #[arg(long, value_name = "RATIO", default_value_t = Tolerances::default().min_anisotropy)]
    pub min_anisotropy: f64,
    /// ...and its stretch rotation U turns by more than this many degrees.
    #[arg(long, value_name = "DEGREES", default_value_t = Tolerances::default().min_stretch_deg)]
    pub min_stretch_deg: f64,
    /// ...and it shears by more than this many degrees (the largest deviation from 90° between two axes).
    #[arg(long, value_name = "DEGREES", default_value_t = Tolerances::default().min_shear_deg)]
    pub min_shear_deg: f64,
    /// A bone not stretched counts as non-uniformly scaled when max/min of its scale factors exceeds 1 + this (below
    /// it, the rounding exporters leave on a scale of 1).
    #[arg(long, value_name = "RATIO", default_value_t = Tolerances::default().min_non_uniform)]
    pub min_non_uniform: f64,
}

impl ToleranceArgs {
    pub fn tolerances(&self) -> anyhow::Result<Tolerances> {
        let values = [
            ("--min-anisotropy", self.min_anisotropy),
            ("--min-stretch-deg", self.min_stretch_deg),
            ("--min-shear-deg", self.min_shear_deg),
            ("--min-non-uniform", self.min_non_uniform),
        ];
        for (name, value) in values {
            if !(value >= 0.0 && value.is_finite()) {
                bail!("{name} must be a finite number ≥ 0, got {value}");
            }
        }
        Ok(Tolerances {
            min_anisotropy: self.min_anisotropy,
            min_stretch_deg: self.min_stretch_deg,
            min_shear_deg: self.min_shear_deg,
            min_non_uniform: self.min_non_uniform,
            ..Tolerances::default()
        })
    }
}

#[cfg(test)]
mod tests {
    use clap::builder::TypedValueParser;

    use super::*;
    use crate::bake::{Engine, Strategy};
    use crate::eval::SkinningMethod;
    use crate::eval::layers::{
        AdditiveOrder, AdditiveReference, FadeCurve, KeyInterpolation, RotationBlend, RotationInterpolation,
    };

    /// Every value of `T` parses from its id on the command line, its id is what the JSON reports write, and its
    /// help says something; anything else is refused.
    fn parses_by_id<T: Choice + serde::Serialize + std::fmt::Debug>() {
        let command = clap::Command::new("test");
        let parser = choice::<T>();
        for &value in T::ALL {
            let parsed = parser.parse_ref(&command, None, std::ffi::OsStr::new(value.id())).unwrap();
            assert_eq!(parsed, value);
            assert_eq!(serde_json::to_string(&value).unwrap(), format!("\"{}\"", value.id()));
            assert!(!value.description().is_empty(), "{value:?}");
        }
        assert!(parser.parse_ref(&command, None, std::ffi::OsStr::new("sideways")).is_err());
    }

    #[test]
    fn every_choice_parses_by_the_id_its_reports_write() {
        parses_by_id::<Strategy>();
        parses_by_id::<Engine>();
        parses_by_id::<SkinningMethod>();
        parses_by_id::<KeyInterpolation>();
        parses_by_id::<RotationInterpolation>();
        parses_by_id::<RotationBlend>();
        parses_by_id::<AdditiveReference>();
        parses_by_id::<AdditiveOrder>();
        parses_by_id::<FadeCurve>();
        parses_by_id::<InheritMode>();
        parses_by_id::<ModeChoice>();
    }
}
