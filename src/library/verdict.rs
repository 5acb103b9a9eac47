//! What a library scan comes to: the exit code a CI job gates on, and the line a page says it in.

use std::fmt;

use crate::analysis::report::FileScan;

/// The verdict on a library scan under `--fail-above`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Verdict {
    /// Some files could not be loaded: how many.
    Refused(usize),
    /// Some clips hold a stretched bone shearing by more than the limit (degrees): how many clips.
    Over {
        clips: usize,
        limit: f64,
    },
    Pass,
}

impl Verdict {
    /// The verdict on `files`: refused files first, then clips over `fail_above` degrees where it is given (0: any
    /// stretched bone).
    pub fn of(files: &[FileScan], fail_above: Option<f64>) -> Self {
        let refused = files.iter().filter(|f| f.error.is_some()).count();
        let clips = files.iter().flat_map(|f| &f.animations);
        let over = |limit: f64| clips.filter(|a| a.stretched.iter().any(|b| b.summary.worst_shear_deg > limit)).count();
        match (refused, fail_above.map(|limit| (over(limit), limit))) {
            (0, Some((clips, limit))) if clips > 0 => Verdict::Over { clips, limit },
            (0, _) => Verdict::Pass,
            (refused, _) => Verdict::Refused(refused),
        }
    }

    /// The exit status: 2 for refused files, 1 for shear over the limit, else 0.
    pub fn exit_status(self) -> u8 {
        match self {
            Verdict::Refused(_) => 2,
            Verdict::Over { .. } => 1,
            Verdict::Pass => 0,
        }
    }
}

impl fmt::Display for Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let plural = super::page::count;
        match *self {
            Verdict::Refused(n) => write!(f, "fail (exit 2): {} could not be read", plural(n, "file", "files")),
            Verdict::Over { clips, limit: 0.0 } => {
                write!(f, "fail (exit 1): {} a stretched bone", plural(clips, "clip holds", "clips hold"))
            }
            Verdict::Over { clips, limit } => {
                write!(
                    f,
                    "fail (exit 1): {} shearing more than {limit}°",
                    plural(clips, "clip has a bone", "clips have a bone")
                )
            }
            Verdict::Pass => write!(f, "pass (exit 0)"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::report::FileReport;

    fn file(name: &str, error: Option<&str>) -> FileScan {
        FileReport { file: name.into(), error: error.map(Into::into), animations: Vec::new() }
    }

    #[test]
    fn refused_files_decide_before_shear_and_no_limit_passes() {
        let files = [file("a.glb", None), file("b.fbx", Some("b.fbx: not an FBX file"))];
        assert_eq!(Verdict::of(&files, Some(1.0)), Verdict::Refused(1));
        assert_eq!(Verdict::of(&files, None).exit_status(), 2);
        assert_eq!(Verdict::of(&files[..1], None), Verdict::Pass);
        assert_eq!(Verdict::Refused(1).to_string(), "fail (exit 2): 1 file could not be read");
        assert_eq!(
            Verdict::Over { clips: 3, limit: 1.5 }.to_string(),
            "fail (exit 1): 3 clips have a bone shearing more than 1.5°"
        );
    }
}
