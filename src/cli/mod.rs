//! The command line: `inspect` prints exact numbers for chosen times, `scan` summarises whole clips (or compares two
//! inheritance modes), `storage` measures the stretch-quaternion storage of whole clips, `export` writes the
//! evaluated meshes of one time, `render` draws the viewport to PNG, `bake` writes any inheritance as plain glTF,
//! `diff` compares two evaluations, `explain` says whose scale shears a bone and which fix costs least, `fit` says
//! which mode a runtime's pose dump implements.
//!
//! Exit codes: 0 success; 1 `scan --fail-above` found a stretched bone, `render --reference` found a picture over
//! its threshold, `bake --fail-above` or `diff --fail-above` a difference over its limit, `fit` no mode that fits the dump; 2 bad usage or a file that
//! cannot be loaded (after reporting every file that could).

mod bake;
mod diff;
mod explain;
mod export;
mod fit;
mod inspect;
mod layers;
mod options;
#[cfg(feature = "gui")]
mod render;
mod report;
mod scan;
mod setup;
mod table;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

pub use layers::{LayerArgs, TargetArg};
pub use options::{OutputFormat, ToleranceArgs};
pub use setup::EvalArgs;

/// See what a skeletal animation really does to every bone: polar decomposition (T·F·R·U·K·Uᵀ) of every bone's
/// matrices, stretched (sheared) bones, and what each scale-inheritance mode makes of them.
///
/// Without a command, opens the desktop app on FILE (or on a built-in demo rig).
#[derive(Debug, Parser)]
#[command(name = "bonescope", version, about, long_about = None, args_conflicts_with_subcommands = true)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// The most memory one file may make bonescope use, e.g. 8GiB or 512M (default: half the machine's memory,
    /// at most a quarter of the process's address-space limit); a file estimated to need more is refused.
    #[arg(long, global = true, value_name = "SIZE", value_parser = crate::import::budget::parse_size)]
    pub max_memory: Option<u64>,
    #[arg(help = options::files_help("The animation file to open in the app", ""))]
    pub file: Option<std::path::PathBuf>,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Print every bone's local and model matrix, their decomposition and findings at chosen times.
    Inspect(inspect::InspectArgs),
    /// Scan whole clips of one or more files and report the stretched bones.
    Scan(scan::ScanArgs),
    /// Measure each clip's stretch-quaternion storage: the bones that need a stretch channel, its bytes, and the
    /// error of rebuilding the matrices with it and without it.
    Storage(scan::StorageArgs),
    /// Merge the JSON lines of several scans (a library's shards) into one report and exit code.
    Report(report::ReportArgs),
    /// Write every mesh as evaluated at one time (skinned), in the file's own units and axes.
    Export(export::ExportArgs),
    /// Explain why bones shear: whose scale causes it (each bone of the chain with its scale made uniform), when,
    /// and the fixes (another mode on one bone, one scale made uniform, a bake) ranked by how far they move the skin.
    Explain(explain::ExplainArgs),
    /// Bake any scale inheritance into a plain glTF binary that every engine plays exactly (or as the closest TRS).
    Bake(bake::BakeArgs),
    /// Compare two evaluations (two files, or one under two sets of modes) over time, bone by bone.
    Diff(diff::DiffArgs),
    /// Say which scale inheritance a runtime's pose dump implements: the source under every mode against the
    /// dump, bone by bone (exit 1 when no mode fits).
    Fit(fit::FitArgs),
    /// Render the viewport (or the whole window) to PNG without a display, optionally checked against a reference.
    #[cfg(feature = "gui")]
    Render(render::RenderArgs),
    /// Render the viewport to PNG (needs the `gui` feature, which this build was made without).
    #[cfg(not(feature = "gui"))]
    Render {
        #[arg(trailing_var_arg = true, allow_hyphen_values = true, hide = true)]
        args: Vec<std::ffi::OsString>,
    },
}

/// What a build without the `gui` feature says of what needs it.
#[cfg(not(feature = "gui"))]
const NEEDS_GUI: &str = "needs the `gui` feature: install bonescope with its default features, from a checkout \
    `cargo install --path . --locked` (not --no-default-features)";

/// Parses the process arguments and runs the command.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    crate::import::budget::set_limit(cli.max_memory);
    let result = match cli.command {
        Some(Command::Inspect(args)) => inspect::run(&args),
        Some(Command::Scan(args)) => scan::run(&args),
        Some(Command::Storage(args)) => scan::run_storage(&args),
        Some(Command::Report(args)) => report::run(&args),
        Some(Command::Export(args)) => export::run(&args),
        #[cfg(feature = "gui")]
        Some(Command::Render(args)) => render::run(&args),
        #[cfg(not(feature = "gui"))]
        Some(Command::Render { .. }) => Err(anyhow::anyhow!("render {NEEDS_GUI}")),
        Some(Command::Explain(args)) => explain::run(&args),
        Some(Command::Bake(args)) => bake::run(&args),
        Some(Command::Diff(args)) => diff::run(&args),
        Some(Command::Fit(args)) => fit::run(&args),
        #[cfg(feature = "gui")]
        None => crate::app::run(cli.file).map(|()| ExitCode::SUCCESS).map_err(|e| anyhow::anyhow!("{e}")),
        #[cfg(not(feature = "gui"))]
        None => Err(anyhow::anyhow!("the desktop app {NEEDS_GUI}; the commands are listed by --help")),
    };
    match result {
        Ok(code) => code,
        // The reader closed the pipe (`bonescope … | head`): nothing more is wanted, and nothing went wrong here. The
        // status a program stopped by the closed pipe has.
        Err(error) if closed_pipe(&error) => ExitCode::from(128 + 13),
        Err(error) => {
            // One line, whatever a file put into the message (its names are escaped on import; paths and
            // options are escaped here).
            eprintln!("error: {}", crate::import::text::printable(&format!("{error:#}")));
            ExitCode::from(2)
        }
    }
}

/// Writes `text` to standard output: an error (a closed pipe among them) is returned, not a panic.
fn print_out(text: impl std::fmt::Display) -> anyhow::Result<()> {
    use std::io::Write;
    write!(std::io::stdout().lock(), "{text}")?;
    Ok(())
}

/// Writes `value` to standard output as pretty JSON and a line end, as it is serialised (a rig of a million bones
/// prints gigabytes, never held in memory whole). A failed write stays the I/O error it is, so that a closed pipe is
/// known as one.
fn print_json(value: &impl serde::Serialize) -> anyhow::Result<()> {
    use std::io::Write;
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    serde_json::to_writer_pretty(&mut out, value).map_err(std::io::Error::from)?;
    writeln!(out)?;
    out.flush()?;
    Ok(())
}

/// Whether `error` is standard output's reader gone.
fn closed_pipe(error: &anyhow::Error) -> bool {
    let kind = |e: &(dyn std::error::Error + 'static)| e.downcast_ref::<std::io::Error>().map(std::io::Error::kind);
    error.chain().any(|e| kind(e) == Some(std::io::ErrorKind::BrokenPipe))
}
