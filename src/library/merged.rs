//! Reports of several scans (the JSON lines of the shards of a library, `cat`-ed or not) read back as one.

use std::path::Path;

use crate::analysis::report::FileScan;

/// The file reports in JSON-lines `text` (one `scan --format jsonl` object per line; blank lines skipped), or an
/// error naming `source` and the line that is not one.
pub fn read_json_lines(source: &Path, text: &str) -> Result<Vec<FileScan>, String> {
    text.lines()
        .enumerate()
        .filter(|(_, line)| !line.trim().is_empty())
        .map(|(n, line)| {
            serde_json::from_str(line)
                .map_err(|e| format!("{}: line {}: not a `scan --format jsonl` report: {e}", source.display(), n + 1))
        })
        .collect()
}

/// The reports of all shards as one: sorted by file, a file reported twice (overlapping inputs) kept once.
pub fn merge(mut files: Vec<FileScan>) -> Vec<FileScan> {
    files.sort_by(|a, b| a.file.cmp(&b.file));
    files.dedup_by(|a, b| a.file == b.file);
    files
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_read_back_sorted_and_bad_lines_are_named() {
        let line = |file: &str| format!(r#"{{"file":"{file}","error":null,"animations":[]}}"#);
        let text = format!("{}\n\n{}\n{}\n", line("b.fbx"), line("a.glb"), line("b.fbx"));
        let files = merge(read_json_lines(Path::new("shard1.jsonl"), &text).unwrap());
        assert_eq!(files.iter().map(|f| f.file.as_str()).collect::<Vec<_>>(), ["a.glb", "b.fbx"]);
        let error = read_json_lines(Path::new("shard2.jsonl"), "{\"file\": 3}\n").unwrap_err();
        assert!(error.starts_with("shard2.jsonl: line 1: not a `scan --format jsonl` report"), "{error}");
    }
}
