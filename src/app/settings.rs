//! What persists across restarts (eframe storage): theme, recent files, camera, view toggles, time display.

use std::collections::BTreeMap;
use std::path::PathBuf;

use super::pane::{Layout, Pane, Visibility};
use crate::analysis::Tolerances;
use crate::eval::layers::TICKS_PER_SECOND;
use crate::model::{At, frames};
use crate::view::{Camera, SceneOptions};

/// How times are shown, on the clip's own clock. The library always works in seconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum TimeUnit {
    #[default]
    Seconds,
    /// Frames at the document's frame rate, counted on the clip's clock: frame `n` at `n / rate` (Blender's first
    /// frame, at 1/30 s, is frame 1).
    Frames,
    /// 3ds Max ticks, 4800 per second.
    Ticks,
}

impl TimeUnit {
    pub const ALL: [TimeUnit; 3] = [TimeUnit::Seconds, TimeUnit::Frames, TimeUnit::Ticks];

    pub fn label(self) -> &'static str {
        match self {
            TimeUnit::Seconds => "seconds",
            TimeUnit::Frames => "frames",
            TimeUnit::Ticks => "ticks",
        }
    }

    /// The time `seconds` in this unit, as text: seconds with their frame beside them; a frame number whole on a
    /// frame, with a decimal between frames.
    pub fn format(self, seconds: f64, frame_rate: f64) -> String {
        match self {
            TimeUnit::Seconds => At { time: seconds, rate: Some(frame_rate) }.to_string(),
            TimeUnit::Frames => format!("frame {}", frames(seconds * frame_rate)),
            TimeUnit::Ticks => format!("{:.0} ticks", seconds * TICKS_PER_SECOND),
        }
    }

    /// A length of `seconds` (how long a clip plays) in this unit, as text.
    pub fn format_length(self, seconds: f64, frame_rate: f64) -> String {
        match self {
            TimeUnit::Seconds => format!("{seconds:.3} s"),
            TimeUnit::Frames => format!("{} frames", frames(seconds * frame_rate)),
            TimeUnit::Ticks => self.format(seconds, frame_rate),
        }
    }

    /// The time a click at `seconds` means in this unit: the nearest whole frame when counting frames (a pointer
    /// cannot aim between them on purpose), the time itself otherwise.
    pub fn snap(self, seconds: f64, frame_rate: f64) -> f64 {
        match self {
            TimeUnit::Frames if frame_rate > 0.0 => (seconds * frame_rate).round() / frame_rate,
            _ => seconds,
        }
    }

    /// Seconds from text in this unit, as typed or as [`TimeUnit::format`] wrote it (`1.5`, `1.5 s`, `frame 45`,
    /// `7200 ticks`); `None` when no number is there.
    pub fn parse(self, text: &str, frame_rate: f64) -> Option<f64> {
        let value = text
            .split_whitespace()
            .find_map(|word| word.trim_matches(char::is_alphabetic).parse::<f64>().ok())
            .filter(|v| v.is_finite())?;
        Some(match self {
            TimeUnit::Seconds => value,
            TimeUnit::Frames => value / frame_rate,
            TimeUnit::Ticks => value / TICKS_PER_SECOND,
        })
    }
}

/// Which plotted quantity, and how rotations are shown.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum RotationFormat {
    #[default]
    Quaternion,
    /// XYZ Euler angles in degrees.
    Euler,
    /// Angle in degrees and unit axis.
    AxisAngle,
}

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct Settings {
    pub dark: bool,
    /// Most recent first.
    pub recent: Vec<PathBuf>,
    pub camera: Camera,
    pub scene: SceneOptions,
    /// The thresholds of the verdicts (View → Thresholds).
    pub tolerances: Tolerances,
    pub time_unit: TimeUnit,
    pub speed: f64,
    pub looping: bool,
    pub rotation_format: RotationFormat,
    /// Plot model-space components (else local).
    pub plot_model_space: bool,
    /// Plot the ghost's curves, dashed (a fix tried turns it on: its ghost is the clip before the fix).
    pub plot_ghost: bool,
    /// The panels shown or hidden in the View menu (the others as they start).
    pub shown: BTreeMap<Pane, bool>,
    /// Bones farther than this percentage of the rig's size from their partner in a compared file are badged.
    pub compare_threshold_percent: f64,
    /// How the panels are arranged; `None` until the first frame makes one for the window's width.
    pub layout: Option<Layout>,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            dark: true,
            recent: Vec::new(),
            camera: Camera::default(),
            scene: SceneOptions::default(),
            tolerances: Tolerances::default(),
            time_unit: TimeUnit::Seconds,
            speed: 1.0,
            looping: true,
            rotation_format: RotationFormat::Quaternion,
            plot_model_space: true,
            plot_ghost: false,
            shown: BTreeMap::new(),
            compare_threshold_percent: 0.01,
            layout: None,
        }
    }
}

/// How many recent files are kept.
const RECENT_FILES: usize = 10;

impl Settings {
    pub const STORAGE_KEY: &'static str = "bonescope-settings";

    /// Whether the panel `pane` shows, given how it starts.
    pub fn shows(&self, pane: &Pane, visibility: Visibility) -> bool {
        match visibility {
            Visibility::Always => true,
            starts => self.shown.get(pane).copied().unwrap_or(starts == Visibility::Shown),
        }
    }

    /// Shows or hides the panel `pane`.
    pub fn show(&mut self, pane: &Pane, shown: bool) {
        self.shown.insert(pane.clone(), shown);
    }

    /// The same with the panel `pane` shown or hidden.
    pub fn showing(mut self, pane: &Pane, shown: bool) -> Self {
        self.show(pane, shown);
        self
    }

    /// Puts `path` first in the recent files.
    pub fn remember(&mut self, path: PathBuf) {
        self.recent.retain(|p| p != &path);
        self.recent.insert(0, path);
        self.recent.truncate(RECENT_FILES);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_units() {
        assert_eq!(TimeUnit::Seconds.format(1.5, 30.0), "1.5000 s (frame 45)");
        assert_eq!(TimeUnit::Seconds.format_length(1.5, 30.0), "1.500 s");
        assert_eq!(TimeUnit::Frames.format(1.5, 30.0), "frame 45");
        assert_eq!(TimeUnit::Frames.format(1.0 / 30.0, 30.0), "frame 1", "Blender's first frame");
        assert_eq!(TimeUnit::Frames.format(1.51, 30.0), "frame 45.3");
        assert_eq!(TimeUnit::Frames.format_length(20959.0 / 120.0, 120.0), "20959 frames");
        assert_eq!(TimeUnit::Frames.snap(1.51, 30.0), 1.5);
        assert_eq!(TimeUnit::Seconds.snap(1.51, 30.0), 1.51);
        assert_eq!(TimeUnit::Ticks.format(1.5, 30.0), "7200 ticks");
    }

    #[test]
    fn recent_files_are_unique_most_recent_first_and_bounded() {
        let mut s = Settings::default();
        for i in 0..12 {
            s.remember(PathBuf::from(format!("{i}.glb")));
        }
        s.remember(PathBuf::from("5.glb"));
        assert_eq!(s.recent.len(), 10);
        assert_eq!(s.recent[0], PathBuf::from("5.glb"));
        assert_eq!(s.recent.iter().filter(|p| p.as_path() == std::path::Path::new("5.glb")).count(), 1);
        let json = serde_json::to_string(&s).unwrap();
        assert_eq!(serde_json::from_str::<Settings>(&json).unwrap(), s);
    }
}
