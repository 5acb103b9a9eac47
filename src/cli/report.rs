//! `bonescope report`: the JSON lines of several scans (a library scanned in shards on many machines) as one
//! report and one exit code.

use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Context;
use clap::{Args, ValueEnum};

use super::options::parse_angle;
use super::scan::{render_animation, render_files, verdict};
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
    }
    for error in files.iter().filter_map(|f| f.error.as_deref()) {
        eprintln!("error: {}", crate::import::text::printable(error));
    }
    Ok(verdict(&files, args.fail_above))
}
