//! `bonescope report`: the JSON lines of several scans (a library scanned in shards on many machines) as one
//! report and one exit code.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::{Args, ValueEnum};

use super::options::parse_angle;
use super::scan::{PAGE_TITLE, render_animation, render_files, verdict};
use crate::library::page::{self, Overview};
use crate::library::{junit, merge, read_json_lines};

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, ValueEnum)]
pub enum ReportFormat {
    /// Aligned columns for people, as `scan` prints them.
    #[default]
    Table,
    /// One JSON array of every file's report.
    Json,
    /// JUnit XML for CI test reporters.
    Junit,
    /// One self-contained HTML page: the verdict, a sortable, filterable row per clip with a picture of its worst
    /// moment, each stretched bone's shear over the clip, refused files with their error.
    Html,
    /// A GitHub-flavoured Markdown summary for a CI job's summary (`$GITHUB_STEP_SUMMARY`): the verdict, the worst
    /// 20 rows, and where the HTML page is (`--page`).
    Markdown,
}

#[derive(Debug, Args)]
pub struct ReportArgs {
    /// Files of `scan --format jsonl` output (one per shard, or `cat`-ed together).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    #[arg(long, value_enum, default_value_t)]
    pub format: ReportFormat,
    /// Exit with status 1 when a bone is stretched and shears by more than DEGREES (without a value: any stretched
    /// bone).
    #[arg(long, value_name = "DEGREES", num_args = 0..=1, default_missing_value = "0", value_parser = parse_angle, alias = "fail-on-stretch")]
    pub fail_above: Option<f64>,
    /// With `--format markdown`: where the HTML page is, as the summary's last line says it (a URL or a sentence).
    #[arg(long, value_name = "WHERE", default_value = "the HTML page among this run's artifacts")]
    pub page: String,
}

pub fn run(args: &ReportArgs) -> anyhow::Result<ExitCode> {
    let mut files = Vec::new();
    for path in &args.files {
        let text = std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))?;
        files.extend(read_json_lines(path, &text).map_err(anyhow::Error::msg)?);
    }
    let files = merge(files);
    match args.format {
        ReportFormat::Table => super::print_out(render_files(&files, &render_animation))?,
        ReportFormat::Json => super::print_json(&files)?,
        ReportFormat::Junit => super::print_out(format_args!("{}\n", junit(&files)))?,
        ReportFormat::Html => super::print_out(page::html(&Overview::new(&files, args.fail_above), PAGE_TITLE))?,
        ReportFormat::Markdown => {
            super::print_out(page::markdown(&Overview::new(&files, args.fail_above), &args.page))?
        }
    }
    for error in files.iter().filter_map(|f| f.error.as_deref()) {
        eprintln!("error: {}", crate::import::text::printable(error));
    }
    Ok(verdict(&files, args.fail_above))
}
