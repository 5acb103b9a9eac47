//! What a rig's lengths mean: the length of one model unit, in metres.

use std::fmt;
use std::str::FromStr;

/// The length of one unit of a rig's numbers, in metres (positive and finite). glTF states metres; FBX states its
/// `UnitScaleFactor` (and is converted to metres on import); BVH states nothing, and then a person does.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(into = "f64", try_from = "f64")]
pub struct Unit {
    metres: f64,
}

/// The units people name, as `(id, plural name, metres)`.
const NAMED: [(&str, &str, f64); 6] = [
    ("m", "metres", 1.0),
    ("cm", "centimetres", 0.01),
    ("mm", "millimetres", 0.001),
    ("in", "inches", 0.0254),
    ("ft", "feet", 0.3048),
    // The CMU motion capture database's skeletons (and the BVH conversions of them) measure in 1/0.45 inch.
    ("cmu", "CMU mocap units (1/0.45 in)", 0.0254 / 0.45),
];

/// The units a figure is commonly measured in, by id, and the height it then stands closest to: a person's.
const FIGURE_UNITS: [&str; 4] = ["m", "cm", "mm", "in"];
const FIGURE_HEIGHT_METRES: f64 = 1.7;

/// How close two lengths in metres must be for a unit to take a name (a file's single-precision factor included).
const SAME_LENGTH: f64 = 1e-6;

/// How close a scale must be to a ratio of units to be one: a few single-precision roundings.
const RATIO_PRECISION: f64 = 1e-6;

impl From<Unit> for f64 {
    fn from(unit: Unit) -> f64 {
        unit.metres
    }
}

impl TryFrom<f64> for Unit {
    type Error = String;

    fn try_from(metres: f64) -> Result<Unit, String> {
        Unit::metres(metres).ok_or_else(|| format!("a unit is a positive, finite length in metres, not {metres}"))
    }
}

impl Unit {
    pub const METRE: Unit = Unit { metres: 1.0 };

    /// A unit `metres` long; `None` unless that is positive and finite.
    pub fn metres(metres: f64) -> Option<Unit> {
        (metres > 0.0 && metres.is_finite()).then_some(Unit { metres })
    }

    pub fn in_metres(self) -> f64 {
        self.metres
    }

    /// The unit in which a figure `size` units across is closest to a person's height (1.7 m, compared as ratios):
    /// what a file that states none most likely measures in (a capture in centimetres stands about 170 of them).
    /// `None` for a size that is not positive and finite.
    pub fn likeliest_for_figure(size: f64) -> Option<Unit> {
        let off = |unit: &Unit| (size * unit.metres / FIGURE_HEIGHT_METRES).ln().abs();
        let units = FIGURE_UNITS.iter().filter_map(|id| id.parse::<Unit>().ok());
        units.filter(|_| size > 0.0 && size.is_finite()).min_by(|a, b| off(a).total_cmp(&off(b)))
    }

    /// `length` (in this unit, or in a rig's own numbers for `None`) for people: in m, cm, mm or µm as its size
    /// asks, to three significant digits, or in units where the unit is not known.
    pub fn readable(unit: Option<Unit>, length: f64) -> String {
        let Some(unit) = unit else {
            return format!("{} units", significant(length));
        };
        let metres = length * unit.metres;
        let (scale, name) = match metres.abs() {
            m if m >= 1.0 => (1.0, "m"),
            m if m >= 0.01 => (100.0, "cm"),
            m if m >= 1e-4 || m == 0.0 => (1000.0, "mm"),
            _ => (1e6, "µm"),
        };
        format!("{} {name}", significant(metres * scale))
    }

    /// How many `other`s one of this unit is: what a length in this unit is multiplied by to be in `other`.
    pub fn per(self, other: Unit) -> f64 {
        self.metres / other.metres
    }

    /// Whether `factor` turns lengths in one named unit into another (1, 100, 0.01, 2.54, …): a scale whose only job
    /// is a change of units, to single precision.
    pub fn is_ratio(factor: f64) -> bool {
        let named = || NAMED.into_iter().map(|(_, _, metres)| metres);
        named().any(|from| named().any(|to| (factor * to / from - 1.0).abs() < RATIO_PRECISION))
    }

    /// The units people name (`m`, `cm`, …), for pickers.
    pub fn named() -> impl Iterator<Item = Unit> {
        NAMED.into_iter().map(|(_, _, metres)| Unit { metres })
    }

    /// The name and id of this unit, when it has one.
    fn name(self) -> Option<(&'static str, &'static str)> {
        NAMED
            .into_iter()
            .find(|&(_, _, metres)| (self.metres / metres - 1.0).abs() < SAME_LENGTH)
            .map(|(id, name, _)| (id, name))
    }
}

impl fmt::Display for Unit {
    /// `centimetres`, or `units of 0.5 m` for a unit without a name.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.name() {
            Some((_, name)) => f.write_str(name),
            None => write!(f, "units of {} m", self.metres),
        }
    }
}

/// A unit that is neither named nor a positive number of metres.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("`{0}` is not a unit: expected m, cm, mm, in, ft, cmu, or the unit's length in metres (0.01)")]
pub struct UnknownUnit(pub String);

impl FromStr for Unit {
    type Err = UnknownUnit;

    /// An id (`cm`) or a length in metres (`0.01`).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let text = s.trim();
        let named = NAMED.into_iter().find(|(id, _, _)| id.eq_ignore_ascii_case(text)).map(|(_, _, m)| m);
        named.or_else(|| text.parse().ok()).and_then(Unit::metres).ok_or_else(|| UnknownUnit(s.to_owned()))
    }
}

/// `x` to three significant digits, without trailing zeros (scientific outside 1e-4..1e6).
pub(crate) fn significant(x: f64) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    if !(1e-4..1e6).contains(&x.abs()) {
        return format!("{x:.2e}");
    }
    let decimals = (2 - x.abs().log10().floor() as i32).max(0) as usize;
    let text = format!("{x:.decimals$}");
    if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.').to_owned() } else { text }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn units_parse_by_id_or_length_and_print_their_name() {
        let cm: Unit = "cm".parse().unwrap();
        assert_eq!(cm.in_metres(), 0.01);
        assert_eq!(cm.to_string(), "centimetres");
        assert_eq!(" IN ".parse::<Unit>().unwrap().to_string(), "inches");
        assert_eq!("0.001".parse::<Unit>().unwrap().to_string(), "millimetres");
        assert_eq!("0.5".parse::<Unit>().unwrap().to_string(), "units of 0.5 m");
        // A factor stored in single precision is still its unit.
        assert_eq!(Unit::metres(f64::from(0.01f32)).unwrap().to_string(), "centimetres");
        for bad in ["", "0", "-1", "inf", "NaN", "furlong"] {
            assert!(bad.parse::<Unit>().is_err(), "{bad}");
        }
        assert_eq!(Unit::metres(f64::NAN), None);
    }

    #[test]
    fn a_figure_is_measured_in_the_unit_it_stands_a_persons_height_in() {
        let id = |size: f64| Unit::likeliest_for_figure(size).and_then(Unit::name).map(|(id, _)| id);
        // Bandai Namco's capture stands 248 units tall: centimetres (2.48 m), not metres or inches (6.3 m).
        assert_eq!(id(248.0), Some("cm"));
        assert_eq!((id(1.8), id(1700.0), id(66.0)), (Some("m"), Some("mm"), Some("in")));
        assert_eq!((id(0.0), id(f64::NAN), id(-3.0)), (None, None, None));
    }

    #[test]
    fn ratios_of_units_are_told_from_other_scales() {
        for ratio in [1.0, 100.0, 0.01, 1000.0, 0.001, 10.0, 2.54, 1.0 / 0.0254, 12.0, f64::from(0.01f32)] {
            assert!(Unit::is_ratio(ratio), "{ratio}");
        }
        for scale in [0.03, 2.0, 0.5, 0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert!(!Unit::is_ratio(scale), "{scale}");
        }
    }

    #[test]
    fn a_length_converts_by_the_ratio_of_the_units() {
        // 1 CMU unit is 1/0.45 in = 0.0254/0.45 m ≈ 5.644 cm.
        let cmu: Unit = "cmu".parse().unwrap();
        let cm: Unit = "cm".parse().unwrap();
        assert!((cmu.per(cm) - 2.54 / 0.45).abs() < 1e-12);
        assert_eq!(Unit::METRE.per(cm), 100.0);
        assert_eq!(Unit::named().count(), NAMED.len());
    }

    #[test]
    fn lengths_read_in_the_unit_their_size_asks_for() {
        let cm = Unit::metres(0.01);
        assert_eq!(Unit::readable(cm, 0.04), "0.4 mm");
        assert_eq!(Unit::readable(cm, 250.0), "2.5 m");
        assert_eq!(Unit::readable(cm, 8.0), "8 cm");
        assert_eq!(Unit::readable(Some(Unit::METRE), 1.234_56e-7), "0.123 µm");
        assert_eq!(Unit::readable(Some(Unit::METRE), 0.0), "0 mm");
        assert_eq!(Unit::readable(None, 0.012_345), "0.0123 units");
        assert_eq!(Unit::readable(None, 3.0e-9), "3.00e-9 units");
    }
}
