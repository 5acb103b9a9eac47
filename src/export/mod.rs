//! Writing evaluated geometry for other tools to read: Wavefront OBJ, and pose dumps (`dump`).
//!
//! Positions are written as evaluated (no axis or unit change: the caller chooses the space when loading), one
//! `g` group per mesh, triangles as `f` lines with 1-based indices. Numbers use Rust's shortest round-trip
//! formatting, so nothing is lost between bonescope and the reader.

mod dump;

pub use dump::DumpWriter;

use std::io::{self, Write};

use glam::DVec3;

/// One mesh as evaluated at some pose.
pub struct EvaluatedMesh<'a> {
    pub name: &'a str,
    pub positions: &'a [DVec3],
    /// Triangle list, indices into `positions`.
    pub indices: &'a [u32],
}

/// Writes `meshes` as one OBJ file; `header` lines become comments at the top.
pub fn write_obj(out: &mut impl Write, header: &[String], meshes: &[EvaluatedMesh]) -> io::Result<()> {
    for line in header {
        for part in line.lines() {
            writeln!(out, "# {part}")?;
        }
    }
    let mut first_vertex = 1usize;
    for mesh in meshes {
        // OBJ group names end at whitespace.
        let name: String = mesh.name.chars().map(|c| if c.is_whitespace() { '_' } else { c }).collect();
        writeln!(out, "g {}", if name.is_empty() { "mesh" } else { &name })?;
        for p in mesh.positions {
            writeln!(out, "v {} {} {}", p.x + 0.0, p.y + 0.0, p.z + 0.0)?;
        }
        for triangle in mesh.indices.chunks_exact(3) {
            let [a, b, c] = [triangle[0], triangle[1], triangle[2]].map(|i| first_vertex + i as usize);
            writeln!(out, "f {a} {b} {c}")?;
        }
        first_vertex += mesh.positions.len();
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_vertices_and_one_based_faces() {
        let a = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let b = [DVec3::new(0.5, -0.0, 2.0), DVec3::Z, DVec3::ONE];
        let meshes = [
            EvaluatedMesh { name: "first mesh", positions: &a, indices: &[0, 1, 2] },
            EvaluatedMesh { name: "b", positions: &b, indices: &[2, 1, 0] },
        ];
        let mut out = Vec::new();
        write_obj(&mut out, &["made by a test".to_owned()], &meshes).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert_eq!(
            text,
            "# made by a test\ng first_mesh\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\ng b\nv 0.5 0 2\nv 0 0 1\nv 1 1 1\nf 6 5 4\n"
        );
    }
}
