//! Aligned text tables for people, and the pieces every report shares (how a path is shown, a mesh table).

use std::fmt;

use crate::diff::MeshDifference;
use crate::model::At;

/// Columns aligned by the widest cell; numbers (columns marked right-aligned) line up on the right.
pub struct Table {
    headers: Vec<&'static str>,
    right: Vec<bool>,
    rows: Vec<Vec<String>>,
}

impl Table {
    /// `columns`: header and whether the column is right-aligned.
    pub fn new(columns: &[(&'static str, bool)]) -> Self {
        Table {
            headers: columns.iter().map(|c| c.0).collect(),
            right: columns.iter().map(|c| c.1).collect(),
            rows: Vec::new(),
        }
    }

    pub fn row(&mut self, cells: Vec<String>) {
        debug_assert_eq!(cells.len(), self.headers.len());
        self.rows.push(cells);
    }
}

/// The frame `time` falls on at `rate`, for a table's frame column (empty without a usable rate).
pub fn frame_at(time: f64, rate: Option<f64>) -> String {
    At { time, rate }.frame().map_or_else(String::new, crate::model::frames)
}

impl fmt::Display for Table {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut widths: Vec<usize> = self.headers.iter().map(|h| h.chars().count()).collect();
        for row in &self.rows {
            for (w, cell) in widths.iter_mut().zip(row) {
                *w = (*w).max(cell.chars().count());
            }
        }
        let headers = self.headers.iter().map(|h| h.to_string()).collect::<Vec<_>>();
        for row in std::iter::once(&headers).chain(&self.rows) {
            let mut line = String::new();
            for ((cell, &width), &right) in row.iter().zip(&widths).zip(&self.right) {
                let pad = width - cell.chars().count();
                line.push_str("  ");
                if right {
                    line.extend(std::iter::repeat_n(' ', pad));
                    line.push_str(cell);
                } else {
                    line.push_str(cell);
                    line.extend(std::iter::repeat_n(' ', pad));
                }
            }
            writeln!(f, "{}", line.trim_end())?;
        }
        Ok(())
    }
}

/// Per mesh of a comparison: its vertices, the largest vertex distance (model units and percent of `rig_size`)
/// with its time, and the mean distance.
pub fn mesh_differences(meshes: &[MeshDifference], rig_size: f64) -> Table {
    let percent = |v: f64| format!("{:.6} %", 100.0 * v / rig_size);
    let mut table = Table::new(&[
        ("mesh", false),
        ("vertices", true),
        ("max", true),
        ("of rig", true),
        ("at s", true),
        ("mean", true),
        ("of rig", true),
    ]);
    for mesh in meshes {
        table.row(vec![
            mesh.name.clone(),
            mesh.vertices.to_string(),
            format!("{:.3e}", mesh.distance.max),
            percent(mesh.distance.max),
            format!("{:.4}", mesh.distance.time),
            format!("{:.3e}", mesh.mean),
            percent(mesh.mean),
        ]);
    }
    table
}

/// `(x, y, z)` with fixed decimals.
pub fn vector(values: &[f64]) -> String {
    let parts: Vec<String> = values.iter().map(|v| format!("{:.4}", v + 0.0)).collect();
    format!("({})", parts.join(", "))
}

/// A path as reports print it: a file's name may hold control characters, which must not reach a terminal.
pub fn shown(path: &std::path::Path) -> String {
    crate::import::text::printable(&path.display().to_string()).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_align() {
        let mut t = Table::new(&[("name", false), ("value", true)]);
        t.row(vec!["a".into(), "1.5".into()]);
        t.row(vec!["longer".into(), "10.25".into()]);
        assert_eq!(t.to_string(), "  name    value\n  a         1.5\n  longer  10.25\n");
        assert_eq!(vector(&[-0.0, 1.0]), "(0.0000, 1.0000)");
    }
}
