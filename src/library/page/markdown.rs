//! The Markdown summary: the verdict and the worst rows, sized for a CI job's summary (GitHub's
//! `$GITHUB_STEP_SUMMARY` holds 1 MiB), with a pointer to the HTML page for the rest.

use super::{Overview, What, clip_label, time_text};

/// How many rows the summary lists.
pub const ROWS: usize = 20;

/// The summary of `overview`; `page` says where the HTML page is (a link, or the artifact's name).
pub fn markdown(overview: &Overview, page: &str) -> String {
    let mut out = format!("## bonescope: {}\n\n{}\n\n", overview.verdict, cell(&overview.summary()));
    out.push_str("| worst shear | file | clip | worst bone |\n|---:|---|---|---|\n");
    for row in overview.rows.iter().take(ROWS) {
        let line = match row.what {
            What::Refused(error) => format!("| refused | {} | {} | |\n", code(row.file), cell(error)),
            What::Clip(clip) => {
                let worst = clip.stretched.first().map_or_else(
                    || "none".to_owned(),
                    |b| format!("{} at {}", cell(&b.name), time_text(clip, b.summary.worst_shear_time)),
                );
                let shear = clip.stretched.first().map_or(0.0, |b| b.summary.worst_shear_deg);
                format!("| {shear:.3}° | {} | {} | {worst} |\n", code(row.file), cell(&clip_label(clip)))
            }
        };
        out.push_str(&line);
    }
    if overview.rows.len() > ROWS {
        out.push_str(&format!("\n{} more rows in the page.\n", overview.rows.len() - ROWS));
    }
    out.push_str(&format!("\nEvery clip, with a picture of its worst moment: {page}\n"));
    out
}

/// Text for a table cell: control characters escaped, and what Markdown or HTML would read escaped too.
fn cell(text: &str) -> String {
    let text = crate::import::text::printable(text);
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '|' | '\\' | '*' | '_' | '`' | '[' | ']' => {
                out.push('\\');
                out.push(c);
            }
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            '\n' | '\r' => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// A file name as code: escaped as a cell, in a code span where it holds no backtick.
fn code(text: &str) -> String {
    if text.contains('`') {
        cell(text)
    } else {
        format!("`{}`", crate::import::text::printable(text).replace('|', "\\|"))
    }
}
