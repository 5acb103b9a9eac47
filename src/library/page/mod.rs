//! The page a library scan makes for people: one self-contained HTML file (a row per clip, each with a picture of
//! its worst moment) and a Markdown summary sized for a CI job's summary, both from the scan's reports alone.

mod html;
mod markdown;
mod svg;

pub use html::html;
pub use markdown::markdown;

use crate::analysis::report::{AnimationScan, FileScan};
use crate::library::Verdict;

/// A library scan as the page shows it.
pub struct Overview<'a> {
    pub files: usize,
    /// One per clip of every file read, and one per file refused.
    pub rows: Vec<Row<'a>>,
    pub verdict: Verdict,
    /// The limit `--fail-above` gave, in degrees.
    pub fail_above: Option<f64>,
}

/// One row: a clip of a file, or a file refused.
pub struct Row<'a> {
    pub file: &'a str,
    /// The file's extension, lowercase: the format people filter by.
    pub format: String,
    pub what: What<'a>,
}

/// What a row shows.
pub enum What<'a> {
    Clip(&'a AnimationScan),
    Refused(&'a str),
}

impl<'a> Overview<'a> {
    /// `files`, judged as `--fail-above` judges them, the refused files first, then the clips by worst shear.
    pub fn new(files: &'a [FileScan], fail_above: Option<f64>) -> Self {
        let mut rows: Vec<Row> = files.iter().flat_map(rows_of).collect();
        rows.sort_by(|a, b| b.sort_key().total_cmp(&a.sort_key()).then_with(|| a.file.cmp(b.file)));
        Overview { files: files.len(), rows, verdict: Verdict::of(files, fail_above), fail_above }
    }

    pub fn clips(&self) -> impl Iterator<Item = &AnimationScan> {
        self.rows.iter().filter_map(|row| match row.what {
            What::Clip(clip) => Some(clip),
            What::Refused(_) => None,
        })
    }

    /// The clips with a stretched bone, and how many bones stretch in them all.
    pub fn stretched(&self) -> (usize, usize) {
        let stretched: Vec<usize> = self.clips().map(|c| c.stretched.len()).filter(|&n| n > 0).collect();
        (stretched.len(), stretched.iter().sum())
    }

    pub fn refused(&self) -> usize {
        self.rows.iter().filter(|row| matches!(row.what, What::Refused(_))).count()
    }

    /// The summary line: "12 files, 30 clips: 4 clips with 9 stretched bones, 1 file refused; verdict: …".
    pub fn summary(&self) -> String {
        let (clips, bones) = self.stretched();
        let refused = match self.refused() {
            0 => String::new(),
            n => format!(", {}", count(n, "file refused", "files refused")),
        };
        format!(
            "{}, {}: {} with {}{refused}; {}",
            count(self.files, "file", "files"),
            count(self.clips().count(), "clip", "clips"),
            count(clips, "clip", "clips"),
            count(bones, "stretched bone", "stretched bones"),
            self.verdict_line()
        )
    }

    /// The verdict, with the limit it was judged by.
    pub fn verdict_line(&self) -> String {
        match self.fail_above {
            Some(limit) => format!("--fail-above {limit}: {}", self.verdict),
            None => format!("without --fail-above: {}", self.verdict),
        }
    }
}

impl Row<'_> {
    /// The worst shear of the clip (0 for none), a refused file above every clip.
    pub fn worst_shear_deg(&self) -> Option<f64> {
        match self.what {
            What::Clip(clip) => Some(clip.stretched.first().map_or(0.0, |b| b.summary.worst_shear_deg)),
            What::Refused(_) => None,
        }
    }

    fn sort_key(&self) -> f64 {
        self.worst_shear_deg().unwrap_or(f64::INFINITY)
    }
}

/// The rows of one file: its clips, or the reason it was refused.
fn rows_of(file: &FileScan) -> Vec<Row<'_>> {
    let format =
        std::path::Path::new(&file.file).extension().map_or_else(String::new, |e| e.to_string_lossy().to_lowercase());
    let row = |what| Row { file: &file.file, format: format.clone(), what };
    match &file.error {
        Some(error) => vec![row(What::Refused(error))],
        None => file.animations.iter().map(|clip| row(What::Clip(clip))).collect(),
    }
}

/// "1 file", "3 files".
pub fn count(n: usize, one: &str, many: &str) -> String {
    if n == 1 { format!("1 {one}") } else { format!("{n} {many}") }
}

/// A clip's name as a row shows it: its name, else its index.
pub fn clip_label(clip: &AnimationScan) -> String {
    match &clip.animation {
        Some(info) => info.name.clone().unwrap_or_else(|| format!("animation {}", info.index)),
        None => "rest pose".to_owned(),
    }
}

/// A time as the page prints it, with its frame at the clip's rate: "0.5539 s (frame 16.6)".
pub fn time_text(clip: &AnimationScan, time: f64) -> String {
    crate::model::At { time, rate: clip.animation.as_ref().map(|a| a.frame_rate) }.to_string()
}
